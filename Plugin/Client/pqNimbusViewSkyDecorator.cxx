#include "pqNimbusViewSkyDecorator.h"

#include "pqApplicationCore.h"
#include "pqCoreUtilities.h"
#include "pqPropertyWidget.h"
#include "pqRepresentation.h"
#include "pqServerManagerModel.h"
#include "pqView.h"
#include "vtkCommand.h"
#include "vtkSMProperty.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMProxy.h"
#include "vtkSMUncheckedPropertyHelper.h"

#include <QTextDocument> // Qt::mightBeRichText

#include <cstring>

namespace
{
// The property that chooses between the cloud's own values and the view's sky.
const char* const UseSceneSkyName = "UseSceneSky";

bool IsVisibleSkyBackground(pqRepresentation* representation)
{
  vtkSMProxy* proxy = representation ? representation->getProxy() : nullptr;
  if (!proxy || !representation->isVisible() || !proxy->GetProperty("Representation"))
  {
    return false;
  }
  const char* type = vtkSMPropertyHelper(proxy, "Representation").GetAsString();
  return type && std::strcmp(type, pqNimbusViewSkyDecorator::SkyBackgroundType()) == 0;
}

// The tooltip with the note in front, in bold; ParaView's tooltips are rich text
// (<html><head/><body><p>documentation</p></body></html>).
QString WithNote(const QString& toolTip, const QString& note)
{
  if (toolTip.isEmpty())
  {
    return note;
  }
  if (!Qt::mightBeRichText(toolTip))
  {
    return note + "\n\n" + toolTip;
  }
  const QString paragraph = "<p><b>" + note.toHtmlEscaped() + "</b></p>";
  const int body = toolTip.indexOf("<body>");
  QString result = toolTip;
  return body >= 0 ? result.insert(body + 6, paragraph) : paragraph + toolTip;
}
}

//------------------------------------------------------------------------------
pqNimbusViewSkyDecorator::pqNimbusViewSkyDecorator(
  vtkPVXMLElement* config, pqPropertyWidget* parentObject)
  : Superclass(config, parentObject)
{
  if (vtkSMProperty* useSceneSky = parentObject->proxy()->GetProperty(UseSceneSkyName))
  {
    // Applied and unapplied changes of "Use the View's Sky".
    pqCoreUtilities::connect(useSceneSky, vtkCommand::ModifiedEvent, this, SLOT(updateState()));
    pqCoreUtilities::connect(
      useSceneSky, vtkCommand::UncheckedPropertyModifiedEvent, this, SLOT(updateState()));
  }
  this->updateView();
}

//------------------------------------------------------------------------------
pqNimbusViewSkyDecorator::~pqNimbusViewSkyDecorator() = default;

//------------------------------------------------------------------------------
void pqNimbusViewSkyDecorator::updateView()
{
  pqServerManagerModel* model = pqApplicationCore::instance()->getServerManagerModel();
  auto* representation = model->findItem<pqRepresentation*>(this->parentWidget()->proxy());
  pqView* view = representation ? representation->getView() : nullptr;
  if (view != this->View)
  {
    if (this->View)
    {
      this->View->disconnect(this);
    }
    this->View = view;
    if (view)
    {
      this->connect(view, SIGNAL(representationAdded(pqRepresentation*)), SLOT(updateState()));
      this->connect(view, SIGNAL(representationRemoved(pqRepresentation*)), SLOT(updateState()));
      this->connect(view, SIGNAL(representationVisibilityChanged(pqRepresentation*, bool)),
        SLOT(updateState()));
      // A representation's type (e.g. Surface -> Sky Background) changes with a render.
      this->connect(view, SIGNAL(endRender()), SLOT(updateState()));
    }
  }
  this->updateState();
}

//------------------------------------------------------------------------------
bool pqNimbusViewSkyDecorator::computeSkyInUse() const
{
  vtkSMProxy* proxy = this->parentWidget()->proxy();
  if (!this->View || !proxy->GetProperty(UseSceneSkyName) ||
    vtkSMUncheckedPropertyHelper(proxy, UseSceneSkyName).GetAsInt() == 0)
  {
    return false;
  }
  for (pqRepresentation* representation : this->View->getRepresentations())
  {
    if (IsVisibleSkyBackground(representation))
    {
      return true;
    }
  }
  return false;
}

//------------------------------------------------------------------------------
void pqNimbusViewSkyDecorator::updateState()
{
  if (!this->View)
  {
    // The panel can be built before the representation joins its view.
    pqServerManagerModel* model = pqApplicationCore::instance()->getServerManagerModel();
    auto* representation = model->findItem<pqRepresentation*>(this->parentWidget()->proxy());
    if (representation && representation->getView())
    {
      this->updateView(); // connects, then comes back here
      return;
    }
  }
  const bool skyInUse = this->computeSkyInUse();
  if (skyInUse == this->SkyInUse)
  {
    return;
  }
  this->SkyInUse = skyInUse;
  pqPropertyWidget* widget = this->parentWidget();
  if (skyInUse)
  {
    // The panel sets the documentation as the tooltip after building the widget.
    this->OriginalToolTip = widget->toolTip();
    const QString note = tr("Set by the Nimbus Sky shown in this view (Use the View's Sky is on): "
                            "change it on the Nimbus Sky, or turn Use the View's Sky off.");
    widget->setToolTip(WithNote(this->OriginalToolTip, note));
  }
  else
  {
    widget->setToolTip(this->OriginalToolTip);
  }
  Q_EMIT this->enableStateChanged();
}

//------------------------------------------------------------------------------
bool pqNimbusViewSkyDecorator::enableWidget() const
{
  return !this->SkyInUse;
}
