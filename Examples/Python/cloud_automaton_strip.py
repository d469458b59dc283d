"""Renders frames of the cloud cellular automaton over time into one PNG strip.

    export PYTHONPATH=$PWD/build/lib/python3.11/site-packages
    Testing/with-display.sh /usr/bin/python3 Examples/Python/cloud_automaton_strip.py \
        docs/cloud-automaton-strip.png

Vapour and activation are supplied in four soft ellipsoids (3-D probability fields given to
vtkNimbusCloudAutomatonSource as its input image); the wind carries the clouds that form
there downwind (+x, faster aloft) while they decay. Each frame is the smoothed, time-interpolated "density"
through VTK's vtkGPUVolumeRayCastMapper (a plain look, not Nimbus's physically based
renderers).
"""
import sys

import numpy as np
import nimbus
from vtkmodules.util.numpy_support import numpy_to_vtk
from vtkmodules.vtkCommonDataModel import vtkImageData, vtkPiecewiseFunction
from vtkmodules.vtkIOImage import vtkPNGWriter
from vtkmodules.vtkFiltersCore import vtkImageAppend
from vtkmodules.vtkRenderingCore import (vtkColorTransferFunction, vtkRenderer,
                                         vtkRenderWindow, vtkVolume, vtkVolumeProperty,
                                         vtkWindowToImageFilter)
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401 (the OpenGL factory)
import vtkmodules.vtkRenderingVolumeOpenGL2  # noqa: F401
from vtkmodules.vtkRenderingVolume import vtkGPUVolumeRayCastMapper

# NIMBUS_OFFSCREEN=egl: render on an EGL pbuffer, no X server (docs/offscreen.md).
nimbus.offscreen_if_requested()

NX, NY, NZ = 128, 96, 32
CELL = 100.0  # metres
STEP_SECONDS = 10.0
FRAME_STEPS = [15, 30, 45, 60, 75]


def probability_fields():
    """p_hum and p_act as 3-D fields: four soft ellipsoids (Gaussian in x, y and z), the
    shape Dobashi et al. give their supply probabilities so that distinct clouds form."""
    z, y, x = np.mgrid[0:NZ, 0:NY, 0:NX].astype(float)
    shape = np.zeros((NZ, NY, NX))
    for cx, cy, cz, r, h in ((20, 28, 12, 9, 5), (30, 66, 14, 11, 6), (58, 46, 11, 7, 4),
                             (12, 80, 10, 6, 3)):
        shape = np.maximum(shape, np.exp(-((x - cx) ** 2 + (y - cy) ** 2) / (2 * r * r)
                                         - (z - cz) ** 2 / (2 * h * h)))
    image = vtkImageData()
    image.SetDimensions(NX, NY, NZ)
    for name, scale in (("p_hum", 0.1), ("p_act", 0.005)):
        array = numpy_to_vtk((scale * shape).ravel().astype(np.float32), deep=True)
        array.SetName(name)
        image.GetPointData().AddArray(array)
    return image


def make_source():
    source = nimbus.vtkNimbusCloudAutomatonSource()
    source.SetInputData(probability_fields())
    source.SetDimensions(NX, NY, NZ)
    source.SetBounds(0, (NX - 1) * CELL, 0, (NY - 1) * CELL, 1000, 1000 + (NZ - 1) * CELL)
    source.SetSeed(4)
    source.SetExtinctionProbability(0.03)
    source.SetInitialHumidity(0.0)
    source.SetInitialActivation(0.0)
    source.SetStepDuration(STEP_SECONDS)
    source.SetNumberOfTimeSteps(max(FRAME_STEPS) + 1)
    source.SetWind(4.0, 0.0)  # m/s: 0.4 cells per step at the bottom
    source.SetShear(0.002, 0.0)  # faster aloft
    source.SetPeriodicBoundary(False)
    source.SetNumberOfFormationRegions(0)  # the four ellipsoids above are the regions
    source.SetSpinUpSteps(0)  # frames from the start, 150 s apart
    source.SetSmoothingRadius(3.0)
    return source


def render_frame(density_image, size):
    opacity = vtkPiecewiseFunction()
    opacity.AddPoint(0.0, 0.0)
    opacity.AddPoint(0.08, 0.0)
    opacity.AddPoint(0.3, 0.35)
    opacity.AddPoint(1.0, 0.9)
    color = vtkColorTransferFunction()
    color.AddRGBPoint(0.0, 0.85, 0.88, 0.93)
    color.AddRGBPoint(1.0, 1.0, 1.0, 1.0)
    prop = vtkVolumeProperty()
    prop.SetScalarOpacity(opacity)
    prop.SetColor(color)
    prop.SetScalarOpacityUnitDistance(CELL)
    prop.ShadeOn()
    prop.SetAmbient(0.45)
    prop.SetDiffuse(0.7)
    prop.SetSpecular(0.0)
    prop.SetInterpolationTypeToLinear()
    mapper = vtkGPUVolumeRayCastMapper()
    mapper.SetInputData(density_image)
    volume = vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)

    renderer = vtkRenderer()
    renderer.AddVolume(volume)
    renderer.SetBackground(0.32, 0.5, 0.78)
    renderer.SetBackground2(0.62, 0.76, 0.92)
    renderer.GradientBackgroundOn()
    camera = renderer.GetActiveCamera()
    cx, cy = 0.5 * (NX - 1) * CELL, 0.5 * (NY - 1) * CELL
    camera.SetFocalPoint(cx - 1800, cy, 1800)
    camera.SetPosition(cx - 3300, cy - 12500, 6500)
    camera.SetViewUp(0, 0, 1)
    camera.SetViewAngle(40)
    renderer.ResetCameraClippingRange()
    window = vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(*size)
    window.AddRenderer(renderer)
    window.Render()
    grab = vtkWindowToImageFilter()
    grab.SetInput(window)
    grab.ReadFrontBufferOff()
    grab.Update()
    frame = vtkImageData()
    frame.DeepCopy(grab.GetOutput())
    window.Finalize()
    return frame


def main():
    output = sys.argv[1] if len(sys.argv) > 1 else "cloud-automaton-strip.png"
    source = make_source()
    strip = vtkImageAppend()
    strip.SetAppendAxis(0)
    for step in FRAME_STEPS:
        source.UpdateTimeStep(step * STEP_SECONDS)
        density = vtkImageData()
        density.DeepCopy(source.GetOutput())
        strip.AddInputData(render_frame(density, (320, 220)))
        print("frame at t = %g s (step %d)" % (step * STEP_SECONDS, step))
    strip.Update()
    writer = vtkPNGWriter()
    writer.SetFileName(output)
    writer.SetInputConnection(strip.GetOutputPort())
    writer.Write()
    print(output)
    return 0


if __name__ == "__main__":
    sys.exit(main())
