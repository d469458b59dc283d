// Smoke (002 §4, Yoshida & Nishita 2000 = 002's [13]): an incompressible fluid with
// temperature and buoyancy on a staggered (MAC) grid, carrying a smoke density. Plain
// C++ (Eigen for the pressure solve), no VTK.
//
// Grid: nx x ny x nz cubic cells of side h [m], cell (i, j, k) spanning
// Origin + h [i, i+1] x [j, j+1] x [k, k+1]; z up. Density rho (smoke, dimensionless, what
// the renderer multiplies by its extinction per density) and temperature T [K] at cell
// centres; the velocity [m/s] as the components normal to the faces, u on the x faces
// ((nx+1) x ny x nz), v on the y faces, w on the z faces (002 §4 / Fig. 8: "at the centre
// of each face ... a velocity component perpendicular to the face, and at the centre of
// the voxel ... temperature and pressure").
//
// One step of dt [s] (sub-stepped so that no sample travels more than MaxCfl cells):
//  1. emitters: inside each sphere the density grows by Rate dt, the temperature is
//     raised to the emitter's, the face velocities are set to its velocity (when it has
//     one);
//  2. forces: Boussinesq buoyancy on w, g ((T - T_amb) / T_amb - Weight rho) [m/s^2];
//     wind as a drag toward the wind velocity, (wind - u) WindCoupling; vorticity
//     confinement (Fedkiw, Stam & Jensen 2001), eps h (N x omega);
//  3. the eddy viscosity of 002 §4's Reynolds equations: the Reynolds stresses of the
//     random velocity components modelled as a turbulent viscosity nu_t [m^2/s]
//     (Boussinesq's eddy-viscosity hypothesis), constant (EddyViscosity) or Smagorinsky's
//     nu_t = (C_s h)^2 |S| (SmagorinskyConstant), applied explicitly (sub-stepped to keep
//     nu_t dt / h^2 <= 1/6);
//  4. projection: the pressure that makes the velocity divergence-free, Poisson's
//     equation on the fluid cells (obstacles and the bottom wall: no flow through them;
//     the top: open, pressure 0; the sides: walls or open, SideBoundaries below) solved
//     by conjugate gradients preconditioned with a geometric multigrid V-cycle (MGPCG,
//     McAdams et al. 2010: SmokePressure.h; multithreaded, its iterations about constant
//     as the grid grows) or, as an option, with an incomplete Cholesky factorisation
//     (Eigen, natural order, factored once per obstacle layout), each solve started from
//     the last pressure;
//  5. advection of velocity, density and temperature along the projected velocity:
//     semi-Lagrangian (a second-order backtrace, trilinear samples) or MacCormack
//     (Selle et al. 2008, clamped to the neighbourhood of the backtraced point);
//  6. decay: the temperature relaxes to ambient at CoolingPerSecond, the density fades
//     at DissipationPerSecond.
//
// The box's sides (its x and y faces; SmokeParameters::SideBoundaries): walls (no flow
// through them), or open: the air beyond them is at pressure 0 like the air above the
// top (Dirichlet in the pressure equation on every multigrid level), their faces'
// velocities are free (set by the forces, the eddy viscosity and the projection, not
// zeroed), and the advection sees the air outside as the inflow: the wind's velocity, no
// smoke, the ambient temperature (one layer of samples beyond each open side holding
// those values, points farther out taking them too); smoke carried out through an open
// side leaves the box. Automatic (the default): open when there is wind (|Wind| > 0 and
// WindCoupling > 0), walls otherwise, so a calm run is exactly what it was with walls.
// Without open sides a uniform wind in a closed box is (nearly) a pure gradient and the
// projection removes it: the air barely moves. The top is always open (its advection
// samples clamped to the last layer), the bottom always a wall, obstacles always solid.
//
// Deterministic: every value is written by one thread, in no order that matters; the
// pressure solve's sums are taken per z-layer and added in layer order (the same for
// any thread count).
#ifndef nimbus_SmokeSolver_h
#define nimbus_SmokeSolver_h

