"""What measurements/gui-drag-check.py and measurements/gui-lights-check.py share to drive the real
ParaView GUI under X: xdotool, a fresh `paraview` with a start-up script, its main window,
and the render view found in a screenshot."""
import os
import shutil
import subprocess

import numpy as np
from PIL import Image


def xdo(*arguments):
    subprocess.run(["xdotool"] + [str(a) for a in arguments], check=True)


def start_paraview(paraview, setup, output, home, plugin_dir, python_path, log, **env):
    """Starts `paraview` (--dr: default settings) with a fresh settings folder
    output/`home`, the start-up script text `setup` written to output/setup.py and run
    (--script), the plugins of `plugin_dir`, PYTHONPATH `python_path` and the further
    environment variables `env`; its output goes to the file `log`. Returns the process."""
    home = os.path.join(output, home)
    shutil.rmtree(home, ignore_errors=True)
    os.makedirs(home)
    path = os.path.join(output, "setup.py")
    with open(path, "w") as stream:
        stream.write(setup)
    environment = dict(os.environ, HOME=home, PV_PLUGIN_PATH=os.path.abspath(plugin_dir),
                       PYTHONPATH=python_path, **env)
    return subprocess.Popen([paraview, "--dr", "--script=" + path], env=environment,
                            stdout=open(log, "w"), stderr=subprocess.STDOUT)


def stop_paraview(paraview):
    """Terminates the process; kills it if it has not ended after 10 s."""
    paraview.terminate()
    try:
        paraview.wait(10)
    except subprocess.TimeoutExpired:
        paraview.kill()


def main_window():
    """The largest window whose name starts with ParaView (waits for one, at most 180 s)."""
    out = subprocess.run(["xdotool", "search", "--sync", "--name", "^ParaView"],
                         stdout=subprocess.PIPE, text=True, timeout=180).stdout.split()
    best = None
    for window in out:
        geometry = subprocess.run(["xdotool", "getwindowgeometry", window],
                                  stdout=subprocess.PIPE, text=True).stdout
        w, h = [int(v) for v in geometry.split("Geometry:")[1].split()[0].split("x")]
        if best is None or w * h > best[1]:
            best = (window, w * h)
    return best[0]


def view_rectangle(png, row_pixels=300):
    """(x, y, w, h) of the render view: inside the active view's blue frame (2 px of
    0,0,255, then 1 px of gap). The frame's rows are those with more than `row_pixels`
    blue pixels, its columns those with more than 300."""
    a = np.asarray(Image.open(png).convert("RGB")).astype(int)
    blue = (a[:, :, 0] == 0) & (a[:, :, 1] == 0) & (a[:, :, 2] == 255)
    rows = np.where(blue.sum(axis=1) > row_pixels)[0]
    cols = np.where(blue.sum(axis=0) > 300)[0]
    top, bottom, left, right = rows.min(), rows.max(), cols.min(), cols.max()
    return int(left + 3), int(top + 3), int(right - left - 5), int(bottom - top - 5)
