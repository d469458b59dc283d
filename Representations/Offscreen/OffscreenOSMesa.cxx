#include "OffscreenOSMesa.h"

#include <cstddef>

#ifdef NIMBUS_HAVE_OSMESA
#include <GL/osmesa.h>

#include <atomic>
#include <dlfcn.h>
#include <sstream>
#endif

namespace nimbus
{
#ifdef NIMBUS_HAVE_OSMESA
namespace
{
//------------------------------------------------------------------------------
// libOSMesa's entry points, loaded once per process.
struct OSMesaLibrary
{
  void* Handle = nullptr;
  std::string Name;
  std::string Error;
  OSMesaContext (*CreateContextAttribs)(const int*, OSMesaContext) = nullptr;
  GLboolean (*MakeCurrent)(OSMesaContext, void*, GLenum, GLsizei, GLsizei) = nullptr;
  void (*DestroyContext)(OSMesaContext) = nullptr;
  OSMesaContext (*GetCurrentContext)() = nullptr;
  OSMESAproc (*GetProcAddress)(const char*) = nullptr;
};

std::atomic<bool> LibraryLoaded{ false };

template <typename Function>
bool Resolve(void* handle, const char* name, Function& function)
{
  function = reinterpret_cast<Function>(dlsym(handle, name));
  return function != nullptr;
}

OSMesaLibrary LoadOSMesa()
{
  OSMesaLibrary library;
  // The library configure found (its soname, then its path), then the usual names.
  const char* const names[] = { NIMBUS_OSMESA_SONAME, NIMBUS_OSMESA_LIBRARY_PATH, "libOSMesa.so.8",
    "libOSMesa.so.6", "libOSMesa.so" };
  std::ostringstream tried;
  for (const char* name : names)
  {
    library.Handle = dlopen(name, RTLD_NOW | RTLD_LOCAL);
    if (library.Handle)
    {
      library.Name = name;
      break;
    }
    const char* why = dlerror();
    tried << "\n    " << (why ? why : name);
  }
  if (!library.Handle)
  {
    library.Error = "libOSMesa could not be loaded (Debian: libosmesa6):" + tried.str();
    return library;
  }
  if (!Resolve(library.Handle, "OSMesaCreateContextAttribs", library.CreateContextAttribs) ||
    !Resolve(library.Handle, "OSMesaMakeCurrent", library.MakeCurrent) ||
    !Resolve(library.Handle, "OSMesaDestroyContext", library.DestroyContext) ||
    !Resolve(library.Handle, "OSMesaGetCurrentContext", library.GetCurrentContext) ||
    !Resolve(library.Handle, "OSMesaGetProcAddress", library.GetProcAddress))
  {
    library.Error = library.Name +
      " lacks OSMesaCreateContextAttribs (Mesa 11.2 or newer is needed for an OpenGL "
      "core profile)";
    dlclose(library.Handle);
    library.Handle = nullptr;
    return library;
  }
  LibraryLoaded = true;
  return library;
}

const OSMesaLibrary& Library()
{
  static const OSMesaLibrary library = LoadOSMesa();
  return library;
}

//------------------------------------------------------------------------------
// libGLdispatch's interface for window-system libraries (libglvnd's GLdispatch.h, ABI
// version 1): a thread state, a dispatch table filled through a look-up callback.
struct GLDispatchThreadState
{
  int Tag; // libglvnd's GLX states have 0, EGL's 1
  void (*ThreadDestroyedCallback)(GLDispatchThreadState*);
  void* Private; // libGLdispatch's
};

struct GLDispatch
{
  bool Present = false; // libGL is libglvnd's
  std::string Error;
  int VendorID = 0;
  void* Table = nullptr;
  unsigned char (*MakeCurrent)(GLDispatchThreadState*, void*, int, const void*) = nullptr;
  void (*LoseCurrent)() = nullptr;
  GLDispatchThreadState* (*GetCurrentThreadState)() = nullptr;
};

const int GLDispatchABIVersion = 1;

void* LookUpInOSMesa(const char* name, void*)
{
  return reinterpret_cast<void*>(Library().GetProcAddress(name));
}

GLDispatch LoadGLDispatch()
{
  GLDispatch dispatch;
  // Loaded already when libGL, libOpenGL or libGLX is libglvnd's (VTK links them).
  void* handle = dlopen("libGLdispatch.so.0", RTLD_NOW | RTLD_NOLOAD);
  if (!handle)
  {
    // libGL is not libglvnd's: its GL calls follow the dispatch OSMesa makes current.
    return dispatch;
  }
  int (*abiVersion)() = nullptr;
  void (*init)() = nullptr;
  int (*newVendorID)() = nullptr;
  void* (*createTable)(void* (*)(const char*, void*), void*) = nullptr;
  if (!Resolve(handle, "__glDispatchGetABIVersion", abiVersion) ||
    !Resolve(handle, "__glDispatchInit", init) ||
    !Resolve(handle, "__glDispatchNewVendorID", newVendorID) ||
    !Resolve(handle, "__glDispatchCreateTable", createTable) ||
    !Resolve(handle, "__glDispatchMakeCurrent", dispatch.MakeCurrent) ||
    !Resolve(handle, "__glDispatchLoseCurrent", dispatch.LoseCurrent) ||
    !Resolve(handle, "__glDispatchGetCurrentThreadState", dispatch.GetCurrentThreadState))
  {
    dispatch.Error = "libGLdispatch.so.0 (libglvnd) lacks the functions libGLX and libEGL use";
    return dispatch;
  }
  if (abiVersion() != GLDispatchABIVersion)
  {
    std::ostringstream message;
    message << "libGLdispatch.so.0 (libglvnd) has ABI version " << abiVersion()
            << "; OSMesa's GL calls can be routed through version " << GLDispatchABIVersion
            << " only";
    dispatch.Error = message.str();
    return dispatch;
  }
  init(); // counted: libGLX and libOpenGL call it too
  dispatch.VendorID = newVendorID();
  dispatch.Table = createTable(LookUpInOSMesa, nullptr);
  if (!dispatch.Table)
  {
    dispatch.Error = "libGLdispatch could not make a dispatch table";
    return dispatch;
  }
  dispatch.Present = true;
  return dispatch;
}

const GLDispatch& Dispatch()
{
  static const GLDispatch dispatch = LoadGLDispatch();
  return dispatch;
}

// This thread's state while OSMesa's dispatch is current in libglvnd; its tag is neither
// GLX's nor EGL's, so glXGetCurrentContext and eglGetCurrentContext report none.
thread_local GLDispatchThreadState OSMesaThreadState = { 0x4f534d41, nullptr, nullptr };

bool OSMesaDispatchCurrent(const GLDispatch& dispatch)
{
  return dispatch.Present && dispatch.GetCurrentThreadState() == &OSMesaThreadState;
}
}

//------------------------------------------------------------------------------
bool OffscreenOSMesa::Available()
{
  return true;
}

//------------------------------------------------------------------------------
bool OffscreenOSMesa::Create(int width, int height, std::string& error)
{
  if (this->Context)
  {
    return true;
  }
  const OSMesaLibrary& library = Library();
  if (!library.Handle)
  {
    error = library.Error;
    return false;
  }
  const GLDispatch& dispatch = Dispatch();
  if (!dispatch.Error.empty())
  {
    error = dispatch.Error;
    return false;
  }
  const int attributes[] = { OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 24, OSMESA_STENCIL_BITS,
    0, OSMESA_ACCUM_BITS, 0, OSMESA_PROFILE, OSMESA_CORE_PROFILE, OSMESA_CONTEXT_MAJOR_VERSION, 3,
    OSMESA_CONTEXT_MINOR_VERSION, 2, 0 };
  this->Context = library.CreateContextAttribs(attributes, nullptr);
  if (!this->Context)
  {
    error = "OSMesaCreateContextAttribs gave no OpenGL 3.2 core context (" + library.Name + ")";
    return false;
  }
  this->Width = width > 0 ? width : 300;
  this->Height = height > 0 ? height : 300;
  this->Buffer.assign(static_cast<std::size_t>(this->Width) * this->Height * 4, 0);
  this->BoundBuffer = nullptr;
  if (!this->Bind(error))
  {
    this->Destroy();
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
void OffscreenOSMesa::Destroy()
{
  if (!this->Context)
  {
    return;
  }
  const OSMesaLibrary& library = Library();
  if (library.GetCurrentContext() == this->Context)
  {
    this->ReleaseCurrent();
  }
  library.DestroyContext(static_cast<OSMesaContext>(this->Context));
  this->Context = nullptr;
  this->Buffer.clear();
  this->Buffer.shrink_to_fit();
  this->BoundBuffer = nullptr;
  this->Width = this->Height = 0;
}

//------------------------------------------------------------------------------
bool OffscreenOSMesa::Bind(std::string& error)
{
  const OSMesaLibrary& library = Library();
  auto* context = static_cast<OSMesaContext>(this->Context);
  if (library.GetCurrentContext() != context || this->BoundBuffer != this->Buffer.data())
  {
    if (!library.MakeCurrent(
          context, this->Buffer.data(), GL_UNSIGNED_BYTE, this->Width, this->Height))
    {
      error = "OSMesaMakeCurrent failed";
      return false;
    }
    this->BoundBuffer = this->Buffer.data();
  }
  const GLDispatch& dispatch = Dispatch();
  if (!dispatch.Present || OSMesaDispatchCurrent(dispatch))
  {
    return true;
  }
  if (dispatch.GetCurrentThreadState() != nullptr)
  {
    error = "another API's OpenGL context (GLX or EGL) is current on this thread";
    return false;
  }
  if (!dispatch.MakeCurrent(&OSMesaThreadState, dispatch.Table, dispatch.VendorID, nullptr))
  {
    error = "libglvnd refused OSMesa's dispatch table (__glDispatchMakeCurrent)";
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
bool OffscreenOSMesa::MakeCurrent(std::string& error)
{
  if (!this->Context)
  {
    error = "no OSMesa context";
    return false;
  }
  return this->Bind(error);
}

//------------------------------------------------------------------------------
void OffscreenOSMesa::ReleaseCurrent()
{
  if (!this->Context)
  {
    return;
  }
  const OSMesaLibrary& library = Library();
  if (library.GetCurrentContext() == this->Context)
  {
    library.MakeCurrent(nullptr, nullptr, GL_UNSIGNED_BYTE, 0, 0);
    this->BoundBuffer = nullptr;
  }
  const GLDispatch& dispatch = Dispatch();
  if (OSMesaDispatchCurrent(dispatch))
  {
    dispatch.LoseCurrent();
  }
}

//------------------------------------------------------------------------------
bool OffscreenOSMesa::IsCurrent() const
{
  if (!this->Context || Library().GetCurrentContext() != this->Context)
  {
    return false;
  }
  const GLDispatch& dispatch = Dispatch();
  return !dispatch.Present || OSMesaDispatchCurrent(dispatch);
}

//------------------------------------------------------------------------------
bool OffscreenOSMesa::Resize(int width, int height, std::string& error)
{
  if (!this->Context || width < 1 || height < 1 || (width == this->Width && height == this->Height))
  {
    return true;
  }
  const OSMesaLibrary& library = Library();
  std::vector<unsigned char> buffer(static_cast<std::size_t>(width) * height * 4, 0);
  if (library.GetCurrentContext() == this->Context)
  {
    // Bound before the old buffer is freed: the context never points at freed memory.
    if (!library.MakeCurrent(static_cast<OSMesaContext>(this->Context), buffer.data(),
          GL_UNSIGNED_BYTE, width, height))
    {
      error = "OSMesaMakeCurrent failed for a new size";
      return false;
    }
    this->BoundBuffer = buffer.data();
  }
  else
  {
    this->BoundBuffer = nullptr; // bound at the next MakeCurrent
  }
  this->Buffer.swap(buffer);
  this->Width = width;
  this->Height = height;
  return true;
}

//------------------------------------------------------------------------------
std::string OffscreenOSMesa::LibraryName()
{
  return LibraryLoaded ? Library().Name : std::string();
}

//------------------------------------------------------------------------------
std::string OffscreenOSMesa::DispatchDescription()
{
  if (!LibraryLoaded)
  {
    return std::string();
  }
  return Dispatch().Present ? "libglvnd dispatch table filled by OSMesaGetProcAddress"
                            : "libOSMesa's own (libGL without libglvnd)";
}

//------------------------------------------------------------------------------
void OffscreenOSMesa::ReleaseAnyCurrent()
{
  if (!LibraryLoaded)
  {
    return; // nothing of OSMesa's can be current
  }
  const OSMesaLibrary& library = Library();
  if (library.GetCurrentContext())
  {
    library.MakeCurrent(nullptr, nullptr, GL_UNSIGNED_BYTE, 0, 0);
  }
  const GLDispatch& dispatch = Dispatch();
  if (OSMesaDispatchCurrent(dispatch))
  {
    dispatch.LoseCurrent();
  }
}

#else // no OSMesa in this build

//------------------------------------------------------------------------------
bool OffscreenOSMesa::Available()
{
  return false;
}

bool OffscreenOSMesa::Create(int, int, std::string& error)
{
  error = "this build of Nimbus has no OSMesa (configure found no GL/osmesa.h and libOSMesa: "
          "install libosmesa6-dev and configure again)";
  return false;
}

void OffscreenOSMesa::Destroy() {}

bool OffscreenOSMesa::Bind(std::string& error)
{
  return this->Create(0, 0, error);
}

bool OffscreenOSMesa::MakeCurrent(std::string& error)
{
  return this->Bind(error);
}

void OffscreenOSMesa::ReleaseCurrent() {}

bool OffscreenOSMesa::IsCurrent() const
{
  return false;
}

bool OffscreenOSMesa::Resize(int, int, std::string&)
{
  return true;
}

std::string OffscreenOSMesa::LibraryName()
{
  return std::string();
}

std::string OffscreenOSMesa::DispatchDescription()
{
  return std::string();
}

void OffscreenOSMesa::ReleaseAnyCurrent() {}

#endif

//------------------------------------------------------------------------------
OffscreenOSMesa::~OffscreenOSMesa()
{
  this->Destroy();
}

} // namespace nimbus
