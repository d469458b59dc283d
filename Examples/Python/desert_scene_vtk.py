#!/usr/bin/env python3
"""A desert under the Nimbus sky: dunes and wind ripples (002 §5) lit by the Nimbus sun.

The dune field of vtkNimbusDunesSource (periodic, so its copies tile) is laid out as
TILES x TILES copies around the camera. Each quadrilateral gets a level of detail from its
distance to the viewer (002 §5.2 step 2(b), as nimbus::RippleLevelOfDetail: level 0 nearer
than NEAR metres, one level coarser per doubling of the distance, 4 levels), and the
quadrilaterals of one level are drawn by one actor whose normal-map texture is the ripple
tile at that level (256^2, 128^2, 64^2, 32^2: vtkNimbusDunesSource.RippleNormalLevel, heights
box-averaged and normals recomputed, no mipmapping). VTK's physically based shading applies the
normal map with the surface's tangents. The sun is vtkNimbusSunlight (the sky's sun and its
colour through the air); vtkNimbusSkyPass draws the sky behind and adds the aerial perspective
over distance.

  PYTHONPATH=build/lib/python3.11/site-packages Testing/with-display.sh /usr/bin/python3 \\
      Examples/Python/desert_scene_vtk.py [--output docs/images/desert.png] [--no-lod] [--frames N]

--no-lod uses the finest level everywhere (for the cost comparison); --frames N renders N
more frames and prints the mean time per frame.
"""
import argparse
import math
import os
import sys
import time

from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkFloatArray
from vtkmodules.vtkCommonDataModel import vtkDataObject, vtkImageData
from vtkmodules.vtkFiltersCore import vtkAppendPolyData, vtkThreshold
from vtkmodules.vtkFiltersGeometry import vtkGeometryFilter
from vtkmodules.vtkIOImage import vtkPNGWriter
from vtkmodules.vtkRenderingCore import (vtkActor, vtkLight, vtkPolyDataMapper, vtkRenderer,
                                         vtkRenderWindow, vtkTexture, vtkWindowToImageFilter)
from vtkmodules.vtkRenderingOpenGL2 import vtkRenderStepsPass
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401 (the OpenGL factories)
import numpy as np

import nimbus  # noqa: F401
from nimbus.NimbusFilters import vtkNimbusDunesSource
from nimbus.NimbusRepresentations import vtkNimbusSky, vtkNimbusSkyPass, vtkNimbusSunlight

SAND = (0.83, 0.62, 0.40)  # albedo of desert sand (linear-ish display colour)
LEVELS = 4


def build_field(source, tiles):
    """TILES x TILES copies of the periodic dune surface, centred on the origin."""
    surface = source.GetOutput()
    bounds = surface.GetBounds()
    size = bounds[1] - bounds[0]
    points = vtk_to_numpy(surface.GetPoints().GetData())
    append = vtkAppendPolyData()
    for i in range(tiles):
        for j in range(tiles):
            copy = type(surface)()
            copy.DeepCopy(surface)
            shifted = points.copy()
            shifted[:, 0] += (i - (tiles - 1) / 2.0) * size
            shifted[:, 1] += (j - (tiles - 1) / 2.0) * size
            copy.GetPoints().SetData(numpy_to_vtk(shifted, deep=True))
            append.AddInputData(copy)
    append.Update()
    return append.GetOutput()


def level_of_detail(field, eye, near, use_lod):
    """Cell array RippleLevel: 002 §5.2's level per quadrilateral from its distance."""
    pts = vtk_to_numpy(field.GetPoints().GetData())
    conn = vtk_to_numpy(field.GetPolys().GetConnectivityArray()).reshape(-1, 4)
    centres = pts[conn].mean(axis=1)
    distance = np.linalg.norm(centres - np.asarray(eye), axis=1)
    if use_lod:
        # nimbus::RippleLevelOfDetail: 0 within near, +1 per doubling, at most LEVELS - 1.
        level = np.where(distance > near,
                         np.floor(np.log2(np.maximum(distance, near) / near)) + 1, 0)
        level = np.minimum(level, LEVELS - 1)
    else:
        level = np.zeros(len(distance))
    array = numpy_to_vtk(level.astype(np.float32), deep=True)
    array.SetName("RippleLevel")
    field.GetCellData().AddArray(array)
    return np.bincount(level.astype(int), minlength=LEVELS)


