/**
 * @class   pqNimbusEstimatedExtinctionWidget
 * @brief   The Cloud representation's Target Optical Thickness field with, under it, the
 *          extinction per unit of the array that the "Unknown" choice of Density Array
 *          Means estimated from it.
 *
 * Given in the XML as the panel widget of the target,
 *
 *   <DoubleVectorProperty name="TargetOpticalThickness" ...
 *       panel_widget="nimbus_estimated_extinction">
 *
 * it shows ParaView's usual editor of the value (pqDoubleVectorPropertyWidget: slider and
 * text entry, applied as any display property) and a read-only line: "gives 0.0123 /m per
 * unit of the array", the scale k [1/m per unit value] for which the cloud's median
 * vertical optical thickness is the target (nimbus::EstimateExtinctionPerDensity in
 * Physics/CloudOptics.h), read from the information-only property
 * EstimatedExtinctionPerDensityInfo (vtkNimbusCloudRepresentation::
 * GetEstimatedExtinctionPerDensity). Before the representation has executed with the
 * estimate (or when it found nothing to scale) the line says "apply and render to
 * estimate", or "choose the density array (Coloring) to estimate" while Coloring is Solid
 * Color (no array: nothing to scale).
 *
 * The value is computed where the representation executes (the data server), so the line
 * pulls it (vtkSMProxy::UpdatePropertyInformation) each time the representation's proxy
 * reports new data (vtkCommand::UpdateDataEvent, sent after a render that executed it) and
 * each time the view reports an update.
 */
#ifndef pqNimbusEstimatedExtinctionWidget_h
#define pqNimbusEstimatedExtinctionWidget_h

#include "pqPropertyWidget.h"

#include <QPointer>

class QLabel;
class vtkSMProperty;

class pqNimbusEstimatedExtinctionWidget : public pqPropertyWidget
{
  Q_OBJECT
  typedef pqPropertyWidget Superclass;

public:
  pqNimbusEstimatedExtinctionWidget(
    vtkSMProxy* proxy, vtkSMProperty* property, QWidget* parent = nullptr);
  ~pqNimbusEstimatedExtinctionWidget() override;

  /// The target's editor applies and resets the value.
  void apply() override;
  void reset() override;
  void select() override;
  void deselect() override;

  /// The line under the field, as shown.
  QString estimateText() const;

  /// The name of the information-only property that holds the estimate [1/m per unit].
  static const char* informationPropertyName();

public Q_SLOTS:
  void setView(pqView* view) override;

private Q_SLOTS:
  /// Pulls the estimate from the representation, then shows it.
  void refreshEstimate();
  /// Shows the value the information property holds.
  void showEstimate();

private:
  /// Whether the display has a density array chosen (Coloring), which the estimate needs.
  bool hasDensityArray() const;

  pqPropertyWidget* Editor;
  QLabel* Estimate;
  vtkSMProxy* Owner;
  vtkSMProperty* Information;
  QPointer<pqView> WatchedView;

  Q_DISABLE_COPY(pqNimbusEstimatedExtinctionWidget)
};

#endif
