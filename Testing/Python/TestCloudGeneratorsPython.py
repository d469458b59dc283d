"""`import nimbus` from Debian's /usr/bin/python3: the cloud automaton source at two times
(and back: identical), and the image cloud filter on the shipped sample image.

    PYTHONPATH=build/lib/python3.11/site-packages python3 TestCloudGeneratorsPython.py IMAGE.png
"""
import sys
import unittest

import nimbus
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOImage import vtkPNGReader

IMAGE = sys.argv.pop(1) if len(sys.argv) > 1 else "Data/SatelliteClouds.png"


def density(algorithm, port=0):
    return vtk_to_numpy(
        algorithm.GetOutputDataObject(port).GetPointData().GetArray("density")).copy()


class CloudAutomatonTest(unittest.TestCase):
    def test_two_times_and_back(self):
        source = nimbus.vtkNimbusCloudAutomatonSource()
        source.SetDimensions(32, 32, 10)
        source.SetStepDuration(2.0)
        source.SetNumberOfTimeSteps(40)
        source.SetSeed(11)
        source.UpdateTimeStep(30.0)
        early = density(source)
        source.UpdateTimeStep(61.0)  # between steps 30 and 31
        late = density(source)
        self.assertEqual(early.dtype.name, "float32")
        self.assertEqual(early.size, 32 * 32 * 10)
        self.assertGreater(late.sum(), 0.0)
        self.assertGreater(abs(late - early).max(), 0.0)
        source.UpdateTimeStep(30.0)
        self.assertTrue((density(source) == early).all())
        step = source.GetOutput().GetFieldData().GetArray("AutomatonStep").GetValue(0)
        self.assertEqual(step, 15.0 + source.GetSpinUpSteps())  # time 0 is the spin-up's end


class ImageCloudTest(unittest.TestCase):
    def test_sample_image(self):
        reader = vtkPNGReader()
        reader.SetFileName(IMAGE)
        cloud = nimbus.vtkNimbusImageCloudFilter()
        cloud.SetInputConnection(reader.GetOutputPort())
        cloud.SetMappingTypeToTwoStream()
        cloud.Update()
        rho = density(cloud)
        self.assertGreater(rho.max(), 0.1)
        self.assertEqual(rho.min(), 0.0)
        maps = cloud.GetOpticalDepthMap().GetPointData()
        self.assertIsNotNone(maps.GetArray("optical_depth"))
        self.assertIsNotNone(maps.GetArray("column_optical_depth"))


if __name__ == "__main__":
    unittest.main()
