"""What a user must do now to get a believable cloud from Data/UserData's files.

    PYTHONPATH=build/lib/python3.11/site-packages \
    /usr/bin/pvpython --force-offscreen-rendering measurements/user-data-after.py \
        --plugin build/lib/paraview-5.11/plugins/Nimbus/Nimbus.so \
        --data-dir Data/UserData --output-dir DIR [--case vdb|netcdf|pvti] [--extinction]

The "after" twin of measurements/user-data-before.py (same view, camera, checks and clock): for
each file, the steps of docs/user-data.md's "after" column, one at a time, each rendered
and judged by the checks of Testing/Python/TestUserData.py, with the seconds since the
file was opened (the checks' own renders not counted). Images: DIR/<case>-<step>.png.

--extinction: the extinction (1/m) each Density Array Means choice gives for a typical
cumulus (LWC 0.3 g/m3, r_e 10 um: 3 LWC / (2 rho_w r_e) = 0.045 1/m), read from what the
Cloud representation hands its mapper (the density array turned into extinction, times
the mapper's Extinction per Unit Density) for a uniform field of each unit's value. Needs
`import nimbus` (PYTHONPATH as above).
"""
import argparse
import importlib.util
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, os.pardir, "Testing", "Python"))
import TestUserData as checks  # noqa: E402
from paraview.simple import (  # noqa: E402
    ColorBy, Delete, GetSources, LoadPlugin, NetCDFReader, OpenDataFile, Render)

_spec = importlib.util.spec_from_file_location("user_data_before",
                                               os.path.join(HERE, "user-data-before.py"))
before = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(before)

UP_AXIS_PLUS_Y = 1
UNITS = {"dimensionless": 0, "extinction": 1, "lwc": 2, "mixing ratio": 3, "iwc": 4,
         "estimated": 5}


def after_vdb(path, view, output_dir):
    steps = before.Steps("vdb", view, output_dir)
    reader = OpenDataFile(path)
    reader.UpAxis = UP_AXIS_PLUS_Y    # before the first Apply: the file names no up axis
    display, _ = before.cloud_display(reader, view)   # the GUI picks Cloud for a .vdb
    before.look(view, reader, display)
    steps.judge("open the .vdb, reader Up Axis = +Y, Apply (Cloud)", display, reader,
                "density", tall=True)
    return steps


def after_netcdf(path, view, output_dir):
    steps = before.Steps("netcdf", view, output_dir)
    reader = NetCDFReader(FileName=[path])
    reader.SphericalCoordinates = 0   # before the first Apply
    reader.UpdatePipeline(reader.TimestepValues[0])
    data = checks.output_of(reader)
    z = np.asarray([data.GetZCoordinates().GetValue(i)
                    for i in range(data.GetZCoordinates().GetNumberOfTuples())])
    sigma = 3.0 * checks.standard_atmosphere_density(z)[:, None, None] * checks.grid_values(
        data, "ql") / (2.0 * checks.RHO_WATER * checks.EFFECTIVE_RADIUS)
    tau = checks.largest_column_optical_depth(data, sigma, 1.0)
    display, _ = before.cloud_display(reader, view)
    before.look(view, reader, display)
    steps.judge("open the .nc (NetCDF Reader), Spherical Coordinates off, Apply; Cloud",
                display, reader, "ql", tau=tau)
    ColorBy(display, ("POINTS", "ql"))
    steps.judge("colour by ql", display, reader, "ql", tau=tau)
    display.DensityUnits = UNITS["mixing ratio"]
    steps.judge("Density Array Means = liquid water mixing ratio (kg/kg)", display, reader,
                "ql", tau=tau)
    return steps


def after_pvti(path, view, output_dir):
    steps = before.Steps("pvti", view, output_dir)
    reader = OpenDataFile(path)
    reader.UpdatePipeline()
    data = checks.output_of(reader)
    tau = checks.largest_column_optical_depth(data, checks.grid_values(data, "extinction"),
                                              1000.0)
    display, _ = before.cloud_display(reader, view)
    before.look(view, reader, display)
    steps.judge("open the .pvti, Apply; Cloud", display, reader, "extinction", tau=tau)
    display.MetresPerUnit = 1000.0
    steps.judge("Metres Per Unit = 1000", display, reader, "extinction", tau=tau)
    display.DensityUnits = UNITS["extinction"]
    steps.judge("Density Array Means = extinction (1/m)", display, reader, "extinction",
                tau=tau)
    return steps


