#pragma once
// FluidObstacle: marks an entity with a static or kinematic `rigid_body` and a `level_set` or
// `shape` as an obstacle in the scene's MAC grid fluid (one-way: the fluid does not move it). The
// system rasterize_obstacles turns it into solid cells or cut faces whose velocity is the body's
// rigid motion (thesis Sec. 5.4.1), and obstacle_forces reports the fluid's force on it.
namespace monolith {

struct FluidObstacle {
  static constexpr const char* kName = "fluid_obstacle";
  template <class V>
  void visitFields(V&) {}
};

}  // namespace monolith
