/**
 * @class   vtkNimbusOffscreenRenderWindow
 * @brief   A render window with no X server: an EGL pbuffer, or OSMesa.
 *
 * Debian's VTK 9.2 (ParaView 5.11) is built for GLX only: it has no vtkEGLRenderWindow nor
 * vtkOSOpenGLRenderWindow, and its GLEW resolves every GL entry point through
 * glXGetProcAddressARB. This window owns its context and is otherwise VTK's own
 * vtkOpenGLRenderWindow: it renders into VTK's framebuffers, blits to its drawable as an X
 * window would, and reads pixels back the same way. The context comes from one of two APIs:
 *
 * - EGL: an EGL display, a desktop OpenGL 3.2+ core context and a pbuffer surface of the
 *   window's size (recreated when the size changes). With libglvnd the GL entry points
 *   are dispatch stubs that also work for a context made current with EGL. The EGL
 *   display is, in order of preference: a device of EGL_EXT_platform_device (the GPU on
 *   NVIDIA machines; Mesa's software device otherwise), Mesa's surfaceless platform
 *   (EGL_MESA_platform_surfaceless), then eglGetDisplay(EGL_DEFAULT_DISPLAY). The first
 *   one on which a pbuffer context can be made is used. Needs libEGL (libglvnd) and a
 *   vendor library: on Debian `libegl1 libegl-mesa0` (Mesa llvmpipe) or NVIDIA's driver.
 * - OSMesa (Mesa's llvmpipe into a buffer in memory, as on HPC nodes without a GPU): an
 *   OpenGL 3.2+ core context and an RGBA8 buffer of the window's size, taken where no EGL
 *   context can be made, or when asked for (RequestedContextAPI, NIMBUS_OFFSCREEN=osmesa).
 *   libOSMesa (Debian: libosmesa6) is loaded only then; OffscreenOSMesa.h says how GLEW's
 *   and VTK's GL calls are routed to OSMesaGetProcAddress through libglvnd's dispatch.
 *   Available when configure found OSMesa (HasOSMesa()).
 *
 * glewInit() returns GLEW_ERROR_NO_GLX_DISPLAY after loading the core GL entry points
 * when no GLX display is current; OpenGLInitContext() accepts that (and only the other
 * GLX-stage failure, GLEW_ERROR_GLX_VERSION_11_ONLY), where vtkOpenGLRenderWindow would
 * give up.
 *
 * Run-time selection: InstallFactory() registers an object-factory override so that
 * vtkRenderWindow::New() (and so vtkNew<vtkRenderWindow>, Python's vtkRenderWindow() and
 * ParaView's views) makes this class. InstallIfRequested() does so when the program was
 * given `--offscreen` (removed from argv) or the environment variable NIMBUS_OFFSCREEN is
 * `egl` (EGL, else OSMesa) or `osmesa` (OSMesa only); InstallFactoryIfRequested() reads
 * only the variable (Python, the ParaView plugin). NIMBUS_OFFSCREEN unset, empty or `0` is
 * off; any other value is an error.
 *
 * The factory also makes vtkRenderWindowInteractor::New() a vtkGenericRenderWindowInteractor:
 * VTK's X interactor opens the X display when its window first renders (ParaView's views
 * have one). Its Start() has no event loop and nothing to show; programs that render
 * offscreen do not start one (see IsFactoryInstalled()).
 */

#ifndef vtkNimbusOffscreenRenderWindow_h
#define vtkNimbusOffscreenRenderWindow_h

#include "NimbusRepresentationsModule.h" // For export macro
#include "vtkGenericOpenGLRenderWindow.h"
#include "vtkWrappingHints.h" // For VTK_WRAPEXCLUDE

#include <memory> // For std::unique_ptr
#include <string> // For std::string

