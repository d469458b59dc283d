#include "vtkNimbusOffscreenRenderWindow.h"

#include "OffscreenOSMesa.h"

#include "vtkGenericRenderWindowInteractor.h"
#include "vtkObjectFactory.h"
#include "vtkObjectFactoryCollection.h"
#include "vtkOpenGLState.h"
#include "vtkSmartPointer.h"
#include "vtkVersionMacros.h"
#include "vtk_glew.h"

// EGL after GLEW; no X11 types from eglplatform.h (this window never talks to X).
#ifndef EGL_NO_X11
#define EGL_NO_X11
#endif
#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <atomic>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <map>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

namespace
{
const char* const OffscreenVariable = "NIMBUS_OFFSCREEN";
const char* const OffscreenFlag = "--offscreen";

//------------------------------------------------------------------------------
// EGL displays are process-wide: eglGetPlatformDisplay returns the same handle to every
// caller and eglTerminate ends every context on it. Windows share a display through this
// count and the last one to let go terminates it.
std::mutex DisplayMutex;
std::map<EGLDisplay, int>& DisplayUsers()
{
  static std::map<EGLDisplay, int> users;
  return users;
}

bool AcquireDisplay(EGLDisplay display)
{
  std::lock_guard<std::mutex> lock(DisplayMutex);
  int& users = DisplayUsers()[display];
  if (users == 0)
  {
    EGLint major = 0;
    EGLint minor = 0;
    if (!eglInitialize(display, &major, &minor))
    {
      DisplayUsers().erase(display);
      return false;
    }
  }
  ++users;
  return true;
}

void ReleaseDisplay(EGLDisplay display)
{
  std::lock_guard<std::mutex> lock(DisplayMutex);
  auto found = DisplayUsers().find(display);
  if (found == DisplayUsers().end())
  {
    return;
  }
  if (--found->second == 0)
  {
    eglTerminate(display);
    DisplayUsers().erase(found);
  }
}

bool HasExtension(const char* extensions, const char* name)
{
  if (!extensions)
  {
    return false;
  }
  const std::size_t length = std::strlen(name);
  for (const char* at = std::strstr(extensions, name); at; at = std::strstr(at + 1, name))
  {
    const bool starts = at == extensions || at[-1] == ' ';
    const bool ends = at[length] == '\0' || at[length] == ' ';
    if (starts && ends)
    {
      return true;
    }
  }
  return false;
}

std::string ErrorName(EGLint error)
{
  switch (error)
  {
    case EGL_SUCCESS:
      return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED:
      return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS:
      return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC:
      return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE:
      return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG:
      return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT:
      return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY:
      return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH:
      return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER:
      return "EGL_BAD_PARAMETER";
    case EGL_BAD_SURFACE:
      return "EGL_BAD_SURFACE";
    default:
    {
      std::ostringstream name;
      name << "EGL error 0x" << std::hex << error;
      return name.str();
    }
  }
}

// One way to reach an EGL display.
struct DisplayCandidate
{
  std::string Platform; // "device", "surfaceless", "default"
  EGLDisplay Display;
};

// Devices of EGL_EXT_platform_device, then Mesa's surfaceless platform, then the default
// display, as far as the client extensions offer them.
std::vector<DisplayCandidate> DisplayCandidates()
{
  std::vector<DisplayCandidate> candidates;
  const char* clientExtensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  auto getPlatformDisplay = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
    eglGetProcAddress("eglGetPlatformDisplayEXT"));
  const bool platformBase =
    getPlatformDisplay && HasExtension(clientExtensions, "EGL_EXT_platform_base");

