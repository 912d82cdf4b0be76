#pragma once
// Sleep<d>: whether a dynamic collider body is asleep (not in the thesis; what Box2D and Bullet
// call deactivation). Present only when the scene sets "solvers": {"contact": {"sleep":
// true}}; systems/sleep.h says when a body falls asleep and what wakes it. While asleep a body
// is held still: the velocity stages skip it and the contact stages treat it as a body of
// infinite mass at rest, so a settled pile costs a broad phase and nothing else.
#include <Eigen/Core>
#include <cstdint>

#include "components/rigid_body.h"
#include "ecs/component_pool.h"

namespace monolith {

template <int d>
struct Sleep {
  static constexpr const char* kName = "sleep";
  bool asleep = false;
  double stillTime = 0;      // how long (s) the body has moved slower than sleep_speed
  std::int64_t group = -1;   // the bodies that fell asleep together wake together
  // The force and torque on the body as it fell asleep (forceKnown), and the distance of its
  // farthest point from its centre of mass: a force that changes by more than 1e-3 of the
  // body's weight plus that force wakes it (systems/sleep.h). A body the scene starts asleep
  // takes the force of its first step.
  bool forceKnown = false;
  Eigen::Matrix<double, d, 1> force = Eigen::Matrix<double, d, 1>::Zero();
  AngularVec<d> torque = AngularVec<d>::Zero();
  double reach = 0;

  template <class V>
  void visitFields(V& visit) {
    visit("asleep", asleep);
    visit("still_time", stillTime);
    visit("group", group);
    visit("force_known", forceKnown);
    visit("force", force);
    visit("torque", torque);
    visit("reach", reach);
  }
};

// Whether the body of `entity` is asleep (false where the scene has no sleeping).
template <int d>
bool isAsleep(const Pool<Sleep<d>>* sleeps, Entity entity) {
  if (!sleeps) return false;
  const Sleep<d>* s = sleeps->get(entity);
  return s && s->asleep;
}

}  // namespace monolith
