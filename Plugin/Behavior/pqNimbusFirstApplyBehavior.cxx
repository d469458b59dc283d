#include "pqNimbusFirstApplyBehavior.h"

#include "NimbusMediumPresets.h"

#include "pqAnimationManager.h"
#include "pqAnimationScene.h"
#include "pqApplicationCore.h"
#include "pqDataRepresentation.h"
#include "pqOutputPort.h"
#include "pqPVApplicationCore.h"
#include "pqPipelineFilter.h"
#include "pqPipelineSource.h"
#include "pqRenderView.h"
#include "pqServer.h"
#include "pqServerManagerModel.h"
#include "pqTimeKeeper.h"
#include "pqUndoStack.h"
#include "vtkCamera.h"
#include "vtkDataObject.h"
#include "vtkMatrix4x4.h"
#include "vtkPVArrayInformation.h"
#include "vtkPVDataInformation.h"
#include "vtkSMPVRepresentationProxy.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMProxy.h"
#include "vtkSMRenderViewProxy.h"
#include "vtkSMSessionProxyManager.h"
#include "vtkSMTransferFunctionManager.h"
#include "vtkSMTransferFunctionProxy.h"
#include "vtkSMViewProxy.h"

#include <QPointer>
#include <QTimer>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

namespace
{
// The sun of a cloud lit by lightning on first Apply: below the horizon (nautical
// twilight, a dark sky), so the flash is what lights it.
constexpr double kNightSunElevationDegrees = -12.0;

// Moves the animation to `time`, and again until the views are there. A first-Apply style
// runs from the event loop, which ParaView also runs inside a render's progress events; once,
// on a loaded machine, a time set so moved the animation's clock but not the views' (the
// toolbar at 2 s, the view's time and picture still at 0). So the time keeper is checked a
// little later and the time pushed again while it differs (and the user has not moved it).
void SetAnimationTime(QObject* context, pqAnimationScene* scene, double time, int tries = 40)
{
  if (!scene)
  {
    return;
  }
  vtkSMProxy* proxy = scene->getProxy();
  vtkSMPropertyHelper(proxy, "AnimationTime").Set(time);
  proxy->UpdateProperty("AnimationTime", /*force=*/1);
  QPointer<pqAnimationScene> guarded(scene);
  QTimer::singleShot(250, context,
    [context, guarded, time, tries]()
    {
      pqTimeKeeper* keeper =
        guarded && guarded->getServer() ? guarded->getServer()->getTimeKeeper() : nullptr;
      if (keeper && std::abs(keeper->getTime() - time) > 1e-9 * std::max(1.0, std::abs(time)) &&
        tries > 0 &&
        std::abs(guarded->getAnimationTime() - time) <= 1e-9 * std::max(1.0, std::abs(time)))
      {
        SetAnimationTime(context, guarded, time, tries - 1);
      }
    });
}

// Sources and filters of clouds and the sky (proxy XML names).
bool IsNimbusCloudProducer(pqPipelineSource* source)
{
  const char* name = source && source->getProxy() ? source->getProxy()->GetXMLName() : nullptr;
  if (!name)
  {
    return false;
  }
  for (const char* cloud : { "NimbusMetaballCloud", "NimbusCloudAutomaton",
         "NimbusCloudAutomatonWithMaps", "NimbusImageCloud", "NimbusOpenVDBReader", "NimbusSkyDome",
         "NimbusLightning", "NimbusLightningIllumination", "NimbusSmoke" })
  {
    if (std::strcmp(name, cloud) == 0)
    {
      return true;
    }
  }
  return false;
}

const char* RepresentationType(pqRepresentation* representation)
{
  vtkSMProxy* proxy = representation ? representation->getProxy() : nullptr;
  if (!proxy || !proxy->GetProperty("Representation"))
  {
    return nullptr;
  }
  return vtkSMPropertyHelper(proxy, "Representation", /*quiet=*/true).GetAsString();
}

// The types whose picture does not use the colour map.
bool DrawsWithoutColorMap(pqRepresentation* representation)
{
  const char* type = RepresentationType(representation);
  return type && (std::strcmp(type, "Cloud") == 0 || std::strcmp(type, "Sky Background") == 0);
}

bool IsLightning(pqPipelineSource* source)
{
  const char* name = source && source->getProxy() ? source->getProxy()->GetXMLName() : nullptr;
  return name && std::strcmp(name, "NimbusLightning") == 0;
}

bool IsLightningIllumination(pqPipelineSource* source)
{
  const char* name = source && source->getProxy() ? source->getProxy()->GetXMLName() : nullptr;
  return name && std::strcmp(name, "NimbusLightningIllumination") == 0;
}

bool IsOpenVdb(pqPipelineSource* source)
{
  const char* name = source && source->getProxy() ? source->getProxy()->GetXMLName() : nullptr;
  return name && std::strcmp(name, "NimbusOpenVDBReader") == 0;
}

// "Unknown: a typical cloud (estimated)" (Density Array Means): a .vdb's density has no
// physical unit (Houdini's and Blender's are 0..1 by convention, at any voxel size), so the
// first look scales it to a cumulus's optical thickness rather than taking it as Nimbus's
// own density (docs/density-units.md). Only while the display is a Cloud with the default
// units, so a user's or a state file's choice stays.
constexpr int kEstimatedDensityUnits = 5;

void EstimateVdbDensity(pqDataRepresentation* cloud)
{
  vtkSMProxy* proxy = cloud->getProxy();
  const char* type = RepresentationType(cloud);
  if (!type || std::strcmp(type, "Cloud") != 0 || !proxy->GetProperty("DensityUnits") ||
    vtkSMPropertyHelper(proxy, "DensityUnits").GetAsInt() != 0)
  {
    return;
  }
  vtkSMPropertyHelper(proxy, "DensityUnits").Set(kEstimatedDensityUnits);
  proxy->UpdateVTKObjects();
}

bool IsSmoke(pqPipelineSource* source)
{
  const char* name = source && source->getProxy() ? source->getProxy()->GetXMLName() : nullptr;
  return name && std::strcmp(name, "NimbusSmoke") == 0;
}

// The Nimbus Lightning feeding a Lightning Illumination filter, or nullptr.
vtkSMProxy* LightningOf(pqPipelineSource* illumination)
{
  auto* filter = qobject_cast<pqPipelineFilter*>(illumination);
  if (!filter)
  {
    return nullptr;
  }
  for (pqOutputPort* port : filter->getInputs("Lightning"))
  {
    if (IsLightning(port->getSource()))
    {
      return port->getSource()->getProxy();
    }
  }
  return nullptr;
}

// The strokes as lines whose grey level is their brightness on a log scale: black (a
// thousandth of the return stroke's peak and less) to white (the peak), the range fixed
// so that the flash fades over time and dimmer branches stay visible.
void StyleLightning(pqDataRepresentation* representation)
{
  vtkSMProxy* proxy = representation->getProxy();
  vtkSMProxy* source = representation->getInput()->getProxy();
  if (!proxy->GetProperty("LineWidth") || !source->GetProperty("Brightness"))
  {
    return;
  }
  vtkSMPVRepresentationProxy::SetScalarColoring(proxy, "intensity", vtkDataObject::CELL);
  vtkSMProxy* lut = vtkSMPropertyHelper(proxy, "LookupTable", /*quiet=*/true).GetAsProxy();
  if (lut)
  {
    const double peak = std::max(vtkSMPropertyHelper(source, "Brightness").GetAsDouble(), 1e-12);
    vtkSMTransferFunctionProxy::ApplyPreset(lut, "Grayscale", /*rescale=*/false);
    vtkSMPropertyHelper(lut, "AutomaticRescaleRangeMode").Set(vtkSMTransferFunctionManager::NEVER);
    vtkSMTransferFunctionProxy::RescaleTransferFunction(lut, 1e-3 * peak, peak);
    vtkSMPropertyHelper(lut, "UseLogScale").Set(1);
    lut->UpdateVTKObjects();
  }
  vtkSMPropertyHelper(proxy, "LineWidth").Set(2.0);
  proxy->UpdateVTKObjects();
}

// The animation at the return stroke's peak (the first time step at or after it) when it
// stands before it: the flash starts dark at time 0 (Play shows the leader and strokes).
void ShowLightningPeak(pqDataRepresentation* representation)
{
  vtkSMProxy* source = IsLightningIllumination(representation->getInput())
    ? LightningOf(representation->getInput())
    : representation->getInput()->getProxy();
  if (!source)
  {
    return;
  }
  auto* core = pqPVApplicationCore::instance();
  pqAnimationScene* scene =
    core && core->animationManager() ? core->animationManager()->getActiveScene() : nullptr;
  if (!scene || !source->GetProperty("TimestepValues") || !source->GetProperty("FlashStartSeconds"))
  {
    return;
  }
  source->UpdatePropertyInformation();
  const double peak = vtkSMPropertyHelper(source, "FlashStartSeconds").GetAsDouble() +
    vtkSMPropertyHelper(source, "LeaderDurationSeconds").GetAsDouble();
  if (scene->getAnimationTime() >= peak)
  {
    return;
  }
  vtkSMPropertyHelper steps(source, "TimestepValues");
  for (unsigned int i = 0; i < steps.GetNumberOfElements(); ++i)
  {
    if (steps.GetAsDouble(i) >= peak - 1e-12)
    {
      scene->setAnimationTime(steps.GetAsDouble(i));
      return;
    }
  }
}

// Runs `style` on the representation after ParaView's own Apply has finished with it
// (its colouring picked), then renders; nothing if the representation is gone by then.
template <typename Style>
void AfterApply(QObject* context, pqDataRepresentation* representation, Style style)
{
  QPointer<pqDataRepresentation> guarded(representation);
  QTimer::singleShot(0, context,
    [guarded, style]()
    {
      if (!guarded)
      {
        return;
      }
      style(guarded.data());
      if (guarded->getView())
      {
        guarded->getView()->render();
      }
    });
}

bool IsSkyBackground(pqRepresentation* representation)
{
  const char* type = RepresentationType(representation);
  return type && std::strcmp(type, "Sky Background") == 0;
}

// A representation added by the user's Apply or Show, not by loading a state file (the
// GUI's or Python's) or by undo and redo: those bring back values the user had, which the
// first look must not change.
bool IsNewlyShown(pqRepresentation* representation)
{
  pqApplicationCore* core = pqApplicationCore::instance();
  pqUndoStack* undo = core ? core->getUndoStack() : nullptr;
  vtkSMSessionProxyManager* proxies = representation->getProxy()->GetSessionProxyManager();
  return core && !core->isLoadingState() && !(proxies && proxies->GetInLoadXMLState()) &&
    !(undo && (undo->getInUndo() || undo->getInRedo()));
}

// The smoke's optics (NimbusMediumPresets.h): not a cloud's over kilometres.
void ApplySmokeOptics(pqDataRepresentation* smoke)
{
  vtkSMProxy* proxy = smoke->getProxy();
  const nimbus::MediumPreset& preset = nimbus::kMediumPresets[nimbus::kSmokePreset];
  const char* names[3] = { "ExtinctionPerDensity", "Albedo", "CloudG" };
  const double values[3] = { preset.ExtinctionPerDensity, preset.Albedo, preset.CloudG };
  for (int k = 0; k < 3; ++k)
  {
    if (proxy->GetProperty(names[k]))
    {
      vtkSMPropertyHelper(proxy, names[k]).Set(values[k]);
    }
  }
  proxy->UpdateVTKObjects();
}

// A smoke starts empty (time 0: nothing emitted yet). When it is empty at the animation's
// time, the animation goes to the first time step at or after kSmokeFirstLookSeconds, a
// plume that has risen (the emitter's density per second times the time, carried up).
constexpr double kSmokeFirstLookSeconds = 2.0;

void ShowRisenSmoke(QObject* context, pqDataRepresentation* smoke)
{
  vtkPVDataInformation* data = smoke->getInputDataInformation();
  vtkPVArrayInformation* density =
    data ? data->GetArrayInformation("density", vtkDataObject::POINT) : nullptr;
  if (!density || density->GetComponentRange(0)[1] > 0.0)
  {
    return;
  }
  auto* core = pqPVApplicationCore::instance();
  pqAnimationScene* scene =
    core && core->animationManager() ? core->animationManager()->getActiveScene() : nullptr;
  vtkSMProxy* source = smoke->getInput()->getProxy();
  if (!scene || !source->GetProperty("TimestepValues") ||
    scene->getAnimationTime() >= kSmokeFirstLookSeconds)
  {
    return;
  }
  source->UpdatePropertyInformation();
  vtkSMPropertyHelper steps(source, "TimestepValues");
  const unsigned int count = steps.GetNumberOfElements();
  for (unsigned int i = 0; i < count; ++i)
  {
    if (steps.GetAsDouble(i) >= kSmokeFirstLookSeconds - 1e-9 || i + 1 == count)
    {
      SetAnimationTime(context, scene, steps.GetAsDouble(i));
      return;
    }
  }
}

bool ValidBounds(const double b[6])
{
  return b[0] <= b[1] && b[2] <= b[3] && b[4] <= b[5];
}

double Diagonal(const double b[6])
{
  return std::sqrt(
    (b[1] - b[0]) * (b[1] - b[0]) + (b[3] - b[2]) * (b[3] - b[2]) + (b[5] - b[4]) * (b[5] - b[4]));
}

// How much of the view the box takes with this camera: the larger side of its on-screen
// rectangle, clipped to the view, over the view's side (0: off screen; 1: fills it). The
// box is clipped against a plane just in front of the eye (homogeneous w = epsilon): its
// corners in front and the points where its edges cross that plane bound its picture.
double OnScreenFraction(vtkCamera* camera, double aspect, const double b[6])
{
  vtkMatrix4x4* matrix = camera->GetCompositeProjectionTransformMatrix(aspect, -1.0, 1.0);
  std::array<std::array<double, 4>, 8> clip;
  for (int corner = 0; corner < 8; ++corner)
  {
    const double in[4] = { b[corner & 1], b[2 + ((corner >> 1) & 1)], b[4 + ((corner >> 2) & 1)],
      1.0 };
    matrix->MultiplyPoint(in, clip[corner].data());
  }
  constexpr double epsilon = 1e-9;
  double low[2] = { 1e300, 1e300 }, high[2] = { -1e300, -1e300 };
  bool any = false;
  const auto include = [&](const std::array<double, 4>& p)
  {
    any = true;
    for (int k = 0; k < 2; ++k)
    {
      low[k] = std::min(low[k], p[k] / p[3]);
      high[k] = std::max(high[k], p[k] / p[3]);
    }
  };
  for (int i = 0; i < 8; ++i)
  {
    if (clip[i][3] > epsilon)
    {
      include(clip[i]);
    }
    for (int axis = 0; axis < 3; ++axis)
    {
      const int j = i | (1 << axis); // each edge once: from i (bit clear) to j (bit set)
      if (j == i || ((clip[i][3] > epsilon) == (clip[j][3] > epsilon)))
      {
        continue;
      }
      const double t = (epsilon - clip[i][3]) / (clip[j][3] - clip[i][3]);
      std::array<double, 4> crossing;
      for (int k = 0; k < 4; ++k)
      {
        crossing[k] = clip[i][k] + t * (clip[j][k] - clip[i][k]);
      }
      crossing[3] = epsilon;
      include(crossing);
    }
  }
  if (!any)
  {
    return 0.0; // all behind the eye
  }
  double fraction = 0.0;
  for (int k = 0; k < 2; ++k)
  {
    const double extent = std::min(high[k], 1.0) - std::max(low[k], -1.0);
    if (!(extent > 0.0))
    {
      return 0.0; // beside the view
    }
    fraction = std::max(fraction, extent / 2.0);
  }
  return fraction;
}

// New data smaller on screen than this (a fraction of the view's side) is framed.
constexpr double kSmallOnScreen = 0.15;
// Framed with what the view shows when it is at least this fraction of it (the
// diagonals), alone otherwise (a smoke of metres beside a cloud of kilometres).
constexpr double kFrameTogether = 0.1;

// Apply frames new data only in an empty view. New Nimbus data that the view's camera
// shows tiny or not at all is framed, keeping the view's direction.
void FrameIfHardToSee(pqDataRepresentation* added, pqRenderView* view)
{
  auto* viewProxy = vtkSMRenderViewProxy::SafeDownCast(view->getProxy());
  vtkPVDataInformation* data = added->getInputDataInformation();
  if (!viewProxy || !data || data->GetNumberOfPoints() == 0 || IsSkyBackground(added) ||
    !added->isVisible())
  {
    return; // a sky background is drawn behind everything: nothing to frame
  }
  std::array<double, 6> mine;
  data->GetBounds(mine.data());
  if (!ValidBounds(mine.data()))
  {
    return;
  }
  int size[2] = { 1, 1 };
  vtkSMPropertyHelper(viewProxy, "ViewSize").Get(size, 2);
  const double aspect = size[1] > 0 ? static_cast<double>(size[0]) / size[1] : 1.0;
  if (OnScreenFraction(viewProxy->GetActiveCamera(), std::max(aspect, 1e-3), mine.data()) >=
    kSmallOnScreen)
  {
    return;
  }
  std::array<double, 6> all = mine;
  for (pqRepresentation* other : view->getRepresentations())
  {
    auto* otherData = qobject_cast<pqDataRepresentation*>(other);
    vtkPVDataInformation* info = otherData && other->isVisible() && !IsSkyBackground(other)
      ? otherData->getInputDataInformation()
      : nullptr;
    if (!info || info->GetNumberOfPoints() == 0)
    {
      continue;
    }
    double b[6];
    info->GetBounds(b);
    if (ValidBounds(b))
    {
      for (int k = 0; k < 3; ++k)
      {
        all[2 * k] = std::min(all[2 * k], b[2 * k]);
        all[2 * k + 1] = std::max(all[2 * k + 1], b[2 * k + 1]);
      }
    }
  }
  std::array<double, 6>& frame =
    Diagonal(mine.data()) >= kFrameTogether * Diagonal(all.data()) ? all : mine;
  viewProxy->ResetCamera(frame.data());
}
}

