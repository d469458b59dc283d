"""Play of a lightning flash in the real ParaView GUI, timed and photographed.

    /usr/bin/python3 measurements/lightning-play-gui.py \
        --plugin-dir build/lib/paraview-5.11/plugins/Nimbus --output-dir DIR \
        [--cache-dir DIR] [--play X Y] [--strokes]

Without a DISPLAY the script starts its own Xvfb (1920x1200) and stops it at the end. A fresh
`paraview` (fresh settings folder, --dr) runs a start-up script that builds what a user builds
(and what the plugin's first Apply then shows): the default Nimbus Metaball Cloud, the default
Nimbus Lightning, a Nimbus Lightning Illumination of the two (shown as a Cloud at night at the
return stroke), its basis from --cache-dir when it is there. The start-up script also logs, to
DIR/renders.jsonl, every render of the view: when it ended, its seconds, the view's size, and
the Cloud mapper's last frame (interactive or still, quality, sun elevation). Then the main
window is made 1920x1200 at 0,0 and the VCR toolbar's Play button is clicked with the mouse
(xdotool; at --play X Y, found from a screenshot of this ParaView 5.11); Play runs through
the flash's time steps once (ParaView's "Snap To TimeSteps"); the script waits for the end.

Prints frames per second during Play (renders while the animation time moved, over their
span), whether they were interactive, and the still frame after. DIR/gui-NN-<step>.png: the
screen before Play, during it and after (ImageMagick `import -window root`). Look at them.
"""
import argparse
import json
import os
import subprocess
import sys
import time

from gui_session import main_window, start_paraview, stop_paraview, xdo

SCREEN = (1920, 1200)

SETUP = r'''
import json, os, time
from paraview.simple import *
LOG = %(log)r
LoadPlugin(%(plugin)r, ns=globals())  # its proxies in this namespace, loaded or not
view = GetActiveViewOrCreate("RenderView")
view.OrientationAxesVisibility = 0
cloud = NimbusMetaballCloud()
bolt = NimbusLightning()
lit = NimbusLightningIllumination(Input=cloud, Lightning=OutputPort(bolt, %(port)d),
                                  CacheDirectory=%(cache)r)
Show(bolt, view)
display = Show(lit, view)
Hide(cloud, view)
SetActiveSource(lit)
window = view.GetRenderWindow()
stream = open(LOG, "w")
state = {"start": None}

def mapper():
    try:
        import nimbus
        return nimbus.find_cloud_mapper(view.SMProxy.GetRenderer())
    except Exception:
        return None

def started(*_):
    state["start"] = time.perf_counter()
    state["wall"] = time.time()

def ended(*_):
    m = mapper()
    row = {"end": time.time(), "seconds": time.perf_counter() - (state["start"] or 0.0),
           "begin": state.get("wall", 0.0),
           "size": list(window.GetSize()), "time": view.ViewTime}
    if m is not None:
        row.update(interactive=bool(m.GetLastFrameInteractive()),
                   quality=m.GetLastFrameQuality(), reused=bool(m.GetLastFrameReused()),
                   sun=m.GetLastSunElevationDegrees(), cloud_seconds=m.GetLastFrameSeconds())
    row.update(spent)
    spent.clear()
    stream.write(json.dumps(row) + "\n")
    stream.flush()

spent = {}

def timed(name, algorithm):
    begin = {}
    algorithm.AddObserver("StartEvent", lambda *_: begin.update(t=time.perf_counter()))
    algorithm.AddObserver("EndEvent", lambda *_: spent.__setitem__(
        name, spent.get(name, 0.0) + time.perf_counter() - begin.get("t", time.perf_counter())))

timed("cloud source", cloud.GetClientSideObject())
timed("filter", lit.GetClientSideObject())
composite = display.GetClientSideObject()
timed("representation", composite.GetActiveRepresentation() if hasattr(
    composite, "GetActiveRepresentation") else composite)
tick = GetAnimationScene().GetClientSideObject()
tick.AddObserver("AnimationCueTickEvent", lambda *_: spent.__setitem__("tick", time.time()))
window.AddObserver("StartEvent", started)
window.AddObserver("EndEvent", ended)
Render(view)
stream.write(json.dumps({"ready": time.time(), "times": list(lit.TimestepValues)}) + "\n")
stream.flush()
'''


def screenshot(output, count, step):
    path = os.path.join(output, "gui-%02d-%s.png" % (count, step))
    subprocess.run(["import", "-window", "root", path], check=True)
    print(path, flush=True)
    return path


def read_log(path):
    rows = []
    if os.path.exists(path):
        with open(path) as stream:
            for line in stream:
                try:
                    rows.append(json.loads(line))
                except ValueError:
                    pass
    return rows


