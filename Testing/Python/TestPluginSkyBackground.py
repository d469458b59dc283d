"""pvpython test of the plugin's "Sky Background" representation (the sky behind a render view).

    pvpython TestPluginSkyBackground.py --plugin Nimbus.so --baseline B.png \
        --output-dir DIR --compare-tool build/bin/nimbus-compare-images

Checks, through paraview.simple only:
  1. the Nimbus Sky source writes its sky parameters into its field data (after the
     preset: Noon is sun 60 deg at azimuth 180);
  2. shown in a render view its default representation is "Sky Background";
  3. the noon sky looking west at the horizon matches the baseline, with blue above
     (B > R), a brighter, whiter band at the horizon and neutral grey ground below it;
  4. the parameters reach the view: Sunset reddens the horizon toward the sun (R > B)
     and a lower Exposure darkens the sky;
  5. hiding the representation, switching to another type and deleting it each
     bring back the plain view background; showing it again brings the sky back;
  6. a small metaball cloud (Cloud representation) under the sky takes the sky's sun
     (vtkNimbusCloudVolumeMapper's UseSceneSky): the Noon scene matches the second
     baseline, and under the Sunset preset the cloud's pixels redden (mean R/B rises).
Every check compares pixels of the rendered images, so each fails when the sky is
not drawn (the background is magenta: R = B).
"""
import argparse
import os
import sys

from paraview import servermanager
from paraview.simple import (ColorBy, CreateRenderView, Delete, Hide, LoadPlugin, Render,
                             SaveScreenshot, Show)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from image_compare import compare_with_baseline, read_png  # noqa: E402

SIZE = [320, 240]
HORIZON_ROW = SIZE[1] // 2          # the camera looks horizontally: the horizon is mid-height
BACKGROUND = [1.0, 0.0, 1.0]        # magenta: R = B, unlike any sky
BACKGROUND_8BIT = [255.0, 0.0, 255.0]




class Checker:
    def __init__(self, view, output_dir):
        self.view = view
        self.output_dir = output_dir
        self.failures = []

    def shot(self, name):
        path = os.path.join(self.output_dir, name + ".png")
        SaveScreenshot(path, self.view, ImageResolution=SIZE)
        return path, read_png(path)

    def expect(self, condition, message):
        if not condition:
            self.failures.append(message)

    def background_fraction(self, pixels):
        return float((abs(pixels - BACKGROUND_8BIT).max(axis=2) <= 1.0).mean())


def field_parameters(source):
    data = servermanager.Fetch(source)
    fields = data.GetFieldData()
    return {fields.GetArrayName(i): fields.GetArray(i).GetValue(0)
            for i in range(fields.GetNumberOfArrays())}


