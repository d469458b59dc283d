#!/usr/bin/env python3
"""Lightning inside a cloud: Nimbus against the path tracer.

    PYTHONPATH=build/lib/python3.11/site-packages Testing/with-display.sh /usr/bin/python3 \\
        measurements/lightning-vs-path-tracer.py [--output-dir DIR] [--time-limit SECONDS]

The scene: the metaball cumulus (seed 3, 3 km wide, base 1000 m) at night (no sun, no
air, no ground, to isolate the cloud), lit by a Nimbus Lightning flash at its return
stroke's peak (a 3.5 km channel from 2 km high inside the cloud down to the ground, its
branches). The reference is the path tracer (vtkNimbusReferenceRenderer) on a version-3
scene file whose lights are the flash's segments as polyline lights of their intensity
per metre (grey, 6500 K); it is cached in the output directory. Nimbus renders the
same view with vtkNimbusCloudVolumeMapper over vtkNimbusLightningIllumination in each of
--variants (the precomputed basis or the direct solve; the first scattering on the
density's grid or on the illumination grid), and the script prints their error
against the reference on aggregates that the path tracer's fireflies do not swamp (the
mean over the cloud's pixels, with its standard error; the RMSE of 10x10-pixel block
means corrected for the reference's noise) with the times, and writes
reference | the variants as lightning-vs-path-tracer.png.

The reference's own noise is printed over its lit pixels (those whose 5x5 mean exceeds 1 %
of that mean's 99.5th percentile): the RMS of the pixels' standard errors over their mean
and the median of each pixel's standard error over its value. --reference-only stops
there (no Nimbus render); --reference-seconds is --time-limit; --threads sets the path
tracer's threads. The path tracer samples each channel segment uniformly in the angle it
subtends at a vertex (docs/ground-truth.md, "Line lights"): a 900 s reference on 2 cores
(--time-limit 900) has an RMS standard error of 0.40 of the mean and a median per-pixel
relative standard error of 0.17 on this scene. --reference-mode light renders the reference
by light tracing instead (paths from the channel connected to the camera, cached apart):
0.050 and 0.063 in 300 s, 0.033 and 0.042 in 900 s on 2 cores.
"""
import argparse
import json
import os
import sys
import time

import numpy as np

import nimbus
from nimbus import harness
from vtkmodules.util.numpy_support import vtk_to_numpy
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--output-dir", default="lightning-vs-path-tracer")
parser.add_argument("--time-limit", "--reference-seconds", dest="time_limit", type=float,
                    default=300.0,
                    help="seconds of path tracing for the reference (default 300)")
parser.add_argument("--reference-only", action="store_true",
                    help="render (or load) the reference, report its noise and stop")
parser.add_argument("--threads", type=int, default=0,
                    help="the path tracer's threads (default 0: all cores)")
parser.add_argument("--reference-mode", choices=("path", "light"), default="path",
                    help="the reference's estimator: camera paths (default) or light tracing "
                         "(paths from the channel connected to the camera, docs/ground-truth.md)")
parser.add_argument("--size", type=int, nargs=2, default=(200, 150))
parser.add_argument("--downsampling", type=int, default=3,
                    help="the illumination grid's blocks of density samples (default 3)")
parser.add_argument("--orders", type=int, default=0,
                    help="scattering orders of the illumination before the geometric tail "
                         "(0: the filter's default)")
parser.add_argument("--directions", type=int, default=0,
                    help="discrete directions of the illumination's solve (0: the filter's 26)")
parser.add_argument("--cache-dir", default="",
                    help="the illumination filter's basis cache (default: its own)")
parser.add_argument("--variants", nargs="+",
                    default=["basis", "direct", "basis-fine1", "basis-coarse", "direct-coarse"],
                    help="Nimbus variants: basis or direct, with the first scattering on the "
                         "density's grid (automatic blocks; -fineN: N blocks) or on the "
                         "illumination grid (-coarse, as before); -march: the mapper's ray "
                         "march instead of its slices; -plain: the lightning's view without "
                         "delta-M (LightningDeltaMView off); -first: only the first scattering drawn "
                         "(compare with --max-order 1); -higher: only the orders >= 2; "
                         "e.g. basis-march-plain")
