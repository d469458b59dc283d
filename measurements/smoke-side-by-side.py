"""Nimbus's smoke and Blender's Mantaflow smoke of the same scene, rendered side by side
with the same renderer, optics, sun and camera (docs/smoke.md).

    PYTHONPATH=build/lib/python3.11/site-packages Testing/with-display.sh /usr/bin/python3 \
        measurements/smoke-side-by-side.py --nimbus A --mantaflow B --out C.png

A, Nimbus's density, is either
  - a .vti with a point array "density" (what vtkNimbusSmokeSource writes; e.g.
    --save-nimbus of an earlier run), or
  - RES:FRAMES, e.g. 64:24: vtkNimbusSmokeSource runs BenchSmoke's scene
    (Benchmarks/BenchSmoke.cxx: RES^3 cells over the 8 m cube from (-4, -4, 0),
    the hot sphere of 0.75 m at (0, 0, 0.75), vorticity 0.3, Smagorinsky 0.15,
    MacCormack, 24 frames per second) to frame FRAMES (--threads, default 2).
B, Mantaflow's, is the .vdb that measurements/mantaflow-smoke-bench.py printed (its last
frame), or that bake's cache directory (its last data/fluid_data_NNNN.vdb is taken).

Read with Nimbus's OpenVDB reader (the density grid only). Blender's cache grids carry a
pure scale transform: voxel size = domain size / resolution in Blender units (metres
here: the bench's domain is 8 units, Blender's factory unit scale is 1 m), index (0, 0, 0)
at the world origin, i.e. in the domain's own frame. The Mantaflow image is therefore
moved to world metres: Mantaflow's voxel (i, j, k) is the cell [i, i+1] h from the
domain's corner (-4, -4, 0) m, its centre at corner + (i + 1/2) h, where Nimbus puts its
own cell centres; the reader's image (the active voxels' box) is padded with zeros to the
whole RES^3 grid, so both panels render the same box. The script prints each plume's
smoke (density m^3), density-weighted centroid and top (the highest cell above 1 % of
the peak) in metres.

Rendering: vtkNimbusCloudVolumeMapper with smoke's optics (the Medium Preset "Smoke":
extinction 1.5 /m per unit density, albedo 0.6, Cornette-Shanks g 0.3), the sun 45
degrees high, no air or ground, the same camera for both; Nimbus on the left, Mantaflow
on the right, joined with vtkImageAppend.
"""
import argparse
import glob
import os
import sys

import numpy as np

import nimbus
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.vtkCommonDataModel import vtkImageData
from vtkmodules.vtkFiltersCore import vtkImageAppend
from vtkmodules.vtkIOImage import vtkPNGWriter
from vtkmodules.vtkIOXML import vtkXMLImageDataReader, vtkXMLImageDataWriter
from vtkmodules.vtkRenderingCore import (vtkRenderer, vtkRenderWindow, vtkVolume,
                                         vtkWindowToImageFilter)
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401

DOMAIN_SIZE = 8.0
DOMAIN_MIN = (-4.0, -4.0, 0.0)
FPS = 24.0

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--nimbus", required=True,
                    help="a .vti with 'density', or RES:FRAMES to run the smoke source")
parser.add_argument("--mantaflow", required=True,
                    help="Mantaflow's .vdb, or its bake's cache directory (last frame)")
parser.add_argument("--out", required=True, help="the PNG to write")
parser.add_argument("--save-nimbus", help="write the Nimbus density here (.vti) for reuse")
parser.add_argument("--threads", type=int, default=2)
parser.add_argument("--size", type=int, nargs=2, default=(360, 400), help="one panel's size")
args = parser.parse_args()


def nimbus_density():
    if args.nimbus.endswith(".vti"):
        reader = vtkXMLImageDataReader()
        reader.SetFileName(args.nimbus)
        reader.Update()
        return reader.GetOutput()
    res, frames = (int(x) for x in args.nimbus.split(":"))
    smoke = nimbus.vtkNimbusSmokeSource()  # BenchSmoke's scene
    smoke.SetDimensions(res, res, res)
    smoke.SetCellSizeMetres(DOMAIN_SIZE / res)
    smoke.SetOrigin(*DOMAIN_MIN)
    smoke.SetEmitterCentre(0.0, 0.0, 0.75)
    smoke.SetEmitterRadiusMetres(0.75)
    smoke.SetEmitterDensityPerSecond(2.0)
    smoke.SetEmitterTemperatureKelvin(600.0)
    smoke.SetVorticityConfinement(0.3)
    smoke.SetSmagorinskyConstant(0.15)
    smoke.SetNumberOfFrames(frames)
    smoke.SetNumberOfThreads(args.threads)
    smoke.UpdateInformation()
    smoke.UpdateTimeStep(frames / FPS)
    image = vtkImageData()
    image.DeepCopy(smoke.GetOutput())
    if args.save_nimbus:
        writer = vtkXMLImageDataWriter()
        writer.SetInputData(image)
        writer.SetFileName(args.save_nimbus)
        writer.Write()
    return image


