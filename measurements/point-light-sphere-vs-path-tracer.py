#!/usr/bin/env python3
"""A point light inside a uniform sphere: Nimbus's lightning illumination against the path tracer.

    PYTHONPATH=build/lib/python3.11/site-packages Testing/with-display.sh /usr/bin/python3 \
        measurements/point-light-sphere-vs-path-tracer.py [--g 0.85] [--albedo 0.99] [--orders N]

The simplest case of light born inside a thick medium: an isotropic point light (1e6 W/sr)
at the centre of a sphere of radius --radius [m] and extinction --sigma [1/m] (sampled on
--n^3 points, written as a .vti), seen from 6 radii away (120x120). The reference is the
path tracer's light tracing (--time seconds, cached in --out); Nimbus is
vtkNimbusLightningIllumination (--method 1: direct solve, 0: basis; --downsampling, --orders,
--directions, --coarse-first for the first scattering on the illumination grid) drawn by
vtkNimbusCloudVolumeMapper. Prints the mean over the lit disc against the reference and the
ratio in rings of 10 pixels from the disc's centre (its centre sees the light that leaves
the sphere straight outward, its limb the grazing light), and writes reference | Nimbus.
docs/lightning.md has the figures.
"""
import argparse, json, os, sys, time
import numpy as np
import nimbus
from nimbus import harness
from vtkmodules.util.numpy_support import vtk_to_numpy, numpy_to_vtk
import vtkmodules.vtkRenderingOpenGL2  # noqa
from vtkmodules.vtkCommonDataModel import vtkImageData, vtkPolyData, vtkCellArray
from vtkmodules.vtkCommonCore import vtkPoints, vtkDoubleArray
from vtkmodules.vtkIOXML import vtkXMLImageDataWriter

p = argparse.ArgumentParser()
p.add_argument("--sigma", type=float, default=0.02)   # extinction 1/m inside
p.add_argument("--radius", type=float, default=500.0)
p.add_argument("--n", type=int, default=64)
p.add_argument("--time", type=float, default=120)
p.add_argument("--g", type=float, default=0.85)
p.add_argument("--albedo", type=float, default=0.99)
p.add_argument("--downsampling", type=int, default=2)
p.add_argument("--method", type=int, default=1)
p.add_argument("--orders", type=int, default=0)
p.add_argument("--offset", type=float, default=0.0)  # light x offset
p.add_argument("--coarse-first", action="store_true")
p.add_argument("--directions", type=int, default=0)
p.add_argument("--out", default="point-light-sphere")
p.add_argument("--reference-scaled", action="store_true",
               help="the reference traces the delta-M-scaled medium the solver solves "
                    "(extinction (1 - f a) sigma, albedo a (1 - f) / (1 - f a), Henyey-Greenstein "
                    "g' = (k1 - f) / (1 - f), f = k2 of the Cornette-Shanks phase): Nimbus against "
                    "its own approximation, to tell the delta-M scaling's error from the solver's "
                    "and the view's")
a = p.parse_args()
os.makedirs(a.out, exist_ok=True)
half = a.radius * 1.2
n = a.n
h = 2 * half / (n - 1)
x = np.linspace(-half, half, n)
Z, Y, X = np.meshgrid(x, x, x, indexing="ij")
rho = (np.sqrt(X**2 + Y**2 + Z**2) <= a.radius).astype(np.float32)
img = vtkImageData(); img.SetDimensions(n, n, n); img.SetOrigin(-half, -half, -half)
img.SetSpacing(h, h, h)
arr = numpy_to_vtk(rho.ravel(), deep=1); arr.SetName("density")
img.GetPointData().AddArray(arr); img.GetPointData().SetActiveScalars("density")
tag = f"s{a.sigma}-r{a.radius}-n{n}-g{a.g}-a{a.albedo}-o{a.offset}"
vti = os.path.join(a.out, f"sphere-{tag}.vti")
w = vtkXMLImageDataWriter(); w.SetFileName(vti); w.SetInputData(img); w.Write()
I = 1e6
light = [a.offset, 0, 0]
CAMERA = {"position": [0, -3 * a.radius * 2, 0], "focal_point": [0, 0, 0], "view_up": [0, 0, 1],
          "view_angle": 25, "width": 120, "height": 120}
def cornette_shanks_moments(g):
    """k1, k2: the Cornette-Shanks phase function's first two Legendre coefficients."""
    mu = np.linspace(-1.0, 1.0, 400001)
    p = 3 / (8 * np.pi) * (1 - g * g) / (2 + g * g) * (1 + mu ** 2) / (1 + g * g - 2 * g * mu) ** 1.5
    return (2 * np.pi * np.trapz(p * mu, mu), 2 * np.pi * np.trapz(p * (1.5 * mu ** 2 - 0.5), mu))


