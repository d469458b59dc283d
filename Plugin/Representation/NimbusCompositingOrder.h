// Where this rank's image goes in ParaView's ordered compositing (under MPI).
//
// Under MPI with ordered compositing (volumes present), IceT composites the ranks'
// images with "over" in the order vtkOrderedCompositingHelper computes from the view's
// cuts (the pieces' boxes) and camera. The layer that must be at the bottom (the air,
// the ground, the sky) belongs to the rank last in that order: this asks ParaView's own
// helper with the same boxes and camera, so the answer is the order IceT uses.
#ifndef NimbusCompositingOrder_h
#define NimbusCompositingOrder_h

class vtkPVRenderView;

namespace nimbus
{
/// Whether `view` composites ordered pieces from more than one rank now.
bool IsOrderedCompositing(vtkPVRenderView* view);
/// Whether this rank's image is the bottom layer (last in the order) for the view's
/// camera now; true without ordered compositing (one image, this one).
bool IsLastInCompositingOrder(vtkPVRenderView* view);
} // namespace nimbus

#endif
