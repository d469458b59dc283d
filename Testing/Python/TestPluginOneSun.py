"""pvpython test of "one sun per view" and of the panels' words (docs/paraview.md).

    pvpython TestPluginOneSun.py --plugin Nimbus.so --output-dir DIR

(with `import nimbus` on PYTHONPATH the mapper's sun is read back too)

Checks, through paraview.simple:
  1. one set of defaults: the Nimbus Sky and the Cloud representation start with the
     same sun elevation and azimuth, ground albedo and exposure;
  2. both panels list the sun's elevation before its azimuth;
  3. the words: no property label, tooltip or enumeration entry of the plugin's proxies
     cites a paper's equation, section or symbol ("000 Eq. 1", "k_multi", "Cloud g",
     "a of theta_e", ...); the cloud's sun and air fields that the sky replaces say so
     in their tooltips and carry the NimbusViewSkyDecorator; every source's and
     filter's property keeps its pvpython name (a label spelling its XML name);
  4. the cloud follows the view's sky: with a Nimbus Sky shown, the mapper renders with
     the sky's sun (not the cloud's own, different one), also with the cloud's balls
     shown beside it (each display carries a hidden sky representation); hidden, with
     its own again;
  5. automatic exposure (Sky Background): looking toward a sun 20 degrees high it keeps
     most of the frame below white (off: a large part is blown out); looking away
     from the sun it changes nothing (same pixels on and off); the tiles of a
     screenshot larger than the view share one exposure.
"""
import argparse
import math
import os
import re
import sys

from paraview import servermanager
from paraview.simple import (ColorBy, CreateRenderView, Delete, Hide, LoadPlugin, OutputPort,
                             Render, SaveScreenshot, Show)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from image_compare import read_png  # noqa: E402

# A paper's equation, section or symbol in GUI text (labels belong to users; the
# mapping to the papers is docs/paraview-properties.md).
PAPER_WORDS = re.compile(r"\b00\d\b|\bEq\.|§|\bsection \d|k_multi|theta_|\bCloud g\b|"
                         r"\bRatio a\b|Basic-shape")
# The Cloud representation's fields that a visible Nimbus Sky replaces.
SKY_SET = ["SunElevationDegrees", "SunAzimuthDegrees", "SunIlluminance", "SunTemperatureKelvin",
           "Exposure", "EncodeSrgb", "Turbidity", "MieScatteringPerMetre", "MieG",
           "RayleighScatteringPerMetre", "SceneAltitudeMetres", "GroundHeight", "GroundAlbedo",
           "MetresPerUnit"]
SHARED_DEFAULTS = ["SunElevationDegrees", "SunAzimuthDegrees", "GroundAlbedo", "Exposure"]




def value(proxy, name):
    return float(proxy.SMProxy.GetProperty(name).GetElement(0))


def group_order(smproxy, label):
    """Property names of the panel group `label`, in panel order."""
    for i in range(smproxy.GetNumberOfPropertyGroups()):
        group = smproxy.GetPropertyGroup(i)
        if group.GetXMLLabel() == label:
            return [smproxy.GetPropertyName(group.GetProperty(j))
                    for j in range(group.GetNumberOfProperties())]
    return []


def hints_text(prop):
    hints = prop.GetHints()
    return str(hints) if hints is not None else ""


def decorator_types(prop):
    """The decorator types named in a property's hints (nested ones included)."""
    types = []
    hints = prop.GetHints()

    def walk(element):
        if element is None:
            return
        if element.GetName() == "PropertyWidgetDecorator" and element.GetAttribute("type"):
            types.append(element.GetAttribute("type"))
        for k in range(element.GetNumberOfNestedElements()):
            walk(element.GetNestedElement(k))
    walk(hints)
    return types


