// Pieces of an image source's output (data parallel, under MPI): the extent the pipeline asks
// for, and the crop of a whole-grid result to it (Nimbus::Common; used by the sources of
// Nimbus::Filters).
//
// With CAN_PRODUCE_SUB_EXTENT set in RequestInformation, VTK's streaming executive turns a
// piece request (UPDATE_PIECE_NUMBER, UPDATE_NUMBER_OF_PIECES, UPDATE_NUMBER_OF_GHOST_LEVELS)
// into UPDATE_EXTENT: the piece's block of the whole extent grown by the ghost levels and
// clamped to the whole extent. After RequestData it marks the layers outside the piece's own
// block in vtkGhostType (DUPLICATEPOINT / DUPLICATECELL), so a source only has to produce
// UPDATE_EXTENT exactly (checked by Testing/Python/TestParallelPieces.py).
#ifndef NimbusPieceExtent_h
#define NimbusPieceExtent_h

#include "vtkDataObject.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>

namespace nimbus
{
/// The extent to produce on the output described by outInfo: UPDATE_EXTENT within
/// WHOLE_EXTENT (the whole extent when nothing was requested). Returns false when it is empty
/// (more pieces than cells, or an empty request): the output is then an empty image.
inline bool RequestedExtent(vtkInformation* outInfo, int extent[6])
{
  int whole[6] = { 0, -1, 0, -1, 0, -1 };
  if (outInfo->Has(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()))
  {
    outInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole);
  }
  std::copy(whole, whole + 6, extent);
  if (outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT()))
  {
    int update[6];
    outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(), update);
    for (int a = 0; a < 3; ++a)
    {
      extent[2 * a] = std::max(whole[2 * a], update[2 * a]);
      extent[2 * a + 1] = std::min(whole[2 * a + 1], update[2 * a + 1]);
    }
  }
  return extent[0] <= extent[1] && extent[2] <= extent[3] && extent[4] <= extent[5];
}

/// Asks an input for all of its data whatever piece this output is: piece 0 of 1, no ghost
/// levels (so no ghost array either), and for structured data the whole extent.
inline void RequestWholeInput(vtkInformation* inInfo)
{
  inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER(), 0);
  inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES(), 1);
  inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_GHOST_LEVELS(), 0);
  if (inInfo->Has(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()))
  {
    inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(),
      inInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()), 6);
  }
}

/// Crops an image computed over the whole extent to the requested one (copies the point and
/// cell arrays of the extent; field data kept). The values are the whole result's, so a piece
/// is bit-identical to the serial output there. An empty request leaves an empty image with
/// the same geometry.
inline void CropToRequestedExtent(vtkImageData* image, vtkInformation* outInfo)
{
  int extent[6];
  if (RequestedExtent(outInfo, extent))
  {
    int current[6];
    image->GetExtent(current);
    if (!std::equal(extent, extent + 6, current))
    {
      image->Crop(extent);
    }
    return;
  }
  double origin[3], spacing[3];
  image->GetOrigin(origin);
  image->GetSpacing(spacing);
  image->Initialize();
  image->SetOrigin(origin);
  image->SetSpacing(spacing);
}
}

#endif
