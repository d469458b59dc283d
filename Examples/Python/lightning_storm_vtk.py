"""VTK Python example: a cloud at night lit from inside by a lightning flash (paper 003).

    PYTHONPATH=build/lib/python3.11/site-packages /usr/bin/python3 \
        Examples/Python/lightning_storm_vtk.py [output.png] [--time SECONDS] [--size W H]

The pipeline: vtkNimbusMetaballCloudSource (the cloud) and vtkNimbusLightningSource (the
strokes and their point sources over time) into vtkNimbusLightningIllumination, which
precomputes the cloud's response to virtual point lights once (003 §4-7; cached on disk,
see its class comment) and relights it for every time step in milliseconds;
vtkNimbusCloudVolumeMapper draws the result under a night sky (sun 12 degrees below
the horizon), the strokes themselves as bright lines with the glow of the rainy air
around them (vtkNimbusLightningGlowMapper). Without --time the frame is the return
stroke's peak.
"""
import argparse
import sys
import time

import nimbus
from vtkmodules.vtkCommonCore import vtkLookupTable
from vtkmodules.vtkIOImage import vtkPNGWriter
from vtkmodules.vtkRenderingCore import (vtkActor, vtkPolyDataMapper, vtkRenderer,
                                         vtkRenderWindow, vtkVolume, vtkWindowToImageFilter)
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401

# NIMBUS_OFFSCREEN=egl: render on an EGL pbuffer, no X server (docs/offscreen.md).
nimbus.offscreen_if_requested()

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("output", nargs="?", default="lightning_storm.png")
parser.add_argument("--time", type=float, default=None,
                    help="seconds into the flash (default: the return stroke's peak)")
parser.add_argument("--size", type=int, nargs=2, default=(800, 450))
args = parser.parse_args()

cloud = nimbus.vtkNimbusMetaballCloudSource()  # 3 km wide, base 1000 m, top ~2.8 km
cloud.SetSeed(3)

lightning = nimbus.vtkNimbusLightningSource()
lightning.SetStartPoint(200, 0, 2000)  # metres, inside the cloud
lightning.SetDirection(0.15, 0, -1)    # down to the ground, leaning east
lightning.SetLength(3500)
lightning.SetSeed(11)

illumination = nimbus.vtkNimbusLightningIllumination()
illumination.SetInputConnection(0, cloud.GetOutputPort(0))
illumination.SetInputConnection(1, lightning.GetOutputPort(1))  # the point sources
start = time.perf_counter()
if args.time is None:
    illumination.Update()
    lightning.Update()
else:
    # A time step: the filter asks the lightning for that time; the outputs are then
    # handed to the mappers as they are (a mapper's own update requests no time).
    illumination.UpdateTimeStep(args.time)
    lightning.UpdateTimeStep(args.time)
grid = [0, 0, 0]
illumination.GetGridDimensions(grid)
print(f"lightning: {illumination.GetNumberOfVirtualLights()} virtual lights on a "
      f"{grid[0]}x{grid[1]}x{grid[2]} grid, "
      + (f"basis read from {illumination.GetCacheFile()}" if illumination.GetLastBasisFromDisk()
         else f"precomputed in {illumination.GetLastPrecomputeSeconds():.1f} s")
      + f", relit in {1000 * illumination.GetLastRelightSeconds():.1f} ms "
      f"(update {time.perf_counter() - start:.1f} s)", file=sys.stderr)

mapper = nimbus.vtkNimbusCloudVolumeMapper()
mapper.SetInputData(illumination.GetOutput())
mapper.SetNumberOfSlices(256)
mapper.SetEncodeSrgb(True)
mapper.SetExposure(2.0)
volume = vtkVolume()
volume.SetMapper(mapper)

sky = nimbus.vtkNimbusSkyBackground()
sky.GetSky().SetSunElevationDegrees(-12.0)  # nautical twilight: a dark sky
sky.GetSky().SetSunAzimuthDegrees(250.0)
sky.GetSky().SetExposure(2.0)
mapper.SetSkyBackground(sky)

# The channels in their brightness now: black (unlit yet, or faded) to blue-white at
# the return stroke's peak.
peak = lightning.GetOutput(0).GetCellData().GetArray("peak_intensity").GetRange()[1]
colours = vtkLookupTable()
colours.SetTableRange(0.0, peak)
colours.SetHueRange(0.62, 0.62)
colours.SetSaturationRange(0.15, 0.15)
colours.SetValueRange(0.0, 1.0)
colours.Build()
strokes = vtkPolyDataMapper()
strokes.SetInputData(lightning.GetOutput(0))
strokes.SetScalarModeToUseCellFieldData()
strokes.SelectColorArray("intensity")
strokes.SetLookupTable(colours)
strokes.UseLookupTableScalarRangeOn()
channel = vtkActor()
channel.SetMapper(strokes)
channel.GetProperty().SetLineWidth(2.0)
channel.GetProperty().LightingOff()

# The glow of the rainy air around the channels (003 §8): emissive splats at the point
# sources with the single-scattering profile of a point source in air.
glow_mapper = nimbus.vtkNimbusLightningGlowMapper()
glow_mapper.SetInputData(lightning.GetOutputDataObject(1))
glow_mapper.SetExposure(2.0)
glow = vtkActor()
glow.SetMapper(glow_mapper)

renderer = vtkRenderer()
renderer.AddViewProp(sky)
renderer.AddActor(channel)
renderer.AddActor(glow)
renderer.AddVolume(volume)
renderer.SetBackground(0, 0, 0)
camera = renderer.GetActiveCamera()
camera.SetPosition(-600.0, -4200.0, 250.0)
camera.SetFocalPoint(0.0, 0.0, 1250.0)
camera.SetViewUp(0, 0, 1)
camera.SetViewAngle(50.0)
camera.SetClippingRange(10.0, 1e6)

window = vtkRenderWindow()
window.SetOffScreenRendering(1)
window.SetMultiSamples(0)
window.SetSize(*args.size)
window.AddRenderer(renderer)
window.Render()
grab = vtkWindowToImageFilter()
grab.SetInput(window)
grab.ReadFrontBufferOff()
writer = vtkPNGWriter()
writer.SetFileName(args.output)
writer.SetInputConnection(grab.GetOutputPort())
writer.Write()
if writer.GetErrorCode():
    sys.exit(f"could not write {args.output}")
print(args.output)
