#pragma once
// A world resource (World::resource), read by the fluid systems and the fluid-structure coupling.

namespace monolith {

// How the fluid step of Ch. 5 is taken (scene "solvers": {"fluid": {...}}).
struct FluidSolverSettings {
  static constexpr const char* kName = "fluid_settings";  // its name among the world's resources
  enum class Advection { SemiLagrangian, MacCormack, Eno3, Weno5, None };  // None: unsteady Stokes flow (Sec. 5.7)
  enum class Projection { Coupled, Chorin };            // (5.31) vs pressure/viscosity splitting
  enum class Preconditioner { None, Jacobi, IC0, MIC0, Multigrid };
  Advection advection = Advection::SemiLagrangian;
  Projection projection = Projection::Coupled;
  Preconditioner preconditioner = Preconditioner::Multigrid;  // flat iteration counts (benchmarks)
  // The coupled solve's preconditioner around the Poisson one: false (scene
  // "coupled_preconditioner": "block_diagonal"): the Poisson preconditioner and a Jacobi viscous
  // block (notes 4.4); true ("cut_corrected", default): the same plus an exact solve on the band
  // of unknowns around cut faces (solvers/fluid/coupled_preconditioner.h). Identical without cut faces.
  bool coupledCutCorrection = true;
  double tolerance = 1e-8;   // relative residual of the Krylov solve
  int maxIterations = 5000;
  // Where the viscous operator puts an obstacle's no-slip wall (scene "obstacle_wall"):
  //  * Face ("face", default): at the obstacle face's centre, the thesis's first-order treatment
  //    (Sec. 5.4.1, 5.7), up to a cell inside the body;
  //  * Surface ("surface"): at the body's true surface, found along each pair's direction;
  //  * CellBoundary ("cell_boundary", staircase only): at the boundary of the solid cells, half a
  //    cell from the first fluid face, where a finite-volume code on the same staircase puts it.
  // The last two store wall distances (docs/architecture.md, measured in docs/benchmarks.md).
  enum class ObstacleWall { Face, Surface, CellBoundary };
  ObstacleWall obstacleWall = ObstacleWall::Face;
  bool obstacleWallDistances() const { return obstacleWall != ObstacleWall::Face; }
  // Where the advection's samples see that wall: false ("advection_wall": "face", default): behind
  // the first fluid faces they read the obstacle faces' own velocity or, inside the body, extend
  // the fluid's (velocity_sampling.h rules 3-4, the thesis's clipping of Sec. 5.2); true
  // ("surface", needs obstacle wall distances): ghost values continue the velocity linearly through
  // the wall at the distance the viscous operator uses (solvers/advection/wall_ghosts.h).
  bool advectionWallAtSurface = false;
  // How obstacles meet the pressure: false (scene "obstacle_cells": "staircase", default): cells
  // with the centre inside are solid, their faces carry the body's velocity (Sec. 5.4.1); true
  // ("cut"): faces cut by the body keep their open part as fluid (solvers::cutFaces).
  bool cutCells = false;
};

}  // namespace monolith
