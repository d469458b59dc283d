"""pvpython test: the Nimbus plugin's sky dome with the Sunset preset.

    pvpython TestPluginSkyDome.py --plugin Nimbus.so --baseline B.png --output-dir DIR \
        --compare-tool build/bin/nimbus-compare-images

Checks the data (point count, "Colors" and "Radiance" arrays, a red-orange horizon
toward the sun and a bluer sky away from it, the preset overriding the sun angles)
and compares a screenshot from inside the dome with the baseline.
"""
import argparse
import os
import sys

from paraview import servermanager
from paraview.simple import CreateRenderView, Delete, LoadPlugin, SaveScreenshot, Show

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
    dome = NimbusSky(Preset="Sunset", Radius=1000.0, Exposure=25.0,  # noqa: F821 (proxy NimbusSkyDome)
                         ElevationResolution=24, AzimuthResolution=72,
                         SunElevationDegrees=70.0, SunAzimuthDegrees=0.0)  # overridden by the preset
    dome.UpdatePipeline()
    data = servermanager.Fetch(dome)
    rings, columns = 24, 72
    if data.GetNumberOfPoints() != rings * columns + 1:
        print("unexpected number of points:", data.GetNumberOfPoints())
        return 1
    colors = data.GetPointData().GetArray("Colors")
    radiance = data.GetPointData().GetArray("Radiance")
    if colors is None or radiance is None:
        print("missing Colors / Radiance arrays")
        return 1
    # Ring 0 is the horizon; column j at azimuth 360 j / columns. Sunset preset: sun at
    # 2 degrees, azimuth 270 (west) -> column 54 faces the sun, column 18 faces away.
    toward = radiance.GetTuple3(54)
    away = radiance.GetTuple3(18)
    print("horizon toward the sun (linear rgb):", toward, " away:", away)
    if not (toward[0] > toward[1] > toward[2] and toward[0] > 3.0 * max(toward[2], 0.0)):
        print("horizon toward the sun is not red-orange")
        return 1
    if not (away[2] / away[0] > toward[2] / max(toward[0], 1e-30)):
        print("the sky away from the sun is not bluer than toward it")
        return 1

    view = CreateRenderView()
    view.ViewSize = [320, 240]
    view.OrientationAxesVisibility = 0
    view.UseColorPaletteForBackground = 0
    view.Background = [0.0, 0.0, 0.0]
    view.EnableRenderOnInteraction = 0
    display = Show(dome, view)
    # In a render view the source shows as "Sky Background" by default; the dome is
    # the Surface.
    display.SetRepresentationType("Surface")
    display.MapScalars = 0
    display.ColorArrayName = ["POINTS", "Colors"]
    display.Ambient = 1.0
    display.Diffuse = 0.0
    view.CameraPosition = [0.0, 0.0, 1.0]
    view.CameraFocalPoint = [-1.0, 0.0, 1.25]
    view.CameraViewUp = [0.0, 0.0, 1.0]
    view.CameraViewAngle = 80.0
    view.CameraParallelProjection = 0
    os.makedirs(args.output_dir, exist_ok=True)
    image = os.path.join(args.output_dir, "TestPluginSkyDome.png")
    SaveScreenshot(image, view, ImageResolution=[320, 240])
    ok = compare_with_baseline(image, args.baseline, args.output_dir, args.compare_tool)
    print("image test", "passed" if ok else "FAILED", "->", image)
    Delete(display)
    Delete(view)
    del display, view
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
