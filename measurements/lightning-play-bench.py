"""Play of a lightning flash in ParaView (pvpython): frames per second, and where a frame goes.

    nice Testing/with-display.sh pvpython measurements/lightning-play-bench.py \
        --plugin build/lib/paraview-5.11/plugins/Nimbus/Nimbus.so [--size 1280 800] \
        [--cache-dir DIR] [--frames N] [--still] [--json out.json]

Builds the pipeline as the GUI's first Apply does: the default Nimbus Metaball Cloud, the
default Nimbus Lightning (its strokes shown as lines), a Nimbus Lightning Illumination of the
two shown as a Cloud with its sun 12 degrees below the horizon, the cloud itself hidden. It
times the first Apply (the filter's update, then the first render) and then steps the
animation through the flash's time steps as Play does (the scene's AnimationTime: every view
updated, then rendered).

Per time step it reports the wall time and its parts: the filter's RequestData (the relight),
the metaball cloud's and the lightning's RequestData (the upstream sources: the cloud must
not run again for a new time), the Cloud representation's RequestData (the data delivered to
it), the render, and the mapper's counters (density uploads, the sun's multiple-scattering
solves, sun-depth builds) and pass times (GPU timer queries).

By default the frames during Play are interactive, as the plugin's GUI makes them (the
representation's PlaybackInteractive property, set while the animation plays), and a still
frame follows the last; --still renders every step at full quality (what ParaView does
without the plugin's help). With `import nimbus` on PYTHONPATH
(build/lib/python3.11/site-packages) the mapper's counters are read.
"""
import argparse
import json
import os
import statistics
import sys
import tempfile
import time

from paraview.simple import (CreateRenderView, Delete, GetAnimationScene, Hide, LoadPlugin,
                             OutputPort, SetActiveView, Show)


class Timed:
    """Seconds spent in an algorithm's RequestData (its StartEvent to EndEvent), summed."""

    def __init__(self, algorithm):
        self.seconds = 0.0
        self.calls = 0
        self._start = None
        self._algorithm = algorithm
        self._tags = []
        if algorithm is not None:
            self._tags = [algorithm.AddObserver("StartEvent", self._begin),
                          algorithm.AddObserver("EndEvent", self._end)]

    def detach(self):
        for tag in self._tags:
            self._algorithm.RemoveObserver(tag)
        self._tags = []

    def _begin(self, *_):
        self._start = time.perf_counter()

    def _end(self, *_):
        if self._start is not None:
            self.seconds += time.perf_counter() - self._start
            self.calls += 1
            self._start = None

    def take(self):
        value = (self.seconds, self.calls)
        self.seconds, self.calls = 0.0, 0
        return value


def cloud_representation(display):
    composite = display.GetClientSideObject()
    active = composite.GetActiveRepresentation() if hasattr(
        composite, "GetActiveRepresentation") else None
    return active if active is not None else composite


def set_playback_interactive(display, on):
    """What the plugin's GUI does when Play starts and stops (an internal property, not
    an attribute of the Python proxy)."""
    display.SMProxy.GetProperty("PlaybackInteractive").SetElement(0, 1 if on else 0)
    display.SMProxy.UpdateVTKObjects()


