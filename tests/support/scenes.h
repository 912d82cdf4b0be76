#pragma once
// What scenario tests share: the scene library's folder and a registry of the built-in types.
#include <map>
#include <string>

#include "ecs/registry.h"

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

}  // namespace monolith::test