pqNimbusFirstApplyBehavior::pqNimbusFirstApplyBehavior(QObject* parent)
  : QObject(parent)
{
}

pqNimbusFirstApplyBehavior::~pqNimbusFirstApplyBehavior() = default;

void pqNimbusFirstApplyBehavior::startup()
{
  pqServerManagerModel* model = pqApplicationCore::instance()->getServerManagerModel();
  QObject::connect(
    model, &pqServerManagerModel::viewAdded, this, &pqNimbusFirstApplyBehavior::onViewAdded);
  for (pqView* view : model->findItems<pqView*>())
  {
    this->onViewAdded(view);
  }
}

void pqNimbusFirstApplyBehavior::shutdown()
{
  QObject::disconnect(this);
}

void pqNimbusFirstApplyBehavior::onViewAdded(pqView* view)
{
  if (qobject_cast<pqRenderView*>(view))
  {
    QObject::connect(view, &pqView::representationAdded, this,
      &pqNimbusFirstApplyBehavior::onRepresentationAdded, Qt::UniqueConnection);
    // The GUI shows a legend right after a change of colouring or representation type, then
    // renders: look after each render (a check of a few properties; at most one more render).
    QPointer<pqView> guarded(view);
    QObject::connect(view, &pqView::endRender, this,
      [this, guarded]()
      { QTimer::singleShot(0, this, [this, guarded]() { this->hideLegends(guarded); }); });
  }
}

