"""VTK Python example: smoke rising around an obstacle into the sky (002 §4).

    PYTHONPATH=build/lib/python3.11/site-packages Testing/with-display.sh /usr/bin/python3 \
        Examples/Python/smoke_obstacle_vtk.py [output.png] [--seconds S] [--size W H]
        [--puffs] [--fire]

The pipeline: a sphere (vtkSphereSource, metres) is the obstacle input of
vtkNimbusSmokeSource, which voxelises it (a cell is solid when its centre is inside) and
simulates hot smoke from a source below it for S seconds (default 5: 120 frames of
1/24 s); the plume splits around the ball and joins above it. vtkNimbusCloudVolumeMapper
draws the smoke with the Smoke medium preset's optics (extinction 1.5 /m per unit
density, albedo 0.6, forward scattering 0.3) under a Nimbus sky (sun 25 degrees high),
and an opaque ball shows the obstacle. --puffs draws the puffs' density (twice as fine
as the simulation); --fire makes the source 1500 K and turns on the temperature
emission (the glow of the hot gas).
"""
import argparse
import sys
import time

import nimbus
from vtkmodules.vtkFiltersSources import vtkSphereSource
from vtkmodules.vtkIOImage import vtkPNGWriter
from vtkmodules.vtkRenderingCore import (vtkActor, vtkPolyDataMapper, vtkRenderer,
                                         vtkRenderWindow, vtkVolume, vtkWindowToImageFilter)
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401

# NIMBUS_OFFSCREEN=egl: render on an EGL pbuffer, no X server (docs/offscreen.md).
nimbus.offscreen_if_requested()

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("output", nargs="?", default="smoke_obstacle.png")
parser.add_argument("--seconds", type=float, default=5.0)
parser.add_argument("--size", type=int, nargs=2, default=(640, 800))
parser.add_argument("--puffs", action="store_true")
parser.add_argument("--fire", action="store_true")
args = parser.parse_args()
if not 0.0 < args.seconds <= 60.0:
    sys.exit("--seconds must be in (0, 60]")

ball = vtkSphereSource()  # the obstacle, metres
ball.SetCenter(0.0, 0.0, 3.2)
ball.SetRadius(1.1)
ball.SetThetaResolution(48)
ball.SetPhiResolution(32)

smoke = nimbus.vtkNimbusSmokeSource()
smoke.SetInputConnection(ball.GetOutputPort())
smoke.SetDimensions(40, 40, 64)     # cells
smoke.SetCellSizeMetres(0.2)        # an 8 x 8 x 12.8 m box
smoke.SetOrigin(-4.0, -4.0, 0.0)
smoke.SetEmitterCentre(0.0, 0.0, 0.7)
smoke.SetEmitterRadiusMetres(0.6)
smoke.SetEmitterDensityPerSecond(6.0)
smoke.SetEmitterTemperatureKelvin(1500.0 if args.fire else 700.0)
if args.fire:
    smoke.SetCoolingPerSecond(1.5)
smoke.SetNumberOfFrames(int(round(args.seconds * 24)))
smoke.SetPuffs(args.puffs)
start = time.perf_counter()
smoke.UpdateInformation()
smoke.UpdateTimeStep(args.seconds)
print(f"smoke: {args.seconds:g} s simulated in {time.perf_counter() - start:.1f} s",
      file=sys.stderr)

mapper = nimbus.vtkNimbusCloudVolumeMapper()
mapper.SetInputData(smoke.GetOutput())
mapper.SetExtinctionPerDensity(1.5)  # the Smoke preset
mapper.SetAlbedo(0.6)
mapper.SetCloudG(0.3)
mapper.SetTemperatureEmission(args.fire)
mapper.SetNumberOfSlices(384)
mapper.SetEncodeSrgb(True)
volume = vtkVolume()
volume.SetMapper(mapper)

sky = nimbus.vtkNimbusSkyBackground()
sky.GetSky().SetSunElevationDegrees(25.0)
sky.GetSky().SetSunAzimuthDegrees(215.0)
mapper.SetSkyBackground(sky)

ball_mapper = vtkPolyDataMapper()
ball_mapper.SetInputConnection(ball.GetOutputPort())
obstacle = vtkActor()
obstacle.SetMapper(ball_mapper)
obstacle.GetProperty().SetColor(0.55, 0.5, 0.45)

renderer = vtkRenderer()
renderer.AddViewProp(sky)
renderer.AddActor(obstacle)
renderer.AddVolume(volume)
camera = renderer.GetActiveCamera()
camera.SetPosition(0.0, -20.0, 1.6)
camera.SetFocalPoint(0.0, 0.0, 5.2)
camera.SetViewUp(0, 0, 1)
camera.SetViewAngle(38.0)
camera.SetClippingRange(0.1, 1e5)
renderer.ResetCameraClippingRange()
camera.SetClippingRange(0.1, 1e5)

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
