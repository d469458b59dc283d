"""ParaView GUI start-up script: a user's steps with Data/UserData/cumulus_y_up.vdb.

    NIMBUS_USER_DATA_STEP=0|1|2|3 NIMBUS_USER_DATA_FILE=Data/UserData/cumulus_y_up.vdb \
    NIMBUS_USER_DATA_TIMING=/tmp/timing.txt \
    PV_PLUGIN_PATH=<build>/lib/paraview-5.11/plugins/Nimbus \
        paraview --dr --script=measurements/user-data-gui.py

Run inside the real GUI after the plugin has loaded (docs/user-data.md photographs the
screen with ImageMagick's `import -window root` a few seconds later):
  0  open the file and show it (what Apply does: the representation the GUI picks, the
     plugin's first-look camera);
  1  the same, then the Cloud representation;
  2  today's way to an upright cloud above the ground: Transform (Rotate 90 0 0), Resample
     To Image (44 x 44 x 64), Cloud, Ground Height = the data's lowest z;
  3  the reader's Up Axis = +Y (where the reader has it), Cloud.
Writes "step <n> seconds_to_first_image <s>" (from opening the file to the first render
finished) to NIMBUS_USER_DATA_TIMING. The GUI stays open for the photograph.
"""
import os
import sys
import time
import traceback

from paraview.simple import (GetActiveViewOrCreate, Hide, OpenDataFile, Render,
                             ResampleToImage, ResetCamera, Show, Transform)


def main():
    step = int(os.environ.get("NIMBUS_USER_DATA_STEP", "0"))
    path = os.environ["NIMBUS_USER_DATA_FILE"]
    view = GetActiveViewOrCreate("RenderView")
    start = time.time()
    reader = OpenDataFile(path)
    if step == 3 and reader.GetProperty("UpAxis") is not None:
        reader.UpAxis = 1
    display = Show(reader, view)
    if step in (1, 3):
        display.SetRepresentationType("Cloud")
    if step == 2:
        Hide(reader, view)
        turn = Transform(Input=reader)
        turn.Transform = "Transform"
        turn.Transform.Rotate = [90.0, 0.0, 0.0]
        image = ResampleToImage(Input=turn)
        image.SamplingDimensions = [44, 44, 64]
        display = Show(image, view)
        display.SetRepresentationType("Cloud")
        display.GroundHeight = image.GetDataInformation().GetBounds()[4]
        ResetCamera(view)
    Render(view)
    seconds = time.time() - start
    with open(os.environ.get("NIMBUS_USER_DATA_TIMING", os.devnull), "a") as out:
        out.write("step %d representation %s seconds_to_first_image %.2f\n" % (
            step, display.Representation, seconds))


try:
    main()
except Exception:
    traceback.print_exc(file=sys.__stdout__)