def wait_for(path, predicate, timeout, paraview=None):
    end = time.time() + timeout
    while time.time() < end:
        if paraview is not None and paraview.poll() is not None:
            break
        with open(os.path.join(os.path.dirname(path), "paraview.log")) as stream:
            if "Traceback" in stream.read():
                break
        rows = read_log(path)
        if predicate(rows):
            return rows
        time.sleep(0.5)
    return read_log(path)


def run(args):
    output = os.path.abspath(args.output_dir)
    log = os.path.join(output, "renders.jsonl")
    if os.path.exists(log):
        os.remove(log)
    setup = SETUP % {"log": log, "cache": os.path.abspath(args.cache_dir),
                     "port": 0 if args.strokes else 1,
                     "plugin": os.path.join(os.path.abspath(args.plugin_dir), "Nimbus.so")}
    paraview = start_paraview(args.paraview, setup, output, "home", args.plugin_dir,
                              args.python_path, os.path.join(output, "paraview.log"))
    try:
        window = main_window()
        rows = wait_for(log, lambda r: any("ready" in x for x in r), 600, paraview)
        if not any("ready" in x for x in rows):
            raise SystemExit("the start-up script did not finish (see paraview.log)")
        xdo("windowmove", window, 0, 0)
        xdo("windowsize", window, *SCREEN)
        time.sleep(8.0)
        screenshot(output, 1, "before-play")
        ready = len(read_log(log))
        times = [x for x in read_log(log) if "ready" in x][0]["times"]
        xdo("mousemove", *args.play)
        time.sleep(0.3)
        clicked = time.time()
        xdo("click", 1)
        time.sleep(1.5)
        screenshot(output, 2, "during-play")
        # Play ends at the last time step; the still frame after it is the last render.
        rows = wait_for(log, lambda r: any(x.get("time", -1) >= times[-1] - 1e-9
                                           for x in r[ready:]), 900, paraview)
        time.sleep(6.0)
        screenshot(output, 3, "after-play")
        rows = read_log(log)[ready:]
    finally:
        stop_paraview(paraview)
    played = [x for x in rows if x.get("end", 0) >= clicked]
    moving = [x for x in played if x.get("interactive")]
    still = [x for x in played if not x.get("interactive")]
    print("renders after the click: %d (%d interactive, %d still); view %s" % (
        len(played), len(moving), len(still), played[0]["size"] if played else "-"))
    if len(moving) >= 2:
        span = moving[-1]["end"] - moving[0]["end"]
        print("Play: %d interactive frames in %.2f s: %.2f frames/s; render seconds median "
              "%.3f, the cloud's passes median %.3f; quality %s" % (
                  len(moving), span, (len(moving) - 1) / span,
                  sorted(x["seconds"] for x in moving)[len(moving) // 2],
                  sorted(x["cloud_seconds"] for x in moving)[len(moving) // 2],
                  sorted(set(round(x["quality"], 3) for x in moving))))
    elif len(played) >= 2:
        span = played[-1]["end"] - played[0]["end"]
        print("Play: %d still frames in %.2f s: %.2f frames/s (render median %.3f s)" % (
            len(played), span, (len(played) - 1) / span,
            sorted(x["seconds"] for x in played)[len(played) // 2]))
    if still:
        print("after Play: still frame %.2f s at quality %.3f, sun %.1f deg" % (
            still[-1]["seconds"], still[-1]["quality"], still[-1]["sun"]))
    print("load average: %.2f %.2f %.2f" % os.getloadavg())
    return 0


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--plugin-dir", required=True)
    parser.add_argument("--output-dir", required=True)
    parser.add_argument("--cache-dir", default=os.path.expanduser("~/.cache/nimbus"))
    parser.add_argument("--paraview", default="paraview")
    parser.add_argument("--python-path", default=os.path.abspath(
        os.path.join(os.path.dirname(__file__), "..", "build", "lib", "python3.11",
                     "site-packages")))
    parser.add_argument("--play", type=int, nargs=2, default=[592, 41],
                        help="where the VCR toolbar's Play button is (screen pixels)")
    parser.add_argument("--strokes", action="store_true",
                        help="the lightning's strokes (port 0) as the filter's Lightning input, "
                        "not its point sources (port 1)")
    args = parser.parse_args()
    os.makedirs(args.output_dir, exist_ok=True)
    if os.environ.get("DISPLAY"):
        return run(args)
    xvfb = subprocess.Popen(["Xvfb", ":71", "-screen", "0", "%dx%dx24" % SCREEN, "-noreset"])
    os.environ["DISPLAY"] = ":71"
    time.sleep(2.0)
    try:
        return run(args)
    finally:
        xvfb.terminate()
        xvfb.wait()


if __name__ == "__main__":
    sys.exit(main())