#include "Math.h"

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace nimbus
{

struct SmokeEmitter
{
  Vector3 Centre{ { 0, 0, 0 } };    // [m]
  double RadiusMetres = 1.0;        // > 0
  double DensityPerSecond = 1.0;    // >= 0: density added per second inside
  double TemperatureKelvin = 600.0; // the smoke's temperature where it is emitted
  Vector3 Velocity{ { 0, 0, 0 } };  // [m/s], set on the faces inside (0: left alone)
};

enum class SmokeAdvection
{
  SemiLagrangian = 0,
  MacCormack = 1
};

/// The box's x and y faces (see the file comment).
enum class SmokeSideBoundaries
{
  Automatic = 0, // open when |Wind| > 0 and WindCoupling > 0, walls otherwise
  Walls = 1,     // no flow through them
  Open = 2       // pressure 0 beyond them; inflow: the wind, no smoke, ambient temperature
};

enum class SmokePressureSolver
{
  Multigrid = 0,         // MGPCG (SmokePressure.h): multithreaded, cost linear in the cells
  IncompleteCholesky = 1 // Eigen's IC-CG: one thread, iterations grow with the grid
};

struct SmokeParameters
{
  std::array<int, 3> Dimensions{ { 32, 32, 48 } }; // cells, each >= 2
  double CellSizeMetres = 0.25;                    // h
  Vector3 Origin{ { 0, 0, 0 } };                   // [m]
  double AmbientTemperatureKelvin = 293.15;
  double Gravity = 9.81;             // [m/s^2]
  double DensityWeight = 0.0;        // how much the smoke's mass pulls it down, per density
  double CoolingPerSecond = 0.2;     // T relaxes to ambient as exp(-this t)
  double DissipationPerSecond = 0.0; // density fades as exp(-this t)
  double EddyViscosity = 0.0;        // nu_t [m^2/s] when SmagorinskyConstant is 0
  double SmagorinskyConstant = 0.0;  // C_s (0.1-0.2 typical); > 0 replaces EddyViscosity
  double VorticityConfinement = 0.0; // eps (dimensionless)
  Vector3 Wind{ { 0, 0, 0 } };       // [m/s]
  double WindCoupling = 0.0;         // [1/s]: how fast the air takes the wind's speed
  /// The box's x and y faces: open with wind by default, so the wind blows through.
  SmokeSideBoundaries SideBoundaries = SmokeSideBoundaries::Automatic;
  SmokeAdvection Advection = SmokeAdvection::MacCormack;
  double MaxCfl = 2.0;             // cells a sample may travel per sub-step
  int MaxSubsteps = 64;            // per Step; more than that is an error
  double PressureTolerance = 1e-7; // relative residual of the pressure solve
  int PressureMaxIterations = 2000;
  SmokePressureSolver PressureSolver = SmokePressureSolver::Multigrid;
  int Threads = 0; // 0: hardware concurrency
  std::vector<SmokeEmitter> Emitters;
  /// Solid cells (1) where nothing flows: empty, or one byte per cell (x fastest).
  std::vector<std::uint8_t> Obstacles;
};

/// "" or the first thing wrong with the parameters (non-finite numbers, dimensions < 2
/// or over 1024 per axis or 2^27 cells, h <= 0, negative rates, an obstacle mask of the
/// wrong size or covering every cell, emitters with radius <= 0, an unknown
/// SideBoundaries or PressureSolver).
std::string CheckSmokeParameters(const SmokeParameters& p);

/// Whether the parameters make the box's sides open: SideBoundaries Open, or Automatic
/// with wind (|Wind| > 0 and WindCoupling > 0).
bool SmokeSidesOpen(const SmokeParameters& p);

struct SmokeStepReport
{
  int Substeps = 0;
  int PressureIterations = 0;    // of the last sub-step
  double PressureResidual = 0.0; // relative, of the last sub-step
  double DivergenceBefore = 0.0; // RMS over fluid cells [1/s], of the last projection
  double DivergenceAfter = 0.0;
  double MaxSpeed = 0.0; // [m/s] after the step
};

class SmokeSolver
{
public:
  /// Throws std::invalid_argument with CheckSmokeParameters's message.
  explicit SmokeSolver(const SmokeParameters& parameters);
  ~SmokeSolver();
  SmokeSolver(const SmokeSolver&) = delete;
  SmokeSolver& operator=(const SmokeSolver&) = delete;

  /// Advances by dt seconds (> 0, finite); throws std::invalid_argument for a bad dt and
  /// std::runtime_error when more than MaxSubsteps would be needed or a value became
  /// non-finite (the state is then left as it was before the step).
  SmokeStepReport Step(double dt);

  const SmokeParameters& GetParameters() const { return this->Parameters; }
  /// Whether the box's sides are open (SmokeSidesOpen of the parameters).
  bool GetSidesOpen() const { return this->SidesOpen; }
  double GetTime() const { return this->Time; }
  std::size_t NumberOfCells() const;
  std::size_t CellIndex(int i, int j, int k) const
  {
    return (static_cast<std::size_t>(k) * this->Parameters.Dimensions[1] + j) *
      this->Parameters.Dimensions[0] +
      i;
  }

  const std::vector<float>& GetDensity() const { return this->Density; }
  const std::vector<float>& GetTemperature() const { return this->Temperature; }
  /// Face velocities: u ((nx+1) ny nz, x fastest), v (nx (ny+1) nz), w (nx ny (nz+1)).
  const std::vector<float>& GetU() const { return this->U; }
  const std::vector<float>& GetV() const { return this->V; }
  const std::vector<float>& GetW() const { return this->W; }
  /// The velocity [m/s] at a point [m]: each component trilinear between its faces (the
  /// samples the advection uses), the point clamped to each component's box of faces
  /// (also with open sides: beyond them it is the faces' nearest value, not the wind).
  /// Throws std::invalid_argument for a NaN coordinate.
  Vector3 VelocityAt(const Vector3& positionMetres) const;
  /// The velocity at cell centres (the mean of the two faces per axis), 3 per cell.
  std::vector<float> CellVelocities() const;
  /// Per fluid cell, the divergence [1/s] of the face velocities (0 in solid cells).
  std::vector<double> Divergence() const;
  /// Total density times cell volume [m^3].
  double TotalSmoke() const;

  /// The pressure solve's last solution, its next first guess (part of the state: a
  /// checkpoint keeps it so a restored run repeats the same iterations).
  std::vector<double> GetPressureGuess() const;
  void SetPressureGuess(const std::vector<double>& guess);

  /// Replaces the state (for checkpoints): sizes must match; throws otherwise.
  void SetState(double time, const std::vector<float>& density,
    const std::vector<float>& temperature, const std::vector<float>& u, const std::vector<float>& v,
    const std::vector<float>& w);

private:
  void Substep(double dt, SmokeStepReport& report);
  void Emit(double dt);
  void AddForces(double dt);
  void Diffuse(double dt);
  void Project(double dt, SmokeStepReport& report);
  void Advect(double dt);
  void Decay(double dt);
  void EnforceSolidFaces();
  double MaxSpeed() const;

  SmokeParameters Parameters;
  bool SidesOpen = false; // SmokeSidesOpen(Parameters)
  double Time = 0.0;
  std::vector<float> Density, Temperature, U, V, W;
  std::vector<std::uint8_t> Solid; // per cell
  struct Pressure;
  std::unique_ptr<Pressure> PressureSolver;
};

} // namespace nimbus

#endif
