#!/usr/bin/env python3
"""Smoke and fire: the Cloud representation against the path tracer (docs/smoke.md).

    PYTHONPATH=build/lib/python3.11/site-packages Testing/with-display.sh /usr/bin/python3 \\
        measurements/smoke-vs-path-tracer.py [--output-dir DIR] [--time-limit SECONDS]

Two media from vtkNimbusSmokeSource (the default 8 x 8 x 12 m box of 32 x 32 x 48
cells), written as .vti files beside their version-3 scene files:

  smoke  the default plume (600 K at the source) after 3 s, by day: sun 30 degrees
         high, smoke's optics (1.5 /m per unit density, albedo 0.6, Cornette-Shanks
         g 0.3); no air, no ground, black background, to isolate the medium;
  fire   a hot plume (1500 K at the source, cooling 1.5 /s) after 2 s at night: no sun,
         the smoke's own blackbody glow (the representation's Temperature Emission,
         E = 1 Y/(sr m) per unit density at 1500 K; the scene's "blackbody" emission).

The reference is the path tracer (vtkNimbusReferenceRenderer, all orders of scattering,
cached in the output directory); Nimbus renders the same view with
vtkNimbusCloudVolumeMapper (its default multiple scattering: the discrete-direction
solve, which with Temperature Emission also scatters the glow; 512 slices). The script
prints, per scene, the mean over the medium's pixels (image / reference, with the
reference's standard error) and the RMSE of 8x8-pixel block means over the medium
corrected for the reference's noise, relative to the mean, with the reference's own RMS
block noise on the same scale; the times (the first frame, which includes the
multiple-scattering solve, and the solve alone) and the solver's estimated memory; it
writes reference | Nimbus strips as smoke-vs-path-tracer-<scene>.png.
"""
import argparse
import json
import os
import sys
import time

import numpy as np

import nimbus
from nimbus import harness
from vtkmodules.vtkIOXML import vtkXMLImageDataWriter
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--output-dir", default="smoke-vs-path-tracer")
parser.add_argument("--time-limit", type=float, default=180.0,
                    help="seconds of path tracing per reference (default 180)")
parser.add_argument("--size", type=int, nargs=2, default=(160, 200))
parser.add_argument("--scenes", nargs="+", default=["smoke", "fire"])
parser.add_argument("--albedo", type=float, default=0.6,
                    help="the smoke's single-scattering albedo (default 0.6; 0 isolates "
                         "the emission from its scattering)")
parser.add_argument("--downsampling", type=int, default=0,
                    help="the multiple-scattering grid's downsampling of the density texture "
                         "(0: the mapper's automatic choice)")
parser.add_argument("--figure", metavar="PNG",
                    help="also write the fire's flame, 2x, as four panels: the reference, "
                         "Nimbus without multiple scattering (the glow not scattered), "
                         "Nimbus, and Nimbus with the solve on the density's own grid "
                         "(downsampling 1)")
parser.add_argument("--gain", type=float, default=1.0,
                    help="brightness of the written strips (default 1: the reference's 99th "
                         "percentile at half scale)")
args = parser.parse_args()
os.makedirs(args.output_dir, exist_ok=True)

CAMERA = {"position": [0, -24, 5.5], "focal_point": [0, 0, 5.5], "view_up": [0, 0, 1],
          "view_angle": 35, "width": args.size[0], "height": args.size[1]}
SCENES = {
    "smoke": {"source": {"EmitterTemperatureKelvin": 600.0, "CoolingPerSecond": 0.2},
              "seconds": 3.0, "sun": 1.0, "emission": False},
    "fire": {"source": {"EmitterTemperatureKelvin": 1500.0, "CoolingPerSecond": 1.5},
             "seconds": 2.0, "sun": 0.0, "emission": True},
}
OPTICS = {"extinction": 1.5, "albedo": args.albedo, "g": 0.3}
EMISSION = {"radiance_per_metre": 1.0, "reference_kelvin": 1500.0}
BLOCK = 8


def simulate(name):
    config = SCENES[name]
    smoke = nimbus.vtkNimbusSmokeSource()
    for key, value in config["source"].items():
        getattr(smoke, "Set" + key)(value)
    smoke.SetNumberOfFrames(int(round(config["seconds"] * 24)))
    start = time.perf_counter()
    smoke.UpdateInformation()
    smoke.UpdateTimeStep(config["seconds"])
    print(f"{name}: simulated {config['seconds']} s in {time.perf_counter() - start:.1f} s",
          file=sys.stderr)
    path = os.path.join(args.output_dir, name + ".vti")
    writer = vtkXMLImageDataWriter()
    writer.SetInputData(smoke.GetOutput())
    writer.SetFileName(path)
    writer.Write()
    return smoke.GetOutput(), path


def scene_for(name, vti):
    config = SCENES[name]
    medium = {"density": {"type": "file", "path": os.path.basename(vti), "array": "density"},
              "extinction_per_density": OPTICS["extinction"],
              "single_scattering_albedo": OPTICS["albedo"],
              "phase": [{"type": "cornette_shanks", "g": OPTICS["g"], "weight": 1}]}
    if config["emission"]:
        medium["emission"] = {"source": "blackbody", "array": "temperature",
                              "radiance_per_metre": EMISSION["radiance_per_metre"],
                              "temperature_kelvin": EMISSION["reference_kelvin"]}
    scene = {"nimbus_scene": 3, "name": "smoke_" + name,
             "description": f"vtkNimbusSmokeSource's {name} (measurements/smoke-vs-path-tracer.py)",
             "camera": CAMERA, "medium": medium,
             "sun": {"azimuth_degrees": 200, "elevation_degrees": 30,
                     "illuminance": config["sun"], "temperature_kelvin": 5778},
             "atmosphere": {"enabled": False}, "ground": {"enabled": False},
             "background": {"type": "constant", "radiance": 0}}
    path = os.path.join(args.output_dir, name + ".json")
    with open(path, "w") as stream:
        json.dump(scene, stream, indent=1)
    return path


