#include "pqNimbusEstimatedExtinctionWidget.h"

#include "pqCoreUtilities.h"
#include "pqDoubleVectorPropertyWidget.h"
#include "pqPropertiesPanel.h"
#include "pqView.h"
#include "vtkCommand.h"
#include "vtkSMProperty.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMProxy.h"

#include <QLabel>
#include <QVBoxLayout>

#include <cmath>

namespace
{
// Significant digits of the estimate shown: the median it comes from is no finer.
constexpr int kShownDigits = 3;
// The representation's choice of array (the density), set with Coloring.
const char* const kColorArrayProperty = "ColorArrayName";
}

const char* pqNimbusEstimatedExtinctionWidget::informationPropertyName()
{
  return "EstimatedExtinctionPerDensityInfo";
}

pqNimbusEstimatedExtinctionWidget::pqNimbusEstimatedExtinctionWidget(
  vtkSMProxy* proxy, vtkSMProperty* property, QWidget* parent)
  : Superclass(proxy, parent)
  , Editor(new pqDoubleVectorPropertyWidget(property, proxy, this))
  , Estimate(new QLabel(this))
  , Owner(nullptr)
  , Information(nullptr)
{
  this->setProperty(property);
  this->setShowLabel(true);
  // The editor says when its value is changed and finished; this widget only relays.
  this->setChangeAvailableAsChangeFinished(false);
  this->Editor->setProperty(property);
  this->Editor->setObjectName("TargetOpticalThicknessEditor");
  QObject::connect(
    this->Editor, &pqPropertyWidget::changeAvailable, this, &pqPropertyWidget::changeAvailable);
  QObject::connect(
    this->Editor, &pqPropertyWidget::changeFinished, this, &pqPropertyWidget::changeFinished);
  QObject::connect(
    this->Editor, &pqPropertyWidget::restartRequired, this, &pqPropertyWidget::restartRequired);

  this->Estimate->setObjectName("EstimatedExtinction");
  this->Estimate->setTextFormat(Qt::PlainText);
  this->Estimate->setWordWrap(true);
  this->Estimate->setTextInteractionFlags(Qt::TextSelectableByMouse);
  this->Estimate->setToolTip(
    tr("The extinction per unit of the density array (1/m) that gives the cloud's typical "
       "column this optical thickness, found when the display last rendered. Nothing is "
       "estimated before that, without a density array (Coloring) or when the array has no "
       "value above 0."));
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  layout->setSpacing(pqPropertiesPanel::suggestedVerticalSpacing());
  layout->addWidget(this->Editor);
  layout->addWidget(this->Estimate);

  // The proxy whose VTK object computes the estimate: the one that owns the target (the
  // Cloud subproxy when the property is exposed by a representation type's proxy).
  this->Owner = property && property->GetParent() ? property->GetParent() : proxy;
  this->Information = this->Owner->GetProperty(informationPropertyName());
  if (!this->Information)
  {
    this->Owner = proxy;
    this->Information = proxy->GetProperty(informationPropertyName());
  }
  if (this->Information)
  {
    pqCoreUtilities::connect(
      this->Information, vtkCommand::ModifiedEvent, this, SLOT(showEstimate()));
  }
  if (vtkSMProperty* array = proxy->GetProperty(kColorArrayProperty))
  {
    pqCoreUtilities::connect(array, vtkCommand::ModifiedEvent, this, SLOT(showEstimate()));
  }
  // New data after a render that executed the representation (its own proxy and, when
  // the target is exposed, the representation type's proxy).
  pqCoreUtilities::connect(this->Owner, vtkCommand::UpdateDataEvent, this, SLOT(refreshEstimate()));
  if (this->Owner != proxy)
  {
    pqCoreUtilities::connect(proxy, vtkCommand::UpdateDataEvent, this, SLOT(refreshEstimate()));
  }
  this->refreshEstimate();
}

pqNimbusEstimatedExtinctionWidget::~pqNimbusEstimatedExtinctionWidget() = default;

void pqNimbusEstimatedExtinctionWidget::apply()
{
  this->Editor->apply();
}

void pqNimbusEstimatedExtinctionWidget::reset()
{
  this->Editor->reset();
}

void pqNimbusEstimatedExtinctionWidget::select()
{
  this->Superclass::select();
  this->Editor->select();
}

void pqNimbusEstimatedExtinctionWidget::deselect()
{
  this->Editor->deselect();
  this->Superclass::deselect();
}

void pqNimbusEstimatedExtinctionWidget::setView(pqView* view)
{
  this->Superclass::setView(view);
  this->Editor->setView(view);
  if (this->WatchedView == view)
  {
    return;
  }
  if (this->WatchedView)
  {
    QObject::disconnect(this->WatchedView, &pqView::updateDataEvent, this,
      &pqNimbusEstimatedExtinctionWidget::refreshEstimate);
  }
  this->WatchedView = view;
  if (view)
  {
    QObject::connect(
      view, &pqView::updateDataEvent, this, &pqNimbusEstimatedExtinctionWidget::refreshEstimate);
  }
}

QString pqNimbusEstimatedExtinctionWidget::estimateText() const
{
  return this->Estimate->text();
}

void pqNimbusEstimatedExtinctionWidget::refreshEstimate()
{
  if (this->Information && this->Owner->GetObjectsCreated())
  {
    // Sends Modified (showEstimate) when the value changed.
    this->Owner->UpdatePropertyInformation(this->Information);
  }
  this->showEstimate();
}

void pqNimbusEstimatedExtinctionWidget::showEstimate()
{
  if (!this->Information)
  {
    this->Estimate->setText(tr("no estimate: this display does not compute one"));
    return;
  }
  // k [1/m per unit value of the array]: 0 when nothing was estimated.
  const double k = vtkSMPropertyHelper(this->Information, /*quiet=*/true).GetAsDouble();
  if (std::isfinite(k) && k > 0.0)
  {
    this->Estimate->setText(tr("gives %1 /m per unit of the array").arg(k, 0, 'g', kShownDigits));
  }
  else if (!this->hasDensityArray())
  {
    // The estimate scales the array chosen with Coloring; Solid Color chooses none.
    this->Estimate->setText(tr("choose the density array (Coloring) to estimate"));
  }
  else
  {
    this->Estimate->setText(tr("apply and render to estimate"));
  }
}

bool pqNimbusEstimatedExtinctionWidget::hasDensityArray() const
{
  vtkSMProxy* proxy = this->proxy();
  if (!proxy || !proxy->GetProperty(kColorArrayProperty))
  {
    return true; // Nothing to tell: say only that an execution is needed.
  }
  const char* name =
    vtkSMPropertyHelper(proxy, kColorArrayProperty, /*quiet=*/true).GetInputArrayNameToProcess();
  return name && name[0];
}
