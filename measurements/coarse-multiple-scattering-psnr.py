#!/usr/bin/env python3
"""How coarse may the multiple-scattering solve be? (docs/parallel.md, "The multiple-scattering
solve across pieces".)

Under MPI every rank solves multiple scattering on the same coarse copy of the whole cloud
(at most 64 points on a side: CoarseDensityMaxSide in the Cloud representation). One process
gets the same coarse solve when the mapper's solver grid (MultipleScatteringDownsampling:
blocks of texels per axis) leaves at most 64 points on a side. This script renders the
metaball cloud (vtkNimbusMetaballCloudSource, default bounds 3000 x 3000 x 2000 m) sampled on
N^3 points for each N given, with vtkNimbusCloudVolumeMapper alone (its defaults: discrete
directions, atmosphere, ground; the sun 45 degrees up, sRGB, --exposure), once per solver
grid side S given (blocks of ceil(N / S) texels), and compares each image with the finest solve's (the largest S,
capped at N) by PSNR:

- linear: the mapper's float radiance (CaptureRadiance), peak = the reference image's
  largest value (any channel);
- 8-bit: the framebuffer's sRGB levels (what a user sees), peak 255;
each over the whole image and over the cloud's pixels only (where the reference differs
from the same view without the cloud by more than 1 % of the peak: the sky and the ground,
the same in every image, do not dilute the error).

It also prints the solve's grid, seconds and estimated bytes, its cell size in metres, and
the cloud's mean free path: 1 / (ExtinctionPerDensity x the mean density over the points
above 1 % of the largest).

    PYTHONPATH=build/lib/python3.11/site-packages Testing/with-display.sh /usr/bin/python3 \
        measurements/coarse-multiple-scattering-psnr.py --sizes 64 128 256 --sides 32 64 128 \
        [--metres-per-unit 1 2 4] [--exposure 2] [--image-size 320 240] [--save DIR]
"""
import argparse
import json
import math
import os
import time

import numpy as np
from PIL import Image
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkRenderingCore import (vtkRenderWindow, vtkRenderer, vtkVolume,
                                         vtkWindowToImageFilter)
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401 (object factories)

import nimbus


def cloudless(source):
    """The source's grid with the density 0 everywhere: the sky and the ground alone."""
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkCommonExecutionModel import vtkTrivialProducer
    empty = vtkImageData()
    empty.DeepCopy(source.GetOutput())
    empty.GetPointData().GetScalars().Fill(0.0)
    producer = vtkTrivialProducer()
    producer.SetOutput(empty)
    return producer


def render(source, block, size, exposure, metres_per_unit=1.0):
    mapper = nimbus.vtkNimbusCloudVolumeMapper()
    mapper.SetInputConnection(source.GetOutputPort())
    mapper.SetMultipleScatteringDownsampling(block)
    mapper.SetCaptureRadiance(True)
    mapper.SetSunElevationDegrees(45.0)
    mapper.SetEncodeSrgb(True)
    mapper.SetExposure(exposure)
    mapper.SetMetresPerUnit(metres_per_unit)
    volume = vtkVolume()
    volume.SetMapper(mapper)
    renderer = vtkRenderer()
    renderer.AddVolume(volume)
    renderer.SetBackground(0, 0, 0)
    camera = renderer.GetActiveCamera()
    camera.SetFocalPoint(0.0, 0.0, 1800.0)  # as Testing/Python/ParallelCloudRender.py
    camera.SetPosition(-2600.0, -3600.0, 1300.0)
    camera.SetViewUp(0.0, 0.0, 1.0)
    camera.SetViewAngle(40.0)
    camera.SetClippingRange(100.0, 1e5)
    window = vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetMultiSamples(0)
    window.SetSize(*size)
    window.AddRenderer(renderer)
    start = time.perf_counter()
    window.Render()
    seconds = time.perf_counter() - start
    radiance = mapper.GetRadianceImage()
    width, height, _ = radiance.GetDimensions()
    linear = vtk_to_numpy(radiance.GetPointData().GetScalars()).reshape(height, width, 4)
    grab = vtkWindowToImageFilter()
    grab.SetInput(window)
    grab.SetInputBufferTypeToRGB()
    grab.ReadFrontBufferOff()
    grab.Update()
    frame = vtk_to_numpy(grab.GetOutput().GetPointData().GetScalars()).reshape(height, width, 3)
    dims = [0, 0, 0]
    mapper.GetMultipleScatteringGridDimensions(dims)
    result = {"grid": dims, "solve_seconds": mapper.GetLastMultipleScatteringSeconds(),
              "solve_mib": mapper.GetLastMultipleScatteringBytes() / 2.0**20,
              "render_seconds": seconds, "k": mapper.GetExtinctionPerDensity()}
    window.Finalize()
    return linear[..., :3].astype(np.float64).copy(), frame.astype(np.float64).copy(), result


