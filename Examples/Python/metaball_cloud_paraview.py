"""pvpython example: load the Nimbus plugin, make a cloud, volume-render it.

    pvpython Examples/Python/metaball_cloud_paraview.py \
        build/lib/paraview-5.11/plugins/Nimbus/Nimbus.so [screenshot.png]

(Without a display, wrap it: Testing/with-display.sh pvpython ...)
"""
import sys

from paraview.simple import (ColorBy, GetActiveViewOrCreate, GetColorTransferFunction,
                             GetOpacityTransferFunction, LoadPlugin, ResetCamera,
                             SaveScreenshot, Show)

plugin = sys.argv[1] if len(sys.argv) > 1 else "build/lib/paraview-5.11/plugins/Nimbus/Nimbus.so"
screenshot = sys.argv[2] if len(sys.argv) > 2 else "metaball_cloud.png"

LoadPlugin(plugin, ns=globals())
cloud = NimbusMetaballCloud(Dimensions=[64, 64, 44], Seed=7)  # noqa: F821 (from the plugin)

view = GetActiveViewOrCreate("RenderView")
display = Show(cloud, view)
display.SetRepresentationType("Volume")
ColorBy(display, ("POINTS", "density"))
display.Shade = 1
GetColorTransferFunction("density").RGBPoints = [0.0, 1, 1, 1, 2.0, 1, 1, 1]
GetOpacityTransferFunction("density").Points = [0.0, 0.0, 0.5, 0.0, 1.0, 0.6, 0.5, 0.0]
view.CameraPosition = [0, -6000, 1500]
view.CameraFocalPoint = [0, 0, 1600]
view.CameraViewUp = [0, 0, 1]
SaveScreenshot(screenshot, view, ImageResolution=[640, 400])
print(screenshot)
