// Plugins: the example wind_drag plugin is loaded from a scene and its force acts; the loader
// refuses missing files, non-plugins and ABI mismatches with messages that say why.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>

#include <unistd.h>

#include "components/rigid_body.h"
#include "ecs/plugin.h"
#include "scenarios/plugin_search.h"
#include "scenarios/simulation.h"

using namespace monolith;

namespace {
std::string dragScene(double dt, long steps) {
  char buf[1024];
  std::snprintf(buf, sizeof buf, R"({
    "dimension": 3, "time": {"dt": %.17g, "steps": %ld}, "gravity": [0, 0, -9.81],
    "plugins": ["%s"],
    "entities": [
      {"name": "falling", "shape": {"type": "sphere", "radius": 0.1},
       "rigid_body": {"mass": 2, "velocity": [0, 0, 0]},
       "wind_drag": {"linear": 4, "wind": [1.5, 0, 0]}},
      {"name": "free", "shape": {"type": "sphere", "radius": 0.1}, "rigid_body": {"mass": 2}}]})",
                dt, steps, MONOLITH_WIND_DRAG_PLUGIN);
  return buf;
}
}  // namespace

TEST(WindDragPlugin, LoadedFromSceneAndReachesAnalyticVelocity) {
  Registry registry;
  registerBuiltins(registry);
  PluginLoader loader;
  const double dt = 1.0 / 240;
  const SceneSpec scene = parseScene(dragScene(dt, 240), "/tmp/drag.json");
  loadScenePlugins(scene, loader, registry);
  ASSERT_NE(registry.findComponent<3>("wind_drag"), nullptr);
  EXPECT_EQ(registry.findComponent<3>("wind_drag")->origin, std::string("plugin ") + MONOLITH_WIND_DRAG_PLUGIN);

  Simulation<3> sim(scene, registry, 2);
  EXPECT_NE(sim.scheduler().indexOf("wind_drag@n"), -1);
  EXPECT_NE(sim.scheduler().indexOf("wind_drag@n+1"), -1);
  for (int n = 0; n < 240; ++n) sim.step();
  const auto& bodies = sim.world().pool<RigidBody<3>>();
  const RigidBody<3>& falling = *bodies.get(*sim.world().find("falling"));
  const RigidBody<3>& free = *bodies.get(*sim.world().find("free"));
  // m dv/dt = m g - k (v - w): v(t) = w + m g/k + (v0 - w - m g/k) e^{-k t/m}, at t = 1 s.
  const double m = 2, k = 4, t = 1, decay = std::exp(-k * t / m);
  const Eigen::Vector3d wind(1.5, 0, 0), g(0, 0, -9.81);
  const Eigen::Vector3d terminal = wind + m * g / k;
  const Eigen::Vector3d exact = terminal + (Eigen::Vector3d::Zero() - terminal) * decay;
  // Second-order accurate (next test): the error at dt = 1/240 is about 1e-5 of |v_terminal|.
  EXPECT_LE((falling.v - exact).norm(), 1e-4 * terminal.norm());
  // Without the plugin's component the body falls freely: the plugin only acts where asked.
  EXPECT_NEAR(free.v.z(), -9.81 * t, 1e-12);
  EXPECT_EQ(free.v.x(), 0.0);
}

TEST(WindDragPlugin, ErrorConvergesAtSecondOrder) {
  Registry registry;
  registerBuiltins(registry);
  PluginLoader loader;
  double previous = 0;
  for (int rate : {30, 60, 120}) {
    const SceneSpec scene = parseScene(dragScene(1.0 / rate, rate), "/tmp/drag.json");
    loadScenePlugins(scene, loader, registry);  // second load of the same path is a no-op
    Simulation<3> sim(scene, registry, 1);
    for (int n = 0; n < rate; ++n) sim.step();
    const RigidBody<3>& b = *sim.world().get<RigidBody<3>>(*sim.world().find("falling"));
    const double vz = -9.81 * 2 / 4 * (1 - std::exp(-2.0));
    const double error = std::abs(b.v.z() - vz);
    if (previous > 0) {
      EXPECT_NEAR(std::log2(previous / error), 2.0, 0.15) << "at " << rate << " steps/s";
    }
    previous = error;
  }
  EXPECT_EQ(loader.loaded().size(), 1u);
}

