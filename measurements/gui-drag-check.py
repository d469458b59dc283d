"""Dragging the camera in the real ParaView GUI over a Nimbus cloud, for each Rendering
Method, photographed: how the interactive frames look and how fast they come, and how long
after the mouse is released the still frame is complete.

    Xvfb :63 -screen 0 1600x1040x24 -noreset &
    DISPLAY=:63 /usr/bin/python3 measurements/gui-drag-check.py \
        --plugin-dir build/lib/paraview-5.11/plugins/Nimbus --output-dir DIR \
        [--method march] [--method slices] [--window 1588 1035] [--drag-seconds 10]

For each method, a fresh `paraview` (fresh settings folder, --dr) runs a start-up script
(--script) that makes Sources > Nimbus Metaball Cloud with Dimensions 128 128 128, shows it
as Cloud coloured by density, sets Rendering Method (march: "Ray Marching (fast)", slices:
"Shadow-View Slicing (the paper's)"), puts the camera on the -Y side (the -Y camera button's
reset) and hangs an observer on the view's render window that writes one line per frame:
time, window size, and the cloud mapper's last frame (interactive, image scale, seconds of
the cloud's passes, slices, reused) to DIR/<method>-frames.log. The main window is moved
to 0,0 and resized with xdotool (no window manager under Xvfb: the window's size is
the maximised one); the render view is found in a screenshot by its blue frame.

Then (once the other processes keep under 0.3 cores busy, or after --idle-wait seconds), as
a user: the left button goes down in the middle of the render view, the mouse
moves 4 px every 40 ms (100 px/s) right and left (200 px either side) for --drag-seconds,
the screen is photographed (ImageMagick `import -window root`) at 2, 5 and 9 s, the button
goes up; then the screen is photographed every 0.25 s until the still frame has been drawn
and three pictures in a row show the same render view. Last, a 3 s drag again, and 0.3 s
after its release a click on the File menu: the seconds until the menu shows (photographed
every 0.1 s) say whether the GUI answers while the still frame is drawn.

DIR/<method>-<step>.png: the whole screen; DIR/view-<method>-<step>.png: the render view
cut out and scaled to 800 px wide; DIR/results.json and the printed summary: frames per
second while dragging (frames whose EndEvent fell between button down and up, divided by
the seconds between), the mapper's image scale and cloud seconds (medians), the seconds
from release to the still frame's EndEvent and to the last changing screenshot, the menu's
delay. The load average and the CPU cores busy while dragging (all processes, and paraview's
own) are recorded beside them: other work on the same CPUs slows the frames.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time

import numpy as np
from PIL import Image

from gui_session import main_window, start_paraview, stop_paraview, view_rectangle, xdo

HERE = os.path.dirname(os.path.abspath(__file__))
METHODS = {"march": 1, "slices": 0}

SETUP = r'''
import os, time
from paraview.simple import *
import nimbus
log = open(os.environ["NIMBUS_GUI_DRAG_LOG"], "a", buffering=1)
source = NimbusMetaballCloud(registrationName="NimbusMetaballCloud1",
                             Dimensions=[128, 128, 128])
view = GetActiveViewOrCreate("RenderView")
display = Show(source, view)
display.Representation = "Cloud"
ColorBy(display, ("POINTS", "density"))
display.RenderingMethod = int(os.environ["NIMBUS_GUI_DRAG_METHOD"])
view.ResetActiveCameraToNegativeY()
view.ResetCamera()
def frame_ended(window, event):
    mapper = nimbus.find_cloud_mapper(view.SMProxy.GetRenderer())
    w, h = window.GetSize()
    if mapper is None:
        log.write("%.3f %d %d -1 0 0 0 0\n" % (time.time(), w, h))
        return
    log.write("%.3f %d %d %d %.4f %.4f %d %d\n" % (
        time.time(), w, h, mapper.GetLastFrameInteractive(), mapper.GetLastFrameImageScale(),
        mapper.GetLastFrameSeconds(), mapper.GetLastFrameSlices(),
        mapper.GetLastFrameReused()))
view.GetRenderWindow().AddObserver("EndEvent", frame_ended)
log.write("# setup done %.3f method %s\n" % (time.time(), display.GetProperty("RenderingMethod").GetData()))
Render()
'''


def shot(path):
    """Photographs the screen in the background; returns (start time, process)."""
    return time.time(), subprocess.Popen(["import", "-window", "root", path])


def cpu_seconds(pid):
    """(CPU seconds all processes have used, CPU seconds of process `pid`), from /proc."""
    tick = os.sysconf("SC_CLK_TCK")
    busy = sum(int(v) for i, v in enumerate(open("/proc/stat").readline().split()[1:])
               if i not in (3, 4, 8, 9))         # not idle, iowait, guest (in user)
    fields = open("/proc/%d/stat" % pid).read().rsplit(")", 1)[1].split()
    return busy / tick, (int(fields[11]) + int(fields[12])) / tick


def wait_for_idle_cpus(pid, timeout, below=0.3):
    """Waits (at most `timeout` s) until the processes other than `pid` keep fewer than
    `below` cores busy over 2 s, so that the drag does not share the CPUs with other work.
    Returns the cores they kept busy in the last 2 s."""
    end = time.time() + timeout
    while True:
        before = cpu_seconds(pid)
        time.sleep(2.0)
        after = cpu_seconds(pid)
        others = ((after[0] - before[0]) - (after[1] - before[1])) / 2.0
        if others < below or time.time() > end:
            return round(others, 2)


def frames(log):
    rows = []
    if not os.path.exists(log):
        return rows
    for line in open(log):
        if line.startswith("#"):
            continue
        t, w, h, interactive, scale, seconds, slices, reused = line.split()
        rows.append({"t": float(t), "size": (int(w), int(h)), "interactive": int(interactive),
                     "scale": float(scale), "seconds": float(seconds), "slices": int(slices),
                     "reused": int(reused)})
    return rows


def wait_quiet(log, quiet, timeout, size=None):
    """Waits until the log has a still frame (of `size` if given) and no new frame for
    `quiet` seconds."""
    end = time.time() + timeout
    while time.time() < end:
        rows = frames(log)
        still = [r for r in rows if r["interactive"] == 0 and (size is None or r["size"] == size)]
        if still and time.time() - rows[-1]["t"] > quiet:
            return rows
        time.sleep(0.2)
    raise SystemExit("no quiet still frame in %s after %.0f s" % (log, timeout))


def crop(png, rectangle):
    x, y, w, h = rectangle
    return np.asarray(Image.open(png).convert("RGB"))[y:y + h, x:x + w].astype(np.int16)


def view_png(png, rectangle, out):
    x, y, w, h = rectangle
    subprocess.run(["convert", png, "-crop", "%dx%d+%d+%d" % (w, h, x, y), "+repage",
                    "-resize", "800x", out], check=True)


def drag(centre, seconds, shots, output, method):
    """Button down at centre, 100 px/s right and left for `seconds`, button up; the screen
    photographed at the times in `shots`. Returns (down, up, [(name, t, process)])."""
    cx, cy = centre
    xdo("mousemove", cx, cy)
    time.sleep(0.3)
    down = time.time()
    xdo("mousedown", 1)
    taken, pending = [], sorted(shots)
    step = 0
    while time.time() - down < seconds:
        step += 1
        phase = (4 * step) % 800                       # 0..200 right, back to -200, to 0
        offset = phase if phase <= 200 else (400 - phase if phase <= 600 else phase - 800)
        xdo("mousemove", cx + offset, cy + (step // 25) % 3 - 1)
        if pending and time.time() - down >= pending[0]:
            name = "drag-%gs" % pending.pop(0)
            t, process = shot(os.path.join(output, "%s-%s.png" % (method, name)))
            taken.append((name, t - down, process))
        time.sleep(max(0.0, down + 0.04 * step - time.time() + 0.04))
    xdo("mouseup", 1)
    up = time.time()
    for _, _, process in taken:
        process.wait()
    return down, up, taken


def run_method(method, args, output):
    log = os.path.join(output, method + "-frames.log")
    if os.path.exists(log):
        os.remove(log)
    paraview = start_paraview(args.paraview, SETUP, output, "home-" + method, args.plugin_dir,
                              args.python_path, os.path.join(output, method + "-paraview.log"),
                              NIMBUS_GUI_DRAG_LOG=log,
                              NIMBUS_GUI_DRAG_METHOD=str(METHODS[method]))
    result = {"method": method}
    try:
        window = main_window()
        small = wait_quiet(log, 2.0, 300)[-1]["size"]
        xdo("windowmove", window, 0, 0)
        xdo("windowsize", window, *args.window)
        end = time.time() + 60
        while not [r for r in frames(log) if r["size"] != small] and time.time() < end:
            time.sleep(0.2)
        size = [r for r in frames(log) if r["size"] != small][-1]["size"]
        rows = wait_quiet(log, 3.0, 300, size)       # the still frame at the new size
        first = os.path.join(output, method + "-before.png")
        shot(first)[1].wait()
        rectangle = view_rectangle(first, row_pixels=400)
        result["view_size"] = size
        result["view_rectangle_on_screen"] = rectangle
        print("[%s] render view %dx%d at %s on the screen" % (method, size[0], size[1],
                                                              rectangle[:2]), flush=True)
        centre = (rectangle[0] + rectangle[2] // 2, rectangle[1] + rectangle[3] // 2)

        # The drag, its screenshots, then screenshots every 0.25 s until the view settles.
        result["other_cores_busy_before_drag"] = wait_for_idle_cpus(paraview.pid, args.idle_wait)
        result["load_average_before_drag"] = [round(v, 2) for v in os.getloadavg()]
        cpu_before = cpu_seconds(paraview.pid)
        down, up, taken = drag(centre, args.drag_seconds, [2, 5, 9], output, method)
        cpu_after = cpu_seconds(paraview.pid)
        result["cpu_while_dragging"] = {
            "cores_busy": round((cpu_after[0] - cpu_before[0]) / (up - down), 2),
            "cores_used_by_paraview": round((cpu_after[1] - cpu_before[1]) / (up - down), 2),
            "cores": os.cpu_count()}
        result["drag_screenshots_s"] = {name: round(t, 2) for name, t, _ in taken}
        after = []
        while True:
            t = time.time()
            path = os.path.join(output, "%s-after-%05.2fs.png" % (method, t - up))
            shot(path)[1].wait()
            after.append((t - up, path))
            rows = frames(log)
            still = [r for r in rows if r["t"] > up and r["interactive"] == 0]
            same = len(after) >= 3 and all(
                np.array_equal(crop(after[-1][1], rectangle), crop(p, rectangle))
                for _, p in after[-3:-1])
            if (still and same and after[-3][0] + up > still[0]["t"]) or t - up > args.settle:
                break
            time.sleep(max(0.0, t + 0.25 - time.time()))
        rows = frames(log)
        during = [r for r in rows if down <= r["t"] <= up]
        interactive = [r for r in during if r["interactive"] == 1]
        still = [r for r in rows if r["t"] > up and r["interactive"] == 0]
        final = crop(after[-1][1], rectangle)
        changing = [t for t, p in after if not np.array_equal(crop(p, rectangle), final)]
        result.update({
            "drag_seconds": round(up - down, 2),
            "frames_while_dragging": len(during),
            "interactive_frames": len(interactive),
            "frames_per_second": round(len(during) / (up - down), 2),
            "frame_period_median_s": round(statistics.median(
                [b["t"] - a["t"] for a, b in zip(during, during[1:])]), 3) if len(during) > 1
            else None,
            "image_scale_median": statistics.median([r["scale"] for r in interactive])
            if interactive else None,
            "image_scale_range": [min(r["scale"] for r in interactive),
                                  max(r["scale"] for r in interactive)] if interactive else None,
            "cloud_seconds_interactive_median": round(statistics.median(
                [r["seconds"] for r in interactive]), 4) if interactive else None,
            "slices_interactive_median": statistics.median([r["slices"] for r in interactive])
            if interactive else None,
            "frames_after_release_before_still": len(
                [r for r in rows if up < r["t"] and (not still or r["t"] < still[0]["t"])]),
            "still_frame_end_after_release_s": round(still[0]["t"] - up, 2) if still else None,
            "still_frame_cloud_seconds": still[0]["seconds"] if still else None,
            "last_changing_screenshot_after_release_s": round(max(changing), 2)
            if changing else None,
            "first_final_screenshot_after_release_s": round(min(
                t for t, _ in after if (not changing or t > max(changing))), 2),
            "screenshots_after_release": [(round(t, 2), os.path.basename(p)) for t, p in after],
        })
        for name, _, _ in taken:
            view_png(os.path.join(output, "%s-%s.png" % (method, name)), rectangle,
                     os.path.join(output, "view-%s-%s.png" % (method, name)))
        view_png(after[0][1], rectangle, os.path.join(output, "view-%s-first-after.png" % method))
        view_png(after[-1][1], rectangle, os.path.join(output, "view-%s-still.png" % method))

        # Responsiveness: a short drag, then a click on the File menu 0.3 s after release.
        time.sleep(1.0)
        menu_area = (0, 25, 250, 250)
        empty = os.path.join(output, method + "-menu-closed.png")
        shot(empty)[1].wait()
        closed = crop(empty, menu_area)
        down2, up2, _ = drag(centre, 3.0, [], output, method)
        time.sleep(max(0.0, up2 + 0.3 - time.time()))
        xdo("mousemove", 20, 10)
        clicked = time.time()
        xdo("click", 1)
        opened = None
        n = 0
        while time.time() - clicked < 60:
            n += 1
            path = os.path.join(output, "%s-menu-%02d.png" % (method, n))
            t = time.time()
            shot(path)[1].wait()
            if not np.array_equal(crop(path, menu_area), closed):
                opened = (t - clicked, path)
                break
            time.sleep(0.1)
        rows = frames(log)
        still2 = [r for r in rows if r["t"] > up2 and r["interactive"] == 0]
        result.update({
            "menu_click_after_release_s": round(clicked - up2, 2),
            "menu_shown_after_click_s": round(opened[0], 2) if opened else None,
            "menu_screenshot": os.path.basename(opened[1]) if opened else None,
            "second_still_frame_end_after_release_s": round(still2[0]["t"] - up2, 2)
            if still2 else None,
        })
        if opened:
            view_png(opened[1], (0, 0, 1600, 1040), os.path.join(output, "screen-%s-menu.png"
                                                                  % method))
        xdo("key", "Escape")
    finally:
        stop_paraview(paraview)
    return result


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--plugin-dir", required=True)
    parser.add_argument("--output-dir", required=True)
    parser.add_argument("--method", choices=sorted(METHODS), action="append")
    parser.add_argument("--window", type=int, nargs=2, default=[1588, 1035],
                        help="the main window's size in pixels (1588x1035: a render view "
                             "of about 1280x800 with the default docks)")
    parser.add_argument("--drag-seconds", type=float, default=10.0)
    parser.add_argument("--settle", type=float, default=60.0,
                        help="the most seconds to photograph after release")
    parser.add_argument("--idle-wait", type=float, default=180.0,
                        help="the most seconds to wait, before each drag, for the other "
                             "processes to leave the CPUs (almost) idle")
    parser.add_argument("--paraview", default="paraview")
    parser.add_argument("--python-path", default=os.path.join(
        HERE, "..", "build", "lib", "python3.11", "site-packages"))
    args = parser.parse_args()
    output = os.path.abspath(args.output_dir)
    os.makedirs(output, exist_ok=True)
    results = []
    for method in args.method or ["march", "slices"]:
        results.append(run_method(method, args, output))
        summary = {k: v for k, v in results[-1].items() if k != "screenshots_after_release"}
        print(json.dumps(summary, indent=1), flush=True)
    with open(os.path.join(output, "results.json"), "w") as out:
        json.dump(results, out, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