  if (platformBase && HasExtension(clientExtensions, "EGL_EXT_platform_device"))
  {
    auto queryDevices =
      reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
    EGLint count = 0;
    if (queryDevices && queryDevices(0, nullptr, &count) && count > 0)
    {
      std::vector<EGLDeviceEXT> devices(static_cast<std::size_t>(count));
      if (queryDevices(count, devices.data(), &count))
      {
        for (EGLint i = 0; i < count; ++i)
        {
          EGLDisplay display = getPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
          if (display != EGL_NO_DISPLAY)
          {
            candidates.push_back({ "device", display });
          }
        }
      }
    }
  }
  if (platformBase && HasExtension(clientExtensions, "EGL_MESA_platform_surfaceless"))
  {
    EGLDisplay display =
      getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (display != EGL_NO_DISPLAY)
    {
      candidates.push_back({ "surfaceless", display });
    }
  }
  EGLDisplay display = eglGetDisplay(EGL_DEFAULT_DISPLAY);
  if (display != EGL_NO_DISPLAY)
  {
    candidates.push_back({ "default", display });
  }
  return candidates;
}

//------------------------------------------------------------------------------
// The overrides vtkRenderWindow -> vtkNimbusOffscreenRenderWindow and
// vtkRenderWindowInteractor -> vtkGenericRenderWindowInteractor: VTK's own interactor
// (vtkXRenderWindowInteractor) opens the X display when a window it watches first renders
// (ParaView's views have one), and there is none.
const char* const OverriddenClasses[] = { "vtkRenderWindow", "vtkRenderWindowInteractor" };

vtkObject* NewOffscreenWindow()
{
  return vtkNimbusOffscreenRenderWindow::New();
}

vtkObject* NewGenericInteractor()
{
  return vtkGenericRenderWindowInteractor::New();
}

class vtkNimbusOffscreenFactory : public vtkObjectFactory
{
public:
  static vtkNimbusOffscreenFactory* New()
  {
    auto* factory = new vtkNimbusOffscreenFactory;
    factory->InitializeObjectBase();
    return factory;
  }
  vtkTypeMacro(vtkNimbusOffscreenFactory, vtkObjectFactory);
  const char* GetVTKSourceVersion() override { return VTK_SOURCE_VERSION; }
  const char* GetDescription() override
  {
    return "Nimbus: vtkRenderWindow on an EGL pbuffer or OSMesa (NIMBUS_OFFSCREEN=egl|osmesa, "
           "--offscreen)";
  }

protected:
  vtkNimbusOffscreenFactory()
  {
    this->RegisterOverride("vtkRenderWindow", "vtkNimbusOffscreenRenderWindow",
      "EGL pbuffer or OSMesa render window, no X server", 1, NewOffscreenWindow);
    this->RegisterOverride("vtkRenderWindowInteractor", "vtkGenericRenderWindowInteractor",
      "an interactor that needs no X server", 1, NewGenericInteractor);
  }

private:
  vtkNimbusOffscreenFactory(const vtkNimbusOffscreenFactory&) = delete;
  void operator=(const vtkNimbusOffscreenFactory&) = delete;
};

std::mutex FactoryMutex;
vtkObjectFactory* InstalledFactory = nullptr; // held by vtkObjectFactory's registry

std::atomic<int> DefaultContextAPI{ vtkNimbusOffscreenRenderWindow::EGLThenOSMesa };
std::once_flag OSMesaFallbackNotice;

// Lets go of the EGL context current on this thread, whichever window made it.
void ReleaseCurrentEGL()
{
  if (eglGetCurrentContext() != EGL_NO_CONTEXT)
  {
    eglMakeCurrent(eglGetCurrentDisplay(), EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  }
}
}

//------------------------------------------------------------------------------
struct vtkNimbusOffscreenRenderWindow::Internals
{
  enum class API
  {
    None,
    EGL,
    OSMesa
  };
  API Current = API::None;
  nimbus::OffscreenOSMesa OSMesa;
  EGLDisplay Display = EGL_NO_DISPLAY;
  EGLConfig Config = nullptr;
  EGLContext Context = EGL_NO_CONTEXT;
  EGLSurface Surface = EGL_NO_SURFACE;
  int SurfaceSize[2] = { 0, 0 };
  std::string Platform;
  std::string Capabilities;
};

vtkStandardNewMacro(vtkNimbusOffscreenRenderWindow);

//------------------------------------------------------------------------------
vtkNimbusOffscreenRenderWindow::vtkNimbusOffscreenRenderWindow()
  : RequestedContextAPI(DefaultContextAPI)
  , Internal(new Internals)
{
  // Our own context: VTK keeps its GL state between renders, as with an X window.
  this->OwnContext = 1;
  this->SetShowWindow(false);
  this->SetWindowName("Nimbus (offscreen)");
}

