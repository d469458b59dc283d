/**
 * @class   pqNimbusFirstApplyBehavior
 * @brief   The ParaView GUI's first look at Nimbus data: a side view, no legends.
 *
 * Started with the plugin (an auto-start interface). In every render view it
 * - turns the camera, when the first data shown in the view comes from a Nimbus source or
 *   filter (Nimbus Metaball Cloud, Cloud Automaton (With Maps), Image Cloud, OpenVDB reader,
 *   Sky; a filter's input, hidden by Apply, and a sky background do not count), to look from
 *   the south (+y), 11 degrees down, z up: the ground at the bottom,
 *   where ParaView would look down -z at the clouds' tops;
 * - in a view that already shows data (where ParaView's Apply keeps the camera), frames new
 *   Nimbus data that the camera shows tiny or not at all (less than 15 % of the view's
 *   side on screen), keeping the view's direction: with what the view shows when it is at
 *   least a tenth of its size, alone otherwise (a smoke of metres beside a cloud of
 *   kilometres);
 * - gives a Nimbus Smoke smoke's optics (the Smoke medium preset) whatever the view holds,
 *   and, when the smoke is still empty at the animation's time (time 0: nothing emitted
 *   yet), moves the animation to 2 s, a plume that has risen;
 * - keeps the "Cloud" and "Sky Background" representations without a colour legend: their
 *   picture does not use the colour map, so a legend (ParaView shows one whenever a
 *   representation is coloured by an array) would describe nothing on screen. The sky starts
 *   with Solid Color (its "Colors" array only matters for the Surface representation); a
 *   cloud coloured by an array (the array chosen is then the density) shows no legend.
 *
 * Representations brought back by loading a state file (the GUI's or Python's) or by undo
 * and redo keep the values they had. Everything else in ParaView (other sources, other
 * representations, pvpython without the GUI) is left as it is.
 */
#ifndef pqNimbusFirstApplyBehavior_h
#define pqNimbusFirstApplyBehavior_h

#include <QObject>
#include <QPointer>

class pqRepresentation;
class pqView;
class vtkObject;

class pqNimbusFirstApplyBehavior : public QObject
{
  Q_OBJECT

public:
  pqNimbusFirstApplyBehavior(QObject* parent = nullptr);
  ~pqNimbusFirstApplyBehavior() override;

  /// Called when the plugin loads and unloads.
  void startup();
  void shutdown();

private Q_SLOTS:
  void onViewAdded(pqView* view);
  void onRepresentationAdded(pqRepresentation* representation);
  /// Hides the legends of the view's Cloud and Sky Background representations.
  void hideLegends(pqView* view);

private:
  Q_DISABLE_COPY(pqNimbusFirstApplyBehavior)
};

#endif