def render_nimbus(name, image_data, method=None, downsampling=None):
    config = SCENES[name]
    mapper = nimbus.vtkNimbusCloudVolumeMapper()
    mapper.SetInputData(image_data)
    mapper.SetExtinctionPerDensity(OPTICS["extinction"])
    mapper.SetAlbedo(OPTICS["albedo"])
    mapper.SetCloudG(OPTICS["g"])
    mapper.SetSunElevationDegrees(30)
    mapper.SetSunAzimuthDegrees(200)
    mapper.SetSunIlluminance(config["sun"])
    mapper.SetAtmosphere(False)
    mapper.SetGround(False)
    mapper.SetTemperatureEmission(config["emission"])
    mapper.SetEmissionRadiancePerMetre(EMISSION["radiance_per_metre"])
    mapper.SetEmissionReferenceTemperatureKelvin(EMISSION["reference_kelvin"])
    mapper.SetNumberOfSlices(512)
    mapper.SetMultipleScatteringDownsampling(
        args.downsampling if downsampling is None else downsampling)
    if method is not None:
        mapper.SetMultipleScatteringMethod(method)
    mapper.SetExposure(harness.VTK_SCALE)
    image, seconds = harness.render_mapper_radiance(mapper, CAMERA, args.size, (0.1, 1e4))
    return image, seconds, mapper


def blocks(image):
    return harness.block_means(image, BLOCK)


def block_errors(error):
    return harness.block_standard_errors(error, BLOCK)


print(f"{'scene':<6} {'Nimbus s':>9} {'solve s':>8} {'solve MiB':>9} {'mean / reference':>20} "
      f"{'block RMSE / mean':>18} {'ref. noise':>10} {'reference':>10}")
for name in args.scenes:
    image_data, vti = simulate(name)
    scene_path = scene_for(name, vti)
    settings = {"mode": "path", "min_spp": 16, "max_spp": 1 << 20,
                "time_limit": args.time_limit, "seed": 1}
    key = "reference-" + harness.scene_hash(scene_path, settings)

    def path_trace():
        start = time.perf_counter()
        image, output = harness.render_reference_mode(scene_path, settings)
        print(f"{name}: path tracer {time.perf_counter() - start:.0f} s", file=sys.stderr)
        return image, harness.standard_error_of(output)

    reference, reference_error, cached = harness.cached_image(args.output_dir, key, path_trace)
    image, seconds, mapper = render_nimbus(name, image_data)
    dims = [0, 0, 0]
    mapper.GetMultipleScatteringGridDimensions(dims)
    luminance = reference.mean(axis=2)
    medium = luminance > 0.01 * luminance.max()
    count = int(medium.sum())
    mean_reference = float(reference[medium].mean())
    mean_error = float(np.sqrt((reference_error[medium] ** 2).sum() / 3.0)) / count
    ratio = float(image[medium].mean()) / mean_reference
    medium_blocks = blocks(np.repeat(medium[..., None], 3, axis=2).astype(np.float64)) > 0.5
    metrics = harness.error_metrics(blocks(image)[medium_blocks],
                                    blocks(reference)[medium_blocks],
                                    block_errors(reference_error)[medium_blocks])
    block_mean = float(blocks(reference)[medium_blocks].mean())
    print(f"{name:<6} {seconds:9.2f} {mapper.GetLastMultipleScatteringSeconds():8.2f} "
          f"{mapper.GetLastMultipleScatteringBytes() / 2 ** 20:9.1f} "
          f"{ratio:12.3f} +- {ratio * mean_error / mean_reference:.3f} "
          f"{metrics['rmse'] / block_mean:18.3f} {metrics['reference_noise'] / block_mean:10.4f} "
          f"{'cached' if cached else 'rendered':>10}")
    print(f"{name}: multiple-scattering grid {dims[0]} x {dims[1]} x {dims[2]}", file=sys.stderr)
    np.save(os.path.join(args.output_dir, f"nimbus-{name}.npy"), image)
    scale = args.gain * 0.5 / max(float(np.percentile(reference[medium], 99)), 1e-30)
    strip = np.concatenate([reference, image], axis=1) * scale / harness.DISPLAY_EXPOSURE
    harness.write_png(strip, os.path.join(args.output_dir, f"smoke-vs-path-tracer-{name}.png"))
    if args.figure and name == "fire":
        panels = [reference, render_nimbus(name, image_data, method=0)[0], image,
                  render_nimbus(name, image_data, downsampling=1)[0]]
        for label, panel in zip(("no multiple scattering", "downsampling 1"),
                                (panels[1], panels[3])):
            print(f"fire, {label}: mean / reference "
                  f"{float(panel[medium].mean()) / mean_reference:.3f}", file=sys.stderr)
        # Rows from the bottom: the flame and the column above it.
        flame = np.concatenate([p[15:135, 30:130] for p in panels], axis=1)
        flame = np.repeat(np.repeat(flame, 2, axis=0), 2, axis=1)
        harness.write_png(flame * scale / harness.DISPLAY_EXPOSURE, args.figure)
