// NIMBUS_OFFSCREEN=egl in ParaView (pvpython, pvbatch, pvserver): when the Nimbus plugin
// loads (LoadPlugin, PV_PLUGIN_PATH), install the vtkRenderWindow override so that the
// render views ParaView makes afterwards draw on an EGL pbuffer, with no X server. A
// static initializer of this library: it runs when the plugin's libraries are loaded,
// before any view of the session is created by the script.
//
// ParaView must also be told that this process can render. A render view asks every
// rank once, when it is created, whether it can render (vtkPVRenderingCapabilitiesInformation:
// on this X-only build, whether XOpenDisplay succeeds). Without a DISPLAY the answer is no,
// and the view turns remote rendering off: under MPI (pvbatch, pvserver) rank 0 then renders
// alone but still takes part in ordered compositing's collective data redistribution, which
// the other ranks never enter, and every rank waits forever. With the override installed
// the answer is yes (the override's window renders without X), so the same switch as
// pvbatch's `--disable-xdisplay-test` is set here, through ParaView's own option parser.
#include "vtkCLIOptions.h"
#include "vtkNew.h"
#include "vtkNimbusOffscreenRenderWindow.h"
#include "vtkProcessModule.h"
#include "vtkRemotingCoreConfiguration.h"

namespace
{
void SkipParaViewDisplayTest()
{
  vtkRemotingCoreConfiguration* config = vtkRemotingCoreConfiguration::GetInstance();
  if (!config || config->GetDisableXDisplayTests())
  {
    return;
  }
  // Only the rendering options, on a parser of their own: nothing else is touched.
  vtkNew<vtkCLIOptions> options;
  options->SetAllowExtras(true);
  options->SetGenerateWarnings(false);
  config->PopulateRenderingOptions(options, vtkProcessModule::PROCESS_BATCH);
  char program[] = "nimbus";
  char flag[] = "--disable-xdisplay-test";
  char* arguments[] = { program, flag, nullptr };
  int count = 2;
  char** argv = arguments;
  options->Parse(count, argv);
}

struct InstallOffscreenAtLoad
{
  InstallOffscreenAtLoad()
  {
    if (vtkNimbusOffscreenRenderWindow::InstallFactoryIfRequested() == 1)
    {
      SkipParaViewDisplayTest();
    }
  }
};
const InstallOffscreenAtLoad installOffscreenAtLoad;
}
