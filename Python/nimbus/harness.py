"""The speed <-> accuracy trade harness.

For named scenes and a renderer with a list of quality settings it renders each
setting, times it (median of several renders in this process), measures the error
against the scene's reference image (RMSE, relative L1, max abs error, PSNR) and
writes a CSV and an error-vs-time plot: the Pareto front users choose from.

    python3 -m nimbus.harness Data/Scenes/cumulus_noon.json [more scenes] \
        --renderer vtk-gpu --output-dir build/harness

Renderers: ``vtk-gpu`` (VTK's vtkGPUVolumeRayCastMapper with the scene's optics
mapped onto its transfer functions; needs a display: run it through
Testing/with-display.sh), ``svs`` (Nimbus's cloud mapper, by shadow-view slicing
or, with setting ``method`` ``march``, by ray marching; setting ``k_multi``
overrides the scene's multiple-scattering constant), ``single``
(Nimbus's single-scattering reference at coarser steps) and ``path`` (the Monte
Carlo path tracer at fewer samples). ``--settings FILE.json`` replaces a
renderer's default list of settings.

Scenes with lights (scene format version 4: point and spot lights, light maps,
occluders; docs/lights-trade.md): ``svs`` draws them by ray marching only (every row
must be ``method`` ``march``), each light a positional vtkLight of its renderer and
each occluder an opaque actor; its settings ``light_method`` (``march`` or
``planes``), ``light_samples``, ``shaft_downsampling``, ``virtual_planes``,
``shadow_map_size`` and ``light_cloud_steps`` trade the shafts' quality for time,
and without --settings a scene with lights gets a list over them. ``vtk-gpu`` and
``single`` refuse lights.

The reference (``--reference``): ``path`` is the Monte Carlo path tracer with full
multiple scattering, run for a time budget (--reference-seconds, default 600 s;
its image-wide error is printed and stored); ``path-single`` the same path tracer
stopped at the first scattering (single scattering of the sun and of every light,
for the scenes ``single`` refuses); ``single`` is converged single
scattering. ``auto`` (the default) judges each setting by what it models: settings
that model single scattering only (the ``single`` renderer, ``svs`` with k_multi
0) against ``single``, every other one against ``path``. Every row, table and plot
names its reference.

The path-traced reference is noisy. Its noise adds to the squared error of every
image measured against it, so RMSE (and PSNR) are corrected for it: RMSE^2 =
mean((image - reference)^2) - mean(sigma_ref^2) - mean(sigma_image^2), sigma the
per-pixel standard errors the path tracer reports (sigma_image: the sky-only
reference that vtk-gpu composites over, times (1 - alpha)). ``rmse_raw`` is the
uncorrected value and ``reference_noise`` the reference's RMS standard error.
Relative L1 and max abs are not corrected (read them with reference_noise in mind).

References are rendered once and cached in --cache-dir under a hash of the scene
file (canonical JSON), the density file it names (bytes) and the reference's own
settings, so editing any of them renders a new reference.
"""
import argparse
import csv
import hashlib
import json
import math
import os
import statistics
import sys
import time

import numpy as np

import nimbus
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.vtkCommonDataModel import vtkImageData, vtkPiecewiseFunction
from vtkmodules.vtkIOImage import vtkPNGWriter

# NIMBUS_OFFSCREEN=egl: every render window below is an EGL pbuffer (no X server).
nimbus.offscreen_if_requested()

# The reference each scene is measured against (see --reference).
REFERENCE_SETTINGS = {
    "single": {"mode": "single", "step_scale": 0.5, "tolerance": 1e-3, "max_refinements": 6},
    # Full multiple scattering for a time budget (seconds; --reference-seconds). 1 % image-wide
    # takes 51 min to 7 h per scene on 2 cores (docs/ground-truth.md), so the budget decides the
    # reference's own error, and the metrics are corrected for it (see the module text).
    "path": {"mode": "path", "min_spp": 16, "max_spp": 1 << 20, "time_limit": 600.0,
             "seed": 1},
    # The path tracer cut at the first scattering (MaxScatteringOrder 1): the single
    # scattering of the sun and of every light, the ground's direct light included, for
    # the scenes the "single" renderer refuses (lights); against "path" it measures what
    # multiple scattering adds.
    "path-single": {"mode": "path", "min_spp": 16, "max_spp": 1 << 20, "time_limit": 600.0,
                    "seed": 1, "max_order": 1},
}
# The sky-only path-traced reference (vtk-gpu's background) gets this share of the budget.
SKY_BUDGET_SHARE = 0.25

# Default quality settings per renderer: each dict is one point of the trade curve.
DEFAULT_SETTINGS = {
    "vtk-gpu": [
        {"shading": "absorption", "sample_distance": 1.0},
        {"shading": "absorption", "sample_distance": 0.5},
        {"shading": "gradient", "sample_distance": 1.0},
        {"shading": "gradient", "sample_distance": 0.5},
        {"shading": "gradient", "sample_distance": 0.25},
        {"shading": "volumetric", "sample_distance": 0.5, "reach": 0.0},
        {"shading": "volumetric", "sample_distance": 0.5, "reach": 0.25},
        {"shading": "volumetric", "sample_distance": 0.5, "reach": 0.5},
        {"shading": "volumetric", "sample_distance": 0.5, "reach": 1.0},
        {"shading": "volumetric", "sample_distance": 0.25, "reach": 1.0},
    ],
    # SVS: single scattering over slices (ms "none", the scene's k_multi), then the
    # multiple-scattering methods (003, 004) at 256 slices over their knobs.
    "svs": [{"slices": n} for n in (8, 16, 32, 64, 128, 256, 512)]
    + [{"slices": 256, "k_multi": k} for k in (2, 4, 8)]
    + [{"ms": "octaves", "octaves": n} for n in (2, 4, 8)]
    + [{"ms": "patterns", "orders": n} for n in (2, 3)]
    + [{"ms": "directions", "downsampling": d, "directions": n, "orders": k}
       for d, n, k in ((8, 26, 32), (4, 26, 8), (4, 14, 32), (4, 26, 32), (4, 50, 32),
                       (3, 26, 32), (2, 26, 32))]
    # The same mapper by ray marching (RenderingMethod 1) with the default multiple
    # scattering, over its step in density texels: its curve beside the slices'.
    + [{"method": "march", "ms": "directions", "step": s} for s in (4, 2, 1, 0.5)],
    "single": [{"step_scale": s, "max_refinements": 0} for s in (4.0, 2.0, 1.0, 0.5, 0.25)],
    "path": [{"max_spp": n, "min_spp": n} for n in (1, 4, 16, 64)],
}

# The svs renderer's default settings for a scene with lights (only the ray march draws
# them), as the mapper draws by default otherwise (step 2 texels, multiple scattering by
# discrete directions, which takes the lights' higher orders in the cloud): the shafts
# by equi-angular samples along each view ray (on a quarter of the pixels, the mapper's
# default, then on all of them and on a sixteenth), then by virtual planes, over their
# counts.
LIGHT_BASE_SETTINGS = {"method": "march", "step": 2, "ms": "directions"}
DEFAULT_LIGHT_SETTINGS = (
    [dict(LIGHT_BASE_SETTINGS, light_method="march", light_samples=n)
     for n in (4, 8, 16, 32, 64)]
    + [dict(LIGHT_BASE_SETTINGS, light_method="march", light_samples=32, shaft_downsampling=d)
       for d in (1, 4)]
    + [dict(LIGHT_BASE_SETTINGS, light_method="planes", virtual_planes=n)
       for n in (16, 32, 64, 128, 256)])

# Linear radiance -> the [0, 1] range VTK renders into (and back): radiance
# 1/VTK_SCALE fills VTK's 8-bit framebuffer. 8-bit quantisation then costs at most
# 1/(2*255*VTK_SCALE) = 6.5e-4 in radiance, below every error the table reports.
VTK_SCALE = 3.0
# Plots draw RMSEs below this (0 after the noise correction) at this value.
PLOT_RMSE_FLOOR = 1e-6
# Exposure of the PNGs the harness writes for looking at (not used in any metric).
DISPLAY_EXPOSURE = 6.0


# --- scenes and references ------------------------------------------------------------------

def load_scene(path):
    """The scene as the C++ reader sees it: validated, every field filled in, in the
    current format version whatever version the file has (docs/scene-format.md)."""
    reader = nimbus.vtkNimbusReferenceRenderer()
    reader.SetSceneFileName(path)
    text = reader.GetCanonicalSceneJson()
    if not text:
        raise RuntimeError(f"{path}: not a valid Nimbus scene (see the error above)")
    return json.loads(text)


def version3_features(scene):
    """The scene format's version-3 features a canonical scene (load_scene) uses: only the
    path tracer renders them all (docs/scene-format.md); VTK's GPU mapper none of them."""
    features = []
    if scene.get("lights"):
        features.append("point and polyline lights (scene.lights)")
    media = scene.get("media", [])
    if "emission" in scene["medium"] or any("emission" in m for m in media):
        features.append("emission (scene.medium.emission, scene.media[i].emission)")
    if media:
        features.append("additional media (scene.media)")
    return features


def version4_features(scene):
    """The scene format's version-4 features a canonical scene uses: spot lights and
    occluders."""
    features = []
    if any(light["type"] == "spot" for light in scene.get("lights", [])):
        features.append("spot lights (scene.lights[i] of type spot)")
    if scene.get("occluders"):
        features.append("occluders (scene.occluders)")
    return features


