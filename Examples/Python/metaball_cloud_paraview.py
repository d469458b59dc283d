"""pvpython example: load the Nimbus plugin, make a cloud, render it under the Nimbus sky.

    pvpython Examples/Python/metaball_cloud_paraview.py \
        build/lib/paraview-5.11/plugins/Nimbus/Nimbus.so [screenshot.png]

(Without a display, wrap it: Testing/with-display.sh pvpython ...)

The cloud is shown with the plugin's "Cloud" representation (vtkNimbusCloudVolumeMapper),
not ParaView's "Volume" (a transfer-function rendering of the density). The Nimbus Sky
is the view's background and its one sun: the cloud is lit by the sky's sun.
"""
import sys

from paraview.simple import (ColorBy, GetActiveViewOrCreate, LoadPlugin, SaveScreenshot, Show)

plugin = sys.argv[1] if len(sys.argv) > 1 else "build/lib/paraview-5.11/plugins/Nimbus/Nimbus.so"
screenshot = sys.argv[2] if len(sys.argv) > 2 else "metaball_cloud.png"

LoadPlugin(plugin, ns=globals())
cloud = NimbusMetaballCloud(Dimensions=[64, 64, 44], Seed=7)  # noqa: F821 (from the plugin)
sky = NimbusSky(SunElevationDegrees=30.0)  # noqa: F821 (from the plugin)

view = GetActiveViewOrCreate("RenderView")
view.OrientationAxesVisibility = 0
Show(sky, view)  # "Sky Background": the view's background and sun
display = Show(cloud, view)
display.SetRepresentationType("Cloud")
ColorBy(display, ("POINTS", "density"))  # the density array; no transfer functions
view.CameraPosition = [0, -6000, 1500]
view.CameraFocalPoint = [0, 0, 1600]
view.CameraViewUp = [0, 0, 1]
SaveScreenshot(screenshot, view, ImageResolution=[640, 400])
print(screenshot)
