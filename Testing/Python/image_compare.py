"""Compare a rendered PNG with a baseline PNG, for the Python image tests.

Runs the same comparison as the C++ image tests (Testing/Cxx/ImageComparison.h:
VTK's own vtkTesting check plus a strict RMSE bound, with their measured
justification) through the nimbus-compare-images command that the build makes.
"""
import os
import subprocess
import sys


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