//------------------------------------------------------------------------------
vtkNimbusOffscreenRenderWindow::~vtkNimbusOffscreenRenderWindow()
{
  // The base class's destructor would only reach its own Finalize.
  this->Finalize();
}

//------------------------------------------------------------------------------
void vtkNimbusOffscreenRenderWindow::InstallFactory()
{
  std::lock_guard<std::mutex> lock(FactoryMutex);
  if (InstalledFactory)
  {
    return;
  }
  // vtkObjectFactory::CreateInstance asks the registered factories in order and the first
  // override wins; VTK's own (vtkRenderingOpenGL2's vtkXOpenGLRenderWindow, vtkRenderingUI's
  // vtkXRenderWindowInteractor) registered at start-up, so take the factories that override
  // either class out, register ours and put them back behind it. Factories registered later
  // also come after ours.
  std::vector<vtkSmartPointer<vtkObjectFactory>> others;
  vtkObjectFactoryCollection* registered = vtkObjectFactory::GetRegisteredFactories();
  vtkCollectionSimpleIterator it;
  registered->InitTraversal(it);
  while (vtkObjectFactory* factory = registered->GetNextObjectFactory(it))
  {
    for (const char* overridden : OverriddenClasses)
    {
      if (factory->HasOverride(overridden))
      {
        others.emplace_back(factory);
        break;
      }
    }
  }
  for (auto& factory : others)
  {
    vtkObjectFactory::UnRegisterFactory(factory);
  }
  vtkNimbusOffscreenFactory* ours = vtkNimbusOffscreenFactory::New();
  vtkObjectFactory::RegisterFactory(ours);
  ours->Delete();
  InstalledFactory = ours;
  for (auto& factory : others)
  {
    vtkObjectFactory::RegisterFactory(factory);
  }
}

//------------------------------------------------------------------------------
void vtkNimbusOffscreenRenderWindow::RemoveFactory()
{
  std::lock_guard<std::mutex> lock(FactoryMutex);
  if (InstalledFactory)
  {
    vtkObjectFactory::UnRegisterFactory(InstalledFactory);
    InstalledFactory = nullptr;
  }
}

//------------------------------------------------------------------------------
bool vtkNimbusOffscreenRenderWindow::IsFactoryInstalled()
{
  std::lock_guard<std::mutex> lock(FactoryMutex);
  return InstalledFactory != nullptr;
}

//------------------------------------------------------------------------------
const char* vtkNimbusOffscreenRenderWindow::GetEnvironmentVariableName()
{
  return OffscreenVariable;
}

//------------------------------------------------------------------------------
void vtkNimbusOffscreenRenderWindow::SetDefaultRequestedContextAPI(int api)
{
  DefaultContextAPI = api < EGLThenOSMesa ? EGLThenOSMesa : (api > OSMesaOnly ? OSMesaOnly : api);
}

//------------------------------------------------------------------------------
int vtkNimbusOffscreenRenderWindow::GetDefaultRequestedContextAPI()
{
  return DefaultContextAPI;
}

//------------------------------------------------------------------------------
bool vtkNimbusOffscreenRenderWindow::HasOSMesa()
{
  return nimbus::OffscreenOSMesa::Available();
}