def check_cloud_under_sky(view, check, sky, args):
    """6. The Cloud representation lit by the Sky Background's sun."""
    sky.Preset = "Noon"
    sky_display = Show(sky, view)
    cloud = NimbusMetaballCloud(Dimensions=[48, 48, 32], Seed=3)  # noqa: F821 (plugin)
    cloud_display = Show(cloud, view)
    cloud_display.SetRepresentationType("Cloud")
    ColorBy(cloud_display, ("POINTS", "density"))
    cloud_display.NumberOfSlices = 64
    # The compositing over the sky is what this checks; its baseline predates the
    # multiple-scattering solver (k_multi 3, the representation's default then).
    cloud_display.MultipleScatteringMethod = 0
    cloud_display.MultipleScattering = 3.0
    cloud_display.AirMultipleScattering = 0
    # From the south, looking north at the cloud; the sunset sun is on the left (west).
    view.CameraPosition = [0.0, -6000.0, 1500.0]
    view.CameraFocalPoint = [0.0, 0.0, 1600.0]
    view.CameraViewUp = [0.0, 0.0, 1.0]
    view.CameraViewAngle = 35.0
    Render(view)
    noon_path, noon = check.shot("TestPluginSkyBackground_cloud")
    check.expect(compare_with_baseline(noon_path, args.cloud_baseline, args.output_dir,
                                       args.compare_tool),
                 "the cloud under the noon sky differs from the baseline")
    # The cloud's pixels: where the scene differs from the sky alone.
    Hide(cloud, view)
    Render(view)
    _, sky_only = check.shot("TestPluginSkyBackground-cloud-skyonly")
    cloud_display = Show(cloud, view)
    mask = abs(noon - sky_only).max(axis=2) > 24.0
    mask[175:] = False  # the cloud, not its shadow on the ground (rows 190-225)
    check.expect(0.02 < mask.mean() < 0.5,
                 "the cloud covers %.3f of the view (expected a small cloud)" % mask.mean())

    sky.Preset = "Sunset"
    Render(view)
    _, sunset = check.shot("TestPluginSkyBackground-cloud-sunset")

    def red_over_blue(pixels):
        return pixels[mask][:, 0].mean() / max(pixels[mask][:, 2].mean(), 1e-6)

    noon_ratio, sunset_ratio = red_over_blue(noon), red_over_blue(sunset)
    print("cloud region %.3f of the view; mean R/B noon %.3f, sunset %.3f"
          % (mask.mean(), noon_ratio, sunset_ratio))
    check.expect(sunset_ratio > noon_ratio + 0.5,
                 "the cloud did not redden under the sunset sky (R/B %.3f -> %.3f)"
                 % (noon_ratio, sunset_ratio))
    # UseSceneSky off: the cloud takes its own sun again (60 deg by default).
    cloud_display.UseSceneSky = 0
    Render(view)
    _, own_sun = check.shot("TestPluginSkyBackground-cloud-ownsun")
    own_ratio = red_over_blue(own_sun)
    print("UseSceneSky off under the sunset sky: cloud R/B %.3f" % own_ratio)
    check.expect(own_ratio < sunset_ratio - 0.5,
                 "UseSceneSky off still follows the sky's sun (R/B %.3f)" % own_ratio)
    Delete(cloud_display)
    Delete(sky_display)
    Delete(cloud)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--plugin", required=True)
    parser.add_argument("--baseline", required=True)
    parser.add_argument("--cloud-baseline", required=True)
    parser.add_argument("--output-dir", required=True)
    parser.add_argument("--compare-tool", required=True)
    args = parser.parse_args()
    os.makedirs(args.output_dir, exist_ok=True)

    LoadPlugin(args.plugin, ns=globals())
    sky = NimbusSky(Preset="Noon")  # noqa: F821 (from the plugin; proxy NimbusSkyDome)

    # 1. The parameters travel in the field data, after the preset.
    parameters = field_parameters(sky)
    print("field data:", parameters)
    view = CreateRenderView()
    check = Checker(view, args.output_dir)
    for name in ("SunElevationDegrees", "SunAzimuthDegrees", "Turbidity", "MieScatteringPerMetre", "GroundAlbedo",
                 "Exposure",
                 "SceneAltitudeMetres", "MetresPerUnit", "ScatteringOrders", "WhiteBalance",
                 "SunDisc"):
        check.expect(name in parameters, "field data lacks %s" % name)
    check.expect(parameters.get("SunElevationDegrees") == 60.0 and parameters.get("SunAzimuthDegrees") == 180.0,
                 "Noon preset not in the field data: %s" % parameters)
    # The haze: Turbidity (default 2); MieScatteringPerMetre >= 0 (a state saved before
    # Turbidity existed) overrides it, -1 (its default) gives it back.
    check.expect(abs(parameters.get("Turbidity", 0.0) - 2.0) < 1e-9, "default Turbidity: %s" % parameters)
    sky.Turbidity = 5.0
    hazy = field_parameters(sky)
    check.expect(abs(hazy.get("Turbidity", 0.0) - 5.0) < 1e-9
                 and hazy.get("MieScatteringPerMetre", 0.0) > 2.0 * parameters.get("MieScatteringPerMetre", 1.0),
                 "Turbidity 5 did not reach the field data: %s" % hazy)
    sky.MieScatteringPerMetre = 2e-5
    old = field_parameters(sky)
    check.expect(old.get("MieScatteringPerMetre") == 2e-5, "MieScatteringPerMetre 2e-5 not applied: %s" % old)
    sky.MieScatteringPerMetre = -1.0
    sky.Turbidity = 2.0
    check.expect(abs(field_parameters(sky).get("Turbidity", 0.0) - 2.0) < 1e-9, "Turbidity 2 not back")

    view.ViewSize = SIZE
    view.OrientationAxesVisibility = 0
    view.UseColorPaletteForBackground = 0
    view.Background = BACKGROUND
    view.EnableRenderOnInteraction = 0

    # 2. The default representation in a render view.
    display = Show(sky, view)
    available = list(display.GetProperty("Representation").Available)
    print("representation: %s of %s" % (display.Representation, available))
    check.expect("Sky Background" in available, "'Sky Background' is not offered: %s" % available)
    check.expect(display.Representation == "Sky Background",
                 "default representation is %s, not Sky Background" % display.Representation)

    # Looking west (the sunset sun's azimuth) at the horizon; 60 deg vertical field.
    view.CameraPosition = [0.0, 0.0, 10.0]
    view.CameraFocalPoint = [-1000.0, 0.0, 10.0]
    view.CameraViewUp = [0.0, 0.0, 1.0]
    view.CameraViewAngle = 60.0
    view.CameraParallelProjection = 0

    # 3. Noon: baseline, blue above, whiter horizon, grey ground.
    noon_path, noon = check.shot("TestPluginSkyBackground")
    check.expect(compare_with_baseline(noon_path, args.baseline, args.output_dir,
                                       args.compare_tool),
                 "the noon sky differs from the baseline")
    top = noon[:24].mean(axis=(0, 1))
    band = noon[HORIZON_ROW - 12:HORIZON_ROW - 2].mean(axis=(0, 1))
    ground = noon[HORIZON_ROW + 4:].mean(axis=(0, 1))
    print("noon rgb: top %s, horizon band %s, ground %s" % (top.round(1), band.round(1),
                                                           ground.round(1)))
    check.expect(top[2] > top[0] + 40.0, "the noon sky above is not blue (B > R): %s" % top)
    check.expect(band.mean() > top.mean() + 30.0,
                 "the horizon is not brighter than the sky above: %s vs %s" % (band, top))
    check.expect(band[2] - band[0] < top[2] - top[0],
                 "the horizon is not whiter than the sky above: %s vs %s" % (band, top))
    check.expect(ground.max() - ground.min() < 20.0 and ground[2] - ground[0] < 0.0 < top[2] - top[0],
                 "the ground below the horizon is not a neutral grey: %s" % ground)

    # 4a. Sunset: the horizon toward the sun turns red-orange.
    sky.Preset = "Sunset"
    Render(view)
    sunset_path, sunset = check.shot("TestPluginSkyBackground-sunset")
    toward_sun = sunset[HORIZON_ROW - 12:HORIZON_ROW - 1, 120:200].mean(axis=(0, 1))
    change = abs(sunset - noon).mean()
    print("sunset: near the horizon toward the sun %s; mean |sunset - noon| %.1f"
          % (toward_sun.round(1), change))
    check.expect(toward_sun[0] > toward_sun[2] + 60.0,
                 "the sunset horizon toward the sun is not reddish (R > B): %s" % toward_sun)
    check.expect(change > 20.0, "Sunset changed the image by only %.1f" % change)
    check.expect(field_parameters(sky).get("SunElevationDegrees") == 2.0,
                 "the Sunset preset is not in the field data")

    # 4b. Exposure (not a sun parameter) reaches the view too.
    sky.Exposure = 4.0
    Render(view)
    _, dim = check.shot("TestPluginSkyBackground-exposure4")
    print("mean value: exposure 10 %.1f, exposure 4 %.1f" % (sunset.mean(), dim.mean()))
    check.expect(dim.mean() < sunset.mean() - 20.0, "a lower Exposure did not darken the sky")
    sky.Exposure = 10.0

    # 5. Hidden, another type, deleted: the plain background; shown again: the sky.
    Hide(sky, view)
    Render(view)
    _, hidden = check.shot("TestPluginSkyBackground-hidden")
    fraction = check.background_fraction(hidden)
    print("hidden: %.3f of the pixels are the view background" % fraction)
    check.expect(fraction == 1.0, "hiding the sky left %.3f of the view covered" % (1 - fraction))

    display = Show(sky, view)
    Render(view)
    _, again = check.shot("TestPluginSkyBackground-shown-again")
    difference = abs(again - sunset).max()
    print("shown again: max |difference| from the first sunset %.1f" % difference)
    check.expect(difference <= 1.0, "showing the sky again did not restore it (%.1f)" % difference)

    display.SetRepresentationType("Outline")
    Render(view)
    _, outline = check.shot("TestPluginSkyBackground-outline")
    fraction = check.background_fraction(outline)
    print("Outline: %.3f of the pixels are the view background" % fraction)
    check.expect(fraction > 0.9, "switching to Outline left the sky (background %.3f)" % fraction)
    display.SetRepresentationType("Sky Background")
    Render(view)
    _, back = check.shot("TestPluginSkyBackground-sky-again")
    check.expect(abs(back - sunset).max() <= 1.0, "switching back to Sky Background failed")

    Delete(display)
    del display
    Render(view)
    _, deleted = check.shot("TestPluginSkyBackground-deleted")
    fraction = check.background_fraction(deleted)
    print("deleted: %.3f of the pixels are the view background" % fraction)
    check.expect(fraction == 1.0, "the sky outlived its representation (%.3f)" % fraction)

    check_cloud_under_sky(view, check, sky, args)

    for failure in check.failures:
        print("FAILED:", failure)
    print("sky background test", "FAILED" if check.failures else "passed")
    # Release the view's OpenGL context while the X connection is still open.
    Delete(view)
    del view
    return 1 if check.failures else 0


if __name__ == "__main__":
    sys.exit(main())