def check_words(failures):
    """3. Labels, tooltips and entries of every Nimbus proxy."""
    pxm = servermanager.ProxyManager().SMProxyManager
    definitions = [("sources", "NimbusMetaballCloud"), ("sources", "NimbusCloudAutomaton"),
                   ("sources", "NimbusSkyDome"), ("filters", "NimbusCloudAutomatonWithMaps"),
                   ("filters", "NimbusImageCloud"), ("sources", "NimbusLightning"),
                   ("filters", "NimbusLightningIllumination"), ("sources", "NimbusSmoke"),
                   ("representations", "CloudRepresentation"),
                   ("representations", "NimbusSkyBackgroundRepresentation")]
    checked = 0
    for group, name in definitions:
        proxy = pxm.NewProxy(group, name)
        if proxy is None:
            failures.append("no proxy %s/%s" % (group, name))
            continue
        iterator = proxy.NewPropertyIterator()
        iterator.Begin()
        while not iterator.IsAtEnd():
            prop, key = iterator.GetProperty(), iterator.GetKey()
            label = prop.GetXMLLabel() or ""
            documentation = prop.GetDocumentation()
            tooltip = documentation.GetDescription() if documentation else ""
            entries = []
            domain = prop.GetDomain("enum")
            if domain is not None and domain.IsA("vtkSMEnumerationDomain"):
                entries = [domain.GetEntryText(k) for k in range(domain.GetNumberOfEntries())]
            for text, what in [(label, "label"), (tooltip, "tooltip")] + \
                    [(entry, "entry") for entry in entries]:
                if PAPER_WORDS.search(text or ""):
                    failures.append("%s.%s %s cites a paper: %r" % (name, key, what, text))
            if group != "representations" and not prop.GetInformationOnly():
                # pvpython names a source's properties after their labels.
                python_name = re.sub(r"[^A-Za-z0-9_]", "", label)
                if python_name != key:
                    failures.append("%s.%s: label %r would rename it to %s in pvpython"
                                    % (name, key, label, python_name))
            if name == "CloudRepresentation" and key in SKY_SET:
                if "NimbusViewSkyDecorator" not in decorator_types(prop):
                    failures.append("CloudRepresentation.%s is not greyed out under a sky" % key)
                if "Nimbus Sky" not in tooltip:
                    failures.append("CloudRepresentation.%s's tooltip does not say the sky "
                                    "sets it" % key)
            checked += 1
            iterator.Next()
        proxy.UnRegister(None)
    print("words: %d properties checked" % checked)


