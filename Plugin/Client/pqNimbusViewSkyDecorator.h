/**
 * @class   pqNimbusViewSkyDecorator
 * @brief   Greys out a Cloud property while the view's Nimbus Sky sets it instead.
 *
 * One sun per view: while a Nimbus Sky is shown in a render view ("Sky Background"
 * representation, visible) and the Cloud representation's UseSceneSky ("Use the
 * View's Sky") is on, vtkNimbusCloudVolumeMapper lights the cloud with the sky's
 * sun, air, ground albedo and exposure, and the cloud's own values of those
 * properties are not used. This decorator, given in the property's XML hints as
 *
 *   <PropertyWidgetDecorator type="NimbusViewSkyDecorator" />
 *
 * (usually inside a CompositeDecorator with the "Representation is Cloud"
 * visibility test), disables the property's widget in that case and names the
 * sky in its tooltip, so that the panel shows which values count. It watches the
 * representation's view (representations added, removed, shown, hidden, and every
 * render, which follows a change of a representation's type) and the UseSceneSky
 * property. It only affects the panel; the rule itself is the mapper's
 * (vtkNimbusCloudVolumeMapper::GetFollowedSky).
 */
#ifndef pqNimbusViewSkyDecorator_h
#define pqNimbusViewSkyDecorator_h

#include "pqPropertyWidgetDecorator.h"

#include <QPointer>

class pqView;

class pqNimbusViewSkyDecorator : public pqPropertyWidgetDecorator
{
  Q_OBJECT
  typedef pqPropertyWidgetDecorator Superclass;

public:
  pqNimbusViewSkyDecorator(vtkPVXMLElement* config, pqPropertyWidget* parentObject);
  ~pqNimbusViewSkyDecorator() override;

  /// False while the view's sky replaces this property (see the class comment).
  bool enableWidget() const override;

  /// The representation type that draws a Nimbus Sky as the view's background.
  static const char* SkyBackgroundType() { return "Sky Background"; }

private Q_SLOTS:
  /// Re-evaluates the state; signals enableStateChanged() when it changed.
  void updateState();
  /// Follows the representation into (another) view.
  void updateView();

private:
  Q_DISABLE_COPY(pqNimbusViewSkyDecorator)

  /// True when UseSceneSky is on and a Nimbus Sky is visible in the view.
  bool computeSkyInUse() const;

  QPointer<pqView> View;
  bool SkyInUse = false;
};

#endif
