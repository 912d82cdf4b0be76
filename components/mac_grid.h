#pragma once
// MacGrid<d>: an incompressible fluid on a uniform MAC grid (thesis Sec. 5.2, 6.3.3). One
// component holds the whole grid: pressures at cell centres, velocity components at the faces
// normal to their axis (layout of solvers/mac_layout.h: axis 0 faces first, x fastest), the
// solid flags of cells covered by obstacles and the domain's boundary conditions.
#include <Eigen/Core>
#include <Eigen/Geometry>  // cross product of ObstacleMotion
#include <functional>
#include <array>
#include <cstdint>
#include <vector>

namespace monolith {

// What bounds the domain on one side (x_min, x_max, y_min, ...).
enum class DomainSide : int {
  Wall = 0,     // no flow through; tangential: no-slip at `velocity` or slip
  Inflow = 1,   // prescribed inflow (uniform or parabolic profile)
  Outflow = 2,  // p = 0 outside, free normal velocity (do-nothing)
  Periodic = 3  // both sides of the axis
};

template <int d>
struct SideCondition {
  DomainSide type = DomainSide::Wall;
  bool slip = false;                                                 // walls, inflow: zero tangential shear
  Eigen::Matrix<double, d, 1> velocity = Eigen::Matrix<double, d, 1>::Zero();  // wall velocity / uniform inflow
  bool parabolic = false;                                            // inflow profile
  double peakVelocity = 0;                                           // parabolic inflow: centre speed
};

// Where an obstacle is and how it moves, as the fluid sees it (rigid motion v + w x (x - c)).
// 2-D uses only the z component of w.
template <int d>
struct ObstacleMotion {
  Eigen::Matrix<double, d, 1> centre = Eigen::Matrix<double, d, 1>::Zero();
  Eigen::Matrix<double, d, 1> velocity = Eigen::Matrix<double, d, 1>::Zero();
  Eigen::Vector3d angularVelocity = Eigen::Vector3d::Zero();
  double reach = 0;  // bounding radius about the centre
  Eigen::Vector4d orientation = Eigen::Vector4d::Zero();  // quaternion coefficients (3-D) or angle (2-D)
  // Signed distance to the body's surface (negative inside), valid for the step that set it
  // (it reads the body's components); empty: the bounding sphere's.
  std::function<double(const Eigen::Matrix<double, d, 1>&)> signedDistance;

  Eigen::Matrix<double, d, 1> velocityAt(const Eigen::Matrix<double, d, 1>& x) const {
    Eigen::Vector3d r = Eigen::Vector3d::Zero();
    r.head<d>() = x - centre;
    return velocity + angularVelocity.cross(r).template head<d>();
  }
  bool moving() const { return !velocity.isZero(0) || !angularVelocity.isZero(0); }
  bool operator==(const ObstacleMotion& o) const {
    return centre == o.centre && velocity == o.velocity && angularVelocity == o.angularVelocity && reach == o.reach &&
           orientation == o.orientation;
  }
};

template <int d>
struct MacGrid {
  static constexpr const char* kName = "mac_grid";
  using Index = Eigen::Matrix<int, d, 1>;
  using VecD = Eigen::Matrix<double, d, 1>;

  // --- geometry and conditions (set by the scene) ---
  Index cells = Index::Ones();
  double dx = 1;
  VecD origin = VecD::Zero();
  std::array<SideCondition<d>, 2 * d> sides{};  // order: x_min, x_max, y_min, y_max, (z_min, z_max)

  // --- state (checkpointed) ---
  std::vector<double> u;          // face velocities
  std::vector<double> uPrevious;  // face velocities at the end of the previous step (steady-state test)
  std::vector<double> p;          // cell pressures (from the last projection)
  std::vector<std::uint8_t> solid;  // per cell: 1 = covered by an obstacle

  // --- derived every step by rasterize_obstacles from the obstacles' bodies (not checkpointed) ---
  std::vector<ObstacleMotion<d>> obstacleMotions;
  // Per face and direction, cells from the face centre to an obstacle surface (FluidDomain::
  // wallDistance); empty when the obstacles' walls sit at the face centres ("obstacle_wall": "face").
  std::vector<double> obstacleWallDistance;
  // With it, when an obstacle moves: the wall's velocity at those wall points (FluidDomain::
  // wallVelocity); empty for still obstacles.
  std::vector<double> obstacleWallVelocity;
  // Per face, the part of its area outside every obstacle (FluidDomain::openFraction); empty for
  // the staircase ("obstacle_cells": "staircase"), where `solid` alone describes the obstacles.
  std::vector<double> openFraction;
  // What the fields above were last rasterized from (grid, settings, every obstacle's shape and
  // pose): while it is unchanged (static obstacles) rasterize_obstacles reuses them. Not
  // checkpointed: empty after a restart, so the first step rasterizes afresh.
  std::vector<double> rasterizedFrom;

  // Velocity of the obstacle nearest to x: the one of smallest signed distance to its surface
  // (the deepest one x lies in), so that a body inside another's hollow (a disk in a ring) moves
  // the faces next to it; zero without obstacles. Solid faces take its normal component (Sec.
  // 5.4.1).
  Eigen::Matrix<double, d, 1> obstacleVelocityAt(const Eigen::Matrix<double, d, 1>& x) const {
    if (obstacleMotions.size() == 1) return obstacleMotions[0].velocityAt(x);
    const ObstacleMotion<d>* best = nullptr;
    double bestDistance = 0;
    for (const auto& m : obstacleMotions) {
      const double distance = m.signedDistance ? m.signedDistance(x) : (x - m.centre).norm() - m.reach;
      if (!best || distance < bestDistance) best = &m, bestDistance = distance;
    }
    return best ? best->velocityAt(x) : Eigen::Matrix<double, d, 1>::Zero().eval();
  }
  bool obstaclesMove() const {
    for (const auto& m : obstacleMotions)
      if (m.moving()) return true;
    return false;
  }

  template <class V>
  void visitFields(V& visit) {
    visit("cells", cells);
    visit("dx", dx);
    visit("origin", origin);
    for (auto& s : sides) {
      int type = static_cast<int>(s.type);
      visit("side_type", type);
      s.type = static_cast<DomainSide>(type);
      visit("side_slip", s.slip);
      visit("side_velocity", s.velocity);
      visit("side_parabolic", s.parabolic);
      visit("side_peak_velocity", s.peakVelocity);
    }
    visit("velocity", u);
    visit("velocity_previous", uPrevious);
    visit("pressure", p);
    visit("solid", solid);
  }

  bool periodic(int axis) const { return sides[2 * axis].type == DomainSide::Periodic; }
  double cellVolume() const {
    double v = 1;
    for (int a = 0; a < d; ++a) v *= dx;
    return v;
  }
};

// Fluid properties (constant density and dynamic viscosity), on the grid's entity.
struct FluidMaterial {
  static constexpr const char* kName = "fluid_material";
  double density = 1;
  double viscosity = 0;
  template <class V>
  void visitFields(V& visit) {
    visit("density", density);
    visit("viscosity", viscosity);
  }
};

}  // namespace monolith
