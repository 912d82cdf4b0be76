#pragma once
// What scenario tests share: the scene library's folder and a registry of the built-in types.
#include <map>
#include <stdexcept>
#include <string>

#include "components/rigid_body.h"
#include "ecs/registry.h"
#include "scenarios/simulation.h"

namespace monolith::test {

inline const std::string kScenes = std::string(MONOLITH_SOURCE_DIR) + "/scenarios/scenes/";

inline Registry builtins() {
  Registry r;
  registerBuiltins(r);
  return r;
}

// A step's diagnostic, 0 when the step did not report it.
inline double diagnostic(const std::map<std::string, double>& m, const std::string& key) {
  const auto it = m.find(key);
  return it == m.end() ? 0.0 : it->second;
}

// The rigid body of the entity called `name`; throws when there is none, so a renamed scene
// entity fails the test instead of reading through a null pointer.
template <int d>
const RigidBody<d>& bodyNamed(Simulation<d>& sim, const std::string& name) {
  const auto entity = sim.world().find(name);
  const RigidBody<d>* b = entity ? sim.world().template get<RigidBody<d>>(*entity) : nullptr;
  if (!b) throw std::runtime_error("no rigid body named " + name);
  return *b;
}

}  // namespace monolith::test
