// Cloth in the deformables' ParaView frames (.vtu): its triangles go into the same unstructured
// grid as the tetrahedra, with the point velocity and per-triangle area ratio and in-plane strain;
// the frames are read back with VTK's own reader (tests/support/read_vtu.py).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>

#include "components/deformable.h"
#include "scenarios/simulation.h"
#include "scenarios/vtk_deformable_writer.h"
#include "support/cli_harness.h"
#include "support/scenes.h"

using namespace monolith;
using namespace monolith::test;
namespace fs = std::filesystem;

namespace {

// A 4 x 4-cell sheet (32 triangles, 25 particles) in free fall beside a tetrahedral box (2 x 2 x 2
// cubes of six tetrahedra: 48, 27 particles); frames at t = 0 and 0.1 s.
const char* kScene = R"({ "dimension": 3, "time": { "dt": 0.01, "end": 0.1, "frame_rate": 10 },
  "gravity": [0, -9.81, 0],
  "entities": [
    { "name": "sheet", "cloth": { "mesh": { "sheet": { "half_extents": [0.2, 0.2], "edge_length": 0.1 } },
        "density": 0.5, "stretch_stiffness": 100 } },
    { "name": "block", "deformable": { "mesh": { "box": { "half_extents": [0.05, 0.05, 0.05], "edge_length": 0.05 } },
        "model": "corotated", "youngs_modulus": 1e4, "density": 500, "position": [1, 0, 0] } } ] })";

nlohmann::json readVtu(const fs::path& file, const fs::path& logs, bool& skip) {
  const CommandResult r =
      run({"/usr/bin/python3", std::string(MONOLITH_SOURCE_DIR) + "/tests/support/read_vtu.py", file.string()}, logs);
  skip = r.exitCode == 77;
  if (skip) return {};
  EXPECT_EQ(r.exitCode, 0) << r.err;
  return nlohmann::json::parse(r.out);
}

}  // namespace

// Through the CLI: the frame series lists .vtu files holding both bodies' cells; in the last
// frame every cloth particle falls at g t (a free, unstretched sheet), and its triangles keep
// their rest area.
TEST(ClothFrames, SheetTrianglesAndVelocityInTheVtuSeries) {
  TempDir tmp;
  writeFile(tmp.path() / "scene.json", kScene);
  const fs::path out = tmp.path() / "run";
  const CommandResult r =
      run({MONOLITH_CLI, "run", (tmp.path() / "scene.json").string(), "--out", out.string(), "--quiet"}, tmp.logs());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(slurp(out / "deformables.pvd").find("deformables_000000.vtu"), std::string::npos);
  std::vector<fs::path> frames;
  for (const auto& e : fs::directory_iterator(out / "frames"))
    if (e.path().extension() == ".vtu") frames.push_back(e.path());
  ASSERT_EQ(frames.size(), 2u);
  std::sort(frames.begin(), frames.end());
  bool skip = false;
  const auto grid = readVtu(frames.back(), tmp.logs(), skip);
  if (skip) GTEST_SKIP() << "python3-vtk9 is not installed";
  EXPECT_EQ(grid["vtk_messages"], "");
  EXPECT_EQ(grid["points"], 25 + 27);
  EXPECT_EQ(grid["cells"], 32 + 48);
  EXPECT_EQ(grid["cell_types"]["5"], 32);   // VTK_TRIANGLE
  EXPECT_EQ(grid["cell_types"]["10"], 48);  // VTK_TETRA
  for (int i = 0; i < 25; ++i) {            // the cloth comes first (entity order)
    EXPECT_NEAR(grid["velocity"][i][0].get<double>(), 0.0, 1e-12);
    EXPECT_NEAR(grid["velocity"][i][1].get<double>(), -0.981, 1e-9) << "particle " << i;
  }
  for (int c = 0; c < 32; ++c) {
    EXPECT_NEAR(grid["volume_ratio"][c][0].get<double>(), 1.0, 1e-9) << "triangle " << c;
    EXPECT_NEAR(grid["strain"][c][0].get<double>(), 0.0, 1e-9) << "triangle " << c;
  }
}

// Values: the sheet stretched by 1.25 along x (and turned about y, which changes nothing) has
// every triangle's area ratio 1.25 and in-plane strain 0.25 in the written frame.
TEST(ClothFrames, StretchedSheetAreaRatioAndStrain) {
  TempDir tmp;
  writeFile(tmp.path() / "scene.json", kScene);
  const Registry registry = builtins();
  Simulation<3> sim(loadScene((tmp.path() / "scene.json").string()), registry);
  Particles<3>& p = *sim.world().get<Particles<3>>(*sim.world().find("sheet"));
  const double c = std::cos(0.3), s = std::sin(0.3);
  for (int i = 0; i < p.count(); ++i) {
    const double x = 1.25 * p.x[3 * i], z = p.x[3 * i + 2];
    p.x[3 * i] = c * x + s * z;
    p.x[3 * i + 2] = -s * x + c * z;
  }
  const fs::path file = tmp.path() / "stretched.vtu";
  writeDeformableFrame<3>(sim.world(), file.string());
  bool skip = false;
  const auto grid = readVtu(file, tmp.logs(), skip);
  if (skip) GTEST_SKIP() << "python3-vtk9 is not installed";
  EXPECT_EQ(grid["cell_types"]["5"], 32);
  for (int k = 0; k < 32; ++k) {
    EXPECT_NEAR(grid["volume_ratio"][k][0].get<double>(), 1.25, 1e-12) << "triangle " << k;
    EXPECT_NEAR(grid["strain"][k][0].get<double>(), 0.25, 1e-12) << "triangle " << k;
  }
  // The tetrahedra behind them are untouched: at rest.
  for (int k = 32; k < 80; ++k) EXPECT_NEAR(grid["volume_ratio"][k][0].get<double>(), 1.0, 1e-12);
}

// A scene whose only deformable body is cloth runs through the CLI: without a tetrahedral or
// triangle solid there is no elastic step limit, and none is reported (the run's guard refuses
// non-finite diagnostics). The free sheet falls at g t (the frame of step 10).
TEST(ClothFrames, ClothOnlySceneRunsThroughTheCli) {
  TempDir tmp;
  writeFile(tmp.path() / "scene.json", R"({ "dimension": 3, "time": { "dt": 0.01, "end": 0.1, "frame_rate": 10 },
    "gravity": [0, -9.81, 0],
    "entities": [
      { "name": "sheet", "cloth": { "mesh": { "sheet": { "half_extents": [0.2, 0.2], "edge_length": 0.1 } },
          "density": 0.5, "stretch_stiffness": 100 } } ] })");
  const fs::path out = tmp.path() / "run";
  const CommandResult r =
      run({MONOLITH_CLI, "run", (tmp.path() / "scene.json").string(), "--out", out.string(), "--quiet"}, tmp.logs());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  bool skip = false;
  const auto grid = readVtu(out / "frames" / "deformables_000010.vtu", tmp.logs(), skip);
  if (skip) GTEST_SKIP() << "python3-vtk9 is not installed";
  EXPECT_EQ(grid["cells"], 32);
  for (int i = 0; i < 25; ++i) EXPECT_NEAR(grid["velocity"][i][1].get<double>(), -0.981, 1e-9) << "particle " << i;
}
