#include "pqNimbusMediumPresetWidget.h"

#include "NimbusMediumPresets.h"

#include "BlackbodyEmission.h" // Nimbus::Physics
#include "SpectralColor.h"

#include "pqApplicationCore.h"
#include "pqCoreUtilities.h"
#include "pqDataRepresentation.h"
#include "pqPipelineSource.h"
#include "pqServerManagerModel.h"
#include "pqUndoStack.h"
#include "pqView.h"
#include "vtkCommand.h"
#include "vtkDataObject.h"
#include "vtkOutputWindow.h"
#include "vtkPVArrayInformation.h"
#include "vtkPVDataInformation.h"
#include "vtkSMProperty.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMProxy.h"

#include <QComboBox>
#include <QLabel>
#include <QSignalBlocker>
#include <QStandardItemModel>
#include <QVBoxLayout>

#include <cmath>
#include <memory>
#include <stdexcept>

namespace
{
// The properties a preset sets, and those the glow's check reads.
const char* const kPresetProperties[] = { "ExtinctionPerDensity", "Albedo", "CloudG",
  "TemperatureEmission", "EmissionRadiancePerMetre" };
const char* const kGlowProperties[] = { "EmissionTemperatureArray",
  "EmissionReferenceTemperatureKelvin", "Exposure" };

// A glow is visible when a unit density at the data's hottest point adds at least this
// to a pixel over one metre of path (linear, before the sRGB encoding: about 3 steps of
// 255 after it). The yardstick is Exposure x E x Y[B(T)] / Y[B(T_ref)], the emission
// coefficient eta = E rho B(T) / Y[B(T_ref)] of Physics/BlackbodyEmission.h for rho = 1,
// integrated over 1 m without absorption, times the exposure.
constexpr double kVisibleGlow = 1e-3;

double Number(vtkSMProxy* proxy, const char* name, double fallback)
{
  return proxy->GetProperty(name) ? vtkSMPropertyHelper(proxy, name, /*quiet=*/true).GetAsDouble()
                                  : fallback;
}

nimbus::MediumValues ValuesOf(vtkSMProxy* proxy)
{
  nimbus::MediumValues values{};
  values.ExtinctionPerDensity = Number(proxy, "ExtinctionPerDensity", 0.0);
  values.Albedo = Number(proxy, "Albedo", 0.0);
  values.CloudG = Number(proxy, "CloudG", 0.0);
  values.TemperatureEmission = static_cast<int>(Number(proxy, "TemperatureEmission", 0.0));
  values.EmissionRadiancePerMetre = Number(proxy, "EmissionRadiancePerMetre", 0.0);
  return values;
}

pqDataRepresentation* RepresentationOf(vtkSMProxy* proxy)
{
  pqServerManagerModel* model = pqApplicationCore::instance()->getServerManagerModel();
  return model ? model->findItem<pqDataRepresentation*>(proxy) : nullptr;
}

// Y[B(T)] / Y[B(T_ref)] (Physics/BlackbodyEmission.h), the blackbody table built once per
// reference temperature.
double RelativeLuminance(double temperatureKelvin, double referenceKelvin)
{
  static std::unique_ptr<nimbus::BlackbodyEmission> emission;
  if (!emission || emission->GetReferenceTemperatureKelvin() != referenceKelvin)
  {
    emission.reset(new nimbus::BlackbodyEmission(nimbus::SpectralSamples(), referenceKelvin));
  }
  return emission->RelativeLuminance(temperatureKelvin);
}

// The lowest temperature [K] whose glow reaches kVisibleGlow for this brightness and
// exposure (bisection: the luminance grows with the temperature), or 0 when none up to
// 50000 K does.
double VisibleFromKelvin(double scale, double referenceKelvin)
{
  double low = 1.0, high = 50000.0;
  if (scale * RelativeLuminance(high, referenceKelvin) < kVisibleGlow)
  {
    return 0.0;
  }
  for (int i = 0; i < 40; ++i)
  {
    const double middle = 0.5 * (low + high);
    (scale * RelativeLuminance(middle, referenceKelvin) < kVisibleGlow ? low : high) = middle;
  }
  return high;
}

QString Describe(const nimbus::MediumValues& values)
{
  return QObject::tr("The values match no preset: extinction %1 /m per unit density, albedo %2, "
                     "forward scattering %3, glow %4.")
    .arg(values.ExtinctionPerDensity)
    .arg(values.Albedo)
    .arg(values.CloudG)
    .arg(values.TemperatureEmission ? QObject::tr("on") : QObject::tr("off"));
}
}