parser.add_argument("--cloud-g", type=float, default=0.85,
                    help="the cloud's Cornette-Shanks asymmetry, in the reference and in Nimbus "
                         "(default 0.85)")
parser.add_argument("--extinction-per-density", type=float, default=0.02,
                    help="the cloud's extinction per unit density [1/m], in the reference and in "
                         "Nimbus (default 0.02; 0.0002 makes it thin, to check the first "
                         "scattering's normalisation where it dominates)")
parser.add_argument("--max-order", type=int, default=0,
                    help="the reference's highest scattering order (0: all; 1: the light "
                         "scattered once, to compare with the variants' -first token)")
args = parser.parse_args()
os.makedirs(args.output_dir, exist_ok=True)

CLOUD = {"Dimensions": [96, 96, 64], "Bounds": [-1500, 1500, -1500, 1500, 800, 2800],
         "Seed": 3}
CAMERA = {"position": [0, -5000, 300], "focal_point": [0, 0, 1300], "view_up": [0, 0, 1],
          "view_angle": 50, "width": args.size[0], "height": args.size[1]}

lightning = nimbus.vtkNimbusLightningSource()
lightning.SetStartPoint(200, 0, 2000)
lightning.SetDirection(0.15, 0, -1)
lightning.SetLength(3500)
lightning.SetSeed(11)
lightning.Update()  # no time: the return stroke's peak
strokes = lightning.GetOutput(0)
intensity = strokes.GetCellData().GetArray("intensity")
lights = []
for cell in range(strokes.GetNumberOfCells()):
    ids = strokes.GetCell(cell).GetPointIds()
    a, b = strokes.GetPoint(ids.GetId(0)), strokes.GetPoint(ids.GetId(1))
    if a != b and intensity.GetValue(cell) > 0:
        lights.append({"type": "polyline", "vertices": [list(a), list(b)],
                       "intensity_per_metre": intensity.GetValue(cell),
                       "temperature_kelvin": 6500})
if len(lights) > 1024:
    sys.exit(f"{len(lights)} segments: more than the scene format's 1024 lights")

scene = {
    "nimbus_scene": 3, "name": "lightning_in_cumulus",
    "description": "The seed-3 metaball cumulus lit from inside by a lightning flash at its "
                   "return stroke (measurements/lightning-vs-path-tracer.py); no sun, air or ground.",
    "camera": CAMERA,
    "medium": {"density": {"type": "metaball_cloud", "parameters": CLOUD},
               "extinction_per_density": args.extinction_per_density, "single_scattering_albedo": 0.99,
               "phase": [{"type": "cornette_shanks", "g": args.cloud_g, "weight": 1}]},
    "sun": {"azimuth_degrees": 0, "elevation_degrees": 45, "illuminance": 0,
            "temperature_kelvin": 5778},
    "atmosphere": {"enabled": False}, "ground": {"enabled": False},
    "background": {"type": "constant", "radiance": 0},
    "lights": lights,
}
scene_path = os.path.join(args.output_dir, "lightning_in_cumulus.json")
with open(scene_path, "w") as stream:
    json.dump(scene, stream, indent=1)

settings = {"mode": args.reference_mode, "min_spp": 16, "max_spp": 1 << 20,
            "time_limit": args.time_limit, "seed": 1}
if args.max_order > 0:
    settings["max_order"] = args.max_order
key = "reference-" + harness.scene_hash(scene_path, settings)


def path_trace():
    start = time.perf_counter()
    renderer = nimbus.vtkNimbusReferenceRenderer()
    renderer.SetSceneFileName(scene_path)
    harness.configure_reference_renderer(renderer, settings, args.threads)
    renderer.Update()
    output = renderer.GetOutput()
    radiance = output.GetPointData().GetArray("radiance")
    if radiance is None:
        sys.exit(f"{scene_path}: the reference renderer failed (see its errors)")
    width, height, _ = output.GetDimensions()
    image = vtk_to_numpy(radiance).reshape(height, width, 3).astype(np.float32)
    spp = output.GetFieldData().GetArray("SamplesPerPixel")
    unit = "light paths" if args.reference_mode == "light" else "samples"
    print(f"path tracer ({args.reference_mode}): {time.perf_counter() - start:.0f} s"
          + (f", {spp.GetValue(0):.1f} {unit} per pixel" if spp else ""), file=sys.stderr)
    return image, harness.standard_error_of(output)


