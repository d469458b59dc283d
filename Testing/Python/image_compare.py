"""Compare a rendered PNG with a baseline PNG using VTK's own image comparison.

Shared by the Python image tests. The threshold is on this VTK's (9.2) scale,
where VTK's own default is 0.15 (see shared/SDK-NOTES.md).
"""
import os
import sys

from vtkmodules.vtkTestingRendering import vtkTesting


def compare_with_baseline(image_path, baseline_path, output_dir, threshold=0.15):
    """Returns True when image_path matches baseline_path within threshold.

    On failure (or a missing baseline) VTK writes the test image and a diff image
    into output_dir, so a new baseline can be inspected and committed.
    """
    os.makedirs(output_dir, exist_ok=True)
    testing = vtkTesting()
    # Absolute paths: vtkTesting prefixes relative ones with its data root.
    for argument in ("-V", os.path.abspath(baseline_path), "-T", os.path.abspath(output_dir)):
        testing.AddArgument(argument)
    result = testing.RegressionTest(os.path.abspath(image_path), threshold)
    sys.stdout.flush()
    return result == vtkTesting.PASSED