pqNimbusMediumPresetWidget::pqNimbusMediumPresetWidget(
  vtkSMProxy* proxy, vtkSMProperty* property, QWidget* parent)
  : Superclass(proxy, parent)
  , Menu(new QComboBox(this))
  , Problem(new QLabel(this))
{
  this->setProperty(property);
  this->setShowLabel(true);
  this->setChangeAvailableAsChangeFinished(false);
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  layout->addWidget(this->Menu);
  layout->addWidget(this->Problem);
  for (const nimbus::MediumPreset& preset : nimbus::kMediumPresets)
  {
    this->Menu->addItem(QString::fromUtf8(preset.Name));
    this->Menu->setItemData(
      this->Menu->count() - 1, QString::fromUtf8(preset.Description), Qt::ToolTipRole);
  }
  // "Custom" says that the values match no preset; it is not a choice.
  this->Menu->addItem(tr("Custom"));
  if (auto* model = qobject_cast<QStandardItemModel*>(this->Menu->model()))
  {
    model->item(this->customIndex())->setEnabled(false);
  }
  this->Menu->setObjectName("MediumPresetMenu");
  this->Problem->setObjectName("MediumPresetProblem");
  this->Problem->setWordWrap(true);
  this->Problem->setTextFormat(Qt::PlainText);
  this->Problem->setStyleSheet("QLabel { color: #a04000; }");
  this->Problem->hide();
  QObject::connect(this->Menu, QOverload<int>::of(&QComboBox::activated), this,
    [this](int index) { this->choose(index); });

  for (const char* name : kPresetProperties)
  {
    if (vtkSMProperty* watched = proxy->GetProperty(name))
    {
      pqCoreUtilities::connect(watched, vtkCommand::ModifiedEvent, this, SLOT(updateFromProxy()));
    }
  }
  for (const char* name : kGlowProperties)
  {
    if (vtkSMProperty* watched = proxy->GetProperty(name))
    {
      pqCoreUtilities::connect(watched, vtkCommand::ModifiedEvent, this, SLOT(updateFromProxy()));
    }
  }
  if (pqDataRepresentation* representation = RepresentationOf(proxy))
  {
    // The glow's check reads the data (a new time step, a changed source).
    QObject::connect(representation, &pqDataRepresentation::dataUpdated, this,
      &pqNimbusMediumPresetWidget::updateFromProxy);
  }
  this->updateFromProxy();
}

pqNimbusMediumPresetWidget::~pqNimbusMediumPresetWidget() = default;

int pqNimbusMediumPresetWidget::customIndex() const
{
  return nimbus::kNumberOfMediumPresets;
}

QString pqNimbusMediumPresetWidget::shownPreset() const
{
  return this->Menu->currentText();
}

void pqNimbusMediumPresetWidget::choose(int index)
{
  if (index < 0 || index >= nimbus::kNumberOfMediumPresets)
  {
    this->updateFromProxy();
    return;
  }
  // Display properties apply at once: the panel calls apply() on changeFinished.
  this->ChosenPreset = index;
  Q_EMIT this->changeAvailable();
  Q_EMIT this->changeFinished();
}

void pqNimbusMediumPresetWidget::apply()
{
  this->Superclass::apply();
  const int index = this->ChosenPreset;
  this->ChosenPreset = -1;
  if (index < 0 || index >= nimbus::kNumberOfMediumPresets)
  {
    return;
  }
  const nimbus::MediumPreset& preset = nimbus::kMediumPresets[index];
  vtkSMProxy* proxy = this->proxy();
  BEGIN_UNDO_SET(tr("Medium Preset: %1").arg(QString::fromUtf8(preset.Name)));
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
  END_UNDO_SET();
  this->updateFromProxy();

  const QString problem = this->glowProblem();
  if (!problem.isEmpty())
  {
    // Said where ParaView says what went wrong, not only under the menu.
    vtkOutputWindow::GetInstance()->DisplayWarningText(
      tr("Medium Preset \"%1\": %2\n")
        .arg(QString::fromUtf8(preset.Name), problem)
        .toUtf8()
        .data());
  }
  // Display properties take effect at once: draw them now.
  pqDataRepresentation* representation = RepresentationOf(proxy);
  if (representation && representation->getView())
  {
    representation->getView()->render();
  }
}

