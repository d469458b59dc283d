#include "pqNimbusPlaybackBehavior.h"

#include "pqAnimationManager.h"
#include "pqAnimationScene.h"
#include "pqApplicationCore.h"
#include "pqDataRepresentation.h"
#include "pqPVApplicationCore.h"
#include "pqServerManagerModel.h"
#include "pqUndoStack.h"
#include "pqView.h"
#include "vtkSMAnimationScene.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMProxy.h"

#include <QSet>
#include <QTimer>

namespace
{
constexpr const char* kPlaybackInteractive = "PlaybackInteractive";

// True while the active scene is being saved (File > Save Animation, Save Extracts): the
// scene's writer turns off the scene's own renders and captures each frame itself, at full
// quality.
bool SavingAnimation(pqAnimationManager* manager)
{
  pqAnimationScene* scene = manager ? manager->getActiveScene() : nullptr;
  vtkSMProxy* proxy = scene ? scene->getProxy() : nullptr;
  auto* object = proxy ? vtkSMAnimationScene::SafeDownCast(proxy->GetClientSideObject()) : nullptr;
  return object && object->GetOverrideStillRender();
}

void SetPlaybackInteractive(pqDataRepresentation* representation, bool on)
{
  vtkSMProxy* proxy = representation->getProxy();
  SCOPED_UNDO_EXCLUDE(); // a play is not an edit
  vtkSMPropertyHelper(proxy, kPlaybackInteractive).Set(on ? 1 : 0);
  proxy->UpdateVTKObjects();
}
}

pqNimbusPlaybackBehavior::pqNimbusPlaybackBehavior(QObject* parent)
  : QObject(parent)
{
}

pqNimbusPlaybackBehavior::~pqNimbusPlaybackBehavior() = default;

void pqNimbusPlaybackBehavior::startup()
{
  // A plugin loaded with the application starts before the animation manager exists:
  // then it connects once the event loop runs.
  if (!this->connectToAnimation())
  {
    QTimer::singleShot(0, this, [this]() { this->connectToAnimation(); });
  }
}

bool pqNimbusPlaybackBehavior::connectToAnimation()
{
  pqAnimationManager* manager =
    pqPVApplicationCore::instance() ? pqPVApplicationCore::instance()->animationManager() : nullptr;
  if (!manager)
  {
    return false;
  }
  using Signal = void (pqAnimationManager::*)(vtkObject*, unsigned long, void*, void*);
  QObject::connect(manager, static_cast<Signal>(&pqAnimationManager::beginPlay), this,
    &pqNimbusPlaybackBehavior::onBeginPlay);
  QObject::connect(manager, static_cast<Signal>(&pqAnimationManager::endPlay), this,
    &pqNimbusPlaybackBehavior::onEndPlay);
  return true;
}

void pqNimbusPlaybackBehavior::shutdown()
{
  QObject::disconnect(this);
}

void pqNimbusPlaybackBehavior::onBeginPlay(vtkObject*, unsigned long, void*, void*)
{
  if (SavingAnimation(pqPVApplicationCore::instance()->animationManager()))
  {
    return;
  }
  pqServerManagerModel* model = pqApplicationCore::instance()->getServerManagerModel();
  for (pqDataRepresentation* representation : model->findItems<pqDataRepresentation*>())
  {
    vtkSMProxy* proxy = representation->getProxy();
    if (representation->isVisible() && proxy && proxy->GetProperty(kPlaybackInteractive) &&
      !this->Interactive.contains(representation))
    {
      SetPlaybackInteractive(representation, true);
      this->Interactive.push_back(representation);
    }
  }
}

void pqNimbusPlaybackBehavior::onEndPlay(vtkObject*, unsigned long, void*, void*)
{
  QSet<pqView*> views;
  for (const QPointer<pqDataRepresentation>& representation : this->Interactive)
  {
    if (representation)
    {
      SetPlaybackInteractive(representation, false);
      if (representation->getView() && representation->isVisible())
      {
        views.insert(representation->getView());
      }
    }
  }
  this->Interactive.clear();
  // The frame the play stopped at, at full quality: one render once the event loop runs
  // (the property's change above asks the views for one too; the two are one render).
  for (pqView* view : views)
  {
    view->render();
  }
}
