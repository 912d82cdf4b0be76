#pragma once
// Collider<d>: makes a rigid body with a `shape` take part in collisions and contact
// (thesis Ch. 2.3 and 4.4-4.6). Bodies without one pass through everything, as before.
// Pair coefficients follow the thesis's code (notes 1.4): restitution = min(e_A, e_B) and
// friction = min(mu_A, mu_B), so a perfectly bouncy ground (e = 1) lets each body's own
// restitution decide.
namespace monolith {

template <int d>
struct Collider {
  static constexpr const char* kName = "collider";
  double restitution = 0.5;
  double friction = 0.5;

  template <class V>
  void visitFields(V& visit) {
    visit("restitution", restitution);
    visit("friction", friction);
  }
};

}  // namespace monolith
