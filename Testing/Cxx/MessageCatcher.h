// Test support: collects the errors and warnings a VTK object reports (and counts its
// progress events) instead of printing them, so a test can check them. Header-only;
// shared by the tests of the sources, filters, reader and writer.
#ifndef NimbusMessageCatcher_h
#define NimbusMessageCatcher_h

#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkNew.h"
#include "vtkObject.h"

#include <string>
#include <vector>

namespace nimbus
{
namespace testing
{

class MessageCatcher
{
public:
  /// Observes ErrorEvent, WarningEvent and ProgressEvent of `object` (which must
  /// outlive the catcher or be observed no more after it is gone).
  explicit MessageCatcher(vtkObject* object)
  {
    this->Callback->SetClientData(this);
    this->Callback->SetCallback(&MessageCatcher::Catch);
    object->AddObserver(vtkCommand::ErrorEvent, this->Callback);
    object->AddObserver(vtkCommand::WarningEvent, this->Callback);
    object->AddObserver(vtkCommand::ProgressEvent, this->Callback);
  }
  MessageCatcher(const MessageCatcher&) = delete;
  MessageCatcher& operator=(const MessageCatcher&) = delete;

  std::vector<std::string> Errors;
  std::vector<std::string> Warnings;
  int ProgressEvents = 0;

  /// Every error (warning), one per line.
  std::string AllErrors() const { return Join(this->Errors); }
  std::string AllWarnings() const { return Join(this->Warnings); }

private:
  static std::string Join(const std::vector<std::string>& messages)
  {
    std::string text;
    for (const std::string& message : messages)
    {
      text += message + "\n";
    }
    return text;
  }

  static void Catch(vtkObject*, unsigned long event, void* clientData, void* callData)
  {
    auto* self = static_cast<MessageCatcher*>(clientData);
    if (event == vtkCommand::ProgressEvent)
    {
      ++self->ProgressEvents;
      return;
    }
    const std::string text = callData ? static_cast<const char*>(callData) : "";
    (event == vtkCommand::ErrorEvent ? self->Errors : self->Warnings).push_back(text);
  }

  vtkNew<vtkCallbackCommand> Callback;
};

} // namespace testing
} // namespace nimbus

#endif
