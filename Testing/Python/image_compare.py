"""Compare a rendered PNG with a baseline PNG, for the Python image tests; read a PNG.

Runs the same comparison as the C++ image tests (Testing/Cxx/ImageComparison.h:
VTK's own vtkTesting check plus a strict RMSE bound, with their measured
justification) through the nimbus-compare-images command that the build makes.
"""
import os
import subprocess
import sys


def read_png(path):
    """A PNG's pixels as a float array [row, column, rgb] (0-255), row 0 at the top."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOImage import vtkPNGReader
    reader = vtkPNGReader()
    reader.SetFileName(path)
    reader.Update()
    image = reader.GetOutput()
    width, height, _ = image.GetDimensions()
    pixels = vtk_to_numpy(image.GetPointData().GetScalars()).reshape(height, width, -1)
    return pixels[::-1, :, :3].astype(float)


def compare_with_baseline(image_path, baseline_path, output_dir, compare_tool):
    """Returns True when image_path matches baseline_path.

    On failure VTK writes a difference image into output_dir; with no baseline
    the message says where the test image is, to inspect before committing it.
    """
    os.makedirs(output_dir, exist_ok=True)
    result = subprocess.run(
        [compare_tool, os.path.abspath(image_path), os.path.abspath(baseline_path),
         os.path.abspath(output_dir)],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, check=False)
    sys.stdout.write(result.stdout)
    sys.stdout.flush()
    return result.returncode == 0
