#pragma once
// A deformable body (tetrahedral solid, triangle solid or cloth) whose surface takes part in
// deformable–deformable and self collisions (systems/deformable_self_collision.h): pairs closer
// than the thickness are repelled, crossings over a step are stopped (Bridson et al. 2002).
namespace monolith {

struct SurfaceCollision {
  static constexpr const char* kName = "surface_collision";
  double thickness = 0.01;  // m; a pair uses the larger of its bodies'
  double friction = 0;      // Coulomb coefficient; a pair uses the larger of its bodies'
  int self = 1;             // 1: the surface also collides with itself (cloth); 0: only with others

  template <class V>
  void visitFields(V& visit) {
    visit("thickness", thickness);
    visit("friction", friction);
    visit("self", self);
  }
};

}  // namespace monolith