//------------------------------------------------------------------------------
int vtkNimbusOffscreenRenderWindow::InstallFactoryIfRequested()
{
  const char* value = std::getenv(OffscreenVariable);
  if (!value || value[0] == '\0' || std::strcmp(value, "0") == 0)
  {
    return 0;
  }
  if (std::strcmp(value, "egl") == 0 || std::strcmp(value, "EGL") == 0)
  {
    vtkNimbusOffscreenRenderWindow::SetDefaultRequestedContextAPI(EGLThenOSMesa);
    vtkNimbusOffscreenRenderWindow::InstallFactory();
    return 1;
  }
  const bool osmesa = std::strcmp(value, "osmesa") == 0 || std::strcmp(value, "OSMesa") == 0 ||
    std::strcmp(value, "OSMESA") == 0;
  if (osmesa && vtkNimbusOffscreenRenderWindow::HasOSMesa())
  {
    vtkNimbusOffscreenRenderWindow::SetDefaultRequestedContextAPI(OSMesaOnly);
    vtkNimbusOffscreenRenderWindow::InstallFactory();
    return 1;
  }
  if (osmesa)
  {
    std::cerr << "Error: " << OffscreenVariable << "=" << value
              << ": this build of Nimbus has no OSMesa (configure found no GL/osmesa.h and "
                 "libOSMesa; Debian: install libosmesa6-dev and configure again). Use "
              << OffscreenVariable << "=egl, or an X display.\n";
    return -1;
  }
  std::cerr << "Error: " << OffscreenVariable << "=" << value << " is not understood: use "
            << OffscreenVariable << "=egl to render without an X server (EGL, else OSMesa), "
            << OffscreenVariable
            << "=osmesa for OSMesa only, or leave it unset, empty or 0 for an X display.\n";
  return -1;
}

//------------------------------------------------------------------------------
int vtkNimbusOffscreenRenderWindow::InstallIfRequested(int& argc, char* argv[])
{
  bool flag = false;
  int kept = argc > 0 ? 1 : 0;
  for (int i = 1; i < argc; ++i)
  {
    if (std::strcmp(argv[i], OffscreenFlag) == 0)
    {
      flag = true;
    }
    else
    {
      argv[kept++] = argv[i];
    }
  }
  if (kept < argc)
  {
    argv[kept] = nullptr;
  }
  argc = kept;

  const int requested = vtkNimbusOffscreenRenderWindow::InstallFactoryIfRequested();
  if (requested < 0)
  {
    return -1;
  }
  if (flag && requested == 0)
  {
    vtkNimbusOffscreenRenderWindow::InstallFactory();
    return 1;
  }
  return requested;
}

//------------------------------------------------------------------------------
bool vtkNimbusOffscreenRenderWindow::CreateContext()
{
  Internals& in = *this->Internal;
  if (in.Current != Internals::API::None)
  {
    return true;
  }
  const int width = this->Size[0] > 0 ? this->Size[0] : 300;
  const int height = this->Size[1] > 0 ? this->Size[1] : 300;
  const int requested = this->RequestedContextAPI;

  std::string eglTried;
  if (requested != OSMesaOnly && this->CreateEGLContext(width, height, eglTried))
  {
    return true;
  }
  std::string osmesaError;
  if (requested != EGLOnly && this->CreateOSMesaContext(width, height, osmesaError))
  {
    if (requested == EGLThenOSMesa)
    {
      // Once per process: every window takes the same way.
      std::call_once(OSMesaFallbackNotice,
        [&]
        {
          std::cerr << "Nimbus offscreen: no EGL display with an OpenGL 3.2 core context and a "
                       "pbuffer (tried:"
                    << eglTried << "); rendering with OSMesa ("
                    << nimbus::OffscreenOSMesa::LibraryName() << ").\n";
        });
    }
    return true;
  }

  std::ostringstream message;
  message << "No offscreen OpenGL context could be made (asked for by " << OffscreenVariable
          << " or " << OffscreenFlag << ").";
  if (requested != OSMesaOnly)
  {
    message << "\nEGL: no display with a desktop OpenGL 3.2 core context and a pbuffer; tried:"
            << eglTried;
  }
  if (requested != EGLOnly)
  {
    message << "\nOSMesa: " << osmesaError;
  }
  message << "\nInstall libEGL and a vendor library (Debian: libegl1 libegl-mesa0 for Mesa's "
             "llvmpipe, or NVIDIA's driver) or OSMesa (Debian: libosmesa6), or unset "
          << OffscreenVariable << " and render on an X display.";
  vtkErrorMacro(<< message.str());
  return false;
}

//------------------------------------------------------------------------------
bool vtkNimbusOffscreenRenderWindow::CreateOSMesaContext(int width, int height, std::string& error)
{
  Internals& in = *this->Internal;
  ReleaseCurrentEGL(); // libglvnd has one current API per thread
  if (!in.OSMesa.Create(width, height, error))
  {
    return false;
  }
  in.Current = Internals::API::OSMesa;
  return true;
}

