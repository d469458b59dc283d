#!/usr/bin/env python3
"""Xvfb/GLX against EGL: every PNG the offscreen twins wrote (build/Testing/Temporary/offscreen)
against the same file from the X run (build/Testing/Temporary), as a Markdown table of the
largest and the RMS difference in 8-bit units over all channels.

    python3 measurements/compare-offscreen.py [build/Testing/Temporary]
"""
import math
import os
import sys

import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOImage import vtkPNGReader


def read_png(path):
    reader = vtkPNGReader()
    reader.SetFileName(path)
    reader.Update()
    image = reader.GetOutput()
    pixels = vtk_to_numpy(image.GetPointData().GetScalars()).astype(np.float64)
    return image.GetDimensions(), pixels


def main():
    x_dir = sys.argv[1] if len(sys.argv) > 1 else os.path.join("build", "Testing", "Temporary")
    egl_dir = os.path.join(x_dir, "offscreen")
    rows = []
    for root, _, files in os.walk(egl_dir):
        for name in sorted(files):
            if not name.endswith(".png"):
                continue
            egl_path = os.path.join(root, name)
            relative = os.path.relpath(egl_path, egl_dir)
            x_path = os.path.join(x_dir, relative)
            if not os.path.exists(x_path):
                rows.append((relative, "no X image", "", ""))
                continue
            x_dims, x_pixels = read_png(x_path)
            egl_dims, egl_pixels = read_png(egl_path)
            if x_dims != egl_dims or x_pixels.shape != egl_pixels.shape:
                rows.append((relative, "size differs", str(x_dims), str(egl_dims)))
                continue
            difference = np.abs(x_pixels - egl_pixels)
            rows.append((relative, "%d" % difference.max(),
                         "%.4f" % math.sqrt(float(np.mean(difference ** 2))),
                         "%d" % int(np.count_nonzero(difference))))
    print("| image | max | RMS | differing values |")
    print("|---|---|---|---|")
    for row in sorted(rows):
        print("| %s | %s | %s | %s |" % row)
    return 0 if rows else 1


if __name__ == "__main__":
    sys.exit(main())
