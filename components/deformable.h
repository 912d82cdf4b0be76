#pragma once
// Deformable solids (thesis Ch. 4): one entity per body, its bulk data in three components
// (DESIGN.md §3: a body's particles are one component, not one entity each):
//  * Particles<d>: positions, velocities and lumped masses, d numbers per particle (flat
//    arrays, so the checkpoint and the blow-up guard see every value), and the particles held
//    fixed (infinite mass: projected out of the implicit solves, never moved);
//  * SimplexMesh<d>: the elements (tetrahedra in 3-D, triangles in 2-D; d+1 particle indices
//    each) and the rest positions they were built from;
//  * Elasticity: the constitutive model and damping (solvers/deformable/elasticity.h).
// Scenes name all three through one "deformable" entry (scenarios/deformable_components.h).
#include <string>
#include <vector>

namespace monolith {

template <int d>
struct Particles {
  static constexpr const char* kName = "particles";
  std::vector<double> x, v;  // d per particle
  std::vector<double> m;     // one per particle
  std::vector<int> fixed;    // 1: held in place

  template <class V>
  void visitFields(V& visit) {
    visit("position", x);
    visit("velocity", v);
    visit("mass", m);
    visit("fixed", fixed);
  }
  int count() const { return static_cast<int>(m.size()); }
};

template <int d>
struct SimplexMesh {
  static constexpr const char* kName = "simplex_mesh";
  std::vector<int> elements;  // d+1 particle indices per simplex, positively oriented at rest
  std::vector<double> restX;  // d per particle

  template <class V>
  void visitFields(V& visit) {
    visit("elements", elements);
    visit("rest_position", restX);
  }
  int elementCount() const { return static_cast<int>(elements.size()) / (d + 1); }
};

struct Elasticity {
  static constexpr const char* kName = "elasticity";
  int model = 0;  // solvers::deformable::Model: 0 corotated, 1 neo-Hookean, 2 mass-spring
  double density = 1000;
  double youngsModulus = 1e5;
  double poissonRatio = 0.3;
  double rayleighAlpha = 0;  // mass-proportional damping (1/s)
  double rayleighBeta = 0;   // stiffness-proportional damping (s)
  double overdamping = 0;    // spring dampers as a fraction of critical damping
  double altitudeStiffness = 0;  // mass-spring: Young's modulus of the altitude springs (0: none)
  double clamp = 0.3;        // neo-Hookean singular-value clamp ([81])

  template <class V>
  void visitFields(V& visit) {
    visit("model", model);
    visit("density", density);
    visit("youngs_modulus", youngsModulus);
    visit("poisson_ratio", poissonRatio);
    visit("rayleigh_alpha", rayleighAlpha);
    visit("rayleigh_beta", rayleighBeta);
    visit("overdamping", overdamping);
    visit("clamp", clamp);
    visit("altitude_stiffness", altitudeStiffness);
  }
};

}  // namespace monolith

namespace monolith {

// The names of a binding's bodies, stored one per line (a string field, as checkpoints keep it).
inline std::vector<std::string> namesOnLines(const std::string& lines) {
  std::vector<std::string> out;
  std::string::size_type start = 0;
  while (start < lines.size()) {
    const auto end = lines.find('\n', start);
    out.push_back(lines.substr(start, end == std::string::npos ? std::string::npos : end - start));
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return out;
}

// Particles of a deformable body hard-bound to rigid bodies (Sifakis et al. 2007 [138]): a bound
// particle has no freedom of its own; it moves with its body at a fixed body-frame offset. Its
// mass and inertia about the body's centre were added to the body when the scene was built, the
// elastic and damping forces on it act on the body (force and torque), and it is projected out of
// the implicit solves with its velocity prescribed (Sec. 4.7.3). Bound particles carry
// Particles::fixed == 2.
template <int d>
struct RigidBinding {
  static constexpr const char* kName = "rigid_binding";
  std::string bodies;             // the bound bodies' names, one per line
  std::vector<int> particle;      // bound particle indices
  std::vector<int> body;          // per bound particle: index into the names
  std::vector<double> offset;     // per bound particle: d numbers, body frame

  template <class V>
  void visitFields(V& visit) {
    visit("bodies", bodies);
    visit("particle", particle);
    visit("body", body);
    visit("offset", offset);
  }
  std::vector<std::string> bodyNames() const { return namesOnLines(bodies); }
};

}  // namespace monolith

namespace monolith {

// Particles of a deformable body embedded in the elements of another deformable body (Sifakis et
// al. 2007 [138], hard bindings): an embedded particle has no freedom of its own; its position and
// velocity are the barycentric interpolation of its host element's, x = sum_i w_i x_i. Its mass
// was distributed to the host element's particles (m_i += w_i m) when the scene was built, the
// elastic and damping forces on it act on them with the same weights (so linear and angular
// momentum are kept: sum w_i = 1, sum w_i x_i = x), and it is projected out of the implicit
// solves with its velocity prescribed (Sec. 4.7.3). Embedded particles carry Particles::fixed == 3.
template <int d>
struct EmbeddedBinding {
  static constexpr const char* kName = "embedded_binding";
  std::string hosts;             // the host bodies' names, one per line
  std::vector<int> particle;     // embedded particle indices
  std::vector<int> host;         // per embedded particle: index into the names
  std::vector<int> element;      // per embedded particle: the host mesh's element
  std::vector<double> weight;    // per embedded particle: d+1 barycentric weights
  std::vector<std::string> hostNames() const { return namesOnLines(hosts); }

  template <class V>
  void visitFields(V& visit) {
    visit("hosts", hosts);
    visit("particle", particle);
    visit("host", host);
    visit("element", element);
    visit("weight", weight);
  }
};

}  // namespace monolith