def svs_unsupported_features(scene):
    """What of a canonical scene the SVS mapper cannot draw. It draws point and spot
    lights (the view's own lights: positional vtkLights, by ray marching only) and
    occluders (opaque actors that shadow them), as SvsRenderer builds them; not lightning
    channels, emission or more media, and not spots that differ in what the mapper
    holds once for all of them (the soft edge's width, the light map), nor more lights
    than it draws in one frame."""
    features = []
    lights = scene.get("lights", [])
    if any(light["type"] == "polyline" for light in lights):
        features.append("polyline lights (scene.lights[i] of type polyline)")
    media = scene.get("media", [])
    if "emission" in scene["medium"] or any("emission" in m for m in media):
        features.append("emission (scene.medium.emission, scene.media[i].emission)")
    if media:
        features.append("additional media (scene.media)")
    sun = scene["sun"]
    if scene.get("occluders") and sun["elevation_degrees"] > 0 and sun["illuminance"] > 0:
        features.append("occluders in sunlight (the mapper's opaque geometry casts no "
                        "shadow of the sun; a scene with occluders needs the sun below the "
                        "horizon or an illuminance of 0)")
    if len(lights) > SVS_MAXIMUM_LIGHTS:
        features.append(f"more than {SVS_MAXIMUM_LIGHTS} lights (scene.lights has "
                        f"{len(lights)}; the mapper draws at most {SVS_MAXIMUM_LIGHTS})")
    spots = [(i, light) for i, light in enumerate(lights) if light["type"] == "spot"]
    edges = sorted({light["edge_degrees"] for _, light in spots})
    if len(edges) > 1:
        features.append("spot lights with different soft edges (the mapper has one "
                        "SpotEdgeWidthDegrees for all spots; scene.lights has "
                        + ", ".join(f"[{i}] {light['edge_degrees']:g}" for i, light in spots)
                        + " degrees)")
    maps = sorted({light.get("light_map", "") for _, light in spots})
    if len(maps) > 1:
        features.append("spot lights with different light maps (the mapper has one "
                        "LightMap for all spots; scene.lights has "
                        + ", ".join(f"[{i}] {light.get('light_map') or 'none'}"
                                    for i, light in spots) + ")")
    return features


# The renderers whose features the harness checks, their names in messages, and what of a
# canonical scene each cannot draw.
UNSUPPORTED_FEATURES = {
    "vtk-gpu": ("VTK GPU mapper",
                lambda scene: version3_features(scene) + version4_features(scene)),
    "svs": ("SVS mapper", svs_unsupported_features),
    "single": ("single-scattering renderer",
               lambda scene: version3_features(scene) + version4_features(scene)),
}


def refuse_unsupported_features(scene_path, scene, renderer):
    """A renderer ("vtk-gpu", "svs" or "single") that does not draw a feature of the scene (lights,
    emission, more media, occluders: scene format versions 3 and 4) says so by name,
    rather than render the scene without it."""
    name, features_of = UNSUPPORTED_FEATURES[renderer]
    features = features_of(scene)
    if features:
        raise ValueError(f"{scene_path}: the {name} does not render {'; '.join(features)}; "
                         "render this scene with the path tracer (--renderer path)")


def scene_hash(scene_path, reference):
    """Hash of everything the reference image depends on."""
    scene = load_scene(scene_path)
    digest = hashlib.sha256()
    digest.update(json.dumps(scene, sort_keys=True).encode())
    digest.update(json.dumps(reference, sort_keys=True).encode())
    densities = [scene.get("medium", {}).get("density", {})]
    densities += [m.get("density", {}) for m in scene.get("media", [])]
    files = []
    for density in densities:
        if density.get("type") == "file":
            files.append(os.path.join(os.path.dirname(os.path.abspath(scene_path)),
                                      density["path"]))
    # Version 4: the spots' light maps and the occluders' meshes (absolute paths).
    files += [light["light_map"] for light in scene.get("lights", []) if light.get("light_map")]
    files += [o["path"] for o in scene.get("occluders", []) if o.get("type") == "mesh"]
    for path in files:
        with open(path, "rb") as stream:
            digest.update(stream.read())
    return digest.hexdigest()[:16]


def configure_reference_renderer(renderer, settings, threads=0):
    mode = settings.get("mode", "single")
    if mode == "single":
        renderer.SetModeToSingleScattering()
        renderer.SetStepScale(settings.get("step_scale", 0.5))
        renderer.SetRelativeTolerance(settings.get("tolerance", 1e-3))
        renderer.SetMaxRefinements(settings.get("max_refinements", 6))
    else:
        # "path": camera paths; "light": light tracing (paths from the lights connected to
        # the camera; min_spp / max_spp count light paths per pixel, light_paths_per_batch
        # a batch, 0 = max(1024, pixels); only scenes lit by point, spot and polyline lights).
        renderer.SetModeToPathTracing()
        renderer.SetLightTracing(mode == "light")
        renderer.SetLightPathsPerBatch(settings.get("light_paths_per_batch", 0))
        renderer.SetMinSamplesPerPixel(settings.get("min_spp", 16))
        renderer.SetMaxSamplesPerPixel(settings.get("max_spp", 256))
        renderer.SetTargetRelativeError(settings.get("target_error", 0.0))
        renderer.SetMaxScatteringOrder(settings.get("max_order", 0))
        renderer.SetSeed(settings.get("seed", 1))
        renderer.SetTimeLimitSeconds(settings.get("time_limit", 0.0))
        renderer.SetTargetImageRelativeError(settings.get("target_image_error", 0.0))
    renderer.SetNumberOfThreads(threads)


def render_reference_mode(scene_path, settings, density=None):
    """Renders with vtkNimbusReferenceRenderer; returns (H x W x 3 float32, output image)."""
    renderer = nimbus.vtkNimbusReferenceRenderer()
    renderer.SetSceneFileName(scene_path)
    if density is not None:
        renderer.SetInputData(density)
    configure_reference_renderer(renderer, settings)
    renderer.Update()
    output = renderer.GetOutput()
    radiance = output.GetPointData().GetArray("radiance")
    if radiance is None:
        raise RuntimeError(f"{scene_path}: the reference renderer failed (see its errors)")
    width, height, _ = output.GetDimensions()
    return vtk_to_numpy(radiance).reshape(height, width, 3).astype(np.float32), output


def standard_error_of(output):
    """The per-pixel standard error (H x W x 3 float32) of a path-traced output, or None."""
    array = output.GetPointData().GetArray("standard_error")
    if array is None:
        return None
    width, height, _ = output.GetDimensions()
    return vtk_to_numpy(array).reshape(height, width, 3).astype(np.float32)


def cached_image(cache_dir, key, compute):
    """(image, standard error or None, cached?) from the cache, or computed and stored.

    compute() returns (image, standard error or None); both are stored as float32 npy
    (KEY.npy, KEY-stderr.npy)."""
    os.makedirs(cache_dir, exist_ok=True)
    path = os.path.join(cache_dir, key + ".npy")
    error_path = os.path.join(cache_dir, key + "-stderr.npy")
    if os.path.exists(path):
        error = np.load(error_path) if os.path.exists(error_path) else None
        return np.load(path), error, True
    image, error = compute()
    if error is not None:
        np.save(error_path, error)
    np.save(path, image)
    return image, error, False


def zero_density(scene_path):
    """The scene's density grid with every value 0 (for sky-only references)."""
    source = nimbus.vtkNimbusSceneDensitySource()
    source.SetSceneFileName(scene_path)
    source.Update()
    empty = vtkImageData()
    empty.DeepCopy(source.GetOutput())
    empty.GetPointData().GetScalars().Fill(0.0)
    return empty


# --- error metrics ----------------------------------------------------------------------------

def render_mapper_radiance(mapper, camera, size, clipping=(0.1, 1e6)):
    """Renders a vtkNimbusCloudVolumeMapper alone (black background, offscreen) from a
    scene-style camera dict (position, focal_point, view_up, view_angle) at size (W, H).

    Returns (H x W x 3 float32 linear radiance from the mapper's radiance capture, seconds
    of the render call)."""
    from vtkmodules.vtkRenderingCore import vtkRenderWindow, vtkRenderer, vtkVolume
    import vtkmodules.vtkRenderingOpenGL2  # noqa: F401 (object factories)
    mapper.SetCaptureRadiance(True)
    volume = vtkVolume()
    volume.SetMapper(mapper)
    renderer = vtkRenderer()
    renderer.AddVolume(volume)
    renderer.SetBackground(0, 0, 0)
    view = renderer.GetActiveCamera()
    view.SetPosition(*camera["position"])
    view.SetFocalPoint(*camera["focal_point"])
    view.SetViewUp(*camera["view_up"])
    view.SetViewAngle(camera["view_angle"])
    view.SetClippingRange(*clipping)
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
    image = vtk_to_numpy(radiance.GetPointData().GetScalars()).reshape(height, width, 4)
    window.Finalize()
    return image[..., :3].astype(np.float32).copy(), seconds


