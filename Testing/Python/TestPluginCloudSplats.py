"""pvpython test of the plugin's "Cloud Splats" representation
(vtkNimbusCloudSplatRepresentation, vtkNimbusCloudSplatMapper).

    pvpython --force-offscreen-rendering TestPluginCloudSplats.py --plugin Nimbus.so \
        --output-dir DIR

Checks, through paraview.simple only:
  1. "Cloud Splats" is offered for the Nimbus Metaball Cloud's second output (Metaballs)
     and its radius and density arrays are chosen by default ("radius", "density");
  2. shown as "Cloud Splats" with the XML defaults, the image is not empty: many cloud
     pixels differ from the background, and the sunlit ones are brighter than it;
  3. the sun reaches the mapper: a sun below the balls' side (elevation -60) changes the
     image;
  4. with a Nimbus Sky shown in the view ("Sky Background"), the balls are drawn over the
     sky, lit by the sky's sun: the sky's sun elevation changes the image, the display's
     own does not; the sky's light and the air between the camera and the balls (Sky
     and Ground Light, Air Between Camera and Cloud) change the balls.
"""
import argparse
import os
import sys

from paraview.simple import (CreateRenderView, Delete, LoadPlugin, OutputPort, Render, SaveScreenshot,
                             Show)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from image_compare import read_png  # noqa: E402

SIZE = [320, 240]
BACKGROUND = [0.1, 0.1, 0.15]  # a dark blue-grey: cloud pixels are brighter


def save(view, output_dir, name):
    """Renders the view and returns its pixels, saved as name.png in output_dir."""
    Render(view)
    path = os.path.join(output_dir, name + ".png")
    SaveScreenshot(path, view, ImageResolution=SIZE)
    return read_png(path)


def check_view_sky(view, display, pixels, output_dir, failures):
    """A Nimbus Sky in the view: the balls over it, lit by its sun (Use the View's Sky)."""
    sky = NimbusSky(SunElevationDegrees=45.0, SunAzimuthDegrees=135.0)  # noqa: F821
    Show(sky, view)  # "Sky Background" by default
    display.SunElevationDegrees = -60.0  # not used while the sky's sun is
    with_sky = save(view, output_dir, "TestPluginCloudSplats-sky")
    display.Visibility = 0
    sky_only = save(view, output_dir, "TestPluginCloudSplats-sky-only")
    display.Visibility = 1
    over_sky = (abs(with_sky - sky_only).max(axis=2) > 8.0).mean()
    print("with the sky: %.3f of the pixels are the balls'" % over_sky)
    if over_sky < 0.05:
        failures.append("the balls are not drawn over the sky (%.3f of the pixels)" % over_sky)
    display.SunElevationDegrees = 10.0
    own_sun = save(view, output_dir, "TestPluginCloudSplats-sky-own-sun")
    own_change = abs(own_sun - with_sky).mean()
    # The sky's own pixels change with its sun too: compare what the balls add to it.
    sky.SunElevationDegrees = 10.0
    sky_sun = save(view, output_dir, "TestPluginCloudSplats-sky-sun")
    display.Visibility = 0
    low_sky_only = save(view, output_dir, "TestPluginCloudSplats-sky-sun-only")
    display.Visibility = 1
    balls = abs(with_sky - sky_only).max(axis=2) > 8.0
    sky_change = abs((sky_sun - low_sky_only) - (with_sky - sky_only)).max(axis=2)[balls].mean()
    print("with the sky: mean change by the display's sun %.2f; by the sky's sun, "
          "of what the balls add, %.2f" % (own_change, sky_change))
    if own_change > 0.5:
        failures.append("the display's own sun changes the image under the view's sky")
    if sky_change < 5.0:
        failures.append("the sky's sun does not reach the balls (%.2f)" % sky_change)
    # The sky's light and the air reach the balls through the representation.
    display.SplatSkyLight = 0
    display.SplatAerialPerspective = 0
    plain = save(view, output_dir, "TestPluginCloudSplats-sky-sun-plain")
    display.SplatSkyLight = 1
    display.SplatAerialPerspective = 1
    terms = abs(sky_sun - plain).max(axis=2)[balls].mean()
    print("with the sky: the sky's light and the air change the balls by %.2f" % terms)
    if terms < 5.0:
        failures.append("the sky's light and the air do not reach the balls (%.2f)" % terms)


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--plugin", required=True)
    parser.add_argument("--output-dir", required=True)
    args = parser.parse_args()
    LoadPlugin(args.plugin, ns=globals())
    failures = []

    cloud = NimbusMetaballCloud()  # noqa: F821 (from the plugin)
    view = CreateRenderView()
    view.ViewSize = SIZE
    view.OrientationAxesVisibility = 0
    view.UseColorPaletteForBackground = 0
    view.Background = BACKGROUND
    display = Show(OutputPort(cloud, 1), view)

    types = list(display.Representation.Available)
    if "Cloud Splats" not in types:
        failures.append("'Cloud Splats' not offered for the metaballs: %s" % types)
    display.SetRepresentationType("Cloud Splats")
    print("radius array:", display.SplatRadiusArray, "density array:", display.SplatDensityArray)
    if display.SplatRadiusArray != "radius" or display.SplatDensityArray != "density":
        failures.append("default arrays %r, %r (expected radius, density)" %
                        (display.SplatRadiusArray, display.SplatDensityArray))

    # The GUI's first look at Nimbus data: looking north, 11 degrees down; the sun (the
    # defaults: azimuth 135, south-east, 45 degrees up) behind the camera's right shoulder.
    view.CameraPosition = [0.0, -9817.0, 3408.0]
    view.CameraFocalPoint = [0.0, 0.0, 1500.0]
    view.CameraViewUp = [0.0, 0.0, 1.0]
    view.ResetCamera()
    Render(view)
    image_path = os.path.join(args.output_dir, "TestPluginCloudSplats.png")
    SaveScreenshot(image_path, view, ImageResolution=SIZE)
    pixels = read_png(image_path)
    background = [255.0 * c for c in BACKGROUND]
    difference = abs(pixels - background).max(axis=2)
    cloud_pixels = difference > 8.0
    brighter = pixels.mean(axis=2) > sum(background) / 3.0 + 40.0
    share = cloud_pixels.mean()
    bright_share = brighter.mean()
    print("cloud pixels: %.3f of the image; brighter than the background by 40+: %.3f; "
          "brightest %.0f" % (share, bright_share, pixels.max()))
    if share < 0.05:
        failures.append("only %.3f of the pixels differ from the background" % share)
    if bright_share < 0.02:
        failures.append("only %.3f of the pixels are brighter than the background" % bright_share)

    display.SunElevationDegrees = -60.0
    Render(view)
    low_path = os.path.join(args.output_dir, "TestPluginCloudSplats-sun-below.png")
    SaveScreenshot(low_path, view, ImageResolution=SIZE)
    change = abs(read_png(low_path) - pixels).mean()
    print("mean change with the sun below: %.2f" % change)
    if change < 1.0:
        failures.append("the sun's elevation does not change the image (%.2f)" % change)

    check_view_sky(view, display, pixels, args.output_dir, failures)

    # The view goes before the interpreter exits: pvpython tearing it down during
    # sys.exit makes a destroyed GLX context current under Xvfb (an X error, exit 1).
    Delete(view)
    del view
    for failure in failures:
        print("FAIL:", failure)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
