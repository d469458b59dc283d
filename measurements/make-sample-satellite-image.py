"""Writes Data/SatelliteClouds.png: a synthetic, satellite-like 8-bit grayscale picture of
clouds over a dark sea (NOT a real satellite image). Deterministic (fixed seed).

    /usr/bin/python3 measurements/make-sample-satellite-image.py Data/SatelliteClouds.png

Sea and land (intensity ~20-60), a band of broken cumulus made of fractal value noise
thresholded and brightened, and a few bright convective cells (discs with soft edges).
"""
import sys

import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk
from vtkmodules.vtkCommonDataModel import vtkImageData
from vtkmodules.vtkIOImage import vtkPNGWriter

SIZE = 128
rng = np.random.default_rng(2026)


def value_noise(size, cells):
    """Smooth noise: random values on a cells x cells lattice, bicubic-ish upsampled."""
    lattice = rng.random((cells + 3, cells + 3))
    t = np.linspace(0, cells, size, endpoint=False)
    i = t.astype(int)
    f = t - i
    s = f * f * (3 - 2 * f)  # smoothstep weights
    rows = lattice[i][:, :] * (1 - s)[:, None] + lattice[i + 1] * s[:, None]
    return rows[:, i] * (1 - s)[None, :] + rows[:, i + 1] * s[None, :]


noise = sum(value_noise(SIZE, c) / (k + 1) for k, c in enumerate((4, 8, 16, 32)))
noise = (noise - noise.min()) / (noise.max() - noise.min())
y, x = np.mgrid[0:SIZE, 0:SIZE]
band = np.exp(-(((y - 0.55 * SIZE) + 0.25 * (x - SIZE / 2)) / (0.22 * SIZE)) ** 2)
cloud = np.clip((noise * band - 0.18) / 0.35, 0, 1)
for cx, cy, r in ((30, 30, 9), (96, 40, 12), (70, 100, 7)):
    d = np.hypot(x - cx, y - cy)
    cloud = np.maximum(cloud, np.clip((r - d) / 3 + 0.6, 0, 1) * (d < r + 2))
ground = 25 + 25 * value_noise(SIZE, 6)
image = np.clip(ground * (1 - cloud) + 245 * cloud, 0, 255).astype(np.uint8)

data = vtkImageData()
data.SetDimensions(SIZE, SIZE, 1)
array = numpy_to_vtk(image.ravel(), deep=True)
array.SetName("intensity")
data.GetPointData().SetScalars(array)
writer = vtkPNGWriter()
writer.SetFileName(sys.argv[1] if len(sys.argv) > 1 else "SatelliteClouds.png")
writer.SetInputData(data)
writer.Write()
