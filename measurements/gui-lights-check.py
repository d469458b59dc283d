"""A lamp in fog built in the real ParaView GUI, as a user would, photographed: the Cloud
display's Lights group, View > Light Inspector, a light added there and made a positional
spotlight, its beam in the fog, and a light-map file that cannot be read.

    DISPLAY=:63 /usr/bin/python3 measurements/gui-lights-check.py \
        --plugin-dir build/lib/paraview-5.11/plugins/Nimbus --output-dir DIR

Without a DISPLAY the script starts its own Xvfb (1600x1040, as measurements/gui-drag-check.py
uses) and stops it at the end. A fresh `paraview` (fresh settings folder, --dr) runs a
start-up script that builds the scene of Examples/Python/lamp_in_fog_paraview.py without
its light: a Wavelet grid, a Calculator that makes its "density" 0 everywhere shown as
Cloud (the air only), and a post, a lamp pole, an arm and a lamp head (Box and Cone
sources). The rest is done with the mouse and the keyboard (xdotool) at the places the
widgets have in a 1588x1035 main window at 0,0 (found from screenshots of this ParaView
5.11): the Properties panel's search box finds Sun Elevation (-10: night), Exposure (800)
and Fog Visibility (80 m) and the values are typed in; View > Light Inspector; Add Light;
Type Positional; Light Position 0 0 4.5, Focal Point 7 0 0.5, Cone Angle 35; Show Light
off; the Properties panel scrolled to the Lights group; a light-map file name that does
not exist typed into Light Map File; the Light Inspector closed (View > Light Inspector).

DIR/gui-NN-<step>.png: the whole screen after each step (ImageMagick `import -window
root`); DIR/lights-group.png and DIR/light-inspector.png: the Lights group and the Light
Inspector cut out; DIR/paraview.log: ParaView's output. Look at every picture: the script
checks only that the render view's median is under 5 of 255 before the light (the air
dark at night) and that at least 8 % of its pixels are above 40 after it (the beam).
"""
import argparse
import os
import subprocess
import sys
import time

import numpy as np
from PIL import Image

from gui_session import main_window, start_paraview, stop_paraview, view_rectangle, xdo

WINDOW = (1588, 1035)

SETUP = r'''
import math
from paraview.simple import *
view = GetActiveViewOrCreate("RenderView")
view.OrientationAxesVisibility = 0
view.UseColorPaletteForBackground = 0
view.Background = [0.0, 0.0, 0.0]
view.UseLight = 0  # no light kit: at night the lamp alone lights the scene
grid = Wavelet(registrationName="Air grid", WholeExtent=[-8, 8, -6, 12, 0, 8])
air = Calculator(registrationName="Air (density 0)", Input=grid, ResultArrayName="density",
                 Function="0")
display = Show(air, view)
display.SetRepresentationType("Cloud")
ColorBy(display, ("POINTS", "density"))
Hide(grid, view)
lamp = [0.0, 0.0, 4.5]
aim = [7.0, 0.0, 0.5]
axis = [a - p for a, p in zip(aim, lamp)]
length = math.sqrt(sum(c * c for c in axis))
axis = [c / length for c in axis]
parts = [
    ("Lamp head", Cone(Radius=0.3, Height=0.5, Resolution=32, Direction=[-c for c in axis],
                       Center=[p - 0.3 * c for p, c in zip(lamp, axis)])),
    ("Lamp pole", Box(XLength=0.18, YLength=0.18, ZLength=4.6, Center=[-0.7, 0.0, 2.3])),
    ("Lamp arm", Box(XLength=0.8, YLength=0.08, ZLength=0.08, Center=[-0.35, 0.0, 4.65])),
    ("Post", Box(XLength=0.5, YLength=0.5, ZLength=3.6, Center=[1.4, 0.0, 1.8])),
]
for name, source in parts:
    RenameSource(name, source)
    part = Show(source, view)
    part.DiffuseColor = [0.35, 0.33, 0.3]
    part.Ambient = 0.5
    part.AmbientColor = [0.1, 0.1, 0.1]
SetActiveSource(air)
Render(view)
view.CameraPosition = [-5.0, -12.0, 1.7]
view.CameraFocalPoint = [2.5, 0.0, 2.3]
view.CameraViewUp = [0.0, 0.0, 1.0]
view.CameraViewAngle = 42.0
Render(view)
'''


class Screen:
    def __init__(self, output):
        self.output = output
        self.count = 0

    def shot(self, step):
        self.count += 1
        path = os.path.join(self.output, "gui-%02d-%s.png" % (self.count, step))
        subprocess.run(["import", "-window", "root", path], check=True)
        print(path, flush=True)
        return path


def click(x, y, wait=0.5):
    xdo("mousemove", x, y)
    time.sleep(0.2)
    xdo("click", 1)
    time.sleep(wait)


