#pragma once
// The SceneError message of a 3-D scene given as JSON text ("" when it loads): what tests of bad
// input compare against.
#include <gtest/gtest.h>

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

// Expects the scene text (file name "bad.json") to be refused when a world of dimension d is
// populated from it, with a SceneError at `path`.
template <int d>
void expectRefusedAt(const Registry& registry, const std::string& text, const std::string& path) {
  try {
    World<d> world;
    populateWorld(parseScene(text, "bad.json"), registry, world);
    ADD_FAILURE() << "accepted: " << text;
  } catch (const SceneError& e) {
    EXPECT_EQ(e.path(), path) << e.what();
    EXPECT_EQ(e.file(), "bad.json");
  }
}

}  // namespace monolith::test
