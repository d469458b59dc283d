"""GUI test: the plugin's first-look behavior (Plugin/Behavior) inside the real ParaView GUI.

    PV_PLUGIN_PATH=build/lib/paraview-5.11/plugins/Nimbus \
        Testing/with-display.sh paraview --dr --script=Testing/Python/TestGuiFirstApply.py

Run by the GUI at start-up, after the plugin has loaded: shows a Nimbus Cloud Automaton in the
GUI's render view and checks that the camera looks from the south, 11 degrees down, with z up
(ParaView's own default looks down -z), and that the sky source starts with Solid Color. Writes
what it checks to stdout and ends the GUI with exit status 0 on success (os._exit: the GUI has
no other way out of a start-up script).

The same file holds the Python steps of TestGuiFirstApply.xml, a test played by the GUI's own
test player (ParaView's --test-script) as a user would work: Sources > Nimbus > Nimbus Metaball
Cloud, Apply, then Sources > Nimbus > Nimbus Smoke, Apply, then the smoke's Medium Preset menu.
The player runs the steps below in the GUI's Python shell and checks the menu's text itself:

    NIMBUS_GUI_TEST_DIR=Testing/Python NIMBUS_GUI_TEST_OUTPUT=DIR \
    PV_PLUGIN_PATH=build/lib/paraview-5.11/plugins/Nimbus Testing/with-display.sh \
        paraview --dr --test-directory=DIR --test-script=Testing/Python/TestGuiFirstApply.xml --exit

A failed step ends the GUI at once with exit status 1; finish() ends it with 0.
"""
import math
import os
import sys
import traceback

from paraview.simple import GetActiveCamera, GetActiveViewOrCreate, NimbusCloudAutomaton, \
    NimbusSky, Render, Show  # noqa: F401 (the plugin's proxies are in paraview.simple)
from paraview import simple


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


# --- Steps of TestGuiFirstApply.xml ------------------------------------------------------

# The smoke preset (Plugin/Client/NimbusMediumPresets.h): extinction per unit density (1/m),
# albedo, forward scattering, glow.
SMOKE = (1.5, 0.6, 0.3, 0)
DARK_SMOKE = (3.0, 0.25, 0.4, 0)
# New data at least this fraction of the view's side on screen (the behavior frames it when
# smaller: kSmallOnScreen in Plugin/Behavior/pqNimbusFirstApplyBehavior.cxx).
SMALLEST_ON_SCREEN = 0.15


def step(function):
    """A step: its checks printed; the GUI ends with status 1 at the first failure."""
    def run(*args):
        try:
            ok = function(*args)
        except Exception:
            traceback.print_exc(file=sys.__stdout__)
            ok = False
        if not ok:
            check(False, "step %s" % function.__name__)
            sys.__stdout__.flush()
            os._exit(1)
    run.__name__ = function.__name__
    return run


def smoke_and_display():
    view = simple.GetActiveView()
    smoke = simple.FindSource("NimbusSmoke1")
    return view, smoke, simple.GetDisplayProperties(smoke, view)


def optics(display):
    return (display.ExtinctionPerDensity, display.Albedo, display.CloudG,
            display.TemperatureEmission)


def same_optics(display, expected):
    return all(abs(a - b) <= 1e-6 + 1e-3 * abs(b) for a, b in zip(optics(display), expected))


def on_screen(view, bounds):
    """The bounds' on-screen rectangle, clipped to the view, in normalised device
    coordinates (x0, x1, y0, y1 in [-1, 1]; empty when x1 <= x0 or y1 <= y0), and the
    larger of its sides over the view's. None when a corner is behind the camera."""
    camera = view.GetActiveCamera()
    width, height = view.ViewSize
    matrix = camera.GetCompositeProjectionTransformMatrix(width / float(height), -1, 1)
    xs, ys = [], []
    for i in range(8):
        corner = [bounds[i & 1], bounds[2 + ((i >> 1) & 1)], bounds[4 + ((i >> 2) & 1)], 1.0]
        x, y, _, w = matrix.MultiplyPoint(corner)
        if w <= 0:
            return None, 1.0
        xs.append(x / w)
        ys.append(y / w)
    rect = (max(min(xs), -1.0), min(max(xs), 1.0), max(min(ys), -1.0), min(max(ys), 1.0))
    extents = (rect[1] - rect[0], rect[3] - rect[2])
    return rect, (0.0 if min(extents) <= 0 else max(extents) / 2.0)


def inside(rect, shape):
    """A mask of the pixels (row 0 at the top) inside a normalised-device rectangle."""
    import numpy
    height, width = shape
    mask = numpy.zeros(shape, dtype=bool)
    if rect is not None and rect[1] > rect[0] and rect[3] > rect[2]:
        x0, x1 = [int(round((v + 1) / 2 * width)) for v in rect[:2]]
        y0, y1 = [int(round((1 - v) / 2 * height)) for v in (rect[3], rect[2])]
        mask[y0:max(y1, y0 + 1), x0:max(x1, x0 + 1)] = True
    return mask


