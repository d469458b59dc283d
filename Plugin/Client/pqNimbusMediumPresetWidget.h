/**
 * @class   pqNimbusMediumPresetWidget
 * @brief   The Cloud representation's "Medium Preset" menu: sets the optics (and the
 *          temperature emission) for clouds, smoke, dark smoke or fire in one choice.
 *
 * Given in the XML as the panel widget of a property without a command,
 *
 *   <Property name="MediumPreset" label="Medium Preset" panel_widget="nimbus_medium_preset" />
 *
 * it shows a menu of NimbusMediumPresets.h's presets. Choosing one sets the proxy's
 * ExtinctionPerDensity, Albedo, CloudG, TemperatureEmission and EmissionRadiancePerMetre,
 * pushes them and renders; the menu then reads "Choose..." again, since the values, not
 * the menu, are the state (each stays editable).
 */
#ifndef pqNimbusMediumPresetWidget_h
#define pqNimbusMediumPresetWidget_h

#include "pqPropertyWidget.h"

class QComboBox;

class pqNimbusMediumPresetWidget : public pqPropertyWidget
{
  Q_OBJECT
  typedef pqPropertyWidget Superclass;

public:
  pqNimbusMediumPresetWidget(vtkSMProxy* proxy, vtkSMProperty* property, QWidget* parent = nullptr);
  ~pqNimbusMediumPresetWidget() override;

private:
  void apply(int index);
  QComboBox* Menu;

  Q_DISABLE_COPY(pqNimbusMediumPresetWidget)
};

#endif
