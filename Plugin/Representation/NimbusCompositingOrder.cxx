#include "NimbusCompositingOrder.h"

#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkOrderedCompositingHelper.h"
#include "vtkPVRenderView.h"
#include "vtkPVRenderViewDataDeliveryManager.h"

#include <vector>

namespace nimbus
{
bool IsOrderedCompositing(vtkPVRenderView* view)
{
  vtkMultiProcessController* controller = vtkMultiProcessController::GetGlobalController();
  auto* delivery =
    view ? vtkPVRenderViewDataDeliveryManager::SafeDownCast(view->GetDeliveryManager()) : nullptr;
  return controller && controller->GetNumberOfProcesses() > 1 && view &&
    view->GetUseOrderedCompositing() && delivery &&
    static_cast<int>(delivery->GetCuts().size()) == controller->GetNumberOfProcesses();
}

bool IsLastInCompositingOrder(vtkPVRenderView* view)
{
  if (!IsOrderedCompositing(view))
  {
    return true;
  }
  auto* delivery = vtkPVRenderViewDataDeliveryManager::SafeDownCast(view->GetDeliveryManager());
  vtkNew<vtkOrderedCompositingHelper> order;
  order->SetBoundingBoxes(delivery->GetCuts());
  const std::vector<int> ranks = order->ComputeSortOrder(view->GetActiveCamera());
  return !ranks.empty() &&
    ranks.back() == vtkMultiProcessController::GetGlobalController()->GetLocalProcessId();
}
} // namespace nimbus
