"""pvpython test of the plugin's "Cloud" representation (vtkNimbusCloudRepresentation).

    pvpython TestPluginCloudRepresentation.py --plugin Nimbus.so --baseline B.png \
        --output-dir DIR --compare-tool build/bin/nimbus-compare-images

With `import nimbus` on PYTHONPATH the mapper's upload counter is checked too.

Checks, through paraview.simple only:
  1. "Cloud" is one of the representation types offered for image data;
  2. the metaball cloud shown as "Cloud" with the XML defaults (noon-like sun,
     atmosphere, ground) matches the baseline image;
  3. changing SunElevationDegrees re-renders and changes the image (a low sun is
     redder and darker), and does not upload the density volume again;
  4. changing the input (a new metaball seed) uploads the volume exactly once;
  5. a two-step time series (.vti files) uploads once per change of time step,
     never for a re-render or a lighting change at the same step;
  6. the "Multiple Scattering" group: every property has the mapper's default, is
     accepted through the proxy and reaches the mapper; each method renders a
     cloud, the solver methods re-solve without uploading the volume again, and
     the methods give different images.
"""
import argparse
import os
import sys

from paraview.simple import (ColorBy, CreateRenderView, Delete, Hide, LoadPlugin, Render,
                             SaveData, SaveScreenshot, Show, XMLImageDataReader)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from image_compare import compare_with_baseline, read_png  # noqa: E402

SIZE = [320, 240]




def cloud_mapper(view):
    """The visible vtkNimbusCloudVolumeMapper in the view (None without `import nimbus`)."""
    try:
        import nimbus
    except ImportError:
        return None
    return nimbus.find_cloud_mapper(view.SMProxy.GetRenderer())


# The "Multiple Scattering" group: property -> (the mapper's default, a test value).
MULTIPLE_SCATTERING = {
    "MultipleScatteringMethod": (3, 1),
    "MultipleScatteringOrders": (32, 3),
    "MultipleScatteringDownsampling": (0, 8),
    "MultipleScatteringDirections": (26, 14),
    "SkyLight": (1, 0),
    "Octaves": (4, 3),
    "OctaveExtinctionScale": (0.5, 0.4),
    "OctaveScatteringScale": (0.5, 0.35),
    "OctaveAsymmetryScale": (0.5, 0.6),
    "PatternRadius": (6, 3),
    "PatternContribution": (0.8, 0.7),
    "PatternSelection": (0.25, 0.5),
    "MultipleScatteringMemoryBudgetMiB": (0.0, 512.0),
}


def scalar(display, name):
    """The value of the display's property `name` as a number (an enumeration's index)."""
    return float(display.SMProxy.GetProperty(name).GetElement(0))


def check_multiple_scattering_defaults(display, failures):
    """The group's XML defaults (read before the test changes any) are the mapper's."""
    for name, (default, _) in MULTIPLE_SCATTERING.items():
        value = scalar(display, name)
        if abs(value - default) > 1e-9:
            failures.append("%s: XML default %g, the mapper's is %g" % (name, value, default))
    print("multiple scattering defaults:", {
        name: scalar(display, name) for name in MULTIPLE_SCATTERING})
    methods = display.GetProperty("MultipleScatteringMethod").Available
    print("multiple scattering methods:", list(methods))
    expected_methods = ["None (constant only)", "Octaves (fastest)", "Reference patterns",
                        "Discrete directions (default)"]
    if list(methods) != expected_methods:
        failures.append("MultipleScatteringMethod offers %s" % list(methods))
    try:
        import nimbus
    except ImportError:
        return
    # The mapper's own defaults (a new one) against the table above.
    fresh = nimbus.vtkNimbusCloudVolumeMapper()
    for name, (default, _) in MULTIPLE_SCATTERING.items():
        own = float(getattr(fresh, "Get" + name)())
        if abs(own - default) > 1e-9:
            failures.append("%s: the mapper's default is %g, the XML's %g" % (name, own, default))


def check_haze_defaults(display, failures):
    """The haze's XML defaults: Turbidity 2, no Mie override (-1)."""
    turbidity = scalar(display, "Turbidity")
    mie = scalar(display, "MieScatteringPerMetre")
    if abs(turbidity - 2.0) > 1e-12 or abs(mie + 1.0) > 1e-12:
        failures.append("haze XML defaults: Turbidity %g, MieScatteringPerMetre %g" % (
            turbidity, mie))


