#!/usr/bin/env python3
"""Frame time of the Cloud mapper drawing a cloud lit by lightning, per view of the lightning.

    PYTHONPATH=build/lib/python3.11/site-packages Testing/with-display.sh /usr/bin/python3 \\
        measurements/lightning-frame-bench.py [--frames 12] [--size 1280 800] [--march]

The scene of measurements/lightning-vs-path-tracer.py (the seed-3 cumulus at night, the
flash at its return stroke, the precomputed basis on the 32x32x22 grid): the mapper draws
--frames frames, the camera turned 0.5 degrees between them so that each is drawn anew, in
the delta-M view (LightningDeltaMView, the default), then in the plain view, and prints each view's median and fastest frame [s]. Run it with two builds' PYTHONPATH to
compare them (the numbers vary with the machine's load: compare runs made one after the
other).
"""
import argparse
import statistics
import time

import nimbus
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401
from vtkmodules.vtkRenderingCore import vtkRenderWindow, vtkRenderer, vtkVolume

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--frames", type=int, default=12)
parser.add_argument("--size", type=int, nargs=2, default=(1280, 800))
parser.add_argument("--march", action="store_true", help="the ray march instead of the slices")
parser.add_argument("--cache-dir", default="", help="the illumination filter's basis cache")
args = parser.parse_args()

cloud = nimbus.vtkNimbusMetaballCloudSource()
cloud.SetDimensions(96, 96, 64)
cloud.SetBounds(-1500, 1500, -1500, 1500, 800, 2800)
cloud.SetSeed(3)
lightning = nimbus.vtkNimbusLightningSource()
lightning.SetStartPoint(200, 0, 2000)
lightning.SetDirection(0.15, 0, -1)
lightning.SetLength(3500)
lightning.SetSeed(11)
illumination = nimbus.vtkNimbusLightningIllumination()
illumination.SetInputConnection(0, cloud.GetOutputPort(0))
illumination.SetInputConnection(1, lightning.GetOutputPort(0))
illumination.SetDownsampling(3)
illumination.SetMemoryBudgetMiB(4096)
if args.cache_dir:
    illumination.SetCacheDirectory(args.cache_dir)
start = time.perf_counter()
illumination.Update()
print(f"illumination: {time.perf_counter() - start:.1f} s")

mapper = nimbus.vtkNimbusCloudVolumeMapper()
mapper.SetInputConnection(illumination.GetOutputPort())
mapper.SetMultipleScatteringMethodToNone()
mapper.SetSunIlluminance(0.0)
mapper.SetAtmosphere(False)
mapper.SetGround(False)
if args.march:
    mapper.SetRenderingMethodToRayMarching()
volume = vtkVolume()
volume.SetMapper(mapper)
renderer = vtkRenderer()
renderer.AddVolume(volume)
camera = renderer.GetActiveCamera()
camera.SetPosition(0, -5000, 300)
camera.SetFocalPoint(0, 0, 1300)
camera.SetViewUp(0, 0, 1)
camera.SetViewAngle(50)
camera.SetClippingRange(10, 1e6)
window = vtkRenderWindow()
window.SetOffScreenRendering(1)
window.SetMultiSamples(0)
window.SetSize(*args.size)
window.AddRenderer(renderer)
times = {True: [], False: []}
for delta_m in (True, False):
    # (A change of view uploads the other first-scattering field: one frame not counted.)
    mapper.SetLightningDeltaMView(delta_m)
    window.Render()
    for frame in range(args.frames):
        camera.Azimuth(0.5)
        start = time.perf_counter()
        window.Render()
        times[delta_m].append(time.perf_counter() - start)
for delta_m, name in ((True, "delta-M view"), (False, "plain view")):
    print(f"{name:<13} {args.size[0]}x{args.size[1]} {'march' if args.march else 'slices'}: "
          f"median {statistics.median(times[delta_m]):.3f} s, fastest {min(times[delta_m]):.3f} s "
          f"({args.frames} frames)")
window.Finalize()
