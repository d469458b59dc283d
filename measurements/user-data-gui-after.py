"""A user's steps with Data/UserData's files in the real ParaView GUI, photographed.

    Xvfb :57 -screen 0 1280x860x24 -noreset &
    DISPLAY=:57 /usr/bin/python3 measurements/user-data-gui-after.py \
        --plugin-dir build/lib/paraview-5.11/plugins/Nimbus --data-dir Data/UserData \
        --output-dir DIR [--case vdb|netcdf|pvti]

For each file this writes a test of ParaView's own test player (--test-script: the events
go to the GUI's widgets as a user's clicks do: File > Open, the reader-choice dialog, the
Properties panel's fields, Apply, the toolbars' menus and buttons) and runs `paraview` with
it, in a fresh settings folder. After each step the player calls this file's mark() and
shot() in the GUI's Python shell (hidden again before the file is opened): the seconds
since File > Open was pressed, then the whole screen photographed with ImageMagick's
`import -window root` (DIR/<case>-<n>-<step>.png). The times include the test player's
own waits between events. DIR/<case>-times.txt: "<step> <seconds>"; DIR/<case>.log: the
GUI's output (a widget the player cannot find fails the test: exit status 1).
"""
import argparse
import os
import subprocess
import sys
import time
from xml.sax.saxutils import quoteattr

PANEL = ("pqClientMainWindow/propertiesDock/propertiesPanel/scrollArea/qt_scrollarea_viewport/"
         "scrollAreaWidgetContents")
READER = PANEL + "/PropertiesFrame/ProxyPanel/"
DISPLAY = PANEL + "/DisplayFrame/ProxyPanel/"
SHELL = "pqClientMainWindow/pythonShellDock/pythonShell/consoleWidget"
APPLY = ("pqClientMainWindow/propertiesDock/propertiesPanel/Accept", "activate", "")
REPRESENTATION = "pqClientMainWindow/representationToolbar/displayRepresentation/comboBox"
COLOR = "pqClientMainWindow/variableToolbar/displayColor/Variables"
MINUS_Y = ("pqClientMainWindow/cameraToolbar/actionNegativeY", "activate", "")


def open_file(path):
    return [("pqClientMainWindow/MainControlsToolbar/actionOpenData", "activate", ""),
            ("pqClientMainWindow/FileOpenDialog", "filesSelected", path)]


# Each case: a list of (step name, events); the picture and the time are taken after each.
def steps_vdb(path):
    return [
        ("open-up-axis-y-apply", open_file(path) + [
            (READER + "UpAxis/ComboBox", "activated", "+Y"), APPLY]),
        ("estimated", [(DISPLAY + "DensityUnits/ComboBox", "activated",
                        "Unknown: a typical cloud (estimated)")]),
    ]


def steps_netcdf(path):
    reader_list = "pqClientMainWindow/pqSelectReaderDialog/listWidget"
    return [
        ("open-netcdf-reader-spherical-off-apply", open_file(path) + [
            # The dialog lists NetCDF CAM reader (selected) and NetCDF Reader (row 1).
            (reader_list, "mousePress", "1,1,0,40,8,/1:0"),
            (reader_list, "mouseRelease", "1,0,0,40,8,/1:0"),
            ("pqClientMainWindow/pqSelectReaderDialog/okButton", "activate", ""),
            (READER + "SphericalCoordinates/CheckBox", "set_boolean", "false"), APPLY]),
        ("cloud", [(REPRESENTATION, "activated", "Cloud")]),
        ("colour-by-ql", [(COLOR, "activated", "ql")]),
        ("mixing-ratio", [(DISPLAY + "DensityUnits/ComboBox", "activated",
                           "Liquid water mixing ratio (kg/kg)")]),
        ("minus-y", [MINUS_Y]),
        ("last-time-step", [("pqClientMainWindow/VCRToolbar/actionVCRLastFrame", "activate",
                             "")]),
    ]


