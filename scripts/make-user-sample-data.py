"""Writes Data/UserData: three small cloud files in the forms users bring to Nimbus.

    PYTHONPATH=build/lib/python3.11/site-packages /usr/bin/python3 \
        scripts/make-user-sample-data.py [--output-dir Data/UserData]

Every file is made from the project's own generators (vtkNimbusMetaballCloudSource,
vtkNimbusCloudAutomatonSource) with fixed seeds, so running this again gives the same
values (byte for byte, except the random file UUID OpenVDB writes in the .vdb header):

  cumulus_y_up.vdb          a Houdini-style fog volume: grid "density" (0..1), y up,
                            voxel size 3.33, centred at (200, 50, -120); whole box active
  les_cumulus_ql.nc         LES-like NetCDF (CF-1.8): ql(time, z, y, x) in kg/kg on a
                            stretched z grid, 3 time steps; rho(z) in kg m-3
  automaton_extinction_km.pvti (+ automaton_extinction_km/*.vti, 4 pieces)
                            cloud automaton field as extinction in 1/m on a grid in km

Data/UserData/README.md describes each file (frame, units, grid, size).
Needs python3-openvdb (pyopenvdb) and python3-netcdf4 (netCDF4); scripts/setup.sh installs both.
"""
import argparse
import os
import sys

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# --- the y-up .vdb --------------------------------------------------------------------------
VDB_NAME = "cumulus_y_up.vdb"
VDB_VOXEL_SIZE = 3.33                     # world units per voxel (Houdini: metres)
VDB_CENTRE = (200.0, 50.0, -120.0)        # world centre of the voxel box
VDB_SEED = 11

# --- the LES-like NetCDF --------------------------------------------------------------------
NC_NAME = "les_cumulus_ql.nc"
NC_NX, NC_NY, NC_DX = 64, 64, 50.0        # horizontal cells and spacing (m)
NC_NZ, NC_DZ_BOTTOM, NC_DZ_TOP = 40, 25.0, 100.0   # stretched levels, spacing (m)
NC_TIMES = (3600.0, 3660.0, 3720.0)       # s since the start of the run
NC_WIND = 5.0                             # m/s along +x: the cloud drifts 300 m per step
NC_GROWTH = (0.85, 1.0, 1.1)              # the cloud's water grows with time
NC_SEED = 7
NC_CLOUD_BASE = 700.0                     # m, lifting condensation level
NC_QL_LAPSE = 1.7e-3 / 1000.0             # kg/kg per m above the base (adiabatic ~2 g/kg/km)

# --- the .pvti ------------------------------------------------------------------------------
PVTI_NAME = "automaton_extinction_km.pvti"
PVTI_SPACING_KM = 0.05                    # 50 m, written in km
PVTI_DIMS = (80, 80, 40)                  # points along x, y, z
PVTI_LAYER = (10, 24)                     # the automaton's levels: first z index, count
PVTI_SIGMA_PER_DENSITY = 0.08             # 1/m of extinction per unit automaton density
PVTI_SEED = 3
PVTI_PIECES = 4


def import_nimbus():
    try:
        import nimbus
    except ImportError:
        sys.path.insert(0, os.path.join(REPO, "build", "lib", "python3.11", "site-packages"))
        import nimbus
    return nimbus


