#pragma once
// TwoPhaseFlow<d>: an incompressible one- or two-phase fluid on its own MAC grid with surface
// tension on a Lagrangian front (thesis Ch. 6). One component holds the grid, the phases'
// parameters, the face velocities, the front (points and simplices, flattened so the layout is the
// same in 3-D: d coordinates per point, d point indices per element) and the cut cells' pressures.
// All of it is state or configuration and is checkpointed.
// Stepped by systems/surface_tension_flow (2-D only: the scene parser refuses 3-D).
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

namespace monolith {

template <int d>
struct TwoPhaseFlow {
  static constexpr const char* kName = "two_phase_flow";
  using VecD = Eigen::Matrix<double, d, 1>;

  // --- grid (walls on every side) ---
  Eigen::Matrix<int, d, 1> cells = Eigen::Matrix<int, d, 1>::Ones();
  double dx = 1;
  VecD origin = VecD::Zero();

  // --- phases and surface tension ---
  double densityInside = 1, densityOutside = 1;  // inside: the phase the front's loops enclose
  std::uint8_t onePhase = 0;                     // 1: Dirichlet air pressure outside (Sec. 6.3.3)
  double viscosity = 0;                          // both phases (the implicit solve needs one value)
  double sigma = 0;
  std::uint8_t implicitSurfaceTension = 1;       // 0: the explicit variant, D = C = 0
  VecD gravity = VecD::Zero();
  std::uint8_t advect = 1;                       // 0 none, 1 semi-Lagrangian, 2 ENO/RK3
  double advectionCfl = 0;                       // ENO/RK3: substeps of at most this CFL (0: one step)
  std::uint8_t remesh = 1;                       // front tracking: remesh every step
  double minSegment = 0.5, maxSegment = 1.5;     // remeshing bounds in dx
  double blowUpSpeed = 1e3;                      // the guard (m/s)
  double tolerance = 1e-12;                      // CG relative tolerance of (6.33)
  std::uint8_t levelSetFront = 0;                // 1: the front is rebuilt each step from `phi`;
                                                 // 2: and phi follows the mesh moved by H u (implicit update)
  std::uint8_t carryCouplingVelocity = 0;        // 1: coupling faces' u* from the points' carried H u^n
  std::uint8_t levelSetRedistancing = 0;         // level-set fronts: 0 to the mesh, 1 fast marching, 2 none
  double levelSetKeep = 3;                       // cells within this many dx keep their advected phi
  std::uint8_t particleLevelSet = 0;             // 1: the particle level set corrects phi
  int particleReseedEvery = 0;                   // particleLevelSet: steps between reseedings (0: never)

  // --- state ---
  std::vector<double> u;               // face velocities, MAC layout order
  std::vector<double> frontPoints;     // d per point
  std::vector<int> frontElements;      // d per element (segments in 2-D)
  std::vector<double> pInside, pOutside;  // per cell
  std::vector<double> phi;             // level-set-tracked fronts: signed distance per cell
  double initialArea = 0;              // enclosed by the front at the start (area drift)
  std::vector<double> frontPointVelocity;  // carryCouplingVelocity: H u^n, d per point (empty: sample the grid)
  std::vector<double> levelSetParticles;   // particleLevelSet: d coordinates, radius, sign per particle

  // --- probes: velocity sampled at points, reported as <name>_u, <name>_v in metrics.csv ---
  std::vector<double> probePoints;     // d per probe
  std::string probeNames;              // comma-separated, one per probe

  template <class V>
  void visitFields(V& visit) {
    visit("cells", cells);
    visit("dx", dx);
    visit("origin", origin);
    visit("density_inside", densityInside);
    visit("density_outside", densityOutside);
    visit("one_phase", onePhase);
    visit("viscosity", viscosity);
    visit("sigma", sigma);
    visit("implicit", implicitSurfaceTension);
    visit("gravity", gravity);
    visit("advect", advect);
    visit("advection_cfl", advectionCfl);
    visit("remesh", remesh);
    visit("min_segment", minSegment);
    visit("max_segment", maxSegment);
    visit("blow_up_speed", blowUpSpeed);
    visit("tolerance", tolerance);
    visit("level_set_front", levelSetFront);
    visit("phi", phi);
    visit("velocity", u);
    visit("front_points", frontPoints);
    visit("front_elements", frontElements);
    visit("pressure_inside", pInside);
    visit("pressure_outside", pOutside);
    visit("initial_area", initialArea);
    visit("probe_points", probePoints);
    visit("probe_names", probeNames);
    // Appended after the original fields, so the layout of the fields before them is unchanged.
    visit("carry_coupling_velocity", carryCouplingVelocity);
    visit("front_point_velocity", frontPointVelocity);
    visit("level_set_redistancing", levelSetRedistancing);
    visit("level_set_keep", levelSetKeep);
    visit("particle_level_set", particleLevelSet);
    visit("level_set_particles", levelSetParticles);
    visit("particle_reseed_every", particleReseedEvery);
  }
};

}  // namespace monolith
