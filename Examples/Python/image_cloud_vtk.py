"""Clouds from a 2-D image: reads a grayscale picture (default: the synthetic sample
Data/SatelliteClouds.png), builds the 3-D density with vtkNimbusImageCloudFilter, and renders
it obliquely through VTK's vtkGPUVolumeRayCastMapper next to the image.

    export PYTHONPATH=$PWD/build/lib/python3.11/site-packages
    Testing/with-display.sh /usr/bin/python3 Examples/Python/image_cloud_vtk.py \
        Data/SatelliteClouds.png docs/image-cloud.png
"""
import sys

import nimbus
from vtkmodules.vtkCommonDataModel import vtkImageData, vtkPiecewiseFunction
from vtkmodules.vtkFiltersCore import vtkImageAppend
from vtkmodules.vtkImagingCore import vtkImageMapToColors, vtkImageResize
from vtkmodules.vtkCommonCore import vtkLookupTable
from vtkmodules.vtkIOImage import vtkPNGReader, vtkPNGWriter
from vtkmodules.vtkRenderingCore import (vtkColorTransferFunction, vtkRenderer,
                                         vtkRenderWindow, vtkVolume, vtkVolumeProperty,
                                         vtkWindowToImageFilter)
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401
import vtkmodules.vtkRenderingVolumeOpenGL2  # noqa: F401
from vtkmodules.vtkRenderingVolume import vtkGPUVolumeRayCastMapper

# NIMBUS_OFFSCREEN=egl: render on an EGL pbuffer, no X server (docs/offscreen.md).
nimbus.offscreen_if_requested()

SIZE = 300


def main():
    image_file = sys.argv[1] if len(sys.argv) > 1 else "Data/SatelliteClouds.png"
    output = sys.argv[2] if len(sys.argv) > 2 else "image-cloud.png"
    reader = vtkPNGReader()
    reader.SetFileName(image_file)
    cloud = nimbus.vtkNimbusImageCloudFilter()
    cloud.SetInputConnection(reader.GetOutputPort())
    cloud.SetMappingTypeToTwoStream()  # bright pixels become optically thick
    cloud.SetMaximumOpticalDepth(40)
    cloud.SetClearIntensity(0.25)  # the sample's sea and land reach 0.2
    cloud.SetPixelSize(100)  # metres
    cloud.Update()
    sigma = cloud.GetExtinctionCoefficient()  # 1/m per unit density

    # Opacity of one 50 m sample: 1 - exp(-sigma * density * 50 m).
    opacity = vtkPiecewiseFunction()
    for density in (0.0, 0.05, 0.2, 0.5, 1.0, 2.0):
        opacity.AddPoint(density, 1.0 - 2.718281828 ** (-sigma * density * 50.0))
    color = vtkColorTransferFunction()
    color.AddRGBPoint(0.0, 1.0, 1.0, 1.0)
    color.AddRGBPoint(2.0, 1.0, 1.0, 1.0)
    prop = vtkVolumeProperty()
    prop.SetScalarOpacity(opacity)
    prop.SetColor(color)
    prop.SetScalarOpacityUnitDistance(50.0)
    prop.ShadeOn()
    prop.SetAmbient(0.4)
    prop.SetDiffuse(0.75)
    prop.SetSpecular(0.0)
    prop.SetInterpolationTypeToLinear()
    mapper = vtkGPUVolumeRayCastMapper()
    mapper.SetInputConnection(cloud.GetOutputPort(0))
    volume = vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)
    renderer = vtkRenderer()
    renderer.AddVolume(volume)
    renderer.SetBackground(0.08, 0.12, 0.2)  # the sea seen from above
    camera = renderer.GetActiveCamera()
    camera.SetFocalPoint(0, 0, 1500)
    camera.SetPosition(0, -9000, 16000)
    camera.SetViewUp(0, 1, 0)
    camera.SetViewAngle(45)
    renderer.ResetCameraClippingRange()
    window = vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(SIZE, SIZE)
    window.AddRenderer(renderer)
    window.Render()
    grab = vtkWindowToImageFilter()
    grab.SetInput(window)
    grab.ReadFrontBufferOff()
    grab.Update()
    rendered = vtkImageData()
    rendered.DeepCopy(grab.GetOutput())

    # The input picture, grey -> RGB, resized to the render's size.
    grey = vtkLookupTable()
    grey.SetRange(0, 255)
    grey.SetSaturationRange(0, 0)
    grey.SetValueRange(0, 1)
    grey.Build()
    to_rgb = vtkImageMapToColors()
    to_rgb.SetInputConnection(reader.GetOutputPort())
    to_rgb.SetLookupTable(grey)
    to_rgb.SetOutputFormatToRGB()
    resize = vtkImageResize()
    resize.SetInputConnection(to_rgb.GetOutputPort())
    resize.SetOutputDimensions(SIZE, SIZE, 1)
    resize.Update()
    picture = vtkImageData()
    picture.DeepCopy(resize.GetOutput())
    picture.SetOrigin(0, 0, 0)
    picture.SetSpacing(1, 1, 1)
    picture.SetExtent(0, SIZE - 1, 0, SIZE - 1, 0, 0)

    both = vtkImageAppend()
    both.SetAppendAxis(0)
    both.AddInputData(picture)
    both.AddInputData(rendered)
    writer = vtkPNGWriter()
    writer.SetFileName(output)
    writer.SetInputConnection(both.GetOutputPort())
    writer.Write()
    print(output)
    return 0


if __name__ == "__main__":
    sys.exit(main())