def check_haze(display, mapper, failures):
    """Turbidity is the haze unless MieScatteringPerMetre >= 0 overrides it (either order);
    -1 goes back to Turbidity. The mapper's value: 0.9 * 0.025 (T - 1) / 1200 m."""
    if mapper is None:
        return
    kept = display.MieScatteringPerMetre
    steps = [("MieScatteringPerMetre", -1.0, 1.875e-5), ("Turbidity", 5.0, 7.5e-5), ("MieScatteringPerMetre", 3e-5, 3e-5),
             ("Turbidity", 3.0, 3e-5), ("MieScatteringPerMetre", -1.0, 3.75e-5)]
    for name, value, expected in steps:
        setattr(display, name, value)
        display.UpdateVTKObjects()
        got = mapper.GetMieScatteringPerMetre()
        print("haze: %s = %g -> the mapper's MieScatteringPerMetre %g" % (name, value, got))
        if abs(got - expected) > 1e-12:
            failures.append("haze: %s = %g gave %g, expected %g" % (name, value, got, expected))
    display.Turbidity = 2.0
    display.MieScatteringPerMetre = kept
    display.UpdateVTKObjects()


def check_multiple_scattering(display, view, output_dir, failures):
    """Sets each multiple-scattering property through the proxy and renders every method."""
    expected_methods = list(display.GetProperty("MultipleScatteringMethod").Available)
    # 004's reference patterns are built only once Physics/MultipleScatteringPatterns.cxx
    # exists; until then the mapper reports that they are missing and draws without them.
    patterns_built = os.path.exists(os.path.join(
        os.path.dirname(os.path.abspath(__file__)), os.pardir, os.pardir, "Physics",
        "MultipleScatteringPatterns.cxx"))
    print("reference patterns built:", patterns_built)
    mapper = cloud_mapper(view)

    # Every property through the proxy reaches the mapper.
    for name, (_, value) in MULTIPLE_SCATTERING.items():
        display.SetPropertyWithName(name, value)
    Render(view)
    mapper = cloud_mapper(view)
    if mapper is not None:
        for name, (_, value) in MULTIPLE_SCATTERING.items():
            got = float(getattr(mapper, "Get" + name)())
            if abs(got - value) > 1e-9:
                failures.append("%s = %g did not reach the mapper (it has %g)" % (name, value, got))
    for name, (default, _) in MULTIPLE_SCATTERING.items():
        display.SetPropertyWithName(name, default)

    # Each method renders a cloud; the solver's methods solve without a volume upload.
    display.MultipleScatteringDownsampling = 4
    images = {}
    for method in (0, 1, 2, 3):
        display.MultipleScatteringMethod = method
        uploads = mapper.GetNumberOfVolumeUploads() if mapper is not None else None
        solves = mapper.GetNumberOfMultipleScatteringSolves() if mapper is not None else None
        Render(view)
        path = os.path.join(output_dir, "TestPluginCloudRepresentation-ms%d.png" % method)
        SaveScreenshot(path, view, ImageResolution=SIZE)
        images[method] = read_png(path)
        line = "method %d (%s): mean pixel %.2f" % (method, expected_methods[method],
                                                   images[method].mean())
        if mapper is not None:
            solved = mapper.GetNumberOfMultipleScatteringSolves() - solves
            line += ", solves %d (%.2f s, %.1f MiB), volume uploads %d" % (
                solved, mapper.GetLastMultipleScatteringSeconds(),
                mapper.GetLastMultipleScatteringBytes() / 1048576.0,
                mapper.GetNumberOfVolumeUploads() - uploads)
            if mapper.GetNumberOfVolumeUploads() != uploads:
                failures.append("method %d uploaded the volume again" % method)
            expected = 1 if method == 3 or (method == 2 and patterns_built) else None
            if expected is not None and solved != expected:
                failures.append("method %d: expected one solve, got %d" % (method, solved))
        print(line)
        if images[method].std() < 1.0:
            failures.append("method %d rendered a flat image" % method)
    if not patterns_built:
        # Without the patterns the term is off: the image is the None one.
        print("reference patterns not built: mean |None - Reference patterns| = %.3f"
              % float(abs(images[0] - images[2]).mean()))
    none_vs_directions = float(abs(images[0] - images[3]).mean())
    print("mean |None - Discrete directions| = %.2f (of 255)" % none_vs_directions)
    if none_vs_directions < 0.5:
        failures.append("multiple scattering (discrete directions) does not change the image "
                        "(%.2f)" % none_vs_directions)
    for name, (default, _) in MULTIPLE_SCATTERING.items():
        display.SetPropertyWithName(name, default)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--plugin", required=True)
    parser.add_argument("--baseline", required=True)
    parser.add_argument("--output-dir", required=True)
    parser.add_argument("--compare-tool", required=True)
    args = parser.parse_args()
    os.makedirs(args.output_dir, exist_ok=True)
    failures = []

    LoadPlugin(args.plugin, ns=globals())
    cloud = NimbusMetaballCloud(Dimensions=[64, 64, 44], Seed=3)  # noqa: F821 (from the plugin)

    view = CreateRenderView()
    view.ViewSize = SIZE
    view.OrientationAxesVisibility = 0
    view.UseColorPaletteForBackground = 0
    # Black: the mapper draws the sky (atmosphere) over the framebuffer background.
    view.Background = [0.0, 0.0, 0.0]
    view.EnableRenderOnInteraction = 0
    # The camera of the mapper's own image tests (TestCloudVolumeMapper).
    view.CameraPosition = [0.0, -6000.0, 1500.0]
    view.CameraFocalPoint = [0.0, 0.0, 1600.0]
    view.CameraViewUp = [0.0, 0.0, 1.0]
    view.CameraViewAngle = 35.0

    display = Show(cloud, view)
    available = list(display.GetProperty("Representation").Available)
    print("representation types:", available)
    if "Cloud" not in available:
        failures.append("'Cloud' is not among the representation types %s" % available)

    display.SetRepresentationType("Cloud")
    ColorBy(display, ("POINTS", "density"))
    check_multiple_scattering_defaults(display, failures)
    check_haze_defaults(display, failures)
    # A few properties set through the proxy (the others keep the XML defaults).
    # The baseline predates the multiple-scattering solver: these checks keep the
    # k_multi-only cloud it shows (check_multiple_scattering covers the methods).
    display.MultipleScatteringMethod = 0
    display.MultipleScattering = 3.0  # the k_multi default of the baseline's time
    display.AirMultipleScattering = 0
    display.SunAzimuthDegrees = 135.0
    display.SunElevationDegrees = 60.0
    # The exposure and ground albedo of the baseline's time (the defaults are now the
    # Nimbus Sky's: 10 and 0.3).
    display.Exposure = 8.0
    display.GroundAlbedo = 0.2
    # The haze of the baseline's time (the default is now Turbidity 2: 1.875e-5 /m).
    display.MieScatteringPerMetre = 2e-5
    display.NumberOfSlices = 192
    print("defaults: k_multi %g, Exposure %g, CloudG %g, MieG %g, slices %d" % (
        display.MultipleScattering, display.Exposure, display.CloudG, display.MieG,
        display.NumberOfSlices))

    noon = os.path.join(args.output_dir, "TestPluginCloudRepresentation.png")
    SaveScreenshot(noon, view, ImageResolution=SIZE)
    if not compare_with_baseline(noon, args.baseline, args.output_dir, args.compare_tool):
        failures.append("the noon image differs from the baseline")

    mapper = cloud_mapper(view)
    check_haze(display, mapper, failures)
    uploads = mapper.GetNumberOfVolumeUploads() if mapper else None
    print("volume uploads after the first render:", uploads)
    if mapper is not None and uploads != 1:
        failures.append("expected 1 volume upload after the first render, got %s" % uploads)

    # A lighting change: re-render, new picture, no new upload.
    display.SunElevationDegrees = 8.0
    Render(view)
    low_sun = os.path.join(args.output_dir, "TestPluginCloudRepresentation-lowsun.png")
    SaveScreenshot(low_sun, view, ImageResolution=SIZE)
    a, b = read_png(noon), read_png(low_sun)
    change = abs(a - b).mean()
    print("mean |noon - low sun| = %.2f (of 255)" % change)
    if change < 5.0:
        failures.append("changing SunElevationDegrees changed the image by only %.2f" % change)
    # The low sun through the atmosphere is redder relative to blue.
    red_blue_noon = a[..., 0].mean() / max(a[..., 2].mean(), 1e-6)
    red_blue_low = b[..., 0].mean() / max(b[..., 2].mean(), 1e-6)
    print("mean red/blue: noon %.3f, low sun %.3f" % (red_blue_noon, red_blue_low))
    if not red_blue_low > red_blue_noon:
        failures.append("the low sun is not redder than noon")
    if mapper is not None:
        after = mapper.GetNumberOfVolumeUploads()
        print("volume uploads after the lighting change:", after)
        if after != uploads:
            failures.append("a lighting change uploaded the volume again (%d -> %d)"
                            % (uploads, after))

        # A data change: exactly one more upload.
        cloud.Seed = 4
        Render(view)
        Render(view)
        changed = mapper.GetNumberOfVolumeUploads()
        print("volume uploads after a new input and two renders:", changed)
        if changed != uploads + 1:
            failures.append("a new input should upload once (%d -> %d)" % (uploads, changed))

        # A time series: step files written from two seeds, read back as one source.
        steps = []
        for step, seed in enumerate((3, 4)):
            cloud.Seed = seed
            path = os.path.join(args.output_dir, "CloudRepresentationStep_%d.vti" % step)
            SaveData(path, proxy=cloud)
            steps.append(path)
        Hide(cloud, view)
        series = XMLImageDataReader(FileName=steps)
        series_display = Show(series, view)
        series_display.SetRepresentationType("Cloud")
        ColorBy(series_display, ("POINTS", "density"))
        counts = []
        for time, lighting in ((0.0, None), (0.0, None), (1.0, None), (1.0, 30.0), (0.0, None)):
            view.ViewTime = time
            if lighting is not None:
                series_display.SunElevationDegrees = lighting
            Render(view)
            series_mapper = cloud_mapper(view)
            counts.append(series_mapper.GetNumberOfVolumeUploads())
        print("time series uploads after t=0, t=0, t=1, t=1 + sun change, t=0:", counts)
        if [c - counts[0] for c in counts] != [0, 0, 1, 1, 2]:
            failures.append("time series: expected one upload per change of time step, got %s"
                            % counts)
        Delete(series_display)
        del series_display

    # "Cloud" chosen while colouring is Solid Color: ParaView picks an array only for
    # "Volume"/"Slice"; the representation falls back to the active scalars.
    Hide(cloud, view)
    plain = NimbusMetaballCloud(Dimensions=[64, 64, 44], Seed=3)  # noqa: F821
    plain_display = Show(plain, view)
    ColorBy(plain_display, None)
    plain_display.SetRepresentationType("Cloud")
    Render(view)
    solid_path = os.path.join(args.output_dir, "TestPluginCloudRepresentation_solid.png")
    SaveScreenshot(solid_path, view, ImageResolution=SIZE)
    ColorBy(plain_display, ("POINTS", "density"))
    Render(view)
    coloured_path = os.path.join(args.output_dir, "TestPluginCloudRepresentation_coloured.png")
    SaveScreenshot(coloured_path, view, ImageResolution=SIZE)
    solid, coloured = read_png(solid_path), read_png(coloured_path)
    difference = float(abs(solid - coloured).mean())
    print("Solid Color vs density-coloured Cloud: mean |difference| %.3f" % difference)
    if difference > 0.5:
        failures.append("Cloud without a chosen array does not render the active scalars "
                        "(mean difference %.3f)" % difference)
    Hide(plain, view)
    Show(cloud, view)
    Delete(plain_display)
    del plain_display

    # 6. The "Multiple Scattering" group (from the XML defaults, method 3).
    display.MultipleScatteringMethod = 3
    check_multiple_scattering(display, view, args.output_dir, failures)

    for failure in failures:
        print("FAILED:", failure)
    print("cloud representation test", "FAILED" if failures else "passed")
    # Release the view's OpenGL context while the X connection is still open.
    Delete(display)
    Delete(view)
    del display, view
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
