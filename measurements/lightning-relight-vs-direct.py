#!/usr/bin/env python3
"""Relight against the direct solve, in the picture (003; docs/lightning.md).

    PYTHONPATH=build/lib/python3.11/site-packages Testing/with-display.sh /usr/bin/python3 \\
        measurements/lightning-relight-vs-direct.py [--spacing M ...] [--threshold XI ...]

vtkNimbusLightningIllumination's two methods on the same cloud and flash (the seed-3
metaball cumulus, a 3.5 km flash from 2 km high inside it, at the return stroke), drawn by
vtkNimbusCloudVolumeMapper in linear radiance (no sun, air or ground): the precomputed
basis (003's relight) for each virtual-light spacing and threshold given, against the
direct multiple-scattering solve with the flash's own point sources. Prints per setting
the precompute, the time per frame of each method, and the RMSE of the basis's picture
against the direct one relative to the direct picture's brightest pixel (the paper's
normalisation, 003 §8) and to the mean of the cloud's pixels, and the ratio of the
means. Writes direct | basis strips to --output-dir.
"""
import argparse
import os
import sys
import time

import numpy as np

import nimbus
from nimbus import harness
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkRenderingCore import vtkRenderWindow, vtkRenderer, vtkVolume
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--spacing", type=float, nargs="+", default=[0.0],
                    help="virtual-light spacings in metres (0: automatic)")
parser.add_argument("--threshold", type=float, nargs="+", default=[1e-3])
parser.add_argument("--downsampling", type=int, default=0)
parser.add_argument("--size", type=int, nargs=2, default=(400, 300))
parser.add_argument("--output-dir", default="lightning-relight-vs-direct")
args = parser.parse_args()
os.makedirs(args.output_dir, exist_ok=True)

cloud = nimbus.vtkNimbusMetaballCloudSource()
cloud.SetSeed(3)
lightning = nimbus.vtkNimbusLightningSource()
lightning.SetStartPoint(200, 0, 2000)
lightning.SetDirection(0.15, 0, -1)
lightning.SetLength(3500)
lightning.SetSeed(11)


def render(method, spacing=0.0, threshold=1e-3):
    illumination = nimbus.vtkNimbusLightningIllumination()
    illumination.SetInputConnection(0, cloud.GetOutputPort(0))
    illumination.SetInputConnection(1, lightning.GetOutputPort(1))
    illumination.SetMethod(method)
    illumination.SetLightSpacingMetres(spacing)
    illumination.SetThreshold(threshold)
    illumination.SetDownsampling(args.downsampling)
    illumination.UseDiskCacheOff()
    illumination.Update()
    mapper = nimbus.vtkNimbusCloudVolumeMapper()
    mapper.SetInputData(illumination.GetOutput())
    mapper.SetMultipleScatteringMethodToNone()
    mapper.SetSunIlluminance(0.0)
    mapper.SetAtmosphere(False)
    mapper.SetGround(False)
    mapper.SetNumberOfSlices(256)
    mapper.SetCaptureRadiance(True)
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
    window.Render()
    radiance = mapper.GetRadianceImage()
    width, height, _ = radiance.GetDimensions()
    image = vtk_to_numpy(radiance.GetPointData().GetScalars()).reshape(height, width, 4)
    window.Finalize()
    return image[..., :3].astype(np.float64).copy(), illumination


direct, solver = render(1)
grid = [0, 0, 0]
solver.GetGridDimensions(grid)
peak = float(direct.max())
cloud_pixels = direct.mean(axis=2) > 0.01 * direct.mean(axis=2).max()
mean = float(direct[cloud_pixels].mean())
print(f"direct solve: {1000 * solver.GetLastRelightSeconds():.0f} ms per frame")
print(f"{'spacing m':>9} {'xi':>7} {'lights':>6} {'precompute s':>12} {'basis MB':>9} "
      f"{'frame ms':>8} {'x faster':>8} {'RMSE/max':>9} {'RMSE/mean':>9} {'mean ratio':>10}")
for spacing in args.spacing:
    for threshold in args.threshold:
        basis, relight = render(0, spacing, threshold)
        rmse = float(np.sqrt(np.mean((basis - direct) ** 2)))
        frame = relight.GetLastRelightSeconds()
        print(f"{spacing:9.0f} {threshold:7.0e} {relight.GetNumberOfVirtualLights():6d} "
              f"{relight.GetLastPrecomputeSeconds():12.1f} {relight.GetBasisBytes() / 1e6:9.1f} "
              f"{1000 * frame:8.2f} {solver.GetLastRelightSeconds() / frame:8.0f} "
              f"{rmse / peak:9.4f} {rmse / mean:9.3f} "
              f"{basis[cloud_pixels].mean() / mean:10.3f}")
        strip = np.concatenate([direct, basis], axis=1)
        harness.write_png(strip * (0.5 / peak) / harness.DISPLAY_EXPOSURE, os.path.join(
            args.output_dir, f"direct-basis-{spacing:.0f}m-{threshold:.0e}.png"))