def block_means(image, block):
    """Means of block x block pixel tiles of an H x W x 3 image (partial tiles dropped)."""
    h, w = (image.shape[0] // block) * block, (image.shape[1] // block) * block
    return image[:h, :w].reshape(h // block, block, w // block, block, 3).mean(axis=(1, 3))


def block_standard_errors(error, block):
    """The standard errors of block_means for independent per-pixel standard errors."""
    h, w = (error.shape[0] // block) * block, (error.shape[1] // block) * block
    return np.sqrt((error[:h, :w] ** 2).reshape(
        h // block, block, w // block, block, 3).sum(axis=(1, 3))) / block ** 2


def error_metrics(image, reference, reference_error=None, image_error=None):
    """RMSE, relative L1, max abs and PSNR of image against reference.

    PSNR's peak is the reference's largest value ("psnr_db"); "psnr_p999_db" takes the
    99.9th percentile of its values instead, which a handful of pixels cannot set: in a
    night scene the pixels next to a light (whose in-scattered radiance grows as the
    inverse of the ray's distance to it) or a Monte Carlo reference's outliers raise
    the largest value far above the picture's bright parts, and with it "psnr_db".

    reference_error / image_error: per-pixel standard errors of a Monte Carlo reference
    and of the noisy part of the image (None = exact). Independent zero-mean noise adds
    its variance to the expected squared difference, so the corrected RMSE is
    sqrt(max(0, mean(d^2) - mean(sigma_ref^2) - mean(sigma_image^2))); "rmse_raw" is
    sqrt(mean(d^2)) and "reference_noise" the reference's RMS standard error."""
    difference = image.astype(np.float64) - reference.astype(np.float64)
    mean_square = float(np.mean(difference ** 2))
    noise = 0.0
    reference_noise = 0.0
    if reference_error is not None:
        reference_noise = float(np.mean(reference_error.astype(np.float64) ** 2))
        noise += reference_noise
    if image_error is not None:
        noise += float(np.mean(image_error.astype(np.float64) ** 2))
    rmse = math.sqrt(max(0.0, mean_square - noise))
    relative_l1 = float(np.sum(np.abs(difference)) / max(np.sum(np.abs(reference)), 1e-30))
    max_abs = float(np.max(np.abs(difference)))
    peak = float(np.max(reference))
    psnr = float(20.0 * math.log10(peak / rmse)) if rmse > 0 and peak > 0 else float("inf")
    robust_peak = float(np.percentile(reference, 99.9))
    psnr_robust = (float(20.0 * math.log10(robust_peak / rmse))
                   if rmse > 0 and robust_peak > 0 else float("inf"))
    return {"rmse": rmse, "rmse_raw": math.sqrt(mean_square),
            "reference_noise": math.sqrt(reference_noise), "relative_l1": relative_l1,
            "max_abs": max_abs, "psnr_db": psnr, "psnr_p999_db": psnr_robust}


def models_single_scattering_only(renderer_name, settings, scene):
    """True for settings whose renderer models single scattering alone (judged by the
    single-scattering reference under --reference auto)."""
    if renderer_name == "single":
        return True
    if scene.get("lights"):  # the single-scattering reference renders no lights
        return False
    if renderer_name == "svs":
        k_multi = settings.get("k_multi",
                               scene.get("medium", {}).get("multiple_scattering_constant", 0.0))
        return (k_multi == 0 and settings.get("ms", "none") == "none"
                and not settings.get("air_ms", True))
    return False


# --- renderers --------------------------------------------------------------------------------

class ReferenceModeRenderer:
    """Nimbus's own reference renderers at lower quality (their own trade curve)."""

    def __init__(self, scene_path, mode):
        self.scene_path = scene_path
        self.mode = mode

    def render(self, settings):
        merged = dict(REFERENCE_SETTINGS[self.mode])
        merged.pop("time_limit", None)  # a trade point is its sample count, not the budget
        merged.update(settings)
        merged["mode"] = self.mode
        image, _ = render_reference_mode(self.scene_path, merged)
        return image

    def close(self):
        pass


def read_framebuffer(window, capture_class, components):
    """The window's back buffer as an H x W x components float32 array in [0, 1]."""
    capture = capture_class()
    capture.SetInput(window)
    if components == 4:
        capture.SetInputBufferTypeToRGBA()
    else:
        capture.SetInputBufferTypeToRGB()
    capture.ReadFrontBufferOff()
    capture.Update()
    image = capture.GetOutput()
    width, height, _ = image.GetDimensions()
    pixels = vtk_to_numpy(image.GetPointData().GetScalars()).reshape(height, width, components)
    return pixels.astype(np.float32) / 255.0


class VtkGpuRenderer:
    """VTK's vtkGPUVolumeRayCastMapper with the scene mapped as faithfully as it allows.

    - Extinction: opacity over the unit distance u (one grid spacing) is
      1 - exp(-sigma_t * density * u) (Beer-Lambert), sampled at 32 densities.
    - Colour: the single-scattering albedo (grey).
    - Sun: a directional light whose colour and intensity are the direct sun at the
      cloud's centre after the atmosphere (vtkNimbusSunlight, no white balance),
      scaled so that a white Lambertian surface facing it has radiance E/pi.
    - Sky light: VTK's ambient term, set to the mean radiance of the sky-only
      reference (the scene rendered with zero density) in the upper half of the image.
    - Background: VTK has no sky, so its cloud (RGBA, premultiplied) is composited
      over the sky-only reference image.
    - "shading": absorption (no lighting: emission = albedo x sky ambient), gradient
      (Phong on the density gradient), volumetric (VTK's volumetric scattering,
      blending 1, GlobalIlluminationReach = "reach", anisotropy = the cloud's first
      phase component's g).
    """

    def __init__(self, scene_path, sky_image, sky_error=None):
        from vtkmodules.vtkRenderingCore import (vtkColorTransferFunction, vtkLight,
                                                 vtkRenderWindow, vtkRenderer, vtkVolume,
                                                 vtkVolumeProperty, vtkWindowToImageFilter)
        from vtkmodules.vtkRenderingVolumeOpenGL2 import vtkOpenGLGPUVolumeRayCastMapper
        import vtkmodules.vtkRenderingOpenGL2  # noqa: F401 (object factories)

        scene = load_scene(scene_path)
        refuse_unsupported_features(scene_path, scene, "vtk-gpu")
        self.scene = scene
        self.sky = sky_image
        self.sky_error = sky_error
        self.noise = None  # standard error of the last image's noisy part (the sky)
        density = nimbus.vtkNimbusSceneDensitySource()
        density.SetSceneFileName(scene_path)
        density.Update()
        volume_data = density.GetOutput()
        self.spacing = min(volume_data.GetSpacing())
        medium = scene["medium"]
        sigma_per_density = medium.get("extinction_per_density", 0.02)
        albedo = medium.get("single_scattering_albedo", 0.99)
        max_density = max(volume_data.GetPointData().GetScalars().GetRange()[1], 1e-6)

        opacity = vtkPiecewiseFunction()
        for i in range(33):
            rho = max_density * i / 32.0
            opacity.AddPoint(rho, 1.0 - math.exp(-sigma_per_density * rho * self.spacing))
        self.albedo = albedo
        self.max_density = max_density
        color = vtkColorTransferFunction()

        self.property = vtkVolumeProperty()
        self.property.SetScalarOpacity(opacity)
        self.property.SetColor(color)
        self.property.SetScalarOpacityUnitDistance(self.spacing)
        self.property.SetInterpolationTypeToLinear()
        phase = medium.get("phase", [{}])
        phase = phase if isinstance(phase, list) else [phase]
        self.g = float(phase[0].get("g", 0.0))

        self.mapper = vtkOpenGLGPUVolumeRayCastMapper()
        self.mapper.SetInputConnection(density.GetOutputPort())
        self.mapper.AutoAdjustSampleDistancesOff()
        self.volume = vtkVolume()
        self.volume.SetMapper(self.mapper)
        self.volume.SetProperty(self.property)

        # Sun after the atmosphere at the cloud's centre.
        bounds = volume_data.GetBounds()
        centre_z = 0.5 * (bounds[4] + bounds[5])
        sun = scene["sun"]
        atmosphere = scene.get("atmosphere", {})
        sunlight = nimbus.vtkNimbusSunlight()
        sunlight.WhiteBalanceOff()
        sunlight.SetSunElevationDegrees(sun["elevation_degrees"])  # the canonical scene
        sunlight.SetSunAzimuthDegrees(sun["azimuth_degrees"])  # has angles, never "direction"
        sunlight.SetSceneAltitudeMetres(atmosphere["scene_altitude_metres"] + centre_z)
        rgb = [0.0, 0.0, 0.0]
        if atmosphere.get("enabled", True):
            sunlight.GetColor(rgb)
        else:
            rgb = [1.0, 1.0, 1.0]  # no atmosphere: the sun as it is (white by construction)
        illuminance = sun.get("illuminance", 1.0)
        rgb = [c * illuminance * VTK_SCALE / math.pi for c in rgb]
        self.light = vtkLight()
        sunlight.ApplyToLight(self.light)  # direction
        brightest = max(rgb)
        if brightest > 0:
            self.light.SetColor(*[c / brightest for c in rgb])
        self.light.SetIntensity(brightest)
        height = sky_image.shape[0]
        sky_mean = sky_image[height // 2:].reshape(-1, 3).mean(axis=0) * VTK_SCALE
        self.ambient = [float(min(1.0, c)) for c in sky_mean]
        self.light.SetAmbientColor(*self.ambient)

        self.renderer = vtkRenderer()
        self.renderer.AddVolume(self.volume)
        self.renderer.AddLight(self.light)
        self.renderer.SetBackground(0.0, 0.0, 0.0)
        self.renderer.SetBackgroundAlpha(0.0)
        camera_description = scene["camera"]
        camera = self.renderer.GetActiveCamera()
        camera.SetPosition(*camera_description["position"])
        camera.SetFocalPoint(*camera_description["focal_point"])
        camera.SetViewUp(*camera_description.get("view_up", [0, 0, 1]))
        camera.SetViewAngle(camera_description.get("view_angle", 30.0))
        self.renderer.ResetCameraClippingRange()

        self.window = vtkRenderWindow()
        self.window.SetOffScreenRendering(1)
        self.window.SetAlphaBitPlanes(1)
        self.window.SetMultiSamples(0)
        self.window.SetSize(camera_description["width"], camera_description["height"])
        self.window.AddRenderer(self.renderer)
        self.capture_class = vtkWindowToImageFilter

    def render(self, settings):
        shading = settings.get("shading", "gradient")
        self.mapper.SetSampleDistance(float(settings.get("sample_distance", 0.5) * self.spacing))
        self.property.SetShade(shading != "absorption")
        # Unlit, VTK emits the colour itself: make it the sky-lit albedo.
        tint = self.ambient if shading == "absorption" else [1.0, 1.0, 1.0]
        color = self.property.GetRGBTransferFunction()
        color.RemoveAllPoints()
        for rho in (0.0, self.max_density):
            color.AddRGBPoint(rho, *[self.albedo * t for t in tint])
        self.property.SetAmbient(1.0)
        self.property.SetDiffuse(0.0 if shading == "absorption" else 1.0)
        self.property.SetSpecular(0.0)
        if shading == "volumetric":
            self.mapper.SetVolumetricScatteringBlending(1.0)
            self.mapper.SetGlobalIlluminationReach(float(settings.get("reach", 0.5)))
            self.property.SetScatteringAnisotropy(float(settings.get("g", self.g)))
        else:
            self.mapper.SetVolumetricScatteringBlending(0.0)
            self.mapper.SetGlobalIlluminationReach(0.0)
        self.window.Render()
        rgba = read_framebuffer(self.window, self.capture_class, 4)
        cloud = rgba[..., :3] / VTK_SCALE  # back to the scene's linear radiance units
        alpha = rgba[..., 3:4]
        if self.sky_error is not None:
            self.noise = (1.0 - alpha) * self.sky_error
        return cloud + (1.0 - alpha) * self.sky

    def close(self):
        self.window.Finalize()


SVS_METHODS = {"none": 0, "octaves": 1, "patterns": 2, "directions": 3}
# The svs renderer's "method" setting -> the mapper's RenderingMethod.
SVS_RENDERING_METHODS = {"slices": 0, "march": 1}
# The svs renderer's "light_method" setting -> the mapper's LightShaftMethod.
SVS_LIGHT_SHAFT_METHODS = {"march": 0, "planes": 1}


class SvsRenderer:
    """Nimbus's cloud mapper (vtkNimbusCloudVolumeMapper): shadow-view slicing (paper
    000) or ray marching (docs/ray-march.md).

    The scene maps one to one onto the mapper: extinction, albedo, the first
    phase component's g (Cornette-Shanks), k_multi, sun, atmosphere, ground.
    Backgrounds "black" and "atmosphere" are a black framebuffer (the mapper
    draws the atmosphere itself) and the image is read back in float from the
    mapper (CaptureRadiance); "constant" is that radiance in the 8-bit
    framebuffer (radiance x VTK_SCALE, quantisation <= 6.5e-4).
    Settings: method (slices, the default, or march: RenderingMethod 0 or 1; every
    row sets it, so a march row leaves no state to the next), step
    (RayMarchStepTexels, the march's step in density texels, default 1),
    slices, a (SliceAngleRatio), shadow (ShadowSurfaceSize),
    atmosphere_steps, jitter (SliceJitter, default on), unlit (the unlit
    compositing floor, for timing only), k_multi
    (000 Eq. 1's multiple-scattering constant; default the scene's), and the
    multiple-scattering term (003, 004): ms (none, the default here, octaves,
    patterns or directions), orders, downsampling (0: the mapper's automatic
    choice), directions, sky_light (bool),
    octaves, pattern_radius, pattern_selection; air_ms (bool, default true: the
    air's multiple scattering and the sky's light on the ground, AirMultipleScattering;
    only with it off are k_multi = 0 and ms none judged as single scattering). The
    row also reports the last solve's seconds (precompute_seconds) and the solver's
    memory (ms_mib).

    The view's own lights (scene format version 4; docs/lights-trade.md): each point and
    spot light is a positional vtkLight of the renderer (scene_vtk_lights), each occluder
    an opaque actor (occluder_actors) that shadows them through the mapper's shadow maps.
    Only the ray march draws lights: a scene with lights refuses a row that is not
    method march. Their settings: light_method (march, the default: equi-angular samples
    along each view ray, or planes: virtual planes, LightShaftMethod), light_samples
    (LightSamples), virtual_planes (NumberOfVirtualPlanes), shadow_map_size
    (LightShadowMapSize; 0: no shadows of the occluders), light_cloud_steps
    (LightCloudSteps; 0: the cloud casts no shadow in the beams) and shaft_downsampling
    (LightShaftDownsampling: the ray-marched shafts on 1 / n of the pixels per side),
    each the mapper's default when a row leaves it out, set on every row. supersample n
    (default 1, any scene): the frame drawn at n x n times the pixels and averaged over
    each n x n block, the pixel's area as the path tracer integrates it (its time is the
    larger frame's).
    """

    def __init__(self, scene_path):
        from vtkmodules.vtkRenderingCore import (vtkRenderWindow, vtkRenderer, vtkVolume,
                                                 vtkWindowToImageFilter)
        import vtkmodules.vtkRenderingOpenGL2  # noqa: F401 (object factories)

        scene = load_scene(scene_path)
        refuse_unsupported_features(scene_path, scene, "svs")
        density = nimbus.vtkNimbusSceneDensitySource()
        density.SetSceneFileName(scene_path)
        density.Update()
        self.mapper = configure_svs_mapper(nimbus.vtkNimbusCloudVolumeMapper(), scene)
        # The light settings a row leaves out take the mapper's defaults.
        self.light_defaults = (self.mapper.GetLightSamples(),
                               self.mapper.GetNumberOfVirtualPlanes(),
                               self.mapper.GetLightShadowMapSize(),
                               self.mapper.GetLightCloudSteps(),
                               self.mapper.GetLightShaftDownsampling())
        self.k_multi = scene["medium"].get("multiple_scattering_constant", 0.0)
        self.extra = {}
        self.mapper.SetInputConnection(density.GetOutputPort())
        self.mapper.SetExposure(VTK_SCALE)
        self.volume = vtkVolume()
        self.volume.SetMapper(self.mapper)
        self.renderer = vtkRenderer()
        self.renderer.AddVolume(self.volume)
        # The view's own lights and the opaque scene that shadows them (version 4).
        self.lights = scene_vtk_lights(scene)
        for light in self.lights:
            self.renderer.AddLight(light)
        self.occluders = occluder_actors(scene)
        for actor in self.occluders:
            self.renderer.AddActor(actor)
        if any(o["albedo"] > 0 for o in scene.get("occluders", [])):
            print(f"svs: {scene_path}: an occluder of albedo > 0 is shaded by VTK's lights, "
                  "not as the path tracer's Lambertian surface, and its own light is not in "
                  "the mapper's radiance this harness measures; use albedo 0", file=sys.stderr)
        background = scene.get("background", {})
        grey = 0.0
        if background.get("type") == "constant":
            grey = min(1.0, background.get("radiance", 0.0) * VTK_SCALE)
        self.renderer.SetBackground(grey, grey, grey)
        # With a black background the image is the slices' float sum: read it in
        # float (no 8-bit floor); otherwise read the 8-bit framebuffer.
        self.float_capture = grey == 0.0
        self.mapper.SetCaptureRadiance(self.float_capture)
        camera_description = scene["camera"]
        camera = self.renderer.GetActiveCamera()
        camera.SetPosition(*camera_description["position"])
        camera.SetFocalPoint(*camera_description["focal_point"])
        camera.SetViewUp(*camera_description.get("view_up", [0, 0, 1]))
        camera.SetViewAngle(camera_description.get("view_angle", 30.0))
        camera.SetClippingRange(1.0, 1e6)
        self.window = vtkRenderWindow()
        self.window.SetOffScreenRendering(1)
        self.window.SetMultiSamples(0)
        self.size = (camera_description["width"], camera_description["height"])
        self.window.SetSize(*self.size)
        self.window.AddRenderer(self.renderer)
        self.capture_class = vtkWindowToImageFilter

    def render(self, settings):
        # supersample n: drawn at n x n times the pixels and averaged over each n x n
        # block, as the path tracer integrates over each pixel's area (it samples the
        # whole pixel; the mapper its centre). Float capture only.
        supersample = int(settings.get("supersample", 1))
        if supersample < 1 or (supersample > 1 and not self.float_capture):
            raise ValueError(f"svs: supersample {supersample}: a positive integer, and above "
                             "1 only for the float capture (black or atmosphere background)")
        self.window.SetSize(self.size[0] * supersample, self.size[1] * supersample)
        method = settings.get("method", "slices")
        if self.lights and method != "march":
            raise ValueError(f"svs: setting {setting_label(settings)}: the scene has lights, "
                             "which only the ray march draws (method march)")
        self.mapper.SetRenderingMethod(SVS_RENDERING_METHODS[method])
        self.mapper.SetLightShaftMethod(SVS_LIGHT_SHAFT_METHODS[settings.get("light_method",
                                                                             "march")])
        defaults = self.light_defaults
        self.mapper.SetLightSamples(int(settings.get("light_samples", defaults[0])))
        self.mapper.SetNumberOfVirtualPlanes(int(settings.get("virtual_planes", defaults[1])))
        self.mapper.SetLightShadowMapSize(int(settings.get("shadow_map_size", defaults[2])))
        self.mapper.SetLightCloudSteps(int(settings.get("light_cloud_steps", defaults[3])))
        self.mapper.SetLightShaftDownsampling(int(settings.get("shaft_downsampling",
                                                               defaults[4])))
        self.mapper.SetRayMarchStepTexels(float(settings.get("step", 1.0)))
        self.mapper.SetNumberOfSlices(int(settings.get("slices", 256)))
        self.mapper.SetSliceAngleRatio(float(settings.get("a", 1.0)))
        self.mapper.SetShadowSurfaceSize(int(settings.get("shadow", 512)))
        self.mapper.SetAtmosphereSteps(int(settings.get("atmosphere_steps", 16)))
        self.mapper.SetSliceJitter(bool(settings.get("jitter", True)))
        self.mapper.SetUnlit(bool(settings.get("unlit", False)))
        self.mapper.SetMultipleScattering(float(settings.get("k_multi", self.k_multi)))
        self.mapper.SetMultipleScatteringMethod(SVS_METHODS[settings.get("ms", "none")])
        if settings.get("ms") == "patterns":
            self.mapper.SetPatternOrders(int(settings.get("orders", 3)))
        else:
            self.mapper.SetMultipleScatteringOrders(int(settings.get("orders", 32)))
        self.mapper.SetMultipleScatteringDownsampling(int(settings.get("downsampling", 0)))
        self.mapper.SetMultipleScatteringDirections(int(settings.get("directions", 26)))
        self.mapper.SetSkyLight(bool(settings.get("sky_light", True)))
        self.mapper.SetAirMultipleScattering(bool(settings.get("air_ms", True)))
        self.mapper.SetOctaves(int(settings.get("octaves", 4)))
        self.mapper.SetPatternRadius(int(settings.get("pattern_radius", 6)))
        self.mapper.SetPatternSelection(float(settings.get("pattern_selection", 0.25)))
        solves = self.mapper.GetNumberOfMultipleScatteringSolves()
        # Every timed frame is drawn in full: the mapper reuses its last image when
        # nothing it depends on changed (a repeat of the same settings).
        self.mapper.Modified()
        self.window.Render()
        if self.mapper.GetNumberOfMultipleScatteringSolves() != solves:
            self.extra = {"precompute_seconds": self.mapper.GetLastMultipleScatteringSeconds(),
                          "ms_mib": self.mapper.GetLastMultipleScatteringBytes() / 2 ** 20}
        elif settings.get("ms", "none") == "none":
            self.extra = {"precompute_seconds": 0.0, "ms_mib": 0.0}
        if self.float_capture:
            radiance = self.mapper.GetRadianceImage()
            width, height, _ = radiance.GetDimensions()
            rgba = vtk_to_numpy(radiance.GetPointData().GetScalars()).reshape(height, width, 4)
            image = rgba[..., :3].astype(np.float32)
            if supersample > 1:
                image = image.reshape(height // supersample, supersample,
                                      width // supersample, supersample, 3).mean(axis=(1, 3))
            return image.copy()
        return read_framebuffer(self.window, self.capture_class, 3) / VTK_SCALE

    def close(self):
        self.window.Finalize()


def configure_svs_mapper(mapper, scene):
    """Sets a vtkNimbusCloudVolumeMapper's optics from a scene (JSON dict)."""
    medium = scene["medium"]
    mapper.SetExtinctionPerDensity(medium.get("extinction_per_density", 0.02))
    mapper.SetAlbedo(medium.get("single_scattering_albedo", 0.99))
    phase = medium.get("phase", [{}])
    phase = phase if isinstance(phase, list) else [phase]
    if len(phase) != 1 or phase[0].get("type", "cornette_shanks") != "cornette_shanks":
        print("svs: the mapper has one Cornette-Shanks phase function; using the first "
              "component's g", file=sys.stderr)
    mapper.SetCloudG(float(phase[0].get("g", 0.85)))
    mapper.SetMultipleScattering(medium.get("multiple_scattering_constant", 0.0))
    sun = scene["sun"]
    mapper.SetSunElevationDegrees(sun["elevation_degrees"])  # the canonical scene has
    mapper.SetSunAzimuthDegrees(sun["azimuth_degrees"])  # angles, never "direction"
    mapper.SetSunIlluminance(sun["illuminance"])
    mapper.SetSunTemperatureKelvin(sun["temperature_kelvin"])
    atmosphere = scene.get("atmosphere", {})
    mapper.SetAtmosphere(bool(atmosphere.get("enabled", True)))
    mapper.SetSceneAltitudeMetres(atmosphere["scene_altitude_metres"])
    mapper.SetRayleighScatteringPerMetre(atmosphere["rayleigh_scattering_per_metre"])
    mapper.SetMieScatteringPerMetre(atmosphere["mie_scattering_per_metre"])
    mapper.SetMieG(atmosphere["mie_g"])
    ground = scene.get("ground", {})
    mapper.SetGround(bool(ground.get("enabled", True)))
    mapper.SetGroundHeight(ground.get("height", 0.0))
    mapper.SetGroundAlbedo(ground.get("albedo", 0.2))
    differing = [f"{key} {atmosphere[key]:g} (the mapper's {value:g})"
                 for key, value in SVS_FIXED_AIR.items()
                 if key in atmosphere and atmosphere[key] != value]
    if differing:
        print("svs: the mapper keeps its own " + ", ".join(differing) + "; its air differs "
              "from the scene's", file=sys.stderr)
    # The view's own lights (SvsRenderer adds them to its renderer as positional vtkLights):
    # the mapper's one soft edge and one light map for every spot.
    mapper.SetLightSources(1)  # PositionalLights
    mapper.SetLightIntensityScale(1.0)
    edge = spot_edge_degrees(scene)
    if edge is not None:
        mapper.SetSpotEdgeWidthDegrees(edge)
    light_map = spot_light_map_path(scene)
    mapper.SetLightMap(read_light_map(light_map) if light_map else None)
    return mapper


# The air's parameters the mapper does not take (vtkNimbusCloudVolumeMapper.h: "the other
# parameters keep their defaults", Physics/Atmosphere.h): a scene with other values is
# drawn by the mapper with these.
SVS_FIXED_AIR = {"earth_radius_metres": 6360000.0, "top_radius_metres": 6420000.0,
                 "rayleigh_scale_height_metres": 8000.0, "mie_scale_height_metres": 1200.0,
                 "mie_albedo": 0.9}


# --- the view's own lights and the opaque scene (scene format version 4) ----------------------

# The most lights vtkNimbusCloudVolumeMapper draws in one frame (MaximumLights' limit).
SVS_MAXIMUM_LIGHTS = 8


def _piecewise_gaussian(wavelength, mean, below, above):
    sigma = np.where(wavelength < mean, below, above)
    return np.exp(-0.5 * ((wavelength - mean) / sigma) ** 2)


def cie_xyz_bar_1931(wavelength_nm):
    """CIE 1931 2-degree colour-matching functions (x-bar, y-bar, z-bar) at the given
    wavelengths (nm): the multi-lobe fit of Wyman, Sloan and Shirley (JCGT 2(2), 2013,
    Eq. 4), the one Physics/SpectralColor.h uses."""
    w = np.asarray(wavelength_nm, dtype=np.float64)
    x = (1.056 * _piecewise_gaussian(w, 599.8, 37.9, 31.0)
         + 0.362 * _piecewise_gaussian(w, 442.0, 16.0, 26.7)
         - 0.065 * _piecewise_gaussian(w, 501.1, 20.4, 26.2))
    y = (0.821 * _piecewise_gaussian(w, 568.8, 46.9, 40.5)
         + 0.286 * _piecewise_gaussian(w, 530.9, 16.3, 31.1))
    z = (1.217 * _piecewise_gaussian(w, 437.0, 11.8, 36.0)
         + 0.681 * _piecewise_gaussian(w, 459.0, 26.0, 13.8))
    return x, y, z


def planck_spectral_radiance(wavelength_nm, temperature_kelvin):
    """Planck's law, W m^-2 sr^-1 nm^-1 (Physics/SpectralColor.h's PlanckSpectralRadiance)."""
    h, c, k = 6.62607015e-34, 299792458.0, 1.380649e-23
    metres = np.asarray(wavelength_nm, dtype=np.float64) * 1e-9
    exponent = h * c / (metres * k * temperature_kelvin)
    return 2.0 * h * c * c / metres ** 5 / np.expm1(exponent) * 1e-9


# IEC 61966-2-1 XYZ -> linear sRGB (D65), as Physics/SpectralColor.cxx.
XYZ_TO_LINEAR_SRGB = np.array([[3.2406, -1.5372, -0.4986],
                               [-0.9689, 1.8758, 0.0415],
                               [0.0557, -0.2040, 1.0570]])


def blackbody_linear_srgb(temperature_kelvin):
    """The colour of a blackbody at temperature_kelvin in linear sRGB, normalised to
    luminance Y = 1: the scene format's light spectrum (a blackbody normalised to
    luminance 1) as a GPU light's colour. Planck against the CIE 1931 functions over
    380-780 nm at 1 nm (the path tracer samples 16 wavelengths with a spline; the two
    differ by about 5e-5 in linear sRGB at Y = 1, SpectralColor.h)."""
    wavelengths = np.arange(380.0, 780.5, 1.0)
    spectrum = planck_spectral_radiance(wavelengths, temperature_kelvin)
    xyz = np.array([np.trapz(spectrum * bar, wavelengths)
                    for bar in cie_xyz_bar_1931(wavelengths)])
    return XYZ_TO_LINEAR_SRGB @ (xyz / xyz[1])


def scene_vtk_lights(scene):
    """A positional vtkLight per point and spot light of a canonical scene, as
    vtkNimbusCloudVolumeMapper reads the view's lights (LightSources PositionalLights,
    LightIntensityScale 1): Intensity x DiffuseColor is the radiant intensity on the
    axis in Y/sr per channel of linear sRGB, the scene's intensity times its blackbody
    colour at luminance 1 (blackbody_linear_srgb). A spot's focal point is its position
    plus its direction and its ConeAngle the scene's cone_angle_degrees (VTK's half
    angle); a point light's ConeAngle is 180 (no cone). Polyline lights are not made
    (svs_unsupported_features refuses them)."""
    from vtkmodules.vtkRenderingCore import vtkLight
    lights = []
    for description in scene.get("lights", []):
        kind = description["type"]
        if kind not in ("point", "spot"):
            continue
        colour = blackbody_linear_srgb(description["temperature_kelvin"])
        brightest = float(max(colour))
        light = vtkLight()
        light.SetLightTypeToSceneLight()
        light.SetPositional(True)
        light.SetSwitch(True)
        position = [float(x) for x in description["position"]]
        light.SetPosition(*position)
        if kind == "spot":
            axis = np.asarray(description["direction"], dtype=np.float64)
            axis = axis / np.linalg.norm(axis)
            light.SetFocalPoint(*(np.asarray(position) + axis).tolist())
            light.SetConeAngle(float(description["cone_angle_degrees"]))
        else:
            light.SetFocalPoint(position[0], position[1], position[2] - 1.0)
            light.SetConeAngle(180.0)
        # Colour in [0, 1] (VTK's convention), the rest in the intensity.
        light.SetDiffuseColor(*(colour / brightest).tolist())
        light.SetIntensity(float(description["intensity"]) * brightest)
        lights.append(light)
    return lights


def spot_edge_degrees(scene):
    """The spots' one soft-edge width (the mapper's SpotEdgeWidthDegrees), or None when
    the scene has no spot. Spots that differ are refused (svs_unsupported_features)."""
    edges = {light["edge_degrees"] for light in scene.get("lights", []) if light["type"] == "spot"}
    if len(edges) > 1:
        raise ValueError(f"the spots' edges differ ({sorted(edges)} degrees); the SVS mapper "
                         "has one SpotEdgeWidthDegrees")
    return edges.pop() if edges else None


def spot_light_map_path(scene):
    """The spots' one light map (absolute path), or None."""
    maps = {light.get("light_map", "") for light in scene.get("lights", [])
            if light["type"] == "spot"}
    if len(maps) > 1:
        raise ValueError(f"the spots' light maps differ ({sorted(maps)}); the SVS mapper has "
                         "one LightMap")
    path = maps.pop() if maps else ""
    return path or None


def srgb_decode(encoded):
    """sRGB's transfer function (IEC 61966-2-1), encoded [0, 1] -> linear."""
    encoded = np.clip(encoded, 0.0, 1.0)
    return np.where(encoded <= 0.04045, encoded / 12.92, ((encoded + 0.055) / 1.055) ** 2.4)


def read_light_map(path):
    """A light map as the path tracer reads it (Reference/SceneAssets.h), handed to the
    mapper as a one-component float vtkImageData of linear luminance: read by
    vtkImageReader2Factory; 8- or 16-bit samples over their range; PNG decoded from sRGB,
    PNM taken as linear; Y = 0.2126 R + 0.7152 G + 0.0722 B of three or four channels,
    the first of one or two. Rows as VTK's readers give them: the first row of VTK's data
    is the picture's bottom row (the file's last), which both renderers put at v = 0
    (Physics/SpotLight.h: the picture thrown upright, its top at v = 1)."""
    from vtkmodules.vtkIOImage import vtkImageReader2Factory
    if not os.path.isfile(path):
        raise ValueError(f"{path}: no such file (the light map)")
    reader = vtkImageReader2Factory.CreateImageReader2(path)
    if reader is None:
        raise ValueError(f"{path}: not an image VTK reads (the light map)")
    reader.SetFileName(path)
    reader.Update()
    image = reader.GetOutput()
    scalars = image.GetPointData().GetScalars()
    width, height, depth = image.GetDimensions()
    if scalars is None or depth != 1 or width < 1 or height < 1:
        raise ValueError(f"{path}: not a 2-D image (the light map)")
    values = vtk_to_numpy(scalars).astype(np.float64).reshape(height, width, -1)
    ranges = {"unsigned char": 255.0, "unsigned short": 65535.0}
    if scalars.GetDataTypeAsString() not in ranges:
        raise ValueError(f"{path}: {scalars.GetDataTypeAsString()} samples; a light map needs "
                         "8 or 16 bits per channel")
    values = values / ranges[scalars.GetDataTypeAsString()]
    if path.lower().endswith(".png"):
        values = srgb_decode(values)
    if values.shape[2] >= 3:
        luminance = 0.2126 * values[..., 0] + 0.7152 * values[..., 1] + 0.0722 * values[..., 2]
    else:
        luminance = values[..., 0]
    luminance = np.ascontiguousarray(luminance, dtype=np.float32)
    light_map = vtkImageData()
    light_map.SetDimensions(width, height, 1)
    array = numpy_to_vtk(luminance.reshape(-1), deep=True)
    array.SetName("luminance")
    light_map.GetPointData().SetScalars(array)
    return light_map


def occluder_actors(scene):
    """A vtkActor per occluder of a canonical scene: boxes by vtkCubeSource, meshes by
    vtkPLYReader or vtkOBJReader placed by a vtkTransformFilter (scale, then translate),
    grey = the occluder's albedo, lit by VTK's diffuse term only (ambient and specular 0).
    With albedo 0 (the light scenes') they are black, as the path tracer's are; a grey one
    is shaded by VTK's lights, not as the path tracer's Lambertian surface, and its own
    light is not in the mapper's float radiance the harness measures (only the air and
    the cloud in front of it)."""
    from vtkmodules.vtkFiltersGeneral import vtkTransformFilter
    from vtkmodules.vtkFiltersSources import vtkCubeSource
    from vtkmodules.vtkCommonTransforms import vtkTransform
    from vtkmodules.vtkIOGeometry import vtkOBJReader
    from vtkmodules.vtkIOPLY import vtkPLYReader
    from vtkmodules.vtkRenderingCore import vtkActor, vtkPolyDataMapper
    actors = []
    for description in scene.get("occluders", []):
        if description["type"] == "box":
            source = vtkCubeSource()
            lo, hi = description["min"], description["max"]
            source.SetBounds(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2])
            output = source.GetOutputPort()
        else:
            path = description["path"]
            if not os.path.isfile(path):
                raise ValueError(f"{path}: no such file (an occluder's mesh)")
            reader = vtkPLYReader() if path.lower().endswith(".ply") else vtkOBJReader()
            reader.SetFileName(path)
            transform = vtkTransform()
            transform.PostMultiply()
            transform.Scale(description["scale"], description["scale"], description["scale"])
            transform.Translate(*description["translate"])
            placed = vtkTransformFilter()
            placed.SetTransform(transform)
            placed.SetInputConnection(reader.GetOutputPort())
            output = placed.GetOutputPort()
        mapper = vtkPolyDataMapper()
        mapper.SetInputConnection(output)
        mapper.ScalarVisibilityOff()
        mapper.Update()
        if mapper.GetInput().GetNumberOfCells() == 0:
            raise ValueError(f"{description['path']}: no surface in this mesh (an occluder)")
        actor = vtkActor()
        actor.SetMapper(mapper)
        grey = float(description["albedo"])
        actor.GetProperty().SetColor(grey, grey, grey)
        actor.GetProperty().SetAmbient(0.0)
        actor.GetProperty().SetDiffuse(1.0)
        actor.GetProperty().SetSpecular(0.0)
        actors.append(actor)
    return actors


# --- the harness ------------------------------------------------------------------------------

def setting_label(settings):
    """The settings as "key=value, ...", every key given: a march row reads
    "method=march, ..." and a row without "method" is drawn by slices."""
    return ", ".join(f"{key}={value}" for key, value in settings.items())


def measure(renderer, settings, repeats, warm_up=False):
    """The last image and the median time of `repeats` renders; with warm_up, after one
    render that is not timed (the GPU renderers' one-time work: shader compilation,
    uploads, the multiple-scattering solve, which the SVS rows report on their own)."""
    times = []
    image = None
    if warm_up:
        image = renderer.render(settings)
    for _ in range(repeats):
        start = time.perf_counter()
        image = renderer.render(settings)
        times.append(time.perf_counter() - start)
    return image, statistics.median(times)


def pareto_front(rows):
    """Rows no other row beats in both time and RMSE, sorted by time."""
    front = []
    for row in sorted(rows, key=lambda r: (r["median_seconds"], r["rmse"])):
        if not front or row["rmse"] < front[-1]["rmse"]:
            front.append(row)
    return front


def plot(rows, title, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axis = plt.subplots(figsize=(7, 4.5), dpi=100)
    # One series per renderer and kind of reference ("svs vs path"); a corrected RMSE of 0
    # (within the reference's noise) is drawn at the floor.
    def series(row):
        name = row["renderer"]
        if name == "svs":  # one series per rendering method and multiple-scattering method
            settings = json.loads(row.get("settings_json", "{}"))
            if settings.get("method", "slices") == "march":
                name += " march"
            name += " " + settings.get("ms", "none")
        return f"{name} vs {row.get('reference', '?').split()[0]}"

    for name in sorted({series(row) for row in rows}):
        mine = [row for row in rows if series(row) == name]
        axis.scatter([r["median_seconds"] for r in mine],
                     [max(r["rmse"], PLOT_RMSE_FLOOR) for r in mine], label=name, s=20)
        front = pareto_front(mine)
        axis.plot([r["median_seconds"] for r in front],
                  [max(r["rmse"], PLOT_RMSE_FLOOR) for r in front], "-", linewidth=1)
    axis.set_xscale("log")
    axis.set_yscale("log")
    axis.set_xlabel("render time (s, median)")
    axis.set_ylabel("RMSE vs reference (linear radiance)")
    axis.set_title(title)
    axis.grid(True, which="both", linewidth=0.3)
    axis.legend(fontsize=8)
    figure.tight_layout()
    figure.savefig(path)
    plt.close(figure)


def write_png(image, path, exposure=None):
    """Tone-mapped PNG of a linear image (exposure, default DISPLAY_EXPOSURE; clip, sRGB),
    like nimbus-render."""
    exposure = DISPLAY_EXPOSURE if exposure is None else exposure
    encoded = np.clip(image * exposure, 0.0, 1.0)
    encoded = np.where(encoded <= 0.0031308, 12.92 * encoded,
                       1.055 * np.power(encoded, 1.0 / 2.4) - 0.055)
    height, width, _ = image.shape
    data = vtkImageData()
    data.SetDimensions(width, height, 1)
    pixels = numpy_to_vtk((encoded.reshape(-1, 3) * 255.0 + 0.5).astype(np.uint8), deep=True)
    data.GetPointData().SetScalars(pixels)
    writer = vtkPNGWriter()
    writer.SetFileName(path)
    writer.SetInputData(data)
    writer.Write()


# The side-by-side PNGs: the difference is drawn this many times brighter.
SIDE_BY_SIDE_DIFFERENCE_GAIN = 4.0


def write_side_by_side(reference, image, path, exposure=None):
    """One PNG for looking at a row: the reference, the image and |image - reference| x
    SIDE_BY_SIDE_DIFFERENCE_GAIN, left to right, at the same exposure, 2 grey pixels
    apart."""
    gap = np.full((reference.shape[0], 2, 3), 0.05 / (exposure or DISPLAY_EXPOSURE),
                  dtype=np.float32)
    difference = np.abs(image.astype(np.float32) - reference) * SIDE_BY_SIDE_DIFFERENCE_GAIN
    write_png(np.concatenate([reference, gap, image, gap, difference], axis=1), path, exposure)


def write_rows_csv(path, rows):
    """Rows (dicts with the same keys) as a CSV file with a header; prints the path."""
    with open(path, "w", newline="") as stream:
        writer = csv.DictWriter(stream, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    print(path)


def path_convergence(scene_paths, samples_per_pixel, output_dir, target=0.01):
    """Time to `target` relative RMSE of the path tracer, per scene.

    Renders with `samples_per_pixel` samples, takes the image's relative error
    from the per-pixel standard errors (RMS standard error / RMS radiance; the
    tests show them calibrated) and extrapolates with the N^-1/2 law the tests
    measured (slope -0.486): t_target = t * (error / target)^2.
    """
    rows = []
    for scene_path in scene_paths:
        scene_name = os.path.splitext(os.path.basename(scene_path))[0]
        settings = {"mode": "path", "min_spp": samples_per_pixel, "max_spp": samples_per_pixel,
                    "seed": 1}
        _, output = render_reference_mode(os.path.abspath(scene_path), settings)
        seconds = output.GetFieldData().GetArray("RenderSeconds").GetValue(0)
        error = output.GetFieldData().GetArray("EstimatedRelativeError").GetValue(0)
        factor = (error / target) ** 2
        row = {"scene": scene_name, "samples_per_pixel": samples_per_pixel,
               "seconds": seconds, "relative_error": error,
               "samples_per_pixel_for_target": samples_per_pixel * factor,
               "seconds_for_target": seconds * factor}
        rows.append(row)
        print(f"{scene_name}: path tracing {samples_per_pixel} spp in {seconds:.1f} s, relative "
              f"error {error:.3f} -> {target:.0%} needs ~{row['samples_per_pixel_for_target']:.3g}"
              f" spp, ~{row['seconds_for_target'] / 3600:.2g} h", flush=True)
    write_rows_csv(os.path.join(output_dir, "path-convergence.csv"), rows)
    return rows


class SceneReferences:
    """A scene's reference images (and the sky-only ones), rendered on first use and cached."""

    def __init__(self, scene_path, scene_name, cache_dir, output_dir, reference_seconds,
                 exposure=None):
        self.exposure = exposure
        self.scene_path = scene_path
        self.scene_name = scene_name
        self.cache_dir = cache_dir
        self.output_dir = output_dir
        self.reference_seconds = reference_seconds
        self.images = {}

    def settings(self, name, sky=False):
        settings = dict(REFERENCE_SETTINGS[name])
        if "time_limit" in settings:
            share = SKY_BUDGET_SHARE if sky else 1.0
            settings["time_limit"] = float(self.reference_seconds) * share
        return settings

    def get(self, name, sky=False):
        """(image, standard error or None, label) of reference `name` (sky-only if sky)."""
        if (name, sky) in self.images:
            return self.images[(name, sky)]
        settings = self.settings(name, sky)
        what = "sky-only reference" if sky else "reference"
        key = scene_hash(self.scene_path, {"sky_only": settings} if sky else settings)

        def compute():
            density = zero_density(self.scene_path) if sky else None
            image, output = render_reference_mode(self.scene_path, settings, density=density)
            field = output.GetFieldData()
            error = field.GetArray("EstimatedRelativeError").GetValue(0)
            seconds = field.GetArray("RenderSeconds").GetValue(0)
            spp = field.GetArray("SamplesPerPixel").GetValue(0)
            print(f"{self.scene_name}: {what} ({name}) rendered in {seconds:.1f} s, "
                  f"{spp:.4g} samples per pixel, estimated relative error {error:.2e}",
                  flush=True)
            return image, standard_error_of(output)

        prefix = f"{self.scene_name}-sky-{name}" if sky else f"{self.scene_name}-{name}"
        image, error, cached = cached_image(self.cache_dir, f"{prefix}-{key}", compute)
        if cached:
            print(f"{self.scene_name}: {what} ({name}) from the cache", flush=True)
        label = name
        if error is not None:
            rms = float(np.sqrt(np.mean(error.astype(np.float64) ** 2)))
            mean = float(np.sqrt(np.mean(image.astype(np.float64) ** 2)))
            label = f"{name} (±{100.0 * rms / max(mean, 1e-30):.2g} %)"
        if not sky:
            write_png(image, os.path.join(self.output_dir,
                                          f"{self.scene_name}-reference-{name}.png"),
                      self.exposure)
        self.images[(name, sky)] = (image, error, label)
        return self.images[(name, sky)]


def compare_references(scene_paths, names, args):
    """Reference names[0] against reference names[1] on each scene (from the cache, or
    rendered into it): the metrics with both references' noise taken off, and the ratio
    of their mean radiances. Writes OUTPUT_DIR/reference-pairs.csv."""
    cache_dir = args.cache_dir or os.path.join(args.output_dir, "reference-cache")
    rows = []
    for scene_path in scene_paths:
        scene_path = os.path.abspath(scene_path)
        scene_name = os.path.splitext(os.path.basename(scene_path))[0]
        references = SceneReferences(scene_path, scene_name, cache_dir, args.output_dir,
                                     args.reference_seconds, args.display_exposure)
        image, image_error, image_label = references.get(names[0])
        reference, reference_error, reference_label = references.get(names[1])
        row = {"scene": scene_name, "image": image_label, "reference": reference_label}
        row.update(error_metrics(image, reference, reference_error, image_error))
        row["mean_ratio"] = float(image.mean() / max(reference.mean(), 1e-30))
        rows.append(row)
        print(f"{scene_name}: {image_label} against {reference_label}: RMSE {row['rmse']:.4g}, "
              f"PSNR {row['psnr_db']:.1f} dB (p99.9 {row['psnr_p999_db']:.1f} dB), rel. L1 "
              f"{row['relative_l1']:.3f}, mean radiance ratio {row['mean_ratio']:.3f}",
              flush=True)
    write_rows_csv(os.path.join(args.output_dir, "reference-pairs.csv"), rows)
    return rows


def run(arguments):
    parser = argparse.ArgumentParser(prog="python3 -m nimbus.harness", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scenes", nargs="+", help="scene files (JSON)")
    parser.add_argument("--renderer", action="append", choices=sorted(DEFAULT_SETTINGS),
                        help="renderer(s) to measure (default: vtk-gpu)")
    parser.add_argument("--settings", help="JSON file: a list of settings (one renderer only)")
    parser.add_argument("--reference", choices=["auto"] + sorted(REFERENCE_SETTINGS),
                        default="auto",
                        help="the ground truth: 'path' (Monte Carlo, full multiple scattering, "
                             "for --reference-seconds), 'path-single' (the same, stopped at "
                             "the first scattering), 'single' (converged single "
                             "scattering), or 'auto' (default): 'single' for settings that "
                             "model single scattering only (in scenes without lights), "
                             "'path' for the others")
    parser.add_argument("--reference-seconds", type=float,
                        default=REFERENCE_SETTINGS["path"]["time_limit"],
                        help="time budget of a path-traced reference (default %(default)g s; "
                             "the sky-only one gets a quarter). Part of the cache key.")
    parser.add_argument("--repeats", type=int, default=3, help="renders per setting (median)")
    parser.add_argument("--output-dir", default="harness-output")
    parser.add_argument("--cache-dir", default=None,
                        help="reference cache (default: OUTPUT_DIR/reference-cache)")
    parser.add_argument("--markdown", help="also write the table as Markdown to this file")
    parser.add_argument("--display-exposure", type=float, default=DISPLAY_EXPOSURE,
                        help="exposure of the PNGs written for looking at (default %(default)g;"
                             " not used in any metric)")
    parser.add_argument("--side-by-side", action="store_true",
                        help="also write SCENE-RENDERER-INDEX-side.png per row: the reference,"
                             " the image and |difference| x "
                             f"{SIDE_BY_SIDE_DIFFERENCE_GAIN:g}")
    parser.add_argument("--path-convergence", type=int, metavar="SPP",
                        help="instead: measure the path tracer at SPP samples per pixel on each "
                             "scene and extrapolate its time to 1%% relative RMSE")
    parser.add_argument("--compare-references", nargs=2, metavar=("IMAGE", "REFERENCE"),
                        choices=sorted(REFERENCE_SETTINGS),
                        help="instead: measure reference IMAGE against reference REFERENCE on "
                             "each scene (both noise-corrected), e.g. path-single path: what "
                             "multiple scattering adds")
    args = parser.parse_args(arguments)
    if not (args.reference_seconds > 0 and math.isfinite(args.reference_seconds)):
        parser.error("--reference-seconds must be a positive number of seconds")
    if not (args.display_exposure > 0 and math.isfinite(args.display_exposure)):
        parser.error("--display-exposure must be a positive number")
    if args.path_convergence:
        os.makedirs(args.output_dir, exist_ok=True)
        path_convergence(args.scenes, args.path_convergence, args.output_dir)
        return 0
    if args.compare_references:
        os.makedirs(args.output_dir, exist_ok=True)
        compare_references(args.scenes, args.compare_references, args)
        return 0
    renderers = args.renderer or ["vtk-gpu"]
    if args.settings and len(renderers) != 1:
        parser.error("--settings needs exactly one --renderer")
    if args.repeats < 1:
        parser.error("--repeats must be >= 1")
    cache_dir = args.cache_dir or os.path.join(args.output_dir, "reference-cache")
    os.makedirs(args.output_dir, exist_ok=True)

    all_rows = []
    used_references = set()
    for scene_path in args.scenes:
        scene_path = os.path.abspath(scene_path)
        scene_name = os.path.splitext(os.path.basename(scene_path))[0]
        scene = load_scene(scene_path)
        references = SceneReferences(scene_path, scene_name, cache_dir, args.output_dir,
                                     args.reference_seconds, args.display_exposure)

        def reference_name(renderer_name, settings):
            if args.reference != "auto":
                return args.reference
            return "single" if models_single_scattering_only(renderer_name, settings,
                                                             scene) else "path"

        scene_rows = []
        for renderer_name in renderers:
            if args.settings:
                with open(args.settings) as stream:
                    settings_list = json.load(stream)
            elif renderer_name == "svs" and scene.get("lights"):
                settings_list = DEFAULT_LIGHT_SETTINGS
            else:
                settings_list = DEFAULT_SETTINGS[renderer_name]
            if renderer_name in UNSUPPORTED_FEATURES:  # before any reference is rendered
                try:
                    refuse_unsupported_features(scene_path, scene, renderer_name)
                except ValueError as refusal:
                    # A glob of Data/Scenes holds scenes with lights: the others still run.
                    print(f"skipped: {refusal}", file=sys.stderr, flush=True)
                    continue
            if renderer_name == "vtk-gpu":
                # VTK has no sky: its cloud goes over the sky-only version of the reference
                # that judges it (every vtk-gpu setting has the same one).
                sky, sky_error, _ = references.get(reference_name("vtk-gpu", {}), sky=True)
                renderer = VtkGpuRenderer(scene_path, sky, sky_error)
            elif renderer_name == "svs":
                renderer = SvsRenderer(scene_path)
            else:
                renderer = ReferenceModeRenderer(scene_path, renderer_name)
            try:
                for index, settings in enumerate(settings_list):
                    if (renderer_name == "svs" and scene.get("lights")
                            and settings.get("method", "slices") != "march"):
                        print(f"skipped: {scene_name} svs [{setting_label(settings)}]: the "
                              "scene has lights, which only the ray march draws",
                              file=sys.stderr, flush=True)
                        continue
                    name = reference_name(renderer_name, settings)
                    reference, reference_error, label = references.get(name)
                    used_references.add(name)
                    image, seconds = measure(renderer, settings, args.repeats,
                                             warm_up=renderer_name in ("vtk-gpu", "svs"))
                    row = {"scene": scene_name, "renderer": renderer_name,
                           "setting": setting_label(settings),
                           "settings_json": json.dumps(settings, sort_keys=True),
                           "median_seconds": seconds, "reference": label}
                    row.update(error_metrics(image, reference, reference_error,
                                             getattr(renderer, "noise", None)))
                    row.update(getattr(renderer, "extra", {}))
                    scene_rows.append(row)
                    print(f"{scene_name} {renderer_name} [{row['setting']}]: "
                          f"{seconds:.3f} s, RMSE {row['rmse']:.4g} vs {label}, "
                          f"PSNR {row['psnr_db']:.1f} dB (p99.9 {row['psnr_p999_db']:.1f} dB)",
                          flush=True)
                    write_png(image, os.path.join(
                        args.output_dir, f"{scene_name}-{renderer_name}-{index}.png"),
                        args.display_exposure)
                    if args.side_by_side:
                        write_side_by_side(reference, image, os.path.join(
                            args.output_dir, f"{scene_name}-{renderer_name}-{index}-side.png"),
                            args.display_exposure)
            finally:
                renderer.close()
        if scene_rows:
            plot(scene_rows, f"{scene_name} (reference: {reference_title(scene_rows)})",
                 os.path.join(args.output_dir, f"{scene_name}-trade.png"))
        all_rows.extend(scene_rows)
    if not all_rows:
        print("nothing measured: every scene was skipped (above)", file=sys.stderr)
        return 1

    fields = ["scene", "renderer", "setting", "median_seconds", "rmse", "rmse_raw",
              "reference_noise", "relative_l1", "max_abs", "psnr_db", "psnr_p999_db", "reference",
              "precompute_seconds", "ms_mib", "settings_json"]
    csv_path = os.path.join(args.output_dir, "trade.csv")
    with open(csv_path, "w", newline="") as stream:
        writer = csv.DictWriter(stream, fieldnames=fields, restval="")
        writer.writeheader()
        writer.writerows(all_rows)
    plot(all_rows, f"all scenes (reference: {', '.join(sorted(used_references))})",
         os.path.join(args.output_dir, "trade.png"))
    if args.markdown:
        with open(args.markdown, "w") as stream:
            stream.write("| scene | renderer | setting | median time (s) | RMSE | rel. L1 | "
                         "max abs | PSNR (dB) | PSNR p99.9 (dB) | reference | precompute (s) | "
                         "solver MiB |\n"
                         "|---|---|---|---|---|---|---|---|---|---|---|---|\n")
            for row in all_rows:
                precompute = row.get("precompute_seconds", "")
                memory = row.get("ms_mib", "")
                stream.write(f"| {row['scene']} | {row['renderer']} | {row['setting']} | "
                             f"{row['median_seconds']:.3f} | {row['rmse']:.4g} | "
                             f"{row['relative_l1']:.3f} | {row['max_abs']:.3g} | "
                             f"{row['psnr_db']:.1f} | {row['psnr_p999_db']:.1f} | "
                             f"{row['reference']} | "
                             f"{'' if precompute == '' else format(precompute, '.3f')} | "
                             f"{'' if memory == '' else format(memory, '.1f')} |\n")
    print(csv_path)
    return 0


def reference_title(rows):
    return ", ".join(sorted({row["reference"] for row in rows})) or "none"


if __name__ == "__main__":
    sys.exit(run(sys.argv[1:]))
