/**
 * @class   vtkNimbusLightningSource
 * @brief   Lightning strokes (003 §3, Reed & Wyvill 1994) and their point sources, over time.
 *
 * Grows one flash's channels from a seed point (Physics/Lightning.h: GenerateLightning):
 * a main channel of Length metres heading along Direction, turning by a mean 16 degrees
 * per segment of about SegmentLength metres (Hill 1968), branching with
 * BranchProbability per segment up to MaxBranchDepth levels, each level carrying
 * BranchIntensityFactor of its parent's intensity; channels end at GroundHeight. The
 * same parameters and Seed give the same flash on every run.
 *
 * Output port 0, the strokes: vtkPolyData, one line cell per segment, with cell data
 * "intensity" (radiant intensity per metre of channel at the requested time, in units
 * where the sun's irradiance is 1: the same radiometry as the cloud mapper's sun),
 * "peak_intensity" (the same at the return stroke) and "depth" (0 main channel, 1 its
 * branches, ...), and point data "path_length" (metres from the seed along the channel).
 * Output port 1, the point sources of 003 Eq. 3: vtkPolyData vertices at most
 * PointSourceSpacing metres apart along every segment, point data "intensity" (radiant
 * intensity of each source at the requested time: the segment's per-metre intensity x
 * its share of the segment's length), which together carry the strokes' emission
 * exactly. Sources of zero intensity are left out (before the flash: none).
 *
 * Time: the flash follows Physics/Lightning.h's LightningFlashTimeline (a faint stepped
 * leader of LeaderDuration seconds, the return stroke, NumberOfStrokes - 1 subsequent
 * strokes InterstrokeInterval apart along the main channel, each decaying with
 * StrokeDecaySeconds) starting at FlashStartTime. The source advertises NumberOfTimeSteps
 * + 1 TIME_STEPS evenly spread over [0, FlashStartTime + the flash's duration] and the
 * peak of every stroke, so ParaView's animation plays the flash; a request without a
 * time gives the return stroke's peak.
 *
 * Default: a 3 km channel down from (0, 0, 2000) m to the ground at z = 0, intensity
 * 100 per metre (at 500 m from a long channel, an irradiance of about 0.6 of the
 * sun's: a return stroke near its peak, ~1e5 W/sr per metre, against the sun's 1 kW/m^2).
 *
 * Bad input (NaN, zero direction, lengths <= 0, probabilities out of range, a stroke of
 * more than a million segments, a spacing that makes more than 1e7 sources) ends in an
 * error naming the parameter and empty outputs.
 */
#ifndef vtkNimbusLightningSource_h
#define vtkNimbusLightningSource_h

#include "NimbusFiltersModule.h" // for export macro
#include "vtkPolyDataAlgorithm.h"