def capture(view, name):
    """The view as the GUI draws it (File > Save Screenshot), as an array of pixels."""
    from image_compare import read_png
    path = os.path.join(os.environ["NIMBUS_GUI_TEST_OUTPUT"], name + ".png")
    simple.SaveScreenshot(path, view)
    return read_png(path)


@step
def view_size():
    """A view of 800 x 500 pixels whatever the docks take (the layout's preview mode)."""
    simple.GetLayout().SetSize(800, 500)
    return check(list(simple.GetActiveView().ViewSize) == [800, 500],
                 "view size %s" % list(simple.GetActiveView().ViewSize))


@step
def second_source_in_occupied_view():
    """A smoke of metres Applied into a view that shows a cloud of kilometres."""
    view, smoke, display = smoke_and_display()
    ok = check(display.Representation == "Cloud", "smoke shown as %s" % display.Representation)
    ok &= check(same_optics(display, SMOKE), "smoke's optics %s (Smoke preset %s)" % (
        optics(display), SMOKE))
    time = view.ViewTime
    density = smoke.PointData["density"].GetRange()[1]
    ok &= check(time >= 2.0 - 1e-6 and density > 0.1,
                "animation at %.3f s (a risen plume, not the empty time 0): density up to %.3f"
                % (time, density))
    rect, fraction = on_screen(view, smoke.GetDataInformation().GetBounds())
    ok &= check(fraction >= SMALLEST_ON_SCREEN,
                "the smoke's box takes %.3f of the view's side (at least %.2f)"
                % (fraction, SMALLEST_ON_SCREEN))
    shown = capture(view, "smoke-shown")
    simple.Hide(smoke, view)
    hidden = capture(view, "smoke-hidden")
    simple.Show(smoke, view)
    simple.Render(view)
    # The smoke itself: pixels inside its box's picture that showing it changes (a Cloud
    # representation also redraws the air and the ground over the whole view).
    changed = abs(shown - hidden).max(axis=2) > 16
    smoke_pixels = (changed & inside(rect, changed.shape)).mean()
    ok &= check(smoke_pixels >= 0.01, "the smoke changes %.1f %% of the view's pixels inside its "
                "box (at least 1 %%: not blank, not a speck)" % (100 * smoke_pixels))
    return ok


@step
def optics_are(expected):
    _, _, display = smoke_and_display()
    return check(same_optics(display, expected), "smoke's optics %s (expected %s)" % (
        optics(display), expected))


@step
def heat_the_smoke():
    """Fire on a smoke hot enough to glow: the panel's warning goes away."""
    view, smoke, display = smoke_and_display()
    smoke.EmitterTemperatureKelvin = 1500.0
    simple.Render(view)
    hottest = smoke.PointData["temperature"].GetRange()[1]
    return check(display.TemperatureEmission == 1 and hottest > 1000.0,
                 "glow on, the hottest point %.0f K" % hottest)


@step
def edit_by_hand():
    view, _, display = smoke_and_display()
    display.ExtinctionPerDensity = 0.7
    simple.Render(view)
    return check(abs(display.ExtinctionPerDensity - 0.7) < 1e-12, "extinction set to 0.7 /m")


@step
def save_dark_smoke_state():
    """A state file whose smoke has the Dark smoke values; the display then leaves them."""
    view, _, display = smoke_and_display()
    display.ExtinctionPerDensity, display.Albedo, display.CloudG = DARK_SMOKE[:3]
    display.TemperatureEmission = 0
    path = os.path.join(os.environ["NIMBUS_GUI_TEST_OUTPUT"], "dark-smoke.pvsm")
    simple.SaveState(path)
    display.ExtinctionPerDensity = 0.5
    return check(os.path.exists(path), "state saved: %s" % path)


@step
def select_smoke():
    """After File > Load State: the loaded smoke keeps the state's optics (the first-look
    behavior leaves loaded representations alone) and becomes the active source."""
    from paraview import servermanager
    smokes = [proxy for proxy in servermanager.ProxyManager().GetProxiesInGroup("sources").values()
              if proxy.GetXMLName() == "NimbusSmoke"]
    shown = [(smoke, view, servermanager.GetRepresentation(smoke, view))
             for smoke in smokes for view in simple.GetViews()]
    shown = [item for item in shown if item[2] is not None]
    if not check(len(shown) == 1, "the loaded smoke is shown in %d view(s)" % len(shown)):
        return False
    smoke, view, display = shown[0]
    simple.SetActiveView(view)
    simple.SetActiveSource(smoke)
    return check(same_optics(display, DARK_SMOKE), "loaded smoke's optics %s (the state's %s)"
                 % (optics(display), DARK_SMOKE))


def finish():
    check(True, "all steps")
    sys.__stdout__.flush()
    os._exit(0)


if __name__ == "__main__":
    try:
        status = main()
    except Exception:
        traceback.print_exc(file=sys.__stdout__)
        status = 1
    sys.stdout.flush()
    os._exit(status)
