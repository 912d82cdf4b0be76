#pragma once
// Static and kinematic obstacles in a MAC grid fluid (thesis Sec. 5.4.1: a staircase of solid
// cells whose faces carry the obstacle's velocity at the face centre, first order).
//  - rasterize_obstacles: grid.solid[c] = 1 for the cells whose centre lies inside any entity
//    with fluid_obstacle + (static or kinematic) rigid_body + a level_set or a shape (box,
//    disk/sphere, 2-D polygon, 3-D cylinder or capsule; systems/obstacle_geometry.h); writes the mask only when
//    it changes (the projection caches its operators keyed on the mask and on the obstacles'
//    motions), and grid.obstacleMotions (pose + rigid velocity) every step. With the default
//    "obstacle_wall": "surface" it also casts, from every free face whose neighbour face along
//    some axis is an obstacle face, a ray that way to the shape's surface
//    (grid.obstacleWallDistance), so the viscous operator puts the no-slip wall where the body is
//    rather than at the obstacle face's centre (operators.h); the normal constraints stay at the
//    face centres as in the thesis.
//    With "obstacle_cells": "cut" it instead measures the open part of every face near an obstacle
//    (grid.openFraction, solvers::cutFaces) and marks solid only the cells whose faces are all
//    covered: the pressure then sees the body's true surface (second order, Ng, Min & Gibou 2009).
//    A cut face whose centre lies inside an obstacle is marked with wall distance 0 in every
//    direction: the viscous rows take it for the obstacle's wall (solvers/fluid/operators.h), and
//    the rays from its neighbours measure to the surface between them and it.
//  - obstacle_forces: the fluid's force on each obstacle: the pressure of the fluid cell on every
//    fluid-solid face (on the covered part of every cut face), plus the viscous stress exactly as the viscous operator applies it,
//    mu (u - u_wall) / (theta dx) for every free face and axis whose neighbour face that way is
//    an obstacle face or a cut face inside it, plus the row holding each such inside face to the
//    body (the body's share of the discrete momentum balance); diagnostics obstacle_<name>_force_x, _y (, _z), and its pressure part
//    obstacle_<name>_pressure_force_x, ...; the torque about the body's position,
//    obstacle_<name>_torque_z in 2-D (_x, _y, _z in 3-D).
#include "components/mac_grid.h"
#include "components/rigid_body.h"
#include "components/shape.h"
#include "ecs/system.h"

namespace monolith {

// The obstacle mask of the grid: 1 for cells whose centre is inside some obstacle.
template <int d>
std::vector<std::uint8_t> obstacleMask(const World<d>& world, const MacGrid<d>& grid);

// Per face, the part of its area outside every obstacle ("obstacle_cells": "cut"; below 1 % counts
// as covered).
template <int d>
std::vector<double> obstacleOpenFractions(const World<d>& world, const MacGrid<d>& grid);

// Per face and direction 2b + (dir > 0), the distance in cells from each free face's centre to
// the obstacle's wall along dir e_b when the next face that way is an obstacle face; 1 elsewhere.
// Layout of FluidDomain::wallDistance. "obstacle_wall": "surface": the nearest true surface
// (clamped to [FluidDomain::kMinWallDistance, 1]); "cell_boundary": 1/2 across the face's control
// volume (b != a), 1 along its own axis.
template <int d>
std::vector<double> obstacleWallDistances(const World<d>& world, const MacGrid<d>& grid);

// The force of the fluid on the obstacle (entity) from the grid's current velocity and pressure,
// split into its pressure and viscous parts.
// The torque about the body's position (z only in 2-D) takes each pressure term at its face's
// centre and each viscous row at the wall point it measures the shear against (the face centre
// moved theta dx towards the obstacle), so a wall's shear acts on the wall's own radius.
template <int d>
struct ObstacleForce {
  Eigen::Matrix<double, d, 1> pressure = Eigen::Matrix<double, d, 1>::Zero();
  Eigen::Matrix<double, d, 1> viscous = Eigen::Matrix<double, d, 1>::Zero();
  Eigen::Vector3d pressureTorque = Eigen::Vector3d::Zero(), viscousTorque = Eigen::Vector3d::Zero();
  Eigen::Matrix<double, d, 1> total() const { return pressure + viscous; }
  Eigen::Vector3d torque() const { return pressureTorque + viscousTorque; }
};
template <int d>
ObstacleForce<d> obstacleForce(const World<d>& world, Entity obstacle, const MacGrid<d>& grid, double viscosity);

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