def psnr(image, reference, peak, mask=None):
    error = (image - reference) ** 2
    mse = float(np.mean(error if mask is None else error[mask]))
    return math.inf if mse == 0.0 else 10.0 * math.log10(peak * peak / mse)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[64, 128, 256])
    parser.add_argument("--sides", type=int, nargs="+", default=[32, 64, 128])
    parser.add_argument("--image-size", type=int, nargs=2, default=[320, 240])
    parser.add_argument("--exposure", type=float, default=1.0,
                        help="framebuffer = exposure x radiance, then sRGB (default 1)")
    parser.add_argument("--metres-per-unit", type=float, nargs="+", default=[1.0],
                        help="the mapper's MetresPerUnit: the same cloud this many times "
                             "larger in metres (optical depth and cell sizes scale with it)")
    parser.add_argument("--save", help="folder for the 8-bit images (PNG)")
    args = parser.parse_args()
    for n, scale in [(n, m) for n in args.sizes for m in args.metres_per_unit]:
        source = nimbus.vtkNimbusMetaballCloudSource()
        source.SetDimensions(n, n, n)
        source.Update()
        image = source.GetOutput()
        density = vtk_to_numpy(image.GetPointData().GetScalars()).astype(np.float64)
        bounds = source.GetBounds()
        sides = sorted({min(s, n) for s in args.sides})
        rows = {}
        for side in sides:
            block = (n + side - 1) // side
            rows[side] = render(source, block, args.image_size, args.exposure, scale)
            rows[side][2]["block"] = block
            if args.save:
                os.makedirs(args.save, exist_ok=True)
                Image.fromarray(rows[side][1][::-1].astype(np.uint8)).save(
                    os.path.join(args.save, "metaball-%d-x%g-solve-%d.png" % (n, scale, side)))
        ref_linear, ref_frame, _ = rows[sides[-1]]
        peak = float(ref_linear.max())
        # The cloud's pixels: where the reference differs from the cloudless picture by more
        # than 1 % of the peak (linear, any channel).
        sky_linear, sky_frame, _ = render(cloudless(source), 1, args.image_size, args.exposure,
                                          scale)
        cloud = np.abs(ref_linear - sky_linear).max(axis=2) > 0.01 * peak
        if args.save:
            Image.fromarray(sky_frame[::-1].astype(np.uint8)).save(
                os.path.join(args.save, "metaball-%d-x%g-cloudless.png" % (n, scale)))
        k = rows[sides[-1]][2]["k"]
        inside = density[density > 0.01 * density.max()]
        mean_free_path = 1.0 / (k * inside.mean())  # metres
        bounds = [b * scale for b in bounds]
        for side in sides:
            linear, frame, result = rows[side]
            cell = [(bounds[2 * a + 1] - bounds[2 * a]) / max(result["grid"][a] - 1, 1)
                    for a in range(3)]
            print(json.dumps({
                "density_points": n, "metres_per_unit": scale, "solve_side_cap": side, "reference_side": sides[-1],
                "block": result["block"], "solve_grid": result["grid"],
                "solve_cell_m": [round(c, 1) for c in cell],
                "mean_free_path_m": round(mean_free_path, 1),
                "mean_density_inside": round(float(inside.mean()), 4),
                "psnr_linear_db": round(psnr(linear, ref_linear, peak), 2),
                "psnr_8bit_db": round(psnr(frame, ref_frame, 255.0), 2),
                "cloud_pixels_fraction": round(float(cloud.mean()), 4),
                "psnr_linear_cloud_db": round(psnr(linear, ref_linear, peak, cloud), 2),
                "psnr_8bit_cloud_db": round(psnr(frame, ref_frame, 255.0, cloud), 2),
                "solve_seconds": round(result["solve_seconds"], 2),
                "solve_mib": round(result["solve_mib"], 1),
                "render_seconds": round(result["render_seconds"], 2)}), flush=True)


if __name__ == "__main__":
    main()
