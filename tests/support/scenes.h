#pragma once
// What scenario tests share: the scene library's folder and a registry of the built-in types.
#include <string>

#include "ecs/registry.h"

namespace monolith::test {

inline const std::string kScenes = std::string(MONOLITH_SOURCE_DIR) + "/scenarios/scenes/";

inline Registry builtins() {
  Registry r;
  registerBuiltins(r);
  return r;
}

}  // namespace monolith::test
