/**
 * @class   pqNimbusPlaybackBehavior
 * @brief   Interactive Cloud frames while the GUI plays an animation, a full-quality one after.
 *
 * Started with the plugin (an auto-start interface). ParaView's animation renders every
 * time step as a still frame: a Cloud at full quality takes seconds on a machine without a
 * GPU, so a flash played through its time steps would crawl. While the active animation
 * scene plays, every visible Cloud representation draws interactive frames (its Frame
 * Budget's reduced work, as while the camera is dragged: the PlaybackInteractive property);
 * when it stops (the end, or Pause), the views are drawn once more at full quality.
 * Saving an animation (File > Save Animation) keeps full quality: the scene's writer turns
 * its still renders off, and those frames are left alone.
 */
#ifndef pqNimbusPlaybackBehavior_h
#define pqNimbusPlaybackBehavior_h

#include <QList>
#include <QObject>
#include <QPointer>

class pqDataRepresentation;
class vtkObject;

class pqNimbusPlaybackBehavior : public QObject
{
  Q_OBJECT

public:
  pqNimbusPlaybackBehavior(QObject* parent = nullptr);
  ~pqNimbusPlaybackBehavior() override;

  /// Called when the plugin loads and unloads.
  void startup();
  void shutdown();

private Q_SLOTS:
  void onBeginPlay(vtkObject* caller, unsigned long, void*, void*);
  void onEndPlay(vtkObject* caller, unsigned long, void*, void*);

private:
  Q_DISABLE_COPY(pqNimbusPlaybackBehavior)
  /// Connects to the animation manager's play signals; false while there is none yet.
  bool connectToAnimation();
  /// The Cloud representations made interactive by the play that runs.
  QList<QPointer<pqDataRepresentation>> Interactive;
};

#endif
