#pragma once
// Cloth (thesis Ch. 4, Fig. 4.4): a triangle shell in 3-D whose particles are the body's
// Particles<3> (components/deformable.h), so contact with rigid bodies, bindings, positions and
// diagnostics treat them like any deformable's. Its forces are springs (solvers/deformable/cloth.h):
// stretch springs on the triangle edges and bending springs across every interior edge.
#include <vector>

namespace monolith {

struct ClothMesh {
  static constexpr const char* kName = "cloth_mesh";
  std::vector<int> triangles;  // 3 particle indices per triangle
  std::vector<double> restX;   // 3 per particle

  template <class V>
  void visitFields(V& visit) {
    visit("triangles", triangles);
    visit("rest_position", restX);
  }
  int triangleCount() const { return static_cast<int>(triangles.size()) / 3; }
};

struct ClothMaterial {
  static constexpr const char* kName = "cloth_material";
  double density = 0.1;          // kg per square metre
  double stretchStiffness = 1e3; // N/m per edge spring
  double bendStiffness = 0;      // N/m per bending spring (0: none)
  double overdamping = 0;        // spring dampers as a fraction of critical damping
  double rayleighAlpha = 0;      // mass damping (1/s)

  template <class V>
  void visitFields(V& visit) {
    visit("density", density);
    visit("stretch_stiffness", stretchStiffness);
    visit("bend_stiffness", bendStiffness);
    visit("overdamping", overdamping);
    visit("rayleigh_alpha", rayleighAlpha);
  }
};

}  // namespace monolith
