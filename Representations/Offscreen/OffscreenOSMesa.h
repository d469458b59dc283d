/**
 * OSMesa for vtkNimbusOffscreenRenderWindow: an OpenGL 3.2+ core context rendering on the
 * CPU into a buffer in memory, with no X server and no EGL (Mesa's llvmpipe through
 * libOSMesa, as on HPC nodes without a GPU). Plain C++, no VTK.
 *
 * libOSMesa is loaded at run time (dlopen, its symbols kept local), the first time a
 * context is made: its gl* functions must not take the place of libglvnd's for every
 * other window in the process (NVIDIA's EGL, VTK's X windows), and programs that never
 * ask for OSMesa do not load it (nor LLVM).
 *
 * Debian's VTK calls the GL 1.x functions directly and Debian's GLEW gets all the others
 * from glXGetProcAddressARB; both are libglvnd's dispatch stubs, which do nothing while
 * no GLX or EGL context is current. MakeCurrent() therefore also makes a libglvnd
 * dispatch table current whose entries libglvnd looks up through OSMesaGetProcAddress
 * (libGLdispatch's interface for window-system libraries, ABI version 1, the one libGLX
 * and libEGL use): every GL call in the process, GLEW's included, reaches OSMesa. Where
 * libGL is not libglvnd's (no libGLdispatch loaded) OSMesa's own make-current is enough.
 *
 * Compiled without OSMesa (configure found no GL/osmesa.h or libOSMesa), Available() is
 * false and Create() says so.
 */

#ifndef nimbus_OffscreenOSMesa_h
#define nimbus_OffscreenOSMesa_h

#include <string>
#include <vector>

namespace nimbus
{

class OffscreenOSMesa
{
public:
  OffscreenOSMesa() = default;
  ~OffscreenOSMesa();
  OffscreenOSMesa(const OffscreenOSMesa&) = delete;
  OffscreenOSMesa& operator=(const OffscreenOSMesa&) = delete;

  /**
   * Whether this build can use OSMesa (found at configure time).
   */
  static bool Available();

  /**
   * Load libOSMesa (once per process), make an OpenGL 3.2+ core context with a depth
   * buffer and an RGBA8 colour buffer of width x height, and make it current. False
   * with the reason in `error`.
   */
  bool Create(int width, int height, std::string& error);

  /**
   * Release the context if current, destroy it and free the buffer.
   */
  void Destroy();

  bool IsCreated() const { return this->Context != nullptr; }

  /**
   * Make the context and libglvnd's OSMesa dispatch current on this thread. Another
   * API's context (EGL, GLX) must have been released first. False with the reason.
   */
  bool MakeCurrent(std::string& error);

  /**
   * Release the context and libglvnd's OSMesa dispatch if they are current.
   */
  void ReleaseCurrent();

  bool IsCurrent() const;

  /**
   * A new colour buffer of width x height (bound at once when the context is current).
   */
  bool Resize(int width, int height, std::string& error);

  void* GetContext() const { return this->Context; }
  void* GetBuffer() { return this->Buffer.empty() ? nullptr : this->Buffer.data(); }
  int GetWidth() const { return this->Width; }
  int GetHeight() const { return this->Height; }

  /**
   * The libOSMesa file loaded ("" before the first Create()).
   */
  static std::string LibraryName();

  /**
   * How GL calls reach OSMesa: "libglvnd dispatch (OSMesaGetProcAddress)" or
   * "libOSMesa's own (libGL without libglvnd)".
   */
  static std::string DispatchDescription();

  /**
   * Lose libglvnd's current state if it is OSMesa's and release any current OSMesa
   * context: called before an EGL context is made current on this thread.
   */
  static void ReleaseAnyCurrent();

private:
  bool Bind(std::string& error);

  void* Context = nullptr;
  std::vector<unsigned char> Buffer;
  void* BoundBuffer = nullptr;
  int Width = 0;
  int Height = 0;
};

} // namespace nimbus

#endif