reference, reference_error, cached = harness.cached_image(args.output_dir, key, path_trace)
print(f"reference: {'cached' if cached else 'rendered'}, {len(lights)} polyline lights; "
      f"noise (RMS standard error) {np.sqrt(np.mean(reference_error ** 2)):.3g}, "
      f"mean {reference.mean():.3g}")


def reference_noise(image, error, pixels):
    """The reference's noise over the given pixels: the RMS of the pixels' standard errors
    over the mean of those pixels, and the median of each pixel's standard error over its
    value (both on the mean of the three channels, dimensionless)."""
    value, sigma = image[pixels].mean(axis=1), error[pixels].mean(axis=1)
    rms = float(np.sqrt(np.mean(sigma ** 2)) / value.mean())
    relative = sigma / np.maximum(value, 1e-30)
    return rms, float(np.median(relative))


def lit_by_reference(image, fraction=0.01, box=5):
    """The pixels whose box x box mean of the reference exceeds fraction of that mean's
    99.5th percentile: the lit cloud, from the reference alone (a stand-in for the direct
    solve's mask where Nimbus does not run)."""
    value = image.mean(axis=2)
    pad = box // 2
    padded = np.pad(value, pad, mode="edge")
    smooth = sum(padded[i:i + value.shape[0], j:j + value.shape[1]]
                 for i in range(box) for j in range(box)) / box ** 2
    return smooth > fraction * np.percentile(smooth, 99.5)


if reference_error is not None:
    mask = lit_by_reference(reference)
    rms, median = reference_noise(reference, reference_error, mask)
    print(f"reference noise over its {int(mask.sum())} lit pixels: RMS standard error / mean "
          f"{rms:.4f}, median per-pixel relative standard error {median:.4f}")
if args.reference_only:
    sys.exit(0)

cloud = nimbus.vtkNimbusMetaballCloudSource()
cloud.SetDimensions(*CLOUD["Dimensions"])
cloud.SetBounds(*CLOUD["Bounds"])
cloud.SetSeed(CLOUD["Seed"])


def keep_one_part(lit_cloud, first):
    """A copy of the lit cloud whose lightning light is only the first scattering (first) or
    only the orders >= 2 (the other arrays zeroed), to tell the two parts' errors apart."""
    copy = lit_cloud.NewInstance()
    copy.ShallowCopy(lit_cloud)
    fields = copy.GetFieldData()
    names = (["nimbus_lightning_in_scattering"] if first else
             ["nimbus_lightning_first_scattering", "nimbus_lightning_first_scattering_reduced"])
    for name in names:
        array = fields.GetArray(name)
        if array is None:
            continue
        zero = array.NewInstance()
        zero.DeepCopy(array)
        zero.Fill(0.0)
        fields.RemoveArray(name)
        fields.AddArray(zero)
    return copy