class NIMBUSREPRESENTATIONS_EXPORT vtkNimbusOffscreenRenderWindow
  : public vtkGenericOpenGLRenderWindow
{
public:
  static vtkNimbusOffscreenRenderWindow* New();
  vtkTypeMacro(vtkNimbusOffscreenRenderWindow, vtkGenericOpenGLRenderWindow);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * Register the object-factory overrides vtkRenderWindow -> this class and
   * vtkRenderWindowInteractor -> vtkGenericRenderWindowInteractor, ahead of VTK's own
   * (vtkXOpenGLRenderWindow, vtkXRenderWindowInteractor). Idempotent.
   */
  static void InstallFactory();

  /**
   * Remove the override installed by InstallFactory() (vtkRenderWindow::New() makes VTK's
   * own window again). Idempotent.
   */
  static void RemoveFactory();

  /**
   * Whether InstallFactory() is in effect.
   */
  static bool IsFactoryInstalled();

  /**
   * Read NIMBUS_OFFSCREEN: `egl` (EGL, else OSMesa) or `osmesa` (OSMesa only) sets the
   * default RequestedContextAPI, installs the factory and returns 1; unset, empty or `0`
   * returns 0 (nothing changes); any other value, or `osmesa` in a build without OSMesa,
   * prints an error and returns -1.
   */
  static int InstallFactoryIfRequested();

  /**
   * For a program's main(): remove every `--offscreen` from argv (argc shrinks), then
   * install the factory if there was one or NIMBUS_OFFSCREEN asks for it. Returns 1 when
   * installed, 0 when not requested, -1 on a bad NIMBUS_OFFSCREEN value (printed).
   */
  VTK_WRAPEXCLUDE static int InstallIfRequested(int& argc, char* argv[]);

  /**
   * The name of the environment variable, "NIMBUS_OFFSCREEN".
   */
  static const char* GetEnvironmentVariableName();

  /**
   * Which API gives the context: EGL, else OSMesa where no EGL context can be made (the
   * default); EGL only; OSMesa only.
   */
  enum ContextAPIs
  {
    EGLThenOSMesa = 0,
    EGLOnly = 1,
    OSMesaOnly = 2
  };

  ///@{
  /**
   * The API this window asks for (ContextAPIs), read when its context is made
   * (Initialize()); new windows start with the default below.
   */
  vtkSetClampMacro(RequestedContextAPI, int, EGLThenOSMesa, OSMesaOnly);
  vtkGetMacro(RequestedContextAPI, int);
  ///@}

  ///@{
  /**
   * The RequestedContextAPI of windows made from now on (EGLThenOSMesa unless set here or
   * by NIMBUS_OFFSCREEN=osmesa).
   */
  static void SetDefaultRequestedContextAPI(int api);
  static int GetDefaultRequestedContextAPI();
  ///@}

  /**
   * Whether this build can render with OSMesa (configure found GL/osmesa.h and libOSMesa).
   */
  static bool HasOSMesa();

  ///@{
  /**
   * Make the context and its drawable (EGL display, context and pbuffer surface, or the
   * OSMesa context and buffer) if not made yet, make them current and initialize VTK's
   * OpenGL state. An error names what is missing.
   */
  void Initialize() override;
  void Finalize() override;
  ///@}

  void Render() override;
  void Frame() override;
  void MakeCurrent() override;
  void ReleaseCurrent() override;
  bool IsCurrent() override;
  int SupportsOpenGL() override;
  vtkTypeBool IsDirect() override;

  ///@{
  /**
   * The pbuffer (the OSMesa buffer) follows the window's size.
   */
  void SetSize(int width, int height) override;
  void SetSize(int a[2]) override { this->SetSize(a[0], a[1]); }
  ///@}

  ///@{
  /**
   * The EGLContext, EGLDisplay and EGLSurface; with OSMesa the OSMesaContext, nullptr and
   * the colour buffer (nullptr before Initialize()).
   */
  void* GetGenericContext() override;
  void* GetGenericDisplayId() override;
  void* GetGenericDrawable() override;
  ///@}

  /**
   * The API that gave the context: "EGL", "OSMesa", or "" before Initialize().
   */
  const char* GetContextAPI();

  /**
   * The EGL platform in use: "device", "surfaceless", "default", or "" before Initialize()
   * and with OSMesa.
   */
  const char* GetEGLPlatform();

  /**
   * The API (EGL's vendor, version and platform, or OSMesa's library and dispatch), then
   * vtkOpenGLRenderWindow's report (GL vendor, renderer, version).
   */
  const char* ReportCapabilities() override;

protected:
  vtkNimbusOffscreenRenderWindow();
  ~vtkNimbusOffscreenRenderWindow() override;

  void OpenGLInitContext() override;

  bool CreateContext();
  bool CreateEGLContext(int width, int height, std::string& tried);
  bool CreateOSMesaContext(int width, int height, std::string& error);
  void DestroyContext();
  bool ResizeSurface(int width, int height);

  int RequestedContextAPI;

private:
  vtkNimbusOffscreenRenderWindow(const vtkNimbusOffscreenRenderWindow&) = delete;
  void operator=(const vtkNimbusOffscreenRenderWindow&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Internal;
};

#endif