def steps_pvti(path):
    return [
        ("open-apply", open_file(path) + [APPLY]),
        ("cloud", [(REPRESENTATION, "activated", "Cloud")]),
        ("metres-per-unit-1000", [(DISPLAY + "MetresPerUnit/DoubleRangeWidget/DoubleLineEdit",
                                   "set_string", "1000")]),
        ("extinction", [(DISPLAY + "DensityUnits/ComboBox", "activated", "Extinction (1/m)")]),
        ("minus-y", [MINUS_Y]),
    ]


CASES = {"vdb": ("cumulus_y_up.vdb", steps_vdb), "netcdf": ("les_cumulus_ql.nc", steps_netcdf),
         "pvti": ("automaton_extinction_km.pvti", steps_pvti)}


# --- run inside the GUI (the player's Python-shell commands) ----------------------------------
_start = []


def mark(output_dir, case, label):
    """Seconds since the first mark (File > Open), appended to <case>-times.txt."""
    now = time.time()
    if not _start:
        _start.append(now)
    with open(os.path.join(output_dir, case + "-times.txt"), "a") as out:
        out.write("%s %.2f\n" % (label, now - _start[0]))


def shot(path):
    subprocess.run(["import", "-window", "root", path], check=False)


# --- the launcher ------------------------------------------------------------------------------
def event(obj, command, arguments):
    return "  <pqevent object=%s command=%s arguments=%s />\n" % (
        quoteattr(obj), quoteattr(command), quoteattr(arguments))


def test_script(case, path, output_dir):
    here = os.path.abspath(__file__)
    menu = [("pqClientMainWindow/menubar", "activate", "menu_View"),
            ("pqClientMainWindow/menubar/menu_View", "activate", "Python Shell")]
    text = '<?xml version="1.0" ?>\n<pqevents>\n'
    # Open the Python shell, load this file, hide the shell again (its commands still run).
    for e in menu:
        text += event(*e)
    text += event(SHELL, "executeCommand",
                  "nimbus_gui = {'__name__': 'nimbus_gui'}; "
                  "exec(open(%r).read(), nimbus_gui)" % here)
    for e in menu:
        text += event(*e)
    text += event(SHELL, "executeCommand", "nimbus_gui['mark'](%r, %r, 'file-open')" % (
        output_dir, case))
    for number, (name, events) in enumerate(CASES[case][1](path), start=1):
        for e in events:
            text += event(*e)
        text += event(SHELL, "executeCommand", "nimbus_gui['mark'](%r, %r, %r)" % (
            output_dir, case, name))
        text += event(SHELL, "executeCommand", "nimbus_gui['shot'](%r)" % os.path.join(
            output_dir, "%s-%d-%s.png" % (case, number, name)))
    return text + "</pqevents>\n"


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--plugin-dir", required=True)
    parser.add_argument("--data-dir", required=True)
    parser.add_argument("--output-dir", required=True)
    parser.add_argument("--case", choices=sorted(CASES), action="append")
    parser.add_argument("--paraview", default="paraview")
    args = parser.parse_args()
    output_dir = os.path.abspath(args.output_dir)
    os.makedirs(output_dir, exist_ok=True)
    status = 0
    for case in args.case or ["vdb", "netcdf", "pvti"]:
        path = os.path.abspath(os.path.join(args.data_dir, CASES[case][0]))
        xml = os.path.join(output_dir, case + ".xml")
        with open(xml, "w") as out:
            out.write(test_script(case, path, output_dir))
        times = os.path.join(output_dir, case + "-times.txt")
        if os.path.exists(times):
            os.remove(times)
        home = os.path.join(output_dir, "home-" + case)   # fresh settings: default layout
        os.makedirs(home, exist_ok=True)
        env = dict(os.environ, HOME=home, PV_PLUGIN_PATH=os.path.abspath(args.plugin_dir))
        result = subprocess.run(
            [args.paraview, "--dr", "--test-directory=" + output_dir, "--test-script=" + xml,
             "--exit"], env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        log = os.path.join(output_dir, case + ".log")
        with open(log, "w") as out:
            out.write(result.stdout)
        print("[%s] paraview exit status %d (log %s)" % (case, result.returncode, log))
        if os.path.exists(times):
            print(open(times).read().rstrip())
        status |= result.returncode != 0
    return status


if __name__ == "__main__":
    sys.exit(main())