TEST(PluginLoader, RefusesMissingFilesNonPluginsAndAbiMismatches) {
  Registry registry;
  registerBuiltins(registry);
  PluginLoader loader;
  try {
    loader.load("/nonexistent/plugin.so", registry);
    FAIL() << "missing plugin accepted";
  } catch (const PluginError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/plugin.so': file not found"), std::string::npos) << e.what();
  }
  try {
    loader.load(MONOLITH_BAD_ABI_PLUGIN, registry);
    FAIL() << "ABI mismatch accepted";
  } catch (const PluginError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("ABI mismatch"), std::string::npos) << m;
    EXPECT_NE(m.find("ABI version is " + std::to_string(kPluginAbiVersion + 98) + " in the plugin but " +
                     std::to_string(kPluginAbiVersion) + " in monolith"),
              std::string::npos)
        << m;
  }
  // A shared library that is not a plugin (the core library itself exports neither symbol).
  try {
    loader.load(std::string(MONOLITH_BINARY_DIR) + "/libmonolith_core.so", registry);
    FAIL() << "non-plugin accepted";
  } catch (const PluginError& e) {
    EXPECT_NE(std::string(e.what()).find("not a Monolith plugin"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(loader.loaded().empty());
  EXPECT_EQ(registry.findComponent<3>("wind_drag"), nullptr);
}

TEST(PluginAbi, MismatchDescriptionNamesEachDifferingField) {
  PluginAbi host = currentPluginAbi(), plugin = currentPluginAbi();
  EXPECT_EQ(describeAbiMismatch(host, plugin), "");
  plugin.eigenVersion += 1;
  plugin.debugBuild ^= 1u;
  const std::string m = describeAbiMismatch(host, plugin);
  EXPECT_NE(m.find("Eigen version"), std::string::npos);
  EXPECT_NE(m.find("debug build"), std::string::npos);
  EXPECT_EQ(m.find("sizeof(Registry)"), std::string::npos);
}

// A plugin named by bare name is searched for: MONOLITH_PLUGIN_PATH first, then this build's own
// plugin directory; a name found nowhere is a scene error naming the entry and where it looked.
TEST(PluginSearch, BareNamesAreFoundInThePluginPathThenInThisBuild) {
  namespace fs = std::filesystem;
  const char* old = std::getenv("MONOLITH_PLUGIN_PATH");
  const std::string saved = old ? old : "";
  auto scene = [](const std::string& entry) {
    return parseScene(R"({"dimension": 3, "time": {"dt": 0.01, "steps": 1}, "plugins": [")" + entry +
                          R"("], "entities": []})",
                      "/tmp/plugin_search.json");
  };

  unsetenv("MONOLITH_PLUGIN_PATH");
  const SceneSpec own = scene("wind_drag");
  ASSERT_EQ(own.plugins.size(), 1u);
  EXPECT_TRUE(fs::equivalent(own.plugins[0], MONOLITH_WIND_DRAG_PLUGIN)) << own.plugins[0];

  // A directory earlier in the path wins (empty entries are skipped).
  const fs::path dir = fs::temp_directory_path() / ("monolith_plugin_search_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  fs::copy_file(MONOLITH_WIND_DRAG_PLUGIN, dir / "wind_drag.so", fs::copy_options::overwrite_existing);
  setenv("MONOLITH_PLUGIN_PATH", ("/no/such/dir::" + dir.string()).c_str(), 1);
  EXPECT_EQ(pluginSearchPath().size(), 3u);
  EXPECT_EQ(scene("wind_drag").plugins.at(0), (dir / "wind_drag.so").string());
  // ... and the copy really is a loadable plugin.
  Registry registry;
  registerBuiltins(registry);
  PluginLoader loader;
  EXPECT_NO_THROW(loadScenePlugins(scene("wind_drag"), loader, registry));
  EXPECT_NE(registry.findComponent<3>("wind_drag"), nullptr);

  try {
    scene("wind_dragg");
    ADD_FAILURE() << "an unknown plugin name was accepted";
  } catch (const SceneError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("/tmp/plugin_search.json"), std::string::npos) << m;
    EXPECT_NE(m.find("plugins[0]"), std::string::npos) << m;
    EXPECT_NE(m.find("wind_dragg.so"), std::string::npos) << m;
    EXPECT_NE(m.find(dir.string()), std::string::npos) << m;
    EXPECT_NE(m.find("MONOLITH_PLUGIN_PATH"), std::string::npos) << m;
  }
  // A path is still a path, relative to the scene file (not searched for).
  EXPECT_EQ(scene("plugins/wind_drag.so").plugins.at(0), "/tmp/plugins/wind_drag.so");

  if (old) setenv("MONOLITH_PLUGIN_PATH", saved.c_str(), 1);
  else unsetenv("MONOLITH_PLUGIN_PATH");
  fs::remove_all(dir);
}
