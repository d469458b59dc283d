"""pvpython image test: the Nimbus plugin's metaball cloud shown as a volume.

    pvpython TestPluginMetaballCloud.py --plugin Nimbus.so --baseline B.png --output-dir DIR \
        --compare-tool build/bin/nimbus-compare-images

Loads the plugin with LoadPlugin, creates the source through paraview.simple,
shows it with ParaView's volume representation, saves a screenshot and compares
it with the baseline.
"""
import argparse
import math
import os
import sys

from paraview.simple import (ColorBy, CreateRenderView, Delete, GetColorTransferFunction,
                             GetOpacityTransferFunction, LoadPlugin, SaveScreenshot,
                             Show)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from image_compare import compare_with_baseline  # noqa: E402


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--plugin", required=True)
    parser.add_argument("--baseline", required=True)
    parser.add_argument("--output-dir", required=True)
    parser.add_argument("--compare-tool", required=True)
    args = parser.parse_args()

    LoadPlugin(args.plugin, ns=globals())
    cloud = NimbusMetaballCloud(Dimensions=[64, 64, 44], Seed=3)  # noqa: F821 (from the plugin)
    cloud.UpdatePipeline()
    info = cloud.GetDataInformation()
    if info.GetNumberOfPoints() != 64 * 64 * 44:
        print("unexpected number of points:", info.GetNumberOfPoints())
        return 1

    view = CreateRenderView()
    view.ViewSize = [320, 240]
    view.OrientationAxesVisibility = 0
    view.UseColorPaletteForBackground = 0
    view.Background = [0.25, 0.42, 0.72]
    view.EnableRenderOnInteraction = 0

    display = Show(cloud, view)
    display.SetRepresentationType("Volume")
    ColorBy(display, ("POINTS", "density"))
    display.Shade = 1
    # Same optics as the C++ test: extinction 0.02 /m per unit density, opacity over
    # one voxel u = 1 - exp(-sigma_t * density * u).
    spacing = 3000.0 / 63.0
    display.ScalarOpacityUnitDistance = spacing
    opacity_points = []
    for density in (0.0, 0.1, 0.25, 0.5, 1.0, 2.0):
        opacity_points += [density, 1.0 - math.exp(-0.02 * density * spacing), 0.5, 0.0]
    GetOpacityTransferFunction("density").Points = opacity_points
    color = GetColorTransferFunction("density")
    color.RGBPoints = [0.0, 1.0, 1.0, 1.0, 2.0, 1.0, 1.0, 1.0]
    color.AutomaticRescaleRangeMode = "Never"

    view.CameraPosition = [0.0, -6000.0, 1500.0]
    view.CameraFocalPoint = [0.0, 0.0, 1600.0]
    view.CameraViewUp = [0.0, 0.0, 1.0]
    view.CameraViewAngle = 35.0

    os.makedirs(args.output_dir, exist_ok=True)
    image = os.path.join(args.output_dir, "TestPluginMetaballCloud.png")
    SaveScreenshot(image, view, ImageResolution=[320, 240])
    ok = compare_with_baseline(image, args.baseline, args.output_dir, args.compare_tool)
    print("image test", "passed" if ok else "FAILED", "->", image)
    # Release the view's OpenGL context while the X connection is still open.
    Delete(display)
    Delete(view)
    del display, view
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