reference_sigma, reference_albedo = a.sigma, a.albedo
reference_phase = [{"type": "cornette_shanks", "g": a.g, "weight": 1}]
if a.reference_scaled:
    k1, f = cornette_shanks_moments(a.g)
    if k1 > f:
        reference_sigma = (1 - f * a.albedo) * a.sigma
        reference_albedo = a.albedo * (1 - f) / (1 - f * a.albedo)
        reference_phase = [{"type": "henyey_greenstein", "g": (k1 - f) / (1 - f), "weight": 1}]
        tag += "-scaled"
scene = {"nimbus_scene": 3, "name": "sphere", "description": "diag",
  "camera": CAMERA,
  "medium": {"density": {"type": "file", "path": vti, "array": "density"},
             "extinction_per_density": reference_sigma, "single_scattering_albedo": reference_albedo,
             "phase": reference_phase},
  "sun": {"azimuth_degrees": 0, "elevation_degrees": 45, "illuminance": 0, "temperature_kelvin": 5778},
  "atmosphere": {"enabled": False}, "ground": {"enabled": False},
  "background": {"type": "constant", "radiance": 0},
  "lights": [{"type": "point", "position": light, "intensity": I, "temperature_kelvin": 6500}]}
sp = os.path.join(a.out, f"scene-{tag}.json")
json.dump(scene, open(sp, "w"), indent=1)
settings = {"mode": "light", "min_spp": 16, "max_spp": 1 << 20, "time_limit": a.time, "seed": 1}
key = "reference-" + harness.scene_hash(sp, settings)
def trace():
    r = nimbus.vtkNimbusReferenceRenderer(); r.SetSceneFileName(sp)
    harness.configure_reference_renderer(r, settings, 0); r.Update()
    o = r.GetOutput(); rad = o.GetPointData().GetArray("radiance")
    wd, ht, _ = o.GetDimensions()
    return vtk_to_numpy(rad).reshape(ht, wd, 3).astype(np.float32), harness.standard_error_of(o)
ref, err, cached = harness.cached_image(a.out, key, trace)

pts = vtkPoints(); pts.InsertNextPoint(*light)
pd = vtkPolyData(); pd.SetPoints(pts); verts = vtkCellArray(); verts.InsertNextCell(1); verts.InsertCellPoint(0)
pd.SetVerts(verts)
ia = vtkDoubleArray(); ia.SetName("intensity"); ia.InsertNextValue(I); pd.GetPointData().AddArray(ia)
il = nimbus.vtkNimbusLightningIllumination()
il.SetInputData(0, img); il.SetInputData(1, pd)
il.SetMethod(a.method); il.SetDownsampling(a.downsampling)
il.SetLightningColor(1, 1, 1); il.SetAlbedo(a.albedo)
if a.orders: il.SetOrders(a.orders)
il.SetFirstScatteringOnDensityGrid(not a.coarse_first)
if a.directions: il.SetNumberOfDirections(a.directions)
il.SetMemoryBudgetMiB(4096)
il.SetExtinctionPerDensity(a.sigma); il.SetCloudG(a.g)
t = time.perf_counter(); il.Update(); tu = time.perf_counter() - t
m = nimbus.vtkNimbusCloudVolumeMapper(); m.SetInputData(il.GetOutput())
m.SetAlbedo(a.albedo); m.SetMultipleScatteringMethodToNone(); m.SetSunIlluminance(0.0)
m.SetAtmosphere(False); m.SetGround(False); m.SetNumberOfSlices(512); m.SetExposure(harness.VTK_SCALE)
m.SetExtinctionPerDensity(a.sigma); m.SetCloudG(a.g)
im, _ = harness.render_mapper_radiance(m, CAMERA, (120, 120), (1.0, 1e6))
mask = ref.mean(axis=2) > 0.01 * np.percentile(ref.mean(axis=2), 99.5)
r = im[mask].mean() / ref[mask].mean()
print(f"{tag} ds{a.downsampling} m{a.method} cf{int(a.coarse_first)} dir{a.directions}: mean ratio {r:.4f} over {mask.sum()} px; ref mean {ref[mask].mean():.4g} "
      f"rel se {np.sqrt((err[mask]**2).sum())/ref[mask].sum() if err is not None else 0:.4f}; update {tu:.1f}s")
# radial profile ratio
yy, xx = np.mgrid[:120, :120]; rr = np.hypot(yy - 59.5, xx - 59.5)
for lo in range(0, 60, 10):
    sel = mask & (rr >= lo) & (rr < lo + 10)
    if sel.sum(): print(f"  ring {lo}-{lo+10}px: ratio {im[sel].mean()/ref[sel].mean():.3f}")
harness.write_side_by_side(ref, im, os.path.join(a.out, f"side-{tag}-m{a.method}-d{a.downsampling}.png"))
