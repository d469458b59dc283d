"""Nimbus: clouds, smoke, lightning and sky for VTK.

    import nimbus
    source = nimbus.vtkNimbusMetaballCloudSource()

The VTK classes of the Nimbus modules are re-exported here; VTK itself comes from
``vtkmodules`` (ParaView's VTK on Debian, through python3-paraview).
"""
from .NimbusFilters import *  # noqa: F401,F403
from .NimbusReference import *  # noqa: F401,F403
from .NimbusRepresentations import *  # noqa: F401,F403
try:  # vtkNimbusOpenVDBReader/Writer: built only when OpenVDB was found
    from .NimbusIOOpenVDB import *  # noqa: F401,F403
except ModuleNotFoundError:
    pass

__version__ = "0.1.0"


def offscreen_if_requested():
    """NIMBUS_OFFSCREEN=egl: make vtkRenderWindow() an EGL pbuffer window
    (vtkNimbusOffscreenRenderWindow), so that rendering needs no X server. Returns True
    when installed, False when the variable is unset, empty or 0; exits with a message
    (status 2) on any other value. Call before the first vtkRenderWindow() is made."""
    installed = vtkNimbusOffscreenRenderWindow.InstallFactoryIfRequested()  # noqa: F405
    if installed < 0:
        raise SystemExit(2)
    return installed == 1


def find_cloud_mapper(renderer):
    """The first visible vtkNimbusCloudVolumeMapper among `renderer`'s volumes, or None
    (e.g. ParaView's Cloud representation: view.SMProxy.GetRenderer())."""
    volumes = renderer.GetVolumes()
    volumes.InitTraversal()
    for _ in range(volumes.GetNumberOfItems()):
        volume = volumes.GetNextVolume()
        mapper = volume.GetMapper()
        if volume.GetVisibility() and mapper is not None and \
                mapper.IsA("vtkNimbusCloudVolumeMapper"):
            return mapper
    return None