def metaball_density(nimbus, dims, bounds, seed, balls=(), **settings):
    """vtkNimbusMetaballCloudSource's "density" as an array [z, y, x] (z up, metres)."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    cloud = nimbus.vtkNimbusMetaballCloudSource()
    cloud.SetDimensions(*dims)
    cloud.SetBounds(*bounds)
    cloud.SetSeed(seed)
    for name, value in settings.items():
        getattr(cloud, "Set" + name)(*(value if isinstance(value, tuple) else (value,)))
    for ball in balls:
        cloud.AddBall(*ball)
    cloud.Update()
    array = cloud.GetOutput().GetPointData().GetArray("density")
    return vtk_to_numpy(array).reshape(dims[2], dims[1], dims[0]).astype(np.float64)


def write_y_up_vdb(nimbus, path):
    """A towering cumulus (taller than wide) as a y-up fog volume, offset from the origin.

    Generated z up (the metaball source's frame) on 44 x 44 x 64 points, then turned to
    y up the way Houdini, Maya and glTF are: world (X, Y, Z) = (east, up, -north), i.e.
    VDB voxel (i, j, k) holds the z-up point (x = i, z = j, y = ny - 1 - k). The density is
    clipped to 0..1 (a fog volume's convention). All 44 x 64 x 44 voxels are active, the
    clear-air margin (zeros) included, so the file's box is the whole volume and has air
    around the cloud.
    """
    import pyopenvdb as vdb
    dims = (44, 44, 64)   # z-up generator points: x, y, z
    bounds = (-700.0, 700.0, -700.0, 700.0, 0.0, 2100.0)
    # A stacked column of balls: the basic shape of a towering cumulus; the fractal growth
    # roughens it.
    balls = [(0, 0, 350, 380, 1.0), (120, -80, 300, 300, 1.0), (-150, 60, 320, 300, 1.0),
             (30, 40, 750, 360, 1.0), (-60, -30, 1100, 330, 1.0), (50, 20, 1450, 300, 1.0),
             (-20, 0, 1750, 240, 1.0)]
    density = metaball_density(nimbus, dims, bounds, VDB_SEED, balls, BaseHeight=120.0,
                               NumberOfLevels=3)
    density = np.clip(density, 0.0, 1.0)                   # [z, y, x]
    voxels = density.transpose(2, 0, 1)[:, :, ::-1]        # [i, j, k] = [x, z, ny-1-y]
    voxels = np.ascontiguousarray(voxels, dtype=np.float32)

    grid = vdb.FloatGrid(0.0)
    # tolerance -1: no voxel equals the background within it, so the zeros stay active.
    grid.copyFromArray(voxels, ijk=(0, 0, 0), tolerance=-1.0)
    size = VDB_VOXEL_SIZE
    extent = [(n - 1) * size for n in voxels.shape]
    origin = [c - e / 2.0 for c, e in zip(VDB_CENTRE, extent)]
    # OpenVDB's row-vector matrix: world = (i, j, k, 1) M; the last row is the translation.
    grid.transform = vdb.createLinearTransform(
        [[size, 0, 0, 0], [0, size, 0, 0], [0, 0, size, 0], [origin[0], origin[1], origin[2], 1]])
    grid.name = "density"
    grid.gridClass = vdb.GridClass.FOG_VOLUME
    vdb.write(path, grids=[grid])
    print(f"{path}: {voxels.shape[0]} x {voxels.shape[1]} x {voxels.shape[2]} voxels, "
          f"{grid.activeVoxelCount()} active, voxel {size}, origin {origin}, "
          f"density max {voxels.max():.3f}, {os.path.getsize(path)} bytes")


def stretched_levels():
    """Cell-centre heights (m) of NC_NZ levels whose spacing grows geometrically from
    NC_DZ_BOTTOM at the ground to NC_DZ_TOP at the top, and the spacings."""
    ratio = (NC_DZ_TOP / NC_DZ_BOTTOM) ** (1.0 / (NC_NZ - 1))
    dz = NC_DZ_BOTTOM * ratio ** np.arange(NC_NZ)
    tops = np.cumsum(dz)
    return tops - dz / 2.0, dz


def standard_atmosphere_density(z):
    """Air density (kg m-3) of the ICAO standard atmosphere's troposphere at height z (m):
    rho = rho0 (1 - L z / T0)^(g / (R L) - 1), rho0 = 1.225, T0 = 288.15 K, L = 0.0065 K/m,
    g = 9.80665, R = 287.053 J/(kg K) (ISO 2533:1975)."""
    rho0, t0, lapse, g, r = 1.225, 288.15, 0.0065, 9.80665, 287.053
    return rho0 * (1.0 - lapse * z / t0) ** (g / (r * lapse) - 1.0)


def les_ql(nimbus):
    """ql(time, z, y, x) in kg/kg: a metaball cumulus drifting with the wind along +x,
    with the adiabatic-like increase of liquid water above its base."""
    z, _ = stretched_levels()
    shift = int(round(NC_WIND * (NC_TIMES[1] - NC_TIMES[0]) / NC_DX))   # cells per step
    extra = shift * (len(NC_TIMES) - 1)
    fine_dz = 12.5
    nz_fine = int(np.ceil(z[-1] / fine_dz)) + 2
    x0 = NC_DX / 2.0 - extra * NC_DX
    dims = (NC_NX + extra, NC_NY, nz_fine)
    bounds = (x0, x0 + (dims[0] - 1) * NC_DX, NC_DX / 2.0, NC_DX / 2.0 + (NC_NY - 1) * NC_DX,
              0.0, (nz_fine - 1) * fine_dz)
    density = metaball_density(nimbus, dims, bounds, NC_SEED, BaseHeight=NC_CLOUD_BASE,
                               FootprintRadius=350.0, BaseBallRadiusRange=(200.0, 350.0),
                               TowerHeight=600.0, NumberOfBaseBalls=8)
    density = np.clip(density, 0.0, 1.0)
    # Linear interpolation from the 12.5 m generator levels to the stretched levels.
    f = z / fine_dz
    lo = np.floor(f).astype(int)
    w = (f - lo)[:, None, None]
    on_levels = (1.0 - w) * density[lo] + w * density[lo + 1]          # [z, y, x]
    water = on_levels * np.maximum(z - NC_CLOUD_BASE, 0.0)[:, None, None] * NC_QL_LAPSE
    ql = np.empty((len(NC_TIMES), NC_NZ, NC_NY, NC_NX), dtype=np.float32)
    for step in range(len(NC_TIMES)):
        first = extra - shift * step        # the cloud moves +x: the window moves -x
        ql[step] = NC_GROWTH[step] * water[:, :, first:first + NC_NX]
    return ql


def write_les_netcdf(nimbus, path):
    """CF-1.8 NetCDF as an LES writes it: 1-D coordinate variables, float ql(time, z, y, x)."""
    import netCDF4
    z, dz = stretched_levels()
    ql = les_ql(nimbus)
    if os.path.exists(path):
        os.remove(path)
    nc = netCDF4.Dataset(path, "w", format="NETCDF4")
    nc.Conventions = "CF-1.8"
    nc.title = "LES-like shallow cumulus: liquid water mixing ratio"
    nc.institution = "Nimbus sample data"
    nc.source = ("vtkNimbusMetaballCloudSource (seed %d) sampled on an LES grid by "
                 "scripts/make-user-sample-data.py" % NC_SEED)
    nc.comment = ("Not a simulation: a metaball cumulus drifting at %g m/s along +x, liquid "
                  "water increasing %.2g kg/kg per m above the base at %g m." %
                  (NC_WIND, NC_QL_LAPSE, NC_CLOUD_BASE))
    nc.createDimension("time", None)
    nc.createDimension("z", NC_NZ)
    nc.createDimension("y", NC_NY)
    nc.createDimension("x", NC_NX)
    time = nc.createVariable("time", "f8", ("time",))
    time.units = "seconds since 2021-07-15 06:00:00"
    time.calendar = "standard"
    time.standard_name = "time"
    time.axis = "T"
    time[:] = np.array(NC_TIMES)
    zvar = nc.createVariable("z", "f4", ("z",))
    zvar.units = "m"
    zvar.positive = "up"
    zvar.axis = "Z"
    zvar.standard_name = "height"
    zvar.long_name = "height of the cell centres above the surface"
    zvar[:] = z
    for name, n, axis in (("y", NC_NY, "Y"), ("x", NC_NX, "X")):
        var = nc.createVariable(name, "f4", (name,))
        var.units = "m"
        var.axis = axis
        var.long_name = f"{name} of the cell centres"
        var[:] = NC_DX / 2.0 + NC_DX * np.arange(n)
    qlvar = nc.createVariable("ql", "f4", ("time", "z", "y", "x"), zlib=True, complevel=6,
                              shuffle=True)
    qlvar.units = "kg/kg"
    qlvar.long_name = "liquid water mixing ratio"
    qlvar.standard_name = "mass_fraction_of_cloud_liquid_water_in_air"
    qlvar[:] = ql
    rho = nc.createVariable("rho", "f4", ("z",))
    rho.units = "kg m-3"
    rho.long_name = "reference air density (ICAO standard atmosphere)"
    rho.standard_name = "air_density"
    rho[:] = standard_atmosphere_density(z)
    nc.close()
    print(f"{path}: ql {ql.shape} (time, z, y, x), max {ql.max():.3g} kg/kg, z {z[0]:.1f}.."
          f"{z[-1]:.1f} m (dz {dz[0]:.1f}..{dz[-1]:.1f} m), {os.path.getsize(path)} bytes")


def automaton_extinction():
    """Extinction (1/m) on PVTI_DIMS points [z, y, x]: the cloud automaton's density in a
    layer of PVTI_LAYER levels, tapered to zero near the box's sides and the layer's base
    so that the box has clear air around the clouds."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    nimbus = import_nimbus()
    nx, ny, nz = PVTI_DIMS
    first, levels = PVTI_LAYER
    spacing_m = PVTI_SPACING_KM * 1000.0
    automaton = nimbus.vtkNimbusCloudAutomatonSource()
    automaton.SetDimensions(nx, ny, levels)
    automaton.SetBounds(0.0, (nx - 1) * spacing_m, 0.0, (ny - 1) * spacing_m,
                        first * spacing_m, (first + levels - 1) * spacing_m)
    automaton.SetSeed(PVTI_SEED)
    automaton.SetNumberOfFormationRegions(2)
    automaton.SetFormationRegionRadiusRange(400.0, 700.0)
    automaton.Update()
    density = vtk_to_numpy(automaton.GetOutput().GetPointData().GetArray("density"))
    density = density.reshape(levels, ny, nx).astype(np.float64)

    def taper(n, width):
        """1 inside, sin^2 ramp to 0 over `width` points at both ends."""
        ramp = np.ones(n)
        t = np.sin(0.5 * np.pi * np.arange(1, width + 1) / (width + 1)) ** 2
        ramp[:width] = t
        ramp[n - width:] = t[::-1]
        return ramp

    layer = density * taper(ny, 8)[None, :, None] * taper(nx, 8)[None, None, :]
    layer *= taper(levels, 3)[:, None, None]
    sigma = np.zeros((nz, ny, nx))
    sigma[first:first + levels] = PVTI_SIGMA_PER_DENSITY * layer
    return sigma.astype(np.float32)


def ImagePieces(image):
    """A source that gives `image` one requested extent at a time (CAN_PRODUCE_SUB_EXTENT),
    so that vtkXMLPImageDataWriter writes pieces of it; a vtkImageData given with
    SetInputData would be written whole into every piece."""
    from vtkmodules.util.vtkAlgorithm import VTKPythonAlgorithmBase
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkCommonExecutionModel import vtkAlgorithm
    from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline as sddp
    from vtkmodules.vtkImagingCore import vtkExtractVOI

    class Source(VTKPythonAlgorithmBase):
        def __init__(self):
            VTKPythonAlgorithmBase.__init__(self, nInputPorts=0, nOutputPorts=1,
                                            outputType="vtkImageData")

        def RequestInformation(self, request, inInfo, outInfo):
            info = outInfo.GetInformationObject(0)
            info.Set(sddp.WHOLE_EXTENT(), image.GetExtent(), 6)
            info.Set(vtkAlgorithm.CAN_PRODUCE_SUB_EXTENT(), 1)
            return 1

        def RequestData(self, request, inInfo, outInfo):
            info = outInfo.GetInformationObject(0)
            voi = vtkExtractVOI()
            voi.SetInputData(image)
            voi.SetVOI(info.Get(sddp.UPDATE_EXTENT()))
            voi.Update()
            output = vtkImageData.GetData(outInfo)
            output.ShallowCopy(voi.GetOutput())
            output.GetFieldData().ShallowCopy(image.GetFieldData())
            return 1

    return Source()


def write_pvti(path):
    """The extinction field as a .pvti of PVTI_PIECES .vti pieces, coordinates in km."""
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonCore import vtkStringArray
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkIOParallelXML import vtkXMLPImageDataWriter
    sigma = automaton_extinction()
    nx, ny, nz = PVTI_DIMS
    image = vtkImageData()
    image.SetDimensions(nx, ny, nz)
    image.SetSpacing(PVTI_SPACING_KM, PVTI_SPACING_KM, PVTI_SPACING_KM)
    image.SetOrigin(0.0, 0.0, 0.0)
    array = numpy_to_vtk(sigma.ravel(), deep=1)
    array.SetName("extinction")
    image.GetPointData().SetScalars(array)
    for key, value in (("extinction_units", "1/m"), ("length_units", "km"),
                       ("up_axis", "+z"),
                       ("source", "vtkNimbusCloudAutomatonSource seed %d, "
                        "scripts/make-user-sample-data.py" % PVTI_SEED)):
        note = vtkStringArray()
        note.SetName(key)
        note.InsertNextValue(value)
        image.GetFieldData().AddArray(note)
    base = os.path.splitext(path)[0]
    for stale in [path] + [f"{base}_{i}.vti" for i in range(16)]:
        if os.path.exists(stale):
            os.remove(stale)
    pieces_source = ImagePieces(image)    # kept alive while the writer runs
    writer = vtkXMLPImageDataWriter()
    writer.SetInputConnection(pieces_source.GetOutputPort())
    writer.SetFileName(path)
    writer.SetNumberOfPieces(PVTI_PIECES)
    writer.SetStartPiece(0)
    writer.SetEndPiece(PVTI_PIECES - 1)
    writer.SetDataModeToAppended()
    writer.SetCompressorTypeToZLib()
    if not writer.Write():
        sys.exit(f"could not write {path}")
    pieces = sorted(f for f in os.listdir(os.path.dirname(path) or ".")
                    if f.startswith(os.path.basename(base)) and f.endswith(".vti"))
    size = os.path.getsize(path) + sum(
        os.path.getsize(os.path.join(os.path.dirname(path), f)) for f in pieces)
    print(f"{path}: {nx} x {ny} x {nz} points at {PVTI_SPACING_KM} km, extinction max "
          f"{sigma.max():.3g} 1/m, pieces {pieces}, {size} bytes in all")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output-dir", default=os.path.join(REPO, "Data", "UserData"))
    args = parser.parse_args()
    os.makedirs(args.output_dir, exist_ok=True)
    nimbus = import_nimbus()
    write_y_up_vdb(nimbus, os.path.join(args.output_dir, VDB_NAME))
    write_les_netcdf(nimbus, os.path.join(args.output_dir, NC_NAME))
    write_pvti(os.path.join(args.output_dir, PVTI_NAME))
    return 0


if __name__ == "__main__":
    sys.exit(main())
