"""`import nimbus` from Debian's /usr/bin/python3: the wrapped classes work and
the source's data are right (data, not images)."""
import sys
import unittest

import nimbus
from vtkmodules.vtkCommonCore import vtkCommand
from vtkmodules.util.numpy_support import vtk_to_numpy


class MetaballCloudSourceTest(unittest.TestCase):
    def make(self, seed=5):
        source = nimbus.vtkNimbusMetaballCloudSource()
        source.SetDimensions(40, 40, 28)
        source.SetSeed(seed)
        source.Update()
        return source

    def test_density_array(self):
        source = self.make()
        image = source.GetOutput()
        self.assertEqual(image.GetDimensions(), (40, 40, 28))
        density = vtk_to_numpy(image.GetPointData().GetArray("density"))
        self.assertEqual(density.dtype.name, "float32")
        self.assertGreaterEqual(density.min(), 0.0)
        self.assertGreater(density.max(), 0.5)

    def test_deterministic_per_seed(self):
        a = vtk_to_numpy(self.make(5).GetOutput().GetPointData().GetArray("density"))
        b = vtk_to_numpy(self.make(5).GetOutput().GetPointData().GetArray("density"))
        c = vtk_to_numpy(self.make(6).GetOutput().GetPointData().GetArray("density"))
        self.assertEqual(a.tobytes(), b.tobytes())
        self.assertNotEqual(a.tobytes(), c.tobytes())

    def test_metaballs_port(self):
        balls = self.make().GetOutputDataObject(1)
        self.assertGreater(balls.GetNumberOfPoints(), 10)
        radius = vtk_to_numpy(balls.GetPointData().GetArray("radius"))
        self.assertTrue((radius > 0).all())

    def test_bad_parameters_report_an_error(self):
        source = nimbus.vtkNimbusMetaballCloudSource()
        messages = []
        source.AddObserver(vtkCommand.ErrorEvent, lambda obj, event: messages.append(event))
        source.SetNumberOfBaseBalls(0)
        source.Update()
        self.assertEqual(len(messages), 1)
        self.assertEqual(source.GetOutput().GetNumberOfPoints(), 0)


class SunlightTest(unittest.TestCase):
    def test_sun_reddens_and_dims_toward_the_horizon(self):
        sun = nimbus.vtkNimbusSunlight()
        previous_luminance = 2.0
        previous_blue_over_red = 2.0
        for elevation in (90, 45, 20, 10, 5, 2):
            sun.SetSunElevationDegrees(elevation)
            rgb = [0.0, 0.0, 0.0]
            sun.GetColor(rgb)
            luminance = sun.GetRelativeLuminance()
            self.assertLess(luminance, previous_luminance)
            self.assertLess(rgb[2] / rgb[0], previous_blue_over_red)
            previous_luminance = luminance
            previous_blue_over_red = rgb[2] / rgb[0]
        sun.SetSunElevationDegrees(-10)
        rgb = [1.0, 1.0, 1.0]
        sun.GetColor(rgb)
        self.assertEqual(rgb, [0.0, 0.0, 0.0])


if __name__ == "__main__":
    result = unittest.main(exit=False, verbosity=2).result
    sys.exit(0 if result.wasSuccessful() else 1)
