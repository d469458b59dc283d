"""The reference renderer through its VTK glue (vtkNimbusReferenceRenderer),
from Python: finite images, determinism, and clear errors for bad density input,
sizes over the memory budget and rotated density images."""
import math
import os
import sys
import unittest

import numpy as np

import nimbus
from vtkmodules.vtkCommonCore import vtkCommand
from vtkmodules.util.misc import calldata_type
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.util.vtkConstants import VTK_STRING

SCENE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "Data", "tiny_scene.json")


def render(mode="single", density=None, errors=None, **settings):
    renderer = nimbus.vtkNimbusReferenceRenderer()
    renderer.SetSceneFileName(SCENE)
    if errors is not None:
        @calldata_type(VTK_STRING)
        def on_error(obj, event, message):
            errors.append(message)
        renderer.AddObserver(vtkCommand.ErrorEvent, on_error)
        renderer.GetExecutive().AddObserver(vtkCommand.ErrorEvent, lambda obj, event: None)
    if density is not None:
        renderer.SetInputData(density)
    if mode == "single":
        renderer.SetModeToSingleScattering()
        renderer.SetRelativeTolerance(settings.get("tolerance", 1e-2))
    else:
        renderer.SetModeToPathTracing()
        renderer.SetMinSamplesPerPixel(settings.get("spp", 4))
        renderer.SetMaxSamplesPerPixel(settings.get("spp", 4))
        renderer.SetSeed(settings.get("seed", 1))
    renderer.Update()
    return renderer.GetOutput()


def radiance(output):
    width, height, _ = output.GetDimensions()
    return vtk_to_numpy(output.GetPointData().GetArray("radiance")).reshape(height, width, 3)


def scene_density():
    source = nimbus.vtkNimbusSceneDensitySource()
    source.SetSceneFileName(SCENE)
    source.Update()
    return source.GetOutput()


class ReferenceRendererTest(unittest.TestCase):
    def test_single_scattering_image(self):
        output = render("single")
        image = radiance(output)
        self.assertEqual(image.shape, (18, 24, 3))
        self.assertTrue(np.isfinite(image).all())
        self.assertGreaterEqual(image.min(), 0.0)
        self.assertGreater(image.max(), 0.0)
        error = output.GetFieldData().GetArray("EstimatedRelativeError").GetValue(0)
        self.assertLess(error, 1e-2)

    def test_path_tracing_is_deterministic_per_seed(self):
        a = radiance(render("path", seed=3))
        b = radiance(render("path", seed=3))
        c = radiance(render("path", seed=4))
        self.assertTrue(np.isfinite(a).all())
        self.assertEqual(a.tobytes(), b.tobytes())
        self.assertNotEqual(a.tobytes(), c.tobytes())
        self.assertIsNotNone(render("path").GetPointData().GetArray("standard_error"))

    def test_density_input_replaces_the_scenes(self):
        density = scene_density()
        self.assertEqual(radiance(render("single", density=density)).tobytes(),
                         radiance(render("single")).tobytes())

    def test_bad_density_values_are_errors_naming_the_array(self):
        for bad in (math.nan, math.inf, -1.0):
            density = scene_density()
            values = density.GetPointData().GetScalars()
            values.SetValue(17, bad)
            errors = []
            output = render("single", density=density, errors=errors)
            self.assertGreaterEqual(len(errors), 1, bad)
            self.assertIn("density array 'density'", errors[0])
            self.assertIn("point 17", errors[0])
            self.assertIsNone(output.GetPointData().GetArray("radiance"), bad)

    def test_memory_budget_is_a_property_and_refuses_with_a_message(self):
        renderer = nimbus.vtkNimbusReferenceRenderer()
        self.assertGreater(renderer.GetMemoryBudgetMiB(), 0.0)
        renderer.SetSceneFileName(SCENE)
        renderer.SetMemoryBudgetMiB(0.001)  # 1 KiB: less than the 24x18 image
        errors = []

        @calldata_type(VTK_STRING)
        def on_error(obj, event, message):
            errors.append(message)
        renderer.AddObserver(vtkCommand.ErrorEvent, on_error)
        renderer.GetExecutive().AddObserver(vtkCommand.ErrorEvent, lambda obj, event: None)
        renderer.Update()
        self.assertEqual(len(errors), 1, errors)
        self.assertIn("the rendered image (24x18 pixels)", errors[0])
        self.assertIn("more than the memory budget", errors[0])
        self.assertIsNone(renderer.GetOutput().GetPointData().GetArray("radiance"))

    def test_rotated_density_is_refused(self):
        density = scene_density()
        density.SetDirectionMatrix(0, -1, 0, 1, 0, 0, 0, 0, 1)
        errors = []
        output = render("single", density=density, errors=errors)
        self.assertGreaterEqual(len(errors), 1)
        self.assertIn("direction matrix that is not the identity", errors[0])
        self.assertIsNone(output.GetPointData().GetArray("radiance"))

    def test_missing_scene_is_an_error(self):
        renderer = nimbus.vtkNimbusReferenceRenderer()
        renderer.SetSceneFileName("/nonexistent/scene.json")
        errors = []
        renderer.AddObserver(vtkCommand.ErrorEvent, lambda obj, event: errors.append(event))
        renderer.Update()
        self.assertGreaterEqual(len(errors), 1)


if __name__ == "__main__":
    result = unittest.main(exit=False, verbosity=2).result
    sys.exit(0 if result.wasSuccessful() else 1)
