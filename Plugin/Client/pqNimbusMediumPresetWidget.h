/**
 * @class   pqNimbusMediumPresetWidget
 * @brief   The Cloud representation's "Medium Preset" menu: sets the optics (and the
 *          temperature emission) for clouds, smoke, dark smoke or fire in one choice,
 *          and shows which of them the display has.
 *
 * Given in the XML as the panel widget of a property without a command,
 *
 *   <Property name="MediumPreset" label="Medium Preset" panel_widget="nimbus_medium_preset" />
 *
 * it shows a menu of NimbusMediumPresets.h's presets and "Custom". The menu always shows
 * the preset whose values the display has (ExtinctionPerDensity, Albedo, CloudG,
 * TemperatureEmission and, while the glow is on, EmissionRadiancePerMetre, each within a
 * small tolerance: nimbus::MatchingMediumPreset), or "Custom" when they match none; it
 * follows every change of those properties (a field edited by hand, undo and redo, a
 * state file loaded, Python).
 *
 * Choosing a preset sets those properties in one undoable step ("Medium Preset: ...")
 * and renders the view at once. While Temperature Emission is on, a line under the menu
 * says in plain words when nothing can glow on this data: no temperature array, or a
 * hottest point too cool to give visible light (the blackbody luminance of
 * Physics/BlackbodyEmission.h against the Reference Temperature); choosing a preset that
 * cannot glow also puts that sentence in ParaView's Output Messages as a warning.
 */
#ifndef pqNimbusMediumPresetWidget_h
#define pqNimbusMediumPresetWidget_h

#include "pqPropertyWidget.h"

class QComboBox;
class QLabel;

class pqNimbusMediumPresetWidget : public pqPropertyWidget
{
  Q_OBJECT
  typedef pqPropertyWidget Superclass;

public:
  pqNimbusMediumPresetWidget(vtkSMProxy* proxy, vtkSMProperty* property, QWidget* parent = nullptr);
  ~pqNimbusMediumPresetWidget() override;

  /// Sets the values of the preset chosen in the menu (one undo step) and renders.
  void apply() override;
  /// Forgets a chosen preset not yet applied; the menu shows the display's values again.
  void reset() override;

  /// What the menu shows: the name of the preset whose values the display has, or
  /// "Custom".
  QString shownPreset() const;
  /// The plain-words reason why the glow cannot show on this data, or an empty string
  /// (also when Temperature Emission is off).
  QString glowProblem() const;

private Q_SLOTS:
  /// Shows the display's preset (or "Custom") and the glow's problem, if any.
  void updateFromProxy();

private:
  void choose(int index);
  int customIndex() const;

  QComboBox* Menu;
  QLabel* Problem;
  int ChosenPreset = -1;

  Q_DISABLE_COPY(pqNimbusMediumPresetWidget)
};

#endif
