#include "pqNimbusMediumPresetWidget.h"

#include "NimbusMediumPresets.h"

#include "pqApplicationCore.h"
#include "pqProxy.h"
#include "pqRepresentation.h"
#include "pqServerManagerModel.h"
#include "pqView.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMProxy.h"

#include <QComboBox>
#include <QHBoxLayout>

pqNimbusMediumPresetWidget::pqNimbusMediumPresetWidget(
  vtkSMProxy* proxy, vtkSMProperty* property, QWidget* parent)
  : Superclass(proxy, parent)
  , Menu(new QComboBox(this))
{
  (void)property;
  this->setShowLabel(true);
  auto* layout = new QHBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  layout->addWidget(this->Menu);
  this->Menu->addItem(tr("Choose..."));
  for (const nimbus::MediumPreset& preset : nimbus::kMediumPresets)
  {
    this->Menu->addItem(QString::fromUtf8(preset.Name));
    this->Menu->setItemData(
      this->Menu->count() - 1, QString::fromUtf8(preset.Description), Qt::ToolTipRole);
  }
  this->Menu->setObjectName("MediumPresetMenu");
  this->Menu->setToolTip(tr("Sets the extinction, albedo, forward scattering and temperature "
                            "emission for the chosen kind of medium; each stays editable."));
  QObject::connect(this->Menu, QOverload<int>::of(&QComboBox::activated), this,
    [this](int index) { this->apply(index); });
}

pqNimbusMediumPresetWidget::~pqNimbusMediumPresetWidget() = default;

void pqNimbusMediumPresetWidget::apply(int index)
{
  const int count =
    static_cast<int>(sizeof(nimbus::kMediumPresets) / sizeof(nimbus::kMediumPresets[0]));
  if (index < 1 || index > count)
  {
    return;
  }
  const nimbus::MediumPreset& preset = nimbus::kMediumPresets[index - 1];
  vtkSMProxy* proxy = this->proxy();
  const auto set = [proxy](const char* name, double value)
  {
    if (proxy->GetProperty(name))
    {
      vtkSMPropertyHelper(proxy, name).Set(value);
    }
  };
  set("ExtinctionPerDensity", preset.ExtinctionPerDensity);
  set("Albedo", preset.Albedo);
  set("CloudG", preset.CloudG);
  set("EmissionRadiancePerMetre", preset.EmissionRadiancePerMetre);
  if (proxy->GetProperty("TemperatureEmission"))
  {
    vtkSMPropertyHelper(proxy, "TemperatureEmission").Set(preset.TemperatureEmission);
  }
  proxy->UpdateVTKObjects();
  this->Menu->setCurrentIndex(0);
  Q_EMIT this->changeAvailable();
  Q_EMIT this->changeFinished();
  // Display properties take effect at once: draw them.
  pqServerManagerModel* model = pqApplicationCore::instance()->getServerManagerModel();
  if (pqProxy* item = model->findItem<pqProxy*>(proxy))
  {
    if (auto* representation = qobject_cast<pqRepresentation*>(item))
    {
      if (pqView* view = representation->getView())
      {
        view->render();
      }
    }
  }
}