def drag(x0, y0, x1, y1):
    xdo("mousemove", x0, y0)
    time.sleep(0.3)
    xdo("mousedown", 1)
    for k in range(1, 11):
        time.sleep(0.05)
        xdo("mousemove", x0 + (x1 - x0) * k // 10, y0 + (y1 - y0) * k // 10)
    time.sleep(0.2)
    xdo("mouseup", 1)
    time.sleep(2.0)


def type_into(x, y, text, wait=3.0):
    """Clicks the field at x, y, replaces its text and presses Return."""
    click(x, y, 0.3)
    xdo("key", "ctrl+a")
    xdo("type", "--delay", 40, "--", text)
    xdo("key", "Return")
    time.sleep(wait)


def search(text):
    """Types `text` into the Properties panel's search box."""
    click(265, 435, 0.3)
    xdo("key", "ctrl+a")
    xdo("key", "BackSpace")
    if text:
        xdo("type", "--delay", 40, "--", text)
    time.sleep(1.5)


def view_pixels(png):
    x, y, w, h = view_rectangle(png)
    return np.asarray(Image.open(png).convert("L"))[y:y + h, x:x + w].astype(float)


def crop(png, box, out):
    x, y, w, h = box
    subprocess.run(["convert", png, "-crop", "%dx%d+%d+%d" % (w, h, x, y), "+repage", out],
                   check=True)


def run(args):
    output = os.path.abspath(args.output_dir)
    paraview = start_paraview(args.paraview, SETUP, output, "home", args.plugin_dir,
                              args.python_path, os.path.join(output, "paraview.log"))
    screen = Screen(output)
    failures = []
    try:
        window = main_window()
        time.sleep(10.0)
        xdo("windowmove", window, 0, 0)
        xdo("windowsize", window, *WINDOW)
        time.sleep(6.0)
        first = screen.shot("start")
        # A wider Properties panel (the splitter left of the view) and a taller one; the
        # places below need them, so the script stops if they did not take.
        for _ in range(3):
            left = view_rectangle(screen.shot("panels"))[0]
            if left >= 560:
                break
            drag(left - 8, 600, 570, 600)
        if left < 560:
            raise SystemExit("the Properties panel did not widen (the view starts at x %d)" % left)
        drag(280, 447, 280, 330)
        screen.shot("panels")

        # Night, the exposure of a lamp, fog: typed into the fields the search finds.
        search("Sun Elevation")
        type_into(437, 569, "-10")
        search("pixel value = Exposure")  # words of Exposure's own help: one field
        type_into(430, 566, "800")
        search("Fog Visibility")
        screen.shot("fog-visibility-found")
        type_into(437, 577, "80")
        search("")  # the whole panel again
        dark = screen.shot("night-fog-no-light")
        # The surfaces are lit by VTK's automatic headlight while the view has no light;
        # the air (most of the view) is dark.
        dark_level = float(np.median(view_pixels(dark)))
        print("render view before the light: median %.1f of 255" % dark_level)
        if dark_level > 5.0:
            failures.append("the night view is not dark before the light (median %.1f)"
                            % dark_level)

        # View > Light Inspector, Add Light.
        click(100, 10, 1.5)
        screen.shot("view-menu")
        click(158, 211, 2.5)
        click(1496, 218, 4.0)
        screen.shot("light-added")
        # A wider Light Inspector (its left edge, right of the view), then Type: Positional.
        for _ in range(3):
            x, _, w, _ = view_rectangle(screen.shot("light-inspector-width"))
            if x + w <= 1205:
                break
            drag(x + w + 6, 600, 1190, 600)
        if x + w > 1205:
            raise SystemExit("the Light Inspector did not widen (the view ends at x %d)" % (x + w))
        click(1440, 414, 1.5)
        screen.shot("type-menu")
        click(1343, 440, 3.0)
        # Light Position z, Focal Point x and z, Cone Angle; each change renders the view
        # (a few seconds here), after which the inspector's fields are filled again from
        # the light: the next field is typed into only then.
        type_into(1534, 443, "4.5", 5.0)
        type_into(1348, 472, "7", 5.0)
        type_into(1534, 472, "0.5", 5.0)
        type_into(1508, 501, "35", 6.0)
        lit = screen.shot("positional-spotlight")
        crop(lit, (1200, 130, 400, 400), os.path.join(output, "light-inspector.png"))
        click(1219, 386, 6.0)  # Show Light off: the light's outline no longer drawn
        lit = screen.shot("show-light-off")
        pixels = view_pixels(lit)
        lit_share = float((pixels > 40.0).mean())
        print("render view with the light: %.1f %% of its pixels above 40 of 255 (median %.1f)"
              % (100.0 * lit_share, float(np.median(pixels))))
        if lit_share < 0.08:
            failures.append("no beam in the view (%.1f %% of the pixels above 40)"
                            % (100.0 * lit_share))

        # The Lights group: the Properties panel scrolled to it.
        xdo("mousemove", 230, 750)
        for _ in range(60):
            xdo("click", 5)
        for _ in range(6):
            xdo("click", 4)
        time.sleep(1.5)
        group = screen.shot("lights-group")
        crop(group, (0, 430, 560, 380), os.path.join(output, "lights-group.png"))

        # A light-map file that does not exist, typed in: one error, the beam still there.
        type_into(325, 703, os.path.join(output, "missing-gobo.png"), 6.0)
        screen.shot("missing-light-map")
        # View > Light Inspector again closes it: the whole view with its beam.
        click(100, 10, 1.5)
        click(158, 211, 6.0)
        screen.shot("light-inspector-closed")
    finally:
        stop_paraview(paraview)
    return failures


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--plugin-dir", required=True)
    parser.add_argument("--output-dir", required=True)
    parser.add_argument("--paraview", default="paraview")
    parser.add_argument("--python-path", default=os.path.join(
        os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
        "build", "lib", "python3.11", "site-packages"))
    args = parser.parse_args()
    os.makedirs(args.output_dir, exist_ok=True)
    xvfb = None
    if not os.environ.get("DISPLAY"):
        display = ":%d" % (1000 + os.getpid() % 30000)
        xvfb = subprocess.Popen(["Xvfb", display, "-screen", "0", "1600x1040x24", "-noreset"],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        os.environ["DISPLAY"] = display
        time.sleep(2.0)
    try:
        failures = run(args)
    finally:
        if xvfb is not None:
            xvfb.terminate()
            xvfb.wait(10)
    for failure in failures:
        print("FAILED:", failure)
    print("gui lights check", "FAILED" if failures else "passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
