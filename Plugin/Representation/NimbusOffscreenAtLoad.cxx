// NIMBUS_OFFSCREEN=egl in ParaView (pvpython, pvbatch, pvserver): when the Nimbus plugin
// loads (LoadPlugin, PV_PLUGIN_PATH), install the vtkRenderWindow override so that the
// render views ParaView makes afterwards draw on an EGL pbuffer, with no X server. A
// static initializer of this library: it runs when the plugin's libraries are loaded,
// before any view of the session is created by the script.
#include "vtkNimbusOffscreenRenderWindow.h"

namespace
{
struct InstallOffscreenAtLoad
{
  InstallOffscreenAtLoad() { vtkNimbusOffscreenRenderWindow::InstallFactoryIfRequested(); }
};
const InstallOffscreenAtLoad installOffscreenAtLoad;
}
