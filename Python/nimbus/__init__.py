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