def ripple_texture(ripples, level):
    image = vtkImageData()
    if not vtkNimbusDunesSource.RippleNormalLevel(ripples, level, image):
        raise RuntimeError("no ripple level %d" % level)
    image.GetPointData().SetActiveScalars("RippleNormalMap")
    texture = vtkTexture()
    texture.SetInputData(image)
    texture.SetRepeat(True)
    texture.SetInterpolate(True)
    texture.SetMipmap(False)  # 002 §5.2: the level is chosen per quadrilateral instead
    return texture


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--output", default=os.path.join(
        os.path.dirname(__file__), "..", "..", "docs", "images", "desert.png"))
    parser.add_argument("--width", type=int, default=1280)
    parser.add_argument("--height", type=int, default=720)
    parser.add_argument("--tiles", type=int, default=11)
    parser.add_argument("--no-lod", action="store_true")
    parser.add_argument("--frames", type=int, default=0)
    parser.add_argument("--sand-depth", type=float, default=4.0)
    parser.add_argument("--eye", type=float, nargs=3, default=(-30.0, -300.0, 32.0))
    parser.add_argument("--focal", type=float, nargs=3, default=(60.0, 400.0, -20.0))
    parser.add_argument("--sun-elevation", type=float, default=14.0)
    parser.add_argument("--sun-azimuth", type=float, default=235.0)
    args = parser.parse_args()

    start = time.perf_counter()
    source = vtkNimbusDunesSource()
    # Ripples drawn larger than life (about 0.3 m apart instead of 0.08 m), so that they show
    # on a picture of a whole dune field, as in 002's Fig. 11: every ripple length times 4.
    source.SetRippleCellSizeMetres(0.04)
    source.SetRippleSaltationLengthMetres(0.24)
    source.SetRippleSaltationDepthMetres(0.012)
    source.SetSandDepthMetres(args.sand_depth)
    source.Update()
    generated = time.perf_counter() - start
    ripples = source.GetRippleOutput()
    field = build_field(source, args.tiles)

    width, height = args.width, args.height
    view_angle = 40.0
    eye = tuple(args.eye)
    focal = tuple(args.focal)
    # Level 0 where a texel of the finest level (RippleCellSizeMetres) is about a pixel.
    pixel_angle = 2.0 * math.tan(math.radians(view_angle) / 2.0) / height
    near = source.GetRippleCellSizeMetres() / pixel_angle
    counts = level_of_detail(field, eye, near, not args.no_lod)

    sky = vtkNimbusSky()
    sky.SetSunElevationDegrees(args.sun_elevation)
    sky.SetSunAzimuthDegrees(args.sun_azimuth)
    sky.SetTurbidity(4.0)  # desert haze
    sky.SetGroundAlbedo(0.35)
    sky.SetExposure(12.0)
    sky.SetSceneAltitudeMetres(300.0)

    renderer = vtkRenderer()
    for level in range(LEVELS):
        threshold = vtkThreshold()
        threshold.SetInputData(field)
        threshold.SetInputArrayToProcess(0, 0, 0, vtkDataObject.FIELD_ASSOCIATION_CELLS,
                                         "RippleLevel")
        threshold.SetLowerThreshold(level - 0.5)
        threshold.SetUpperThreshold(level + 0.5)
        threshold.SetThresholdFunction(vtkThreshold.THRESHOLD_BETWEEN)
        geometry = vtkGeometryFilter()
        geometry.SetInputConnection(threshold.GetOutputPort())
        geometry.Update()
        if geometry.GetOutput().GetNumberOfCells() == 0:
            continue
        assert geometry.GetOutput().GetPointData().GetTangents() is not None
        mapper = vtkPolyDataMapper()
        mapper.SetInputData(geometry.GetOutput())
        mapper.ScalarVisibilityOff()
        actor = vtkActor()
        actor.SetMapper(mapper)
        prop = actor.GetProperty()
        prop.SetInterpolationToPBR()
        prop.SetColor(*SAND)
        prop.SetMetallic(0.0)
        prop.SetRoughness(0.95)
        prop.SetNormalTexture(ripple_texture(ripples, level))
        prop.SetNormalScale(1.0)
        renderer.AddActor(actor)

    sun = vtkNimbusSunlight()
    sun.SetSunElevationDegrees(args.sun_elevation)
    sun.SetSunAzimuthDegrees(args.sun_azimuth)
    sun.SetSceneAltitudeMetres(300.0)
    light = vtkLight()
    sun.ApplyToLight(light)
    light.SetIntensity(light.GetIntensity() * 3.2)
    renderer.AddLight(light)
    # The sky's light on the shaded sides: a dim fill from above, bluish.
    fill = vtkLight()
    fill.SetLightTypeToSceneLight()
    fill.SetPositional(False)
    fill.SetPosition(0.0, 0.0, 1.0)
    fill.SetFocalPoint(0.0, 0.0, 0.0)
    fill.SetColor(0.55, 0.65, 0.85)
    fill.SetIntensity(0.55)
    renderer.AddLight(fill)

    camera = renderer.GetActiveCamera()
    camera.SetPosition(*eye)
    camera.SetFocalPoint(*focal)
    camera.SetViewUp(0.0, 0.0, 1.0)
    camera.SetViewAngle(view_angle)
    camera.SetClippingRange(1.0, 2.0e4)

    steps = vtkRenderStepsPass()
    sky_pass = vtkNimbusSkyPass()
    sky_pass.SetSky(sky)
    sky_pass.SetDelegatePass(steps)
    renderer.SetPass(sky_pass)

    window = vtkRenderWindow()
    window.SetSize(width, height)
    window.SetMultiSamples(0)
    window.AddRenderer(renderer)
    first = time.perf_counter()
    window.Render()
    first = time.perf_counter() - first

    capture = vtkWindowToImageFilter()
    capture.SetInput(window)
    capture.ReadFrontBufferOff()
    capture.Update()
    writer = vtkPNGWriter()
    writer.SetFileName(os.path.abspath(args.output))
    writer.SetInputConnection(capture.GetOutputPort())
    writer.Write()

    per_frame = float("nan")
    if args.frames > 0:
        tic = time.perf_counter()
        for k in range(args.frames):
            camera.Azimuth(0.01 if k % 2 == 0 else -0.01)
            window.Render()
        per_frame = (time.perf_counter() - tic) / args.frames
    print("dunes and ripples generated in %.2f s; %d quadrilaterals, per level %s (near %.0f m); "
          "first frame %.2f s; %s per frame %.3f s over %d frames; wrote %s"
          % (generated, field.GetNumberOfCells(), list(counts), near, first,
             "no LOD" if args.no_lod else "LOD", per_frame, args.frames, args.output))
    return 0


if __name__ == "__main__":
    sys.exit(main())