//------------------------------------------------------------------------------
bool vtkNimbusOffscreenRenderWindow::CreateEGLContext(int width, int height, std::string& attempts)
{
  Internals& in = *this->Internal;
  nimbus::OffscreenOSMesa::ReleaseAnyCurrent(); // libglvnd has one current API per thread
  std::ostringstream tried;
  for (const DisplayCandidate& candidate : DisplayCandidates())
  {
    tried << "\n  " << candidate.Platform << ": ";
    if (!AcquireDisplay(candidate.Display))
    {
      tried << "eglInitialize failed (" << ErrorName(eglGetError()) << ")";
      continue;
    }
    const EGLint configAttributes[] = { EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE,
      EGL_OPENGL_BIT, EGL_RED_SIZE, 8, EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8, EGL_ALPHA_SIZE, 8,
      EGL_DEPTH_SIZE, 24, EGL_NONE };
    EGLConfig config = nullptr;
    EGLint configs = 0;
    if (!eglChooseConfig(candidate.Display, configAttributes, &config, 1, &configs) || configs < 1)
    {
      tried << "no RGBA8 + depth-24 pbuffer config for desktop OpenGL";
      ReleaseDisplay(candidate.Display);
      continue;
    }
    if (!eglBindAPI(EGL_OPENGL_API))
    {
      tried << "eglBindAPI(EGL_OPENGL_API) failed (" << ErrorName(eglGetError()) << ")";
      ReleaseDisplay(candidate.Display);
      continue;
    }
    const EGLint contextAttributes[] = { EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 2,
      EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE };
    EGLContext context =
      eglCreateContext(candidate.Display, config, EGL_NO_CONTEXT, contextAttributes);
    if (context == EGL_NO_CONTEXT)
    {
      tried << "no OpenGL 3.2 core context (" << ErrorName(eglGetError()) << ")";
      ReleaseDisplay(candidate.Display);
      continue;
    }
    const EGLint surfaceAttributes[] = { EGL_WIDTH, width, EGL_HEIGHT, height, EGL_NONE };
    EGLSurface surface = eglCreatePbufferSurface(candidate.Display, config, surfaceAttributes);
    if (surface == EGL_NO_SURFACE)
    {
      tried << "no " << width << "x" << height << " pbuffer (" << ErrorName(eglGetError()) << ")";
      eglDestroyContext(candidate.Display, context);
      ReleaseDisplay(candidate.Display);
      continue;
    }
    if (!eglMakeCurrent(candidate.Display, surface, surface, context))
    {
      tried << "eglMakeCurrent failed (" << ErrorName(eglGetError()) << ")";
      eglDestroySurface(candidate.Display, surface);
      eglDestroyContext(candidate.Display, context);
      ReleaseDisplay(candidate.Display);
      continue;
    }
    in.Display = candidate.Display;
    in.Config = config;
    in.Context = context;
    in.Surface = surface;
    in.SurfaceSize[0] = width;
    in.SurfaceSize[1] = height;
    in.Platform = candidate.Platform;
    in.Current = Internals::API::EGL;
    return true;
  }
  attempts = tried.str();
  if (attempts.empty())
  {
    attempts = "\n  no EGL display at all";
  }
  return false;
}

