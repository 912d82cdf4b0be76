#pragma once
// Sleep<d>: whether a dynamic collider body is asleep (not in the thesis; what Box2D and Bullet
// call deactivation, issue 3). Present only when the scene sets "solvers": {"contact": {"sleep":
// true}}; systems/sleep.h says when a body falls asleep and what wakes it. While asleep a body
// is held still: the velocity stages skip it and the contact stages treat it as a body of
// infinite mass at rest, so a settled pile costs a broad phase and nothing else.
#include <cstdint>

#include "ecs/component_pool.h"

namespace monolith {

template <int d>
struct Sleep {
  static constexpr const char* kName = "sleep";
  bool asleep = false;
  double stillTime = 0;      // how long (s) the body has moved slower than sleep_speed
  std::int64_t group = -1;   // the bodies that fell asleep together wake together

  template <class V>
  void visitFields(V& visit) {
    visit("asleep", asleep);
    visit("still_time", stillTime);
    visit("group", group);
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