def render(variant):
    """One Nimbus variant (see --variants): the image, the filter's update seconds, the filter."""
    tokens = variant.split("-")
    method = 1 if tokens[0] == "direct" else 0
    illumination = nimbus.vtkNimbusLightningIllumination()
    illumination.SetInputConnection(0, cloud.GetOutputPort(0))
    illumination.SetInputConnection(1, lightning.GetOutputPort(0))  # the strokes
    illumination.SetMethod(method)
    illumination.SetDownsampling(args.downsampling)
    illumination.SetFirstScatteringOnDensityGrid("coarse" not in tokens)
    for token in tokens:
        if token.startswith("fine"):
            illumination.SetFirstScatteringDownsampling(int(token[len("fine"):]))
    if args.cache_dir:
        illumination.SetCacheDirectory(args.cache_dir)
    if args.orders > 0:
        illumination.SetOrders(args.orders)
    if args.directions > 0:
        illumination.SetNumberOfDirections(args.directions)
    illumination.SetLightningColor(1, 1, 1)  # grey, as the reference's 6500 K
    illumination.SetAlbedo(0.99)
    illumination.SetCloudG(args.cloud_g)
    illumination.SetExtinctionPerDensity(args.extinction_per_density)
    # The basis of this grid (96 x 96 x 64 in blocks of 3) may need ~2.3 GiB: more than
    # the filter's default budget of 2 GiB (it then refuses and leaves the cloud dark).
    illumination.SetMemoryBudgetMiB(4096)
    start = time.perf_counter()
    illumination.Update()
    update = time.perf_counter() - start
    lit_cloud = illumination.GetOutput()
    if "first" in tokens or "higher" in tokens:
        lit_cloud = keep_one_part(lit_cloud, "first" in tokens)
    mapper = nimbus.vtkNimbusCloudVolumeMapper()
    mapper.SetInputData(lit_cloud)
    mapper.SetAlbedo(0.99)
    mapper.SetCloudG(args.cloud_g)
    mapper.SetExtinctionPerDensity(args.extinction_per_density)
    mapper.SetMultipleScatteringMethodToNone()
    mapper.SetSunIlluminance(0.0)
    mapper.SetAtmosphere(False)
    mapper.SetGround(False)
    mapper.SetNumberOfSlices(512)
    if "march" in tokens:
        mapper.SetRenderingMethodToRayMarching()
    if "plain" in tokens:
        mapper.SetLightningDeltaMView(False)
    mapper.SetExposure(harness.VTK_SCALE)
    image, _ = harness.render_mapper_radiance(mapper, CAMERA, args.size, (1.0, 1e6))
    return image, update, illumination


# Point and line lights inside an optically thick cloud make the path tracer's pixels
# heavy-tailed (fireflies: a pixel's standard error can be many times the image's mean),
# so the comparison is made on aggregates whose noise is small: the mean over the cloud
# (the pixels the direct solve lights above 1 % of its brightest), and the means of
# BLOCK x BLOCK pixel blocks (their RMSE corrected for the reference's noise).
BLOCK = 10


def blocks(image):
    return harness.block_means(image, BLOCK)


def block_errors(error):
    return harness.block_standard_errors(error, BLOCK)


rendered = {variant: render(variant) for variant in args.variants}
lit = rendered[args.variants[0]][0].mean(axis=2)
cloud_pixels = lit > 0.01 * lit.max()
count = int(cloud_pixels.sum())
mean_cloud = float(reference[cloud_pixels].mean())
mean_error = float(np.sqrt((reference_error[cloud_pixels] ** 2).sum() / 3.0)) / count
reference_blocks, reference_block_errors = blocks(reference), block_errors(reference_error)
cloud_blocks = blocks(np.repeat(cloud_pixels[..., None], 3, axis=2).astype(np.float64)) > 0.5
print(f"cloud: {count} pixels, reference mean {mean_cloud:.4g} +- {mean_error:.2g} "
      f"(standard error); {int(cloud_blocks[..., 0].sum())} blocks of {BLOCK}x{BLOCK}")
images = [reference]
print(f"{'variant':<22} {'update s':>9} {'relight ms':>11} {'first s':>8} "
      f"{'mean / reference':>17} {'block RMSE / mean':>18}")
for name in args.variants:
    image, update, illumination = rendered[name]
    ratio = float(image[cloud_pixels].mean()) / mean_cloud
    block_metrics = harness.error_metrics(blocks(image)[cloud_blocks],
                                          reference_blocks[cloud_blocks],
                                          reference_block_errors[cloud_blocks])
    print(f"{name:<22} {update:9.1f} {1000 * illumination.GetLastRelightSeconds():11.1f} "
          f"{illumination.GetLastFirstScatteringSeconds():8.2f} "
          f"{ratio:11.3f} +- {ratio * mean_error / mean_cloud:.3f} "
          f"{block_metrics['rmse'] / float(reference_blocks[cloud_blocks].mean()):18.3f}")
    images.append(image)
strip = np.concatenate(images, axis=1)
scale = 0.5 / max(float(np.percentile(rendered[args.variants[0]][0][cloud_pixels], 99)), 1e-30)
path = os.path.join(args.output_dir, "lightning-vs-path-tracer.png")
harness.write_png(strip * scale / harness.DISPLAY_EXPOSURE, path)
print(path)
