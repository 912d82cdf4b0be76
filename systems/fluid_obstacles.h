#pragma once
// Static and kinematic obstacles in a MAC grid fluid (thesis Sec. 5.4.1: a staircase of solid
// cells whose faces carry the obstacle's velocity at the face centre, first order).
//  - rasterize_obstacles: grid.solid[c] = 1 for the cells whose centre lies inside any entity
//    with shape + (static or kinematic) rigid_body + fluid_obstacle; writes the mask only when
//    it changes (the projection caches its operators keyed on the mask and on the obstacles'
//    motions), and grid.obstacleMotions (pose + rigid velocity) every step.
//  - obstacle_forces: the fluid's force on each obstacle, a first-order stress integral over the
//    staircase boundary (pressure of the fluid cell on every fluid-solid face, and the wall
//    shear mu (u - u_wall) / (dx/2) of the free faces next to solid cells); diagnostics
//    obstacle_<name>_force_x, _y (, _z).
#include "components/mac_grid.h"
#include "components/rigid_body.h"
#include "components/shape.h"
#include "ecs/system.h"

namespace monolith {

// Whether the world point x lies inside the shape at the body's pose (boundary included).
template <int d>
bool shapeContains(const Shape<d>& shape, const RigidBody<d>& body, const Eigen::Matrix<double, d, 1>& x);

// The obstacle mask of the grid: 1 for cells whose centre is inside some obstacle.
template <int d>
std::vector<std::uint8_t> obstacleMask(const World<d>& world, const MacGrid<d>& grid);

// The force of the fluid on the obstacle (entity) from the grid's current velocity and pressure.
template <int d>
Eigen::Matrix<double, d, 1> obstacleForce(const World<d>& world, Entity obstacle, const MacGrid<d>& grid,
                                          double viscosity);

template <int d>
class RasterizeObstacles final : public System<d> {
 public:
  std::string name() const override { return "rasterize_obstacles"; }
  Stage stage() const override { return Stage::ForcesAtStart; }
  std::vector<std::string> reads() const override;
  std::vector<std::string> writes() const override { return {MacGrid<d>::kName}; }
  bool needed(const World<d>& w) const override;
  void run(World<d>& world, StepContext& ctx) override;
};

template <int d>
class ObstacleForces final : public System<d> {
 public:
  std::string name() const override { return "obstacle_forces"; }
  Stage stage() const override { return Stage::Diagnostics; }
  std::vector<std::string> reads() const override;
  std::vector<std::string> writes() const override { return {"diagnostics"}; }
  bool needed(const World<d>& w) const override;
  void run(World<d>& world, StepContext& ctx) override;
};

}  // namespace monolith
