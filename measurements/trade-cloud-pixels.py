"""Where do the errors against the path-traced reference come from: the cloud or the sky?
Splits each image's squared error into the pixels the cloud changes (cloud, its shadow and
shafts: |reference - sky-only reference| beyond 4 combined standard errors, any channel) and
the rest (sky and ground the cloud does not touch), noise-corrected like the harness."""
import os
import sys

import numpy as np

from nimbus import harness

# Usage (after a harness run that cached the path-traced references and their sky-only
# versions, e.g. --renderer vtk-gpu under --reference auto):
#   Testing/with-display.sh /usr/bin/python3 measurements/trade-cloud-pixels.py CACHE_DIR SCENE.json...
cache = sys.argv[1]
settings = {"vtk-gpu": [{"shading": "absorption", "sample_distance": 1.0},
                        {"shading": "volumetric", "sample_distance": 0.5, "reach": 0.0},
                        {"shading": "volumetric", "sample_distance": 0.5, "reach": 0.5}],
            "svs": [{"slices": 256, "k_multi": k} for k in (0, 2, 4, 16)]}
print("| scene | renderer | setting | cloud pixels | RMSE, cloud pixels | RMSE, other pixels | RMSE, all |")
print("|---|---|---|---|---|---|---|")
for path in sys.argv[2:]:
    path = os.path.abspath(path)
    scene_name = os.path.splitext(os.path.basename(path))[0]
    refs = harness.SceneReferences(path, scene_name, cache, cache, 600.0)
    ref, ref_err, _ = refs.get("path")
    sky, sky_err, _ = refs.get("path", sky=True)
    combined = np.sqrt(ref_err.astype(np.float64) ** 2 + sky_err.astype(np.float64) ** 2)
    mask = np.any(np.abs(ref.astype(np.float64) - sky) > 4.0 * combined, axis=2)
    for name, items in settings.items():
        if name == "vtk-gpu":
            renderer = harness.VtkGpuRenderer(path, sky, sky_err)
        else:
            renderer = harness.SvsRenderer(path)
        for s in items:
            image = renderer.render(s).astype(np.float64)
            noise = getattr(renderer, "noise", None)
            d2 = (image - ref) ** 2 - ref_err.astype(np.float64) ** 2
            if noise is not None:
                d2 -= noise.astype(np.float64) ** 2
            def rmse(m):
                return float(np.sqrt(max(0.0, d2[m].mean()))) if m.any() else float("nan")

            print(f"| {scene_name} | {name} | {harness.setting_label(s)} | "
                  f"{100 * mask.mean():.0f} % | {rmse(mask):.4g} | {rmse(~mask):.4g} | "
                  f"{rmse(np.ones_like(mask)):.4g} |", flush=True)
        renderer.close()