//------------------------------------------------------------------------------
void vtkNimbusOffscreenRenderWindow::DestroyContext()
{
  Internals& in = *this->Internal;
  if (in.Current == Internals::API::OSMesa)
  {
    in.OSMesa.Destroy();
    in.Current = Internals::API::None;
    return;
  }
  if (in.Display == EGL_NO_DISPLAY)
  {
    return;
  }
  if (eglGetCurrentContext() == in.Context)
  {
    eglMakeCurrent(in.Display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  }
  if (in.Surface != EGL_NO_SURFACE)
  {
    eglDestroySurface(in.Display, in.Surface);
  }
  if (in.Context != EGL_NO_CONTEXT)
  {
    eglDestroyContext(in.Display, in.Context);
  }
  ReleaseDisplay(in.Display);
  in.Display = EGL_NO_DISPLAY;
  in.Config = nullptr;
  in.Context = EGL_NO_CONTEXT;
  in.Surface = EGL_NO_SURFACE;
  in.SurfaceSize[0] = in.SurfaceSize[1] = 0;
  in.Platform.clear();
  in.Current = Internals::API::None;
}

//------------------------------------------------------------------------------
bool vtkNimbusOffscreenRenderWindow::ResizeSurface(int width, int height)
{
  Internals& in = *this->Internal;
  if (in.Current == Internals::API::OSMesa)
  {
    std::string error;
    if (!in.OSMesa.Resize(width, height, error))
    {
      vtkErrorMacro("Could not make a " << width << "x" << height << " OSMesa buffer: " << error);
      return false;
    }
    return true;
  }
  if (in.Context == EGL_NO_CONTEXT || width < 1 || height < 1 ||
    (in.SurfaceSize[0] == width && in.SurfaceSize[1] == height))
  {
    return true;
  }
  const bool wasCurrent = eglGetCurrentContext() == in.Context;
  if (wasCurrent)
  {
    eglMakeCurrent(in.Display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  }
  eglDestroySurface(in.Display, in.Surface);
  const EGLint surfaceAttributes[] = { EGL_WIDTH, width, EGL_HEIGHT, height, EGL_NONE };
  in.Surface = eglCreatePbufferSurface(in.Display, in.Config, surfaceAttributes);
  if (in.Surface == EGL_NO_SURFACE)
  {
    vtkErrorMacro("Could not make a " << width << "x" << height
                                      << " EGL pbuffer: " << ErrorName(eglGetError()));
    in.SurfaceSize[0] = in.SurfaceSize[1] = 0;
    return false;
  }
  in.SurfaceSize[0] = width;
  in.SurfaceSize[1] = height;
  if (wasCurrent)
  {
    eglMakeCurrent(in.Display, in.Surface, in.Surface, in.Context);
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkNimbusOffscreenRenderWindow::Initialize()
{
  if (!this->CreateContext())
  {
    return;
  }
  this->MakeCurrent();
  if (!this->Initialized)
  {
    // VTK's own initialization (not vtkGenericOpenGLRenderWindow's, which saves and
    // restores a host application's GL state around it): glew through OpenGLInitContext
    // below, VTK's GL state, the framebuffers.
    this->vtkOpenGLRenderWindow::OpenGLInit();
  }
  this->Mapped = this->Initialized ? 1 : 0;
}

//------------------------------------------------------------------------------
void vtkNimbusOffscreenRenderWindow::Finalize()
{
  if (this->Internal->Current != Internals::API::None)
  {
    this->MakeCurrent();
    this->ReleaseGraphicsResources(this);
    this->DestroyContext();
  }
  this->Initialized = false;
  this->Mapped = 0;
}

//------------------------------------------------------------------------------
void vtkNimbusOffscreenRenderWindow::OpenGLInitContext()
{
  if (!this->Initialized)
  {
    // Debian's GLEW loads the core GL entry points, then asks GLX for its display and
    // returns GLEW_ERROR_NO_GLX_DISPLAY when there is none (the GLX extensions are not
    // loaded; VTK does not use them). vtkOpenGLRenderWindow would take any code but
    // GLEW_OK as failure, so this window calls glewInit itself and accepts the two
    // GLX-stage codes; VTK's call below then finds the window initialized.
    const GLenum result = glewInit();
    const bool glxStageOnly =
      result == GLEW_ERROR_NO_GLX_DISPLAY || result == GLEW_ERROR_GLX_VERSION_11_ONLY;
    if (result != GLEW_OK && !glxStageOnly)
    {
      this->GlewInitValid = false;
      vtkErrorMacro("GLEW could not be initialized on the "
        << this->GetContextAPI()
        << " context: " << reinterpret_cast<const char*>(glewGetErrorString(result)));
      return;
    }
    if (!GLEW_VERSION_3_2)
    {
      this->GlewInitValid = false;
      vtkErrorMacro("The " << this->GetContextAPI()
                           << " context does not offer OpenGL 3.2 (GL_VERSION "
                           << reinterpret_cast<const char*>(glGetString(GL_VERSION)) << ")");
      return;
    }
    this->GlewInitValid = true;
    this->Initialized = true;

    // VTK keeps the widest line the hardware draws (its own init would have asked).
    GLfloat range[2] = { 1.0f, 1.0f };
    glGetFloatv(
      this->LineSmoothing ? GL_SMOOTH_LINE_WIDTH_RANGE : GL_ALIASED_LINE_WIDTH_RANGE, range);
    this->MaximumHardwareLineWidth = glGetError() == GL_NO_ERROR ? range[1] : 1.0f;
  }
  // Initialized now: only stamps the context's creation time.
  this->Superclass::OpenGLInitContext();
}

//------------------------------------------------------------------------------
void vtkNimbusOffscreenRenderWindow::Render()
{
  if (!this->ReadyForRendering)
  {
    return;
  }
  if (!this->Initialized)
  {
    this->Initialize();
    if (!this->Initialized)
    {
      return; // the error is reported
    }
  }
  // vtkOpenGLRenderWindow's render, as for an X window: our context, our GL state.
  this->vtkOpenGLRenderWindow::Render();
}

//------------------------------------------------------------------------------
void vtkNimbusOffscreenRenderWindow::Frame()
{
  this->MakeCurrent();
  // Blits VTK's display framebuffer to the pbuffer or the OSMesa buffer (the "hardware"
  // buffer). Both are single-buffered, so there is nothing to swap.
  this->vtkOpenGLRenderWindow::Frame();
}

//------------------------------------------------------------------------------
void vtkNimbusOffscreenRenderWindow::MakeCurrent()
{
  Internals& in = *this->Internal;
  if (in.Current == Internals::API::OSMesa)
  {
    if (!in.OSMesa.IsCurrent())
    {
      ReleaseCurrentEGL(); // another window's (libglvnd has one current API per thread)
      std::string error;
      if (!in.OSMesa.MakeCurrent(error))
      {
        vtkErrorMacro("Could not make the OSMesa context current: " << error);
      }
    }
    return;
  }
  if (in.Context != EGL_NO_CONTEXT && eglGetCurrentContext() != in.Context)
  {
    nimbus::OffscreenOSMesa::ReleaseAnyCurrent(); // another window's
    if (!eglMakeCurrent(in.Display, in.Surface, in.Surface, in.Context))
    {
      vtkErrorMacro("eglMakeCurrent failed: " << ErrorName(eglGetError()));
    }
  }
}

//------------------------------------------------------------------------------
void vtkNimbusOffscreenRenderWindow::ReleaseCurrent()
{
  Internals& in = *this->Internal;
  if (in.Current == Internals::API::OSMesa)
  {
    in.OSMesa.ReleaseCurrent();
    return;
  }
  if (in.Context != EGL_NO_CONTEXT && eglGetCurrentContext() == in.Context)
  {
    eglMakeCurrent(in.Display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  }
}

//------------------------------------------------------------------------------
bool vtkNimbusOffscreenRenderWindow::IsCurrent()
{
  if (this->Internal->Current == Internals::API::OSMesa)
  {
    return this->Internal->OSMesa.IsCurrent();
  }
  return this->Internal->Context != EGL_NO_CONTEXT &&
    eglGetCurrentContext() == this->Internal->Context;
}

//------------------------------------------------------------------------------
int vtkNimbusOffscreenRenderWindow::SupportsOpenGL()
{
  if (!this->Initialized)
  {
    this->Initialize();
  }
  return this->Initialized && this->GlewInitValid ? 1 : 0;
}

//------------------------------------------------------------------------------
vtkTypeBool vtkNimbusOffscreenRenderWindow::IsDirect()
{
  return this->Internal->Current != Internals::API::None ? 1 : 0;
}

//------------------------------------------------------------------------------
void vtkNimbusOffscreenRenderWindow::SetSize(int width, int height)
{
  this->Superclass::SetSize(width, height);
  this->ResizeSurface(width, height);
}

//------------------------------------------------------------------------------
void* vtkNimbusOffscreenRenderWindow::GetGenericContext()
{
  Internals& in = *this->Internal;
  return in.Current == Internals::API::OSMesa ? in.OSMesa.GetContext() : in.Context;
}

//------------------------------------------------------------------------------
void* vtkNimbusOffscreenRenderWindow::GetGenericDisplayId()
{
  Internals& in = *this->Internal;
  return in.Current == Internals::API::OSMesa ? nullptr : in.Display;
}

//------------------------------------------------------------------------------
void* vtkNimbusOffscreenRenderWindow::GetGenericDrawable()
{
  Internals& in = *this->Internal;
  return in.Current == Internals::API::OSMesa ? in.OSMesa.GetBuffer() : in.Surface;
}

//------------------------------------------------------------------------------
const char* vtkNimbusOffscreenRenderWindow::GetContextAPI()
{
  switch (this->Internal->Current)
  {
    case Internals::API::EGL:
      return "EGL";
    case Internals::API::OSMesa:
      return "OSMesa";
    default:
      return "";
  }
}

//------------------------------------------------------------------------------
const char* vtkNimbusOffscreenRenderWindow::GetEGLPlatform()
{
  return this->Internal->Platform.c_str();
}

//------------------------------------------------------------------------------
const char* vtkNimbusOffscreenRenderWindow::ReportCapabilities()
{
  if (!this->Initialized)
  {
    this->Initialize();
  }
  Internals& in = *this->Internal;
  if (in.Current == Internals::API::None)
  {
    in.Capabilities = "Offscreen: no EGL or OSMesa context could be made\n";
    return in.Capabilities.c_str();
  }
  this->MakeCurrent();
  std::ostringstream report;
  if (in.Current == Internals::API::OSMesa)
  {
    report << "OSMesa library: " << nimbus::OffscreenOSMesa::LibraryName() << "\n"
           << "OSMesa GL dispatch: " << nimbus::OffscreenOSMesa::DispatchDescription() << "\n"
           << "OSMesa buffer: " << in.OSMesa.GetWidth() << "x" << in.OSMesa.GetHeight() << "\n";
    const char* opengl = this->Superclass::ReportCapabilities();
    report << (opengl ? opengl : "");
    in.Capabilities = report.str();
    return in.Capabilities.c_str();
  }
  const char* vendor = eglQueryString(in.Display, EGL_VENDOR);
  const char* version = eglQueryString(in.Display, EGL_VERSION);
  report << "EGL platform: " << in.Platform << "\n"
         << "EGL vendor: " << (vendor ? vendor : "?") << "\n"
         << "EGL version: " << (version ? version : "?") << "\n"
         << "EGL pbuffer: " << in.SurfaceSize[0] << "x" << in.SurfaceSize[1] << "\n";
  const char* opengl = this->Superclass::ReportCapabilities();
  report << (opengl ? opengl : "");
  in.Capabilities = report.str();
  return in.Capabilities.c_str();
}

//------------------------------------------------------------------------------
void vtkNimbusOffscreenRenderWindow::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  Internals& in = *this->Internal;
  os << indent << "RequestedContextAPI: " << this->RequestedContextAPI << "\n";
  os << indent
     << "ContextAPI: " << (in.Current == Internals::API::None ? "(none)" : this->GetContextAPI())
     << "\n";
  os << indent << "OSMesaContext: " << in.OSMesa.GetContext() << " (" << in.OSMesa.GetWidth() << "x"
     << in.OSMesa.GetHeight() << ")\n";
  os << indent << "EGLPlatform: " << (in.Platform.empty() ? "(none)" : in.Platform) << "\n";
  os << indent << "EGLDisplay: " << in.Display << "\n";
  os << indent << "EGLContext: " << in.Context << "\n";
  os << indent << "EGLSurface: " << in.Surface << " (" << in.SurfaceSize[0] << "x"
     << in.SurfaceSize[1] << ")\n";
  os << indent << "FactoryInstalled: " << (IsFactoryInstalled() ? "yes" : "no") << "\n";
}
