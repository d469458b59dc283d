"""GUI test: a cloud lit by lightning in the real ParaView GUI, shown and played.

    PV_PLUGIN_PATH=build/lib/paraview-5.11/plugins/Nimbus \
    PYTHONPATH=build/lib/python3.11/site-packages Testing/with-display.sh \
        paraview --dr --script=Testing/Python/TestGuiLightningPlay.py

Run by the GUI at start-up, after the plugin has loaded: a small Nimbus Metaball Cloud, a
Nimbus Lightning and a Nimbus Lightning Illumination of the two (cheap settings), shown in the
GUI's render view. Every render of the view is watched (the Cloud mapper's last frame: its
sun, whether it was interactive, its quality). Checks:

- every frame of the lit cloud, from the first, is drawn at night (the plugin's first look
  sets the sun below the horizon before anything renders it: no daylight frame first);
- Play through the flash's last time steps draws interactive frames (the reduced work of
  the Cloud's frame budget), and the next frame after it is a full-quality still one
  (measurements/lightning-play-gui.py shows the GUI drawing it by itself);
- the time steps re-run neither the cloud source nor the density's upload nor the sun's
  multiple-scattering solve (only the illumination filter's relight runs per step);
- the representation's PlaybackInteractive is off again after Play.

Writes what it checks to stdout and ends the GUI with exit status 0 on success (os._exit).
"""
import os
import sys
import traceback

from paraview import simple


def check(condition, message):
    print(("ok    " if condition else "FAIL  ") + message, file=sys.__stdout__, flush=True)
    return bool(condition)


def proxy_factory(name):
    if not hasattr(simple, name):
        for folder in os.environ.get("PV_PLUGIN_PATH", "").split(os.pathsep):
            plugin = os.path.join(folder, "Nimbus.so")
            if os.path.exists(plugin):
                simple.LoadPlugin(plugin, ns=vars(simple))
    return getattr(simple, name)


def main():
    import nimbus
    ok = True
    view = simple.GetActiveViewOrCreate("RenderView")
    cloud = proxy_factory("NimbusMetaballCloud")(Dimensions=[48, 48, 32])
    bolt = proxy_factory("NimbusLightning")()
    lit = proxy_factory("NimbusLightningIllumination")(
        Input=cloud, Lightning=simple.OutputPort(bolt, 1), NumberOfDirections=14,
        LightSpacingMetres=750.0, UseDiskCache=0)
    frames = []
    window = view.GetRenderWindow()

    def rendered(*_):
        mapper = nimbus.find_cloud_mapper(view.SMProxy.GetRenderer())
        if mapper is not None:
            frames.append({"sun": mapper.GetLastSunElevationDegrees(),
                           "interactive": bool(mapper.GetLastFrameInteractive()),
                           "quality": mapper.GetLastFrameQuality(), "time": view.ViewTime})

    window.AddObserver("EndEvent", rendered)
    cloud_runs = []
    cloud.GetClientSideObject().AddObserver("EndEvent", lambda *_: cloud_runs.append(1))

    display = simple.Show(lit, view)
    simple.Hide(cloud, view)
    simple.Render(view)
    ok &= check(display.Representation == "Cloud", "shown as %s" % display.Representation)
    ok &= check(len(frames) > 0 and all(f["sun"] < -11.0 for f in frames),
                "every frame of the lit cloud at night, from the first: suns %s degrees"
                % [round(f["sun"], 1) for f in frames])
    ok &= check(display.SunElevationDegrees < -11.0,
                "the display's sun at %.1f degrees" % display.SunElevationDegrees)

    mapper = nimbus.find_cloud_mapper(view.SMProxy.GetRenderer())
    times = list(lit.TimestepValues)
    scene = simple.GetAnimationScene()
    scene.PlayMode = "Snap To TimeSteps"
    scene.AnimationTime = times[-6]
    simple.Render(view)
    uploads = mapper.GetNumberOfVolumeUploads()
    solves = mapper.GetNumberOfMultipleScatteringSolves()
    del cloud_runs[:]
    del frames[:]
    scene.Play()
    played = [f for f in frames if f["time"] > times[-6]]
    ok &= check(len(played) >= 4 and all(f["interactive"] for f in played),
                "Play: %d frames at the time steps after the start, interactive: %s" % (
                    len(played), [f["interactive"] for f in played]))
    # The GUI draws the still frame once its event loop runs (after this start-up script);
    # here a render asks for it.
    simple.Render(view)
    last = frames[-1] if frames else {}
    ok &= check(last.get("interactive") is False and last.get("quality") == 1.0 and
                abs(last.get("time", -1.0) - times[-1]) < 1e-9,
                "after Play: a still frame at the last time step (%s)" % last)
    ok &= check(all(f["sun"] < -11.0 for f in frames), "all played frames at night")
    ok &= check(not cloud_runs, "the cloud source ran %d times during Play" % len(cloud_runs))
    ok &= check(mapper.GetNumberOfVolumeUploads() == uploads,
                "density uploads during Play: %d" % (mapper.GetNumberOfVolumeUploads() - uploads))
    ok &= check(mapper.GetNumberOfMultipleScatteringSolves() == solves,
                "the sun's multiple-scattering solves during Play: %d" % (
                    mapper.GetNumberOfMultipleScatteringSolves() - solves))
    flag = display.SMProxy.GetProperty("PlaybackInteractive").GetElement(0)
    ok &= check(flag == 0, "PlaybackInteractive after Play: %d" % flag)
    return 0 if ok else 1


if __name__ == "__main__":
    try:
        status = main()
    except Exception:
        traceback.print_exc(file=sys.__stdout__)
        status = 1
    sys.stdout.flush()
    os._exit(status)