def counters(mapper):
    if mapper is None:
        return {}
    return {
        "density uploads": mapper.GetNumberOfVolumeUploads(),
        "sun solves": mapper.GetNumberOfMultipleScatteringSolves(),
        "sun-depth builds": mapper.GetNumberOfSunDepthBuilds(),
        "atmosphere builds": mapper.GetNumberOfAtmosphereBuilds(),
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--plugin", required=True)
    parser.add_argument("--size", type=int, nargs=2, default=[1280, 800])
    parser.add_argument("--cache-dir", help="the basis's disk cache (default: a new empty "
                        "directory, so the first Apply precomputes)")
    parser.add_argument("--frames", type=int, default=0,
                        help="time steps to play (0: all of the flash's)")
    parser.add_argument("--still", action="store_true",
                        help="full-quality renders during Play (ParaView's own behaviour)")
    parser.add_argument("--screenshot", help="a PNG of the still frame after Play")
    parser.add_argument("--filter-set", nargs=2, action="append", default=[],
                        metavar=("PROPERTY", "VALUE"),
                        help="a property of the illumination filter (a number), e.g. "
                        "FirstScatteringOnDensityGrid 0")
    parser.add_argument("--strokes", action="store_true",
                        help="the lightning's strokes (port 0) as the filter's Lightning input, "
                        "not its point sources (port 1)")
    parser.add_argument("--json")
    arguments = parser.parse_args()
    cache = arguments.cache_dir or tempfile.mkdtemp(prefix="nimbus-play-bench-")

    LoadPlugin(arguments.plugin, ns=globals())
    try:
        import nimbus
    except ImportError:
        nimbus = None
    view = CreateRenderView()
    view.ViewSize = arguments.size
    view.OrientationAxesVisibility = 0
    SetActiveView(view)

    cloud = globals()["NimbusMetaballCloud"]()
    bolt = globals()["NimbusLightning"]()
    port = 0 if arguments.strokes else 1
    lit = globals()["NimbusLightningIllumination"](Input=cloud, Lightning=OutputPort(bolt, port),
                                                   CacheDirectory=cache)
    for name, value in arguments.filter_set:
        setattr(lit, name, float(value) if "." in value else int(value))
    timers = {
        "cloud source": Timed(cloud.GetClientSideObject()),
        "lightning source": Timed(bolt.GetClientSideObject()),
        "illumination filter": Timed(lit.GetClientSideObject()),
    }
    scene = GetAnimationScene()
    scene.UpdateAnimationUsingDataTimeSteps()
    times = list(lit.TimestepValues)
    peak = bolt.FlashStartSeconds + bolt.LeaderDurationSeconds
    start_time = min((t for t in times if t >= peak - 1e-12), default=times[0])

    # --- the first Apply: the data at the return stroke, shown, rendered ---
    begin = time.perf_counter()
    scene.AnimationTime = start_time
    lit.UpdatePipeline(start_time)
    apply_update = time.perf_counter() - begin
    first = {name: timer.take()[0] for name, timer in timers.items()}
    filter_object = lit.GetClientSideObject()
    first["basis precompute"] = filter_object.GetLastPrecomputeSeconds()
    first["relight"] = filter_object.GetLastRelightSeconds()
    strokes = Show(bolt, view)
    strokes.SetRepresentationType("Surface")
    display = Show(lit, view)
    display.SetRepresentationType("Cloud")
    display.SunElevationDegrees = -12.0
    timers["representation"] = Timed(cloud_representation(display))
    Hide(cloud, view)
    view.ResetCamera()
    camera = view.GetActiveCamera()
    camera.Elevation(-79.0)
    camera.OrthogonalizeViewUp()
    view.ResetCamera()
    mapper = nimbus.find_cloud_mapper(view.SMProxy.GetRenderer()) if nimbus else None
    begin = time.perf_counter()
    view.StillRender()
    first_render = time.perf_counter() - begin
    mapper = mapper or (nimbus.find_cloud_mapper(view.SMProxy.GetRenderer()) if nimbus else None)
    timers["render window"] = Timed(view.GetRenderWindow())
    if mapper is not None:
        mapper.SetTimePasses(True)
    for timer in timers.values():
        timer.take()
    print("first Apply: update %.2f s (cloud source %.2f s, lightning %.3f s, illumination "
          "filter %.2f s: the basis's precompute %.2f s (0: read from the disk cache), the "
          "relight %.4f s, the rest %.2f s), first render %.2f s" % (
              apply_update, first["cloud source"], first["lightning source"],
              first["illumination filter"], first["basis precompute"], first["relight"],
              first["illumination filter"] - first["basis precompute"] - first["relight"],
              first_render))

    # --- Play: every time step from the start of the flash ---
    steps = times if arguments.frames <= 0 else times[:arguments.frames]
    interactive = not arguments.still
    if interactive and display.SMProxy.GetProperty("PlaybackInteractive") is not None:
        set_playback_interactive(display, True)
    elif interactive:
        print("note: this build has no PlaybackInteractive property; frames are still renders")
        interactive = False
    rows = []
    before = counters(mapper)
    play_begin = time.perf_counter()
    for t in steps:
        begin = time.perf_counter()
        scene.AnimationTime = t  # as a tick of Play: update all views, then render them
        wall = time.perf_counter() - begin
        row = {"time": t, "wall": wall}
        for name, timer in timers.items():
            row[name], row[name + " calls"] = timer.take()
        if mapper is not None:
            row["interactive"] = bool(mapper.GetLastFrameInteractive())
            row["quality"] = mapper.GetLastFrameQuality()
            row["passes"] = mapper.GetLastPassTimes()
            row["cloud seconds"] = mapper.GetLastFrameSeconds()
        rows.append(row)
    play_seconds = time.perf_counter() - play_begin
    after = counters(mapper)
    still = None
    if interactive:
        set_playback_interactive(display, False)
        begin = time.perf_counter()
        view.StillRender()
        still = time.perf_counter() - begin
    if arguments.screenshot:
        view.StillRender()
        from paraview.simple import SaveScreenshot
        SaveScreenshot(arguments.screenshot, view, ImageResolution=arguments.size)

    print("%-7s %6s %6s %6s %6s %6s %6s %6s %5s %5s  %s" % (
        "time s", "wall s", "filter", "cloud", "bolt", "repr", "render", "mapper", "inter",
        "qual", "passes (GPU timer s)"))
    for row in rows:
        print("%-7.4f %6.3f %6.3f %6.3f %6.3f %6.3f %6.3f %6.3f %5s %5.3f  %s" % (
            row["time"], row["wall"], row["illumination filter"], row["cloud source"],
            row["lightning source"], row["representation"], row["render window"],
            row.get("cloud seconds", 0.0), row.get("interactive", "?"),
            row.get("quality", 0.0), row.get("passes", "")[:100]))
    median = statistics.median(r["wall"] for r in rows)
    delta = {k: after[k] - before[k] for k in after}
    summary = {
        "size": arguments.size, "frames": len(rows), "play seconds": play_seconds,
        "frames per second": len(rows) / play_seconds if play_seconds > 0 else 0.0,
        "median frame seconds": median,
        "cloud source runs during play": sum(r["cloud source calls"] for r in rows),
        "filter runs during play": sum(r["illumination filter calls"] for r in rows),
        "counters during play": delta, "still after play seconds": still,
        "first apply update seconds": apply_update, "first render seconds": first_render,
        "first apply parts": first, "load average": os.getloadavg(), "rows": rows,
    }
    print("Play: %d frames in %.2f s: %.2f frames/s (median frame %.3f s); cloud source ran "
          "%d times, the filter %d; during Play: %s; still frame after Play: %s s" % (
              len(rows), play_seconds, summary["frames per second"], median,
              summary["cloud source runs during play"], summary["filter runs during play"],
              delta, "%.2f" % still if still is not None else "-"))
    print("load average: %.2f %.2f %.2f" % os.getloadavg())
    if arguments.json:
        with open(arguments.json, "w") as out:
            json.dump(summary, out, indent=1)
    for timer in timers.values():
        timer.detach()
    # The view goes before the interpreter ends: torn down at exit, after the X connection,
    # VTK's FXAA filter releases its textures in a context that is gone (a crash at exit).
    Delete(view)
    return 0


if __name__ == "__main__":
    sys.exit(main())
