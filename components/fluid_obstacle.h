#pragma once
// FluidObstacle: marks an entity with a `shape` and a static `rigid_body` as an obstacle in the
// scene's MAC grid fluid. The system rasterize_obstacles covers the cells whose centres lie
// inside the shape (a staircase boundary, thesis Sec. 5.4.1: first-order equal-velocity
// constraints at the face centres), and obstacle_forces reports the fluid's force on it.
// Only static obstacles (velocity 0) are supported.
namespace monolith {

struct FluidObstacle {
  static constexpr const char* kName = "fluid_obstacle";
  template <class V>
  void visitFields(V&) {}
};

}  // namespace monolith