def mantaflow_density(res):
    path = args.mantaflow
    if os.path.isdir(path):
        files = sorted(glob.glob(os.path.join(path, "data", "fluid_data_*.vdb")))
        if not files:
            sys.exit(f"smoke-side-by-side: no data/fluid_data_*.vdb in {path}")
        path = files[-1]
    reader = nimbus.vtkNimbusOpenVDBReader()
    reader.SetFileName(path)
    reader.Update()
    raw = reader.GetOutput()
    values = raw.GetPointData().GetArray("density")
    if values is None:
        sys.exit(f"smoke-side-by-side: {path} has no density grid")
    h = raw.GetSpacing()[0]
    if abs(h * res - DOMAIN_SIZE) > 1e-6 * DOMAIN_SIZE:
        sys.exit(f"smoke-side-by-side: {path}'s voxels are {h} m, not {DOMAIN_SIZE / res} m "
                 f"(RES {res})")
    x0, x1, y0, y1, z0, z1 = raw.GetExtent()
    block = vtk_to_numpy(values).reshape(z1 - z0 + 1, y1 - y0 + 1, x1 - x0 + 1)
    full = np.zeros((res, res, res), dtype=np.float32)
    full[z0:z1 + 1, y0:y1 + 1, x0:x1 + 1] = block
    image = vtkImageData()
    image.SetDimensions(res, res, res)
    image.SetSpacing(h, h, h)
    image.SetOrigin(*(m + 0.5 * h for m in DOMAIN_MIN))  # cell centres, world metres
    array = numpy_to_vtk(full.reshape(-1), deep=True)
    array.SetName("density")
    image.GetPointData().SetScalars(array)
    return image, path


def describe(name, image):
    res = image.GetDimensions()
    density = vtk_to_numpy(image.GetPointData().GetArray("density")).reshape(
        res[2], res[1], res[0]).astype(np.float64)
    h = image.GetSpacing()[0]
    origin = image.GetOrigin()
    total = density.sum()
    z, y, x = np.indices(density.shape)
    centroid = [origin[a] + h * float((c * density).sum() / max(total, 1e-30))
                for a, c in enumerate((x, y, z))]
    rows = np.nonzero((density > 0.01 * density.max()).any(axis=(1, 2)))[0]
    top = origin[2] + h * (rows.max() + 0.5) if len(rows) else float("nan")
    print(f"{name:>9}: smoke {total * h ** 3:.3f} density m^3, peak {density.max():.3f}, "
          f"centroid ({centroid[0]:.2f}, {centroid[1]:.2f}, {centroid[2]:.2f}) m, "
          f"top {top:.2f} m")


def render(image):
    mapper = nimbus.vtkNimbusCloudVolumeMapper()
    mapper.SetInputData(image)
    mapper.SetExtinctionPerDensity(1.5)
    mapper.SetAlbedo(0.6)
    mapper.SetCloudG(0.3)
    mapper.SetSunElevationDegrees(45.0)
    mapper.SetSunAzimuthDegrees(200.0)
    mapper.SetAtmosphere(False)
    mapper.SetGround(False)
    mapper.SetNumberOfSlices(512)
    mapper.SetExposure(8.0)
    mapper.SetEncodeSrgb(True)
    volume = vtkVolume()
    volume.SetMapper(mapper)
    renderer = vtkRenderer()
    renderer.AddVolume(volume)
    renderer.SetBackground(0.3, 0.4, 0.55)
    camera = renderer.GetActiveCamera()
    camera.SetPosition(0.0, -12.0, 2.2)
    camera.SetFocalPoint(0.0, 0.0, 2.2)
    camera.SetViewUp(0, 0, 1)
    camera.SetViewAngle(30.0)
    camera.SetClippingRange(0.1, 1e3)
    window = vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetMultiSamples(0)
    window.SetSize(*args.size)
    window.AddRenderer(renderer)
    window.Render()
    grab = vtkWindowToImageFilter()
    grab.SetInput(window)
    grab.ReadFrontBufferOff()
    grab.Update()
    out = vtkImageData()
    out.DeepCopy(grab.GetOutput())
    window.Finalize()
    return out


mine = nimbus_density()
res = mine.GetDimensions()[0]
theirs, vdb = mantaflow_density(res)
print(f"grid {res}^3; Mantaflow: {vdb}")
describe("Nimbus", mine)
describe("Mantaflow", theirs)
append = vtkImageAppend()
append.SetAppendAxis(0)
append.AddInputData(render(mine))
append.AddInputData(render(theirs))
writer = vtkPNGWriter()
writer.SetFileName(args.out)
writer.SetInputConnection(append.GetOutputPort())
writer.Write()
print(args.out)