class NIMBUSFILTERS_EXPORT vtkNimbusLightningSource : public vtkPolyDataAlgorithm
{
public:
  static vtkNimbusLightningSource* New();
  vtkTypeMacro(vtkNimbusLightningSource, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// Seed point (metres; inside the cloud) and overall direction of the main channel.
  /// Defaults (0, 0, 2000) and (0, 0, -1).
  vtkSetVector3Macro(StartPoint, double);
  vtkGetVector3Macro(StartPoint, double);
  vtkSetVector3Macro(Direction, double);
  vtkGetVector3Macro(Direction, double);
  ///@}

  ///@{
  /// Main channel length and mean segment length, metres. Defaults 3000 and 30.
  vtkSetMacro(Length, double);
  vtkGetMacro(Length, double);
  vtkSetMacro(SegmentLength, double);
  vtkGetMacro(SegmentLength, double);
  ///@}

  ///@{
  /// Branching: probability per segment (default 0.06), levels (default 3), intensity
  /// and length of a branch relative to its parent (defaults 0.4 and 0.35).
  vtkSetMacro(BranchProbability, double);
  vtkGetMacro(BranchProbability, double);
  vtkSetMacro(MaxBranchDepth, int);
  vtkGetMacro(MaxBranchDepth, int);
  vtkSetMacro(BranchIntensityFactor, double);
  vtkGetMacro(BranchIntensityFactor, double);
  vtkSetMacro(BranchLengthFactor, double);
  vtkGetMacro(BranchLengthFactor, double);
  ///@}

  ///@{
  /// Mean turn between segments (degrees, default 16: Hill 1968) and the pull toward
  /// Direction per segment ([0, 1], default 0.1).
  vtkSetMacro(MeanAngleDegrees, double);
  vtkGetMacro(MeanAngleDegrees, double);
  vtkSetMacro(Straightness, double);
  vtkGetMacro(Straightness, double);
  ///@}

  ///@{
  /// Radiant intensity per metre of the main channel at the return stroke's peak (sun
  /// irradiance = 1 units; default 100) and the height where channels end (metres,
  /// default 0: the ground).
  vtkSetMacro(Intensity, double);
  vtkGetMacro(Intensity, double);
  vtkSetMacro(GroundHeight, double);
  vtkGetMacro(GroundHeight, double);
  ///@}

  ///@{
  /// Seed of every random draw. Default 1.
  vtkSetMacro(Seed, int);
  vtkGetMacro(Seed, int);
  ///@}

  ///@{
  /// Largest distance between point sources along a segment (metres, default 10).
  vtkSetMacro(PointSourceSpacing, double);
  vtkGetMacro(PointSourceSpacing, double);
  ///@}

  ///@{
  /// The flash over time (seconds; see the class description): when it starts
  /// (default 0.05), the leader's duration (0.03), the number of strokes (4), the
  /// interval between them (0.06), each subsequent stroke's strength relative to the
  /// one before (0.6) and the strokes' decay time (0.015); NumberOfTimeSteps (default
  /// 60) frames advertised over the flash.
  vtkSetMacro(FlashStartTime, double);
  vtkGetMacro(FlashStartTime, double);
  vtkSetMacro(LeaderDuration, double);
  vtkGetMacro(LeaderDuration, double);
  vtkSetMacro(NumberOfStrokes, int);
  vtkGetMacro(NumberOfStrokes, int);
  vtkSetMacro(InterstrokeInterval, double);
  vtkGetMacro(InterstrokeInterval, double);
  vtkSetMacro(SubsequentStrokeFactor, double);
  vtkGetMacro(SubsequentStrokeFactor, double);
  vtkSetMacro(StrokeDecaySeconds, double);
  vtkGetMacro(StrokeDecaySeconds, double);
  vtkSetClampMacro(NumberOfTimeSteps, int, 1, 100000);
  vtkGetMacro(NumberOfTimeSteps, int);
  ///@}

protected:
  vtkNimbusLightningSource();
  ~vtkNimbusLightningSource() override = default;

  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  double StartPoint[3] = { 0.0, 0.0, 2000.0 };
  double Direction[3] = { 0.0, 0.0, -1.0 };
  double Length = 3000.0;
  double SegmentLength = 30.0;
  double BranchProbability = 0.06;
  int MaxBranchDepth = 3;
  double BranchIntensityFactor = 0.4;
  double BranchLengthFactor = 0.35;
  double MeanAngleDegrees = 16.0;
  double Straightness = 0.1;
  double Intensity = 100.0;
  double GroundHeight = 0.0;
  int Seed = 1;
  double PointSourceSpacing = 10.0;
  double FlashStartTime = 0.05;
  double LeaderDuration = 0.03;
  int NumberOfStrokes = 4;
  double InterstrokeInterval = 0.06;
  double SubsequentStrokeFactor = 0.6;
  double StrokeDecaySeconds = 0.015;
  int NumberOfTimeSteps = 60;

private:
  vtkNimbusLightningSource(const vtkNimbusLightningSource&) = delete;
  void operator=(const vtkNimbusLightningSource&) = delete;
};

#endif
