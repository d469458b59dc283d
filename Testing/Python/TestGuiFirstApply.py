"""GUI test: the plugin's first-look behavior (Plugin/Behavior) inside the real ParaView GUI.

    PV_PLUGIN_PATH=build/lib/paraview-5.11/plugins/Nimbus \
        Testing/with-display.sh paraview --dr --script=Testing/Python/TestGuiFirstApply.py

Run by the GUI at start-up, after the plugin has loaded: shows a Nimbus Cloud Automaton in the
GUI's render view and checks that the camera looks from the south, 11 degrees down, with z up
(ParaView's own default looks down -z), and that the sky source starts with Solid Color. Writes
what it checks to stdout and ends the GUI with exit status 0 on success (os._exit: the GUI has
no other way out of a start-up script).
"""
import math
import os
import sys
import traceback

from paraview.simple import GetActiveCamera, GetActiveViewOrCreate, NimbusCloudAutomaton, \
    NimbusSky, Render, Show  # noqa: F401 (the plugin's proxies are in paraview.simple)


def check(condition, message):
    print(("ok    " if condition else "FAIL  ") + message, file=sys.__stdout__, flush=True)
    return bool(condition)


def main():
    ok = True
    view = GetActiveViewOrCreate("RenderView")
    clouds = NimbusCloudAutomaton(Dimensions=[48, 48, 16], SpinUpSteps=10)
    display = Show(clouds, view)
    Render(view)
    ok &= check(display.Representation == "Cloud", "shown as %s" % display.Representation)
    camera = GetActiveCamera()
    position, focal = camera.GetPosition(), camera.GetFocalPoint()
    look = [f - p for f, p in zip(focal, position)]
    norm = math.sqrt(sum(c * c for c in look))
    look = [c / norm for c in look]
    expected = [0.0, math.cos(math.radians(11.0)), -math.sin(math.radians(11.0))]
    if os.environ.get("NIMBUS_GUI_TEST_EXPECT_TOP_VIEW"):  # to see the test fail
        expected = [0.0, 0.0, -1.0]
    ok &= check(max(abs(a - b) for a, b in zip(look, expected)) < 1e-3,
                "camera looks along %s (expected %s)" % (
                    ["%.3f" % c for c in look], ["%.3f" % c for c in expected]))
    up = camera.GetViewUp()
    ok &= check(abs(up[2] - 1.0) < 1e-3, "view up %s is +z" % (["%.3f" % c for c in up],))

    sky = NimbusSky()
    sky_display = Show(sky, view)
    Render(view)
    color = sky_display.ColorArrayName[1] if sky_display.ColorArrayName else ""
    ok &= check(sky_display.Representation == "Sky Background" and color == "",
                "the sky: %s, colour array %r (Solid Color)" % (sky_display.Representation, color))
    return 0 if ok else 1


try:
    status = main()
except Exception:
    traceback.print_exc(file=sys.__stdout__)
    status = 1
sys.stdout.flush()
os._exit(status)