# --- the extinction each choice gives --------------------------------------------------------
# A typical cumulus: LWC 0.3 g/m3, droplets of effective radius 10 um (the representation's
# default): sigma = 3 LWC / (2 rho_w r_e) = 0.045 1/m (Hansen & Travis 1974; Stephens 1978).
CUMULUS_LWC = 0.3                 # g/m3
AIR_AT_1KM = 1.1117               # kg/m3: U.S. Standard Atmosphere 1976 at 1 km
SLAB = dict(points=11, spacing=20.0 / 0.045 / 10.0, base=1000.0)   # 444 m thick from 1 km
# (name, array, value, DensityUnits, other properties)
CHOICES = [
    ("Density (no unit) x Extinction per Unit Density 0.05", "dimensionless", 0.9,
     "dimensionless", {"ExtinctionPerDensity": 0.05}),
    ("Extinction (1/m)", "extinction", 0.045, "extinction", {}),
    ("Liquid water content (g/m3), r_e 10 um", "lwc", CUMULUS_LWC, "lwc", {}),
    ("Liquid water content (g/m3), N 100 /cm3", "lwc", CUMULUS_LWC, "lwc",
     {"DropletSize": 1}),
    ("Liquid water mixing ratio (kg/kg), standard atmosphere at 1 km", "ql",
     CUMULUS_LWC / (1000.0 * AIR_AT_1KM), "mixing ratio", {}),
    ("Liquid water mixing ratio (kg/kg), Air Density Array rho = 1.1117", "ql",
     CUMULUS_LWC / (1000.0 * AIR_AT_1KM), "mixing ratio", {"AirDensityArray": "rho"}),
    ("Ice water content (g/m3), r_e 10 um", "iwc", CUMULUS_LWC, "iwc", {}),
    ("Unknown: a typical cloud (estimated), Target Optical Thickness 20 over 444 m",
     "lwc", CUMULUS_LWC, "estimated", {}),
]


def uniform_slab(path):
    """An image of 11^3 points, 44.4 m apart, from z = 1 km: every array uniform."""
    from vtkmodules.vtkCommonCore import vtkFloatArray
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkIOXML import vtkXMLImageDataWriter
    image = vtkImageData()
    n = SLAB["points"]
    image.SetDimensions(n, n, n)
    image.SetSpacing(SLAB["spacing"], SLAB["spacing"], SLAB["spacing"])
    image.SetOrigin(0.0, 0.0, SLAB["base"])
    values = {"dimensionless": 0.9, "extinction": 0.045, "lwc": CUMULUS_LWC,
              "ql": CUMULUS_LWC / (1000.0 * AIR_AT_1KM), "iwc": CUMULUS_LWC, "rho": AIR_AT_1KM}
    for name, value in values.items():
        array = vtkFloatArray()
        array.SetName(name)
        array.SetNumberOfTuples(n ** 3)
        array.Fill(value)
        image.GetPointData().AddArray(array)
    writer = vtkXMLImageDataWriter()
    writer.SetFileName(path)
    writer.SetInputData(image)
    writer.Write()


def extinction_of_each_choice(output_dir):
    import nimbus
    path = os.path.join(output_dir, "uniform-cumulus.vti")
    uniform_slab(path)
    reader = OpenDataFile(path)
    view = checks.make_view()
    display = checks.show_as_cloud(reader, view, [])
    rows = []
    for label, array, value, units, extra in CHOICES:
        ColorBy(display, ("POINTS", array))
        display.DensityUnits = UNITS[units]
        display.ExtinctionPerDensity = 0.02
        display.DropletSize = 0
        display.AirDensityArray = ""
        for name, setting in extra.items():
            display.SetPropertyWithName(name, setting)
        Render(view)
        mapper = nimbus.find_cloud_mapper(view.SMProxy.GetRenderer())
        image = mapper.GetInput()
        sigma = image.GetPointData().GetArray(array)
        # The bottom layer (z = 1 km, where the mixing ratio was made for 1.1117 kg/m3).
        bottom = sigma.GetValue(0) * mapper.GetExtinctionPerDensity()
        middle = sigma.GetValue(sigma.GetNumberOfTuples() // 2) * \
            mapper.GetExtinctionPerDensity()
        rows.append((label, value, bottom, middle))
        print("%-78s value %-10.4g sigma at 1 km %.5f 1/m, at 1.22 km %.5f 1/m" % (
            label, value, bottom, middle))
    for representation in list(view.Representations):
        Delete(representation)
    Delete(view)
    return rows


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--plugin", required=True)
    parser.add_argument("--data-dir", required=True)
    parser.add_argument("--output-dir", required=True)
    parser.add_argument("--case", choices=["vdb", "netcdf", "pvti"], action="append")
    parser.add_argument("--extinction", action="store_true")
    args = parser.parse_args()
    os.makedirs(args.output_dir, exist_ok=True)
    LoadPlugin(args.plugin, ns=globals())
    if args.extinction:
        extinction_of_each_choice(args.output_dir)
    recipes = {"vdb": after_vdb, "netcdf": after_netcdf, "pvti": after_pvti}
    for case in args.case or ([] if args.extinction else ["vdb", "netcdf", "pvti"]):
        view = checks.make_view()
        recipes[case](os.path.join(args.data_dir, checks.FILES[case]), view, args.output_dir)
        for representation in list(view.Representations):
            Delete(representation)
        Delete(view)
        del view
    for proxy in list(GetSources().values()):
        Delete(proxy)
    return 0


if __name__ == "__main__":
    sys.exit(main())
