// nimbus::PassTimer — the GPU time of each pass of a frame of vtkNimbusCloudVolumeMapper,
// measured with GL timer queries (GL_TIME_ELAPSED, through VTK's vtkOpenGLRenderTimer,
// as vtkOpenGLRenderTimerLog does): Begin(name) ends the pass before and starts the
// next; Collect() after the frame waits for the queries and keeps (name, seconds) in
// order, summing passes of the same name (the slices). Off, it does nothing; on, the
// wait at the end of the frame costs the pipelining of one frame.
#ifndef nimbus_PassTimer_h
#define nimbus_PassTimer_h

#include "NimbusRepresentationsModule.h"

#include <memory>
#include <string>
#include <utility>
#include <vector>

class vtkOpenGLRenderTimer;

namespace nimbus
{
class NIMBUSREPRESENTATIONS_EXPORT PassTimer
{
public:
  PassTimer();
  ~PassTimer();
  PassTimer(const PassTimer&) = delete;
  PassTimer& operator=(const PassTimer&) = delete;

  /// Starts timing a frame (clears the queries of the last one); off: nothing is timed.
  void BeginFrame(bool enabled);
  /// Ends the pass being timed, if any, and starts timing `name`.
  void Begin(const std::string& name);
  /// Ends the pass being timed.
  void End();
  /// Waits for the frame's queries and keeps their times (see Last()).
  void Collect();
  /// The last collected frame: (pass, seconds), in the order first begun.
  const std::vector<std::pair<std::string, double>>& Last() const { return this->Times; }
  /// "name seconds; name seconds; ..." of Last().
  std::string Report() const;
  /// Frees the queries (the context is going away).
  void Release();

private:
  bool Enabled = false;
  bool Running = false;
  std::vector<std::pair<std::string, std::unique_ptr<vtkOpenGLRenderTimer>>> Queries;
  std::size_t Used = 0;
  std::vector<std::pair<std::string, double>> Times;
};
}

#endif
