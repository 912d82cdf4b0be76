#pragma once
// The SceneError message of a 3-D scene given as JSON text ("" when it loads): what tests of bad
// input compare against.
#include <string>

#include "scenarios/simulation.h"
#include "support/scenes.h"

namespace monolith::test {

inline std::string sceneError(const std::string& json) {
  try {
    const Registry registry = builtins();
    Simulation<3> sim(parseScene(json, "bad.json"), registry);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

}  // namespace monolith::test