void pqNimbusFirstApplyBehavior::onRepresentationAdded(pqRepresentation* representation)
{
  auto* data = qobject_cast<pqDataRepresentation*>(representation);
  auto* view = qobject_cast<pqRenderView*>(representation ? representation->getView() : nullptr);
  if (!data || !view || !IsNewlyShown(representation))
  {
    return;
  }
  if (IsSkyBackground(representation) &&
    vtkSMPVRepresentationProxy::GetUsingScalarColoring(representation->getProxy()))
  {
    // Solid Color: the sky background does not use the colour map.
    vtkSMPVRepresentationProxy::SetScalarColoring(representation->getProxy(), nullptr, 0);
    representation->getProxy()->UpdateVTKObjects();
  }

  if (IsLightning(data->getInput()))
  {
    AfterApply(this, data,
      [](pqDataRepresentation* lightning)
      {
        StyleLightning(lightning);
        ShowLightningPeak(lightning);
      });
  }

  if (IsSmoke(data->getInput()))
  {
    // Whatever the view already shows: smoke's optics, and a plume that has risen.
    AfterApply(this, data,
      [this](pqDataRepresentation* smoke)
      {
        ApplySmokeOptics(smoke);
        ShowRisenSmoke(this, smoke);
      });
  }

  if (IsOpenVdb(data->getInput()))
  {
    AfterApply(this, data, [](pqDataRepresentation* cloud) { EstimateVdbDensity(cloud); });
  }

  if (IsLightningIllumination(data->getInput()))
  {
    // A flash is seen at night: the cloud's own sun below the horizon (a Nimbus Sky in
    // the view still sets the sun for both), and the frame at the return stroke. The sun
    // is set now, before anything renders the new representation: set after Apply (as
    // the time is), a render of Apply's or a script's own would first draw the cloud
    // in daylight.
    vtkSMProxy* proxy = data->getProxy();
    if (proxy->GetProperty("SunElevationDegrees"))
    {
      vtkSMPropertyHelper(proxy, "SunElevationDegrees").Set(kNightSunElevationDegrees);
      proxy->UpdateVTKObjects();
    }
    AfterApply(this, data, [](pqDataRepresentation* lit) { ShowLightningPeak(lit); });
  }

  // The camera: only for the first data in the view (a sky background does not count).
  if (!IsNimbusCloudProducer(data->getInput()))
  {
    return;
  }
  // The filter's inputs do not count: Apply hides them (an image under the image cloud).
  QList<pqPipelineSource*> inputs;
  if (auto* filter = qobject_cast<pqPipelineFilter*>(data->getInput()))
  {
    for (pqOutputPort* port : filter->getAllInputs())
    {
      inputs.push_back(port->getSource());
    }
  }
  for (pqRepresentation* other : view->getRepresentations())
  {
    auto* otherData = qobject_cast<pqDataRepresentation*>(other);
    if (other != representation && other->isVisible() && !IsSkyBackground(other) && otherData &&
      !inputs.contains(otherData->getInput()))
    {
      // A view that already shows data keeps its camera unless the new data would be hard
      // to see in it.
      QPointer<pqRenderView> guardedView(view);
      AfterApply(this, data,
        [guardedView](pqDataRepresentation* added)
        {
          if (guardedView)
          {
            FrameIfHardToSee(added, guardedView);
          }
        });
      return;
    }
  }
  // Looking north (+y), 11 degrees down, z up. ParaView resets the camera to the data's
  // bounds right after (Apply), keeping this direction.
  vtkSMProxy* viewProxy = view->getProxy();
  double focal[3] = { 0.0, 0.0, 0.0 };
  vtkSMPropertyHelper(viewProxy, "CameraFocalPoint").Get(focal, 3);
  const double look[3] = { 0.0, std::cos(11.0 * M_PI / 180.0), -std::sin(11.0 * M_PI / 180.0) };
  const double position[3] = { focal[0] - look[0], focal[1] - look[1], focal[2] - look[2] };
  const double up[3] = { 0.0, 0.0, 1.0 };
  vtkSMPropertyHelper(viewProxy, "CameraPosition").Set(position, 3);
  vtkSMPropertyHelper(viewProxy, "CameraViewUp").Set(up, 3);
  viewProxy->UpdateVTKObjects();
  // Fit the data once Apply is done (Apply resets the camera itself only when this is the
  // one visible representation, i.e. not while a filter's input is still shown).
  QPointer<pqRenderView> guarded(view);
  QTimer::singleShot(0, this,
    [guarded]()
    {
      if (guarded)
      {
        guarded->resetCamera();
        guarded->render();
      }
    });
}

void pqNimbusFirstApplyBehavior::hideLegends(pqView* view)
{
  if (!view)
  {
    return;
  }
  vtkSMProxy* viewProxy = view->getProxy();
  bool hidden = false;
  for (pqRepresentation* representation : view->getRepresentations())
  {
    vtkSMProxy* proxy = representation->getProxy();
    if (DrawsWithoutColorMap(representation) &&
      vtkSMPVRepresentationProxy::GetUsingScalarColoring(proxy) &&
      vtkSMPVRepresentationProxy::IsScalarBarVisible(proxy, viewProxy))
    {
      vtkSMPVRepresentationProxy::SetScalarBarVisibility(proxy, viewProxy, false);
      hidden = true;
    }
  }
  if (hidden)
  {
    view->render();
  }
}
