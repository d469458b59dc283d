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
#include <QTimer>

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

// The note in front of a greyed-out field's tooltip, in bold; ParaView's tooltips
// are rich text (<html><head/><body><p>documentation</p></body></html>).
QString Note()
{
  return QObject::tr("Set by the Nimbus Sky shown in this view (Use the View's Sky is on): "
                     "change it on the Nimbus Sky, or turn Use the View's Sky off.");
}

QString NoteParagraph()
{
  return "<p><b>" + Note().toHtmlEscaped() + "</b></p>";
}

QString WithoutNote(QString toolTip)
{
  toolTip.remove(NoteParagraph());
  toolTip.remove(Note() + "\n\n");
  toolTip.remove(Note());
  return toolTip;
}

QString WithNote(const QString& toolTip, bool note)
{
  if (!note)
  {
    return toolTip;
  }
  if (toolTip.isEmpty())
  {
    return Note();
  }
  if (!Qt::mightBeRichText(toolTip))
  {
    return Note() + "\n\n" + toolTip;
  }
  const int body = toolTip.indexOf("<body>");
  QString result = toolTip;
  return body >= 0 ? result.insert(body + 6, NoteParagraph()) : NoteParagraph() + toolTip;
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
  // Once more after the panel has finished the widget (and set its tooltip).
  QTimer::singleShot(0, this, SLOT(updateState()));
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
  const bool changed = skyInUse != this->SkyInUse;
  this->SkyInUse = skyInUse;
  // The panel sets the documentation as the tooltip after building the widget,
  // and again when it rebuilds it: the note is (re)applied on every update.
  pqPropertyWidget* widget = this->parentWidget();
  const QString toolTip = WithNote(WithoutNote(widget->toolTip()), skyInUse);
  if (toolTip != widget->toolTip())
  {
    widget->setToolTip(toolTip);
  }
  if (changed)
  {
    Q_EMIT this->enableStateChanged();
  }
}

//------------------------------------------------------------------------------
bool pqNimbusViewSkyDecorator::enableWidget() const
{
  return !this->SkyInUse;
}