def cloud_mapper(view):
    """The visible vtkNimbusCloudVolumeMapper (None without `import nimbus`)."""
    try:
        import nimbus
    except ImportError:
        return None
    return nimbus.find_cloud_mapper(view.SMProxy.GetRenderer())


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--plugin", required=True)
    parser.add_argument("--output-dir", required=True)
    args = parser.parse_args()
    os.makedirs(args.output_dir, exist_ok=True)
    LoadPlugin(args.plugin, ns=globals())
    failures = []

    view = CreateRenderView()
    view.ViewSize = [160, 100]
    view.OrientationAxesVisibility = 0
    view.EnableRenderOnInteraction = 0
    sky = NimbusSky()  # noqa: F821 (plugin)
    cloud = NimbusMetaballCloud(Dimensions=[24, 24, 16], Seed=3, NumberOfLevels=1)  # noqa: F821
    cloud_display = Show(cloud, view)
    cloud_display.SetRepresentationType("Cloud")
    ColorBy(cloud_display, ("POINTS", "density"))

    # 1. One set of defaults.
    for name in SHARED_DEFAULTS:
        print("default %s: sky %g, cloud %g" % (name, value(sky, name), value(cloud_display, name)))
        if value(sky, name) != value(cloud_display, name):
            failures.append("default %s: sky %g, cloud %g"
                            % (name, value(sky, name), value(cloud_display, name)))

    # 2. Elevation before azimuth in both panels.
    for proxy, label in ((cloud_display.SMProxy, "Cloud Lighting"),
                         (sky.SMProxy, "Sun and atmosphere")):
        order = group_order(proxy, label)
        print("%s: %s" % (label, order))
        if "SunElevationDegrees" not in order or "SunAzimuthDegrees" not in order or \
                order.index("SunElevationDegrees") > order.index("SunAzimuthDegrees"):
            failures.append("%s does not list elevation before azimuth: %s" % (label, order))

    # 3. Words.
    check_words(failures)

    # 4. The cloud follows the view's sky, and its own sun without one.
    cloud_display.NumberOfSlices = 16
    cloud_display.MultipleScatteringMethod = 0
    cloud_display.SunElevationDegrees = 50.0
    sky.SunElevationDegrees = 25.0
    sky_display = Show(sky, view)
    view.CameraPosition = [0.0, -6000.0, 1500.0]
    view.CameraFocalPoint = [0.0, 0.0, 1600.0]
    view.CameraViewUp = [0.0, 0.0, 1.0]
    Render(view)
    mapper = cloud_mapper(view)
    if mapper is not None:
        print("sky shown: the mapper's sun %.1f deg (sky 25, cloud 50), over the sky %d"
              % (mapper.GetLastSunElevationDegrees(), mapper.GetLastRenderUsedSceneSky()))
        if mapper.GetLastSunElevationDegrees() != 25.0 or not mapper.GetLastRenderUsedSceneSky():
            failures.append("with the sky shown the cloud did not take the sky's sun")
        # Every display of a data set carries a hidden Sky Background representation of
        # its own: the cloud's balls (port 1) shown beside it must not hide the sky.
        Show(OutputPort(cloud, 1), view)
        Render(view)
        print("balls shown too: the mapper's sun %.1f deg, over the sky %d"
              % (mapper.GetLastSunElevationDegrees(), mapper.GetLastRenderUsedSceneSky()))
        if mapper.GetLastSunElevationDegrees() != 25.0 or not mapper.GetLastRenderUsedSceneSky():
            failures.append("with the cloud's balls shown too the cloud lost the sky's sun")
        Hide(OutputPort(cloud, 1), view)
        Hide(sky, view)
        Render(view)
        print("sky hidden: the mapper's sun %.1f deg" % mapper.GetLastSunElevationDegrees())
        if mapper.GetLastSunElevationDegrees() != 50.0 or mapper.GetLastRenderUsedSceneSky():
            failures.append("with the sky hidden the cloud did not take its own sun")
        sky_display = Show(sky, view)
    else:
        print("no `import nimbus`: the mapper's sun is not read back")
    Hide(cloud, view)

    # 5. Automatic exposure: toward a sun 20 degrees high, and away from it.
    sky.SunElevationDegrees = 20.0
    sky.SunAzimuthDegrees = 135.0
    azimuth = math.radians(135.0)

    def look(sign, auto, name):
        sky_display.AutomaticExposure = auto
        view.CameraPosition = [-sign * 7000.0 * math.sin(azimuth),
                               -sign * 7000.0 * math.cos(azimuth), 1200.0]
        view.CameraFocalPoint = [0.0, 0.0, 1800.0]
        view.CameraViewAngle = 40.0
        Render(view)
        path = os.path.join(args.output_dir, "TestPluginOneSun-%s.png" % name)
        SaveScreenshot(path, view, ImageResolution=[320, 200])
        return read_png(path)

    toward_off = look(1.0, 0, "toward-sun-fixed")
    toward_on = look(1.0, 1, "toward-sun-automatic")
    away_off = look(-1.0, 0, "away-fixed")
    away_on = look(-1.0, 1, "away-automatic")

    def blown(pixels):
        return float((pixels.max(axis=2) >= 254.0).mean())
    print("toward the sun: %.2f of the frame blown out at the fixed exposure, %.2f automatic"
          % (blown(toward_off), blown(toward_on)))
    print("away from the sun: max |automatic - fixed| = %.1f" % abs(away_on - away_off).max())
    if not blown(toward_off) > 0.25:
        failures.append("the fixed exposure toward the sun is not blown out (%.2f): the "
                        "check needs another view" % blown(toward_off))
    if not blown(toward_on) < 0.1:
        failures.append("automatic exposure left %.2f of the frame blown out" % blown(toward_on))
    # The 320 x 200 screenshot of a 160 x 100 view is rendered in 2 x 2 tiles: they
    # must share one exposure (no step between rows 99 and 100).
    seam = abs(toward_on[100] - toward_on[99]).max()
    print("automatic exposure: largest step between the tiles' rows %.1f" % seam)
    if seam > 8.0:
        failures.append("the screenshot's tiles got different exposures (step %.1f)" % seam)
    if abs(away_on - away_off).max() > 1.0:
        failures.append("automatic exposure changed a view away from the sun")

    Delete(sky_display)
    Delete(cloud_display)
    for failure in failures:
        print("FAILED:", failure)
    print("one-sun test", "FAILED" if failures else "passed")
    Delete(view)
    del view
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