void pqNimbusMediumPresetWidget::reset()
{
  this->Superclass::reset();
  this->ChosenPreset = -1;
  this->updateFromProxy();
}

void pqNimbusMediumPresetWidget::updateFromProxy()
{
  const nimbus::MediumValues values = ValuesOf(this->proxy());
  const int preset = nimbus::MatchingMediumPreset(values);
  {
    const QSignalBlocker blocker(this->Menu);
    this->Menu->setCurrentIndex(preset >= 0 ? preset : this->customIndex());
  }
  QString toolTip =
    preset >= 0 ? QString::fromUtf8(nimbus::kMediumPresets[preset].Description) : Describe(values);
  toolTip += "\n" +
    tr("Choose a preset to set the extinction, albedo, forward scattering and temperature "
       "emission for that kind of medium; each stays editable.");
  const QString problem = this->glowProblem();
  this->Problem->setText(problem);
  this->Problem->setVisible(!problem.isEmpty());
  if (!problem.isEmpty())
  {
    toolTip += "\n\n" + problem;
  }
  this->Menu->setToolTip(toolTip);
}

QString pqNimbusMediumPresetWidget::glowProblem() const
{
  vtkSMProxy* proxy = this->proxy();
  if (Number(proxy, "TemperatureEmission", 0.0) == 0.0)
  {
    return QString();
  }
  const double brightness = Number(proxy, "EmissionRadiancePerMetre", 0.0);
  if (!(brightness > 0.0))
  {
    return tr("Nothing glows: the Glow Brightness is 0.");
  }
  pqDataRepresentation* representation = RepresentationOf(proxy);
  vtkPVDataInformation* data = representation ? representation->getInputDataInformation() : nullptr;
  if (!data || data->GetNumberOfPoints() == 0 || !proxy->GetProperty("EmissionTemperatureArray"))
  {
    return QString(); // nothing to look at yet
  }
  const QString arrayName = QString::fromUtf8(
    vtkSMPropertyHelper(proxy, "EmissionTemperatureArray", /*quiet=*/true).GetAsString());
  const QByteArray arrayBytes = arrayName.toUtf8();
  vtkPVArrayInformation* array = data->GetArrayInformation(arrayBytes.data(), vtkDataObject::POINT);
  if (!array)
  {
    array = data->GetArrayInformation(arrayBytes.data(), vtkDataObject::CELL);
  }
  const QString source =
    representation->getInput() ? representation->getInput()->getSMName() : tr("this data");
  if (!array || array->GetNumberOfComponents() != 1)
  {
    return tr("Nothing glows: Temperature Emission needs an array \"%1\" of temperatures in "
              "kelvin, and %2 has none. Fire is for data with a temperature, such as a Nimbus "
              "Smoke.")
      .arg(arrayName, source);
  }
  const double hottest = array->GetComponentRange(0)[1];
  const double reference = Number(proxy, "EmissionReferenceTemperatureKelvin", 1500.0);
  const double scale = brightness * Number(proxy, "Exposure", 10.0);
  try
  {
    const double glow = scale * RelativeLuminance(hottest, reference);
    if (glow >= kVisibleGlow)
    {
      return QString();
    }
    const double visible = VisibleFromKelvin(scale, reference);
    return tr("Nothing visible glows: the hottest point of \"%1\" on %2 is %3 K, too cool to "
              "give visible light (with this Glow Brightness and Exposure the glow starts to "
              "show at about %4 K). Make the data hotter (a Nimbus Smoke's Emitter "
              "Temperature, e.g. 1500 K).")
      .arg(arrayName, source)
      .arg(hottest, 0, 'f', 0)
      .arg(visible, 0, 'f', 0);
  }
  catch (const std::invalid_argument&)
  {
    return tr("Nothing glows: the Reference Temperature must be between 500 and 50000 K.");
  }
}
