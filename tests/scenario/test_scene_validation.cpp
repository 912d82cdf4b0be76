// Scene validation (DESIGN.md §7): broken scenes are rejected with a SceneError naming the file,
// the JSON path and what was expected; none of them may crash or simulate. Each case goes
// through the code path of `monolith validate` (loadScene, loadScenePlugins, populateWorld) and
// then through runScene, which must refuse it without writing metrics. A few cases also run the
// CLI itself to check the exit status and the message on stderr.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "ecs/plugin.h"
#include "ecs/registry.h"
#include "scenarios/runner.h"
#include "scenarios/scene.h"

namespace {

namespace fs = std::filesystem;
using namespace monolith;

fs::path baseDirectory() {
  return fs::path(::testing::TempDir()) / ("monolith_validation_" + std::to_string(::getpid()));
}

// The scene files are kept for inspection when a test fails.
class RemoveTempFilesOnSuccess : public ::testing::Environment {
 public:
  void TearDown() override {
    std::error_code ec;
    if (::testing::UnitTest::GetInstance()->Passed()) fs::remove_all(baseDirectory(), ec);
  }
};
[[maybe_unused]] ::testing::Environment* const kCleanup =
    ::testing::AddGlobalTestEnvironment(new RemoveTempFilesOnSuccess);

// A per-test directory under the GoogleTest temp dir, so every scene file has a known name.
fs::path testDirectory() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = std::string(info->test_suite_name()) + "_" + info->name();
  for (char& c : name)
    if (c == '/') c = '_';
  const fs::path dir = baseDirectory() / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void writeFile(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  ASSERT_TRUE(out.good()) << path;
}

// A small valid 3-D scene with the given parts replaced.
std::string scene3(const std::string& entities, const std::string& time = R"({ "dt": 0.1, "steps": 10 })",
                   const std::string& extraTop = "") {
  return "{\n  \"dimension\": 3,\n  \"time\": " + time + ",\n" + extraTop + "  \"entities\": [\n    " + entities +
         "\n  ]\n}\n";
}
std::string scene2(const std::string& entities) {
  return "{\n  \"dimension\": 2,\n  \"time\": { \"dt\": 0.1, \"steps\": 10 },\n  \"entities\": [\n    " + entities +
         "\n  ]\n}\n";
}
const std::string kBall =
    R"({ "name": "ball", "shape": { "type": "sphere", "radius": 0.5 }, "rigid_body": { "mass": 1 } })";
std::string body(const std::string& rigidBody) { return R"({ "name": "b", "rigid_body": )" + rigidBody + " }"; }

struct Case {
  std::string name;
  std::string text;          // written to <dir>/<name>.json
  std::string path;          // expected SceneError::path()
  std::vector<std::string> contains;  // substrings of what()
  std::vector<Override> overrides = {};
  enum class File { Written, Missing, Directory } file = File::Written;
};

std::ostream& operator<<(std::ostream& os, const Case& c) { return os << c.name; }

std::vector<Case> cases() {
  const std::string badAbi = MONOLITH_BAD_ABI_PLUGIN;
  return {
      // --- JSON syntax ---------------------------------------------------------------------
      {"syntax_missing_comma",
       "{\n  \"dimension\": 3,\n  \"time\": { \"dt\": 0.1 \"steps\": 10 },\n  \"entities\": []\n}\n",
       "line 3, column 29",  // the end of the unexpected token "steps"
       {"expected valid JSON (comments allowed)", "unexpected string literal"}},
      {"syntax_trailing_comma", scene3(kBall + ",", R"({ "dt": 0.1, "steps": 10 })"), "line 6, column 3",
       {"expected valid JSON", "unexpected ']'"}},
      {"syntax_empty_file", "", "line 1, column 1", {"expected valid JSON", "unexpected end of input"}},
      {"syntax_nan_literal", scene3(body(R"({ "mass": NaN, "inertia": [1, 1, 1] })")), "line 5, column 44",
       {"expected a finite number (JSON has no NaN or Infinity)", "got 'NaN'"}},
      {"syntax_infinity_literal", scene3(body(R"({ "mass": -Infinity, "inertia": [1, 1, 1] })")), "line 5, column 45",
       {"JSON has no NaN or Infinity", "'Infinity'"}},
      {"number_overflow_1e999", scene3(body(R"({ "mass": 1e999, "inertia": [1, 1, 1] })")), "line 5, column 44",
       {"a finite number", "too large", "'1e999'"}},
      {"duplicate_json_key", scene3(body(R"({ "mass": 1, "inertia": [1, 1, 1], "mass": 2 })")),
       "entities[0].rigid_body.mass", {"a key given only once", "given twice"}},
      {"duplicate_json_key_nested",
       scene3(R"({ "name": "a", "rigid_body": { "mass": 1, "inertia": [[1, 0, 0], [0, 1, 0], [0, 0, 1]] } },
    { "name": "b", "shape": { "type": "sphere", "radius": 1, "radius": 2 } })"),
       "entities[1].shape.radius", {"a key given only once", "\"radius\" given twice"}},
      {"top_level_not_object", "[1, 2]", "", {"(top level): expected a JSON object at the top level", "an array of 2"}},
      // --- top level -----------------------------------------------------------------------
      {"unknown_top_level_key", scene3(kBall, R"({ "dt": 0.1, "steps": 10 })", "  \"dimensions\": 3,\n"),
       "dimensions", {"unknown key", "did you mean \"dimension\"?"}},
      {"dimension_4", "{ \"dimension\": 4, \"time\": { \"dt\": 0.1, \"steps\": 1 }, \"entities\": [] }", "dimension",
       {"expected an integer in [2, 3]", "got 4"}},
      {"threads_0", scene3(kBall, R"({ "dt": 0.1, "steps": 10 })", "  \"threads\": 0,\n"), "threads",
       {"expected an integer in [1, 256]", "got 0"}},
      {"missing_time", "{ \"dimension\": 3, \"entities\": [] }", "time", {"an object (required key is missing)"}},
      {"missing_entities", "{ \"dimension\": 3, \"time\": { \"dt\": 0.1, \"steps\": 1 } }", "entities",
       {"an array of entities (required key is missing)"}},
      {"missing_dimension", "{ \"time\": { \"dt\": 0.1, \"steps\": 1 }, \"entities\": [] }", "dimension",
       {"an integer in [2, 3] (required key is missing)"}},
      {"entities_not_array",
       "{ \"dimension\": 3, \"time\": { \"dt\": 0.1, \"steps\": 1 }, \"entities\": { \"ball\": {} } }", "entities",
       {"expected an array of entities", "got an object"}},
      {"gravity_wrong_length", scene3(kBall, R"({ "dt": 0.1, "steps": 10 })", "  \"gravity\": [0, -9.81],\n"),
       "gravity", {"an array of 3 finite numbers", "an array of 2 elements"}},
      {"solver_order_4", scene3(kBall, R"({ "dt": 0.1, "steps": 10 })",
                                "  \"solvers\": { \"rigid_rotation\": { \"order\": 4 } },\n"),
       "solvers.rigid_rotation.order", {"an integer in [1, 3]", "got 4"}},
      // --- time ----------------------------------------------------------------------------
      {"dt_zero", scene3(kBall, R"({ "dt": 0, "steps": 10 })"), "time.dt", {"a positive finite number", "got 0"}},
      {"dt_negative", scene3(kBall, R"({ "dt": -1, "steps": 10 })"), "time.dt", {"a positive finite number", "got -1"}},
      {"dt_string", scene3(kBall, R"({ "dt": "0.1", "steps": 10 })"), "time.dt",
       {"a positive finite number", "got the string \"0.1\""}},
      {"end_not_multiple_of_dt", scene3(kBall, R"({ "dt": 0.1, "end": 0.25 })"), "time.end",
       {"a whole number of steps of dt = 0.1", "end/dt = 2.5", "got 0.25"}},
      {"end_and_steps", scene3(kBall, R"({ "dt": 0.1, "end": 1, "steps": 10 })"), "time.end",
       {"either \"end\" or \"steps\", not both"}},
      {"neither_end_nor_steps", scene3(kBall, R"({ "dt": 0.1 })"), "time",
       {"a \"steps\" or an \"end\" key (neither is given)"}},
      {"time_key_typo", scene3(kBall, R"({ "dt": 0.1, "stpes": 10 })"), "time.stpes",
       {"unknown key", "did you mean \"steps\"?"}},
      {"end_too_many_steps", scene3(kBall, R"({ "dt": 0.001, "end": 1e9 })"), "time.end",
       {"at most 1000000000 steps", "1e+12"}},
      // --- entities ------------------------------------------------------------------------
      {"entity_not_object", scene3("5"), "entities[0]", {"an entity object", "got 5"}},
      {"duplicate_entity_name", scene3(kBall + ",\n    " + kBall), "entities[1].name",
       {"a name not used by another entity", "\"ball\" again"}},
      {"entity_name_not_string", scene3(R"({ "name": 7, "rigid_body": { "mass": 1, "inertia": [1, 1, 1] } })"),
       "entities[0].name", {"expected a string", "got 7"}},
      {"unknown_component_rigidbody", scene3(R"({ "name": "b", "rigidbody": { "mass": 1 } })"), "entities[0].rigidbody",
       {"a component name for a 3-D scene", "did you mean \"rigid_body\"?"}},
      {"component_not_object", scene3(R"({ "name": "b", "rigid_body": 1 })"), "entities[0].rigid_body",
       {"expected an object", "got 1"}},
      {"second_entity_broken", scene3(kBall + ",\n    " + body(R"({ "mass": -2, "inertia": [1, 1, 1] })")),
       "entities[1].rigid_body.mass", {"a positive finite number", "got -2"}},
      // --- rigid_body ----------------------------------------------------------------------
      {"unknown_key_mas", scene3(body(R"({ "mas": 1, "inertia": [1, 1, 1] })")), "entities[0].rigid_body.mas",
       {"no key \"mas\" here", "did you mean \"mass\"?"}},
      {"unknown_key_in_rigid_body", scene3(body(R"({ "mass": 1, "inertia": [1, 1, 1], "colour": "red" })")),
       "entities[0].rigid_body.colour", {"unknown key"}},
      {"mass_string", scene3(body(R"({ "mass": "1", "inertia": [1, 1, 1] })")), "entities[0].rigid_body.mass",
       {"a positive finite number", "got the string \"1\""}},
      {"mass_negative", scene3(body(R"({ "mass": -1, "inertia": [1, 1, 1] })")), "entities[0].rigid_body.mass",
       {"a positive finite number", "got -1"}},
      {"mass_zero", scene3(body(R"({ "mass": 0, "inertia": [1, 1, 1] })")), "entities[0].rigid_body.mass",
       {"a positive finite number", "got 0"}},
      {"position_wrong_length", scene3(body(R"({ "mass": 1, "inertia": [1, 1, 1], "position": [1, 2] })")),
       "entities[0].rigid_body.position", {"an array of 3 finite numbers", "got an array of 2 elements"}},
      {"position_null_element", scene3(body(R"({ "mass": 1, "inertia": [1, 1, 1], "position": [1, null, 2] })")),
       "entities[0].rigid_body.position[1]", {"an array of 3 finite numbers", "got null"}},
      {"inertia_singular", scene3(body(R"({ "mass": 1, "inertia": [1, 1, 0] })")), "entities[0].rigid_body.inertia",
       {"a positive-definite (non-singular) inertia", "principal moments"}},
      {"inertia_not_realizable", scene3(body(R"({ "mass": 1, "inertia": [1, 1, 5] })")),
       "entities[0].rigid_body.inertia", {"physically realizable", "principal moments"}},
      {"inertia_not_symmetric",
       scene3(body(R"({ "mass": 1, "inertia": [[1, 0.5, 0], [0, 1, 0], [0, 0, 1]] })")),
       "entities[0].rigid_body.inertia", {"a symmetric 3x3 matrix", "non-symmetric"}},
      {"inertia_wrong_shape", scene3(body(R"({ "mass": 1, "inertia": [1, 1] })")), "entities[0].rigid_body.inertia",
       {"principal moments [Ixx, Iyy, Izz] or a 3x3 matrix", "an array of 2 elements"}},
      {"inertia_missing_no_shape", scene3(body(R"({ "mass": 1 })")), "entities[0].rigid_body.inertia",
       {"an inertia, or a \"shape\" component", "got neither"}},
      {"static_with_velocity", scene3(body(R"({ "static": true, "inertia": [1, 1, 1], "velocity": [1, 0, 0] })")),
       "entities[0].rigid_body.velocity", {"no velocity on a static body"}},
      {"static_with_angular_velocity",
       scene3(body(R"({ "static": true, "inertia": [1, 1, 1], "angular_velocity": [0, 0, 1] })")),
       "entities[0].rigid_body.angular_velocity", {"no angular velocity on a static body"}},
      {"zero_quaternion", scene3(body(R"({ "mass": 1, "inertia": [1, 1, 1], "orientation": [0, 0, 0, 0] })")),
       "entities[0].rigid_body.orientation", {"a non-zero quaternion", "a zero quaternion"}},
      // --- shape ---------------------------------------------------------------------------
      {"box_negative_half_extent",
       scene3(R"({ "name": "b", "shape": { "type": "box", "half_extents": [1, -1, 1] } })"),
       "entities[0].shape.half_extents[1]", {"an array of 3 finite numbers > 0", "got -1"}},
      {"sphere_missing_radius", scene3(R"({ "name": "b", "shape": { "type": "sphere" } })"),
       "entities[0].shape.radius", {"a positive finite number (required key is missing)"}},
      {"sphere_radius_typo",
       scene3(R"({ "name": "b", "shape": { "type": "sphere", "radus": 1 }, "rigid_body": { "mass": 1 } })"),
       "entities[0].shape.radus", {"unknown key", "did you mean \"radius\"?"}},
      {"disk_in_3d", scene3(R"({ "name": "b", "shape": { "type": "disk", "radius": 1 } })"),
       "entities[0].shape.type", {"one of \"box\", \"sphere\"", "the string \"disk\"", "did you mean \"sphere\"?"}},
      {"shape_type_typo", scene3(R"({ "name": "b", "shape": { "type": "bx", "half_extents": [1, 1, 1] } })"),
       "entities[0].shape.type", {"one of \"box\", \"sphere\"", "did you mean \"box\"?"}},
      // --- 2-D -----------------------------------------------------------------------------
      {"2d_position_3_vector",
       scene2(R"({ "name": "d", "shape": { "type": "disk", "radius": 1 },
                   "rigid_body": { "mass": 1, "position": [1, 2, 3] } })"),
       "entities[0].rigid_body.position", {"an array of 2 finite numbers", "got an array of 3 elements"}},
      {"sphere_in_2d", scene2(R"({ "name": "d", "shape": { "type": "sphere", "radius": 1 } })"),
       "entities[0].shape.type", {"one of \"box\", \"disk\"", "did you mean \"disk\"?"}},
      // --- plugins -------------------------------------------------------------------------
      {"missing_plugin", scene3(kBall, R"({ "dt": 0.1, "steps": 10 })", "  \"plugins\": [\"nope.so\"],\n"),
       "plugins[0]", {"a loadable Monolith plugin", "nope.so", "file not found"}},
      {"bad_abi_plugin", scene3(kBall, R"({ "dt": 0.1, "steps": 10 })", "  \"plugins\": [\"" + badAbi + "\"],\n"),
       "plugins[0]", {"a loadable Monolith plugin", "ABI mismatch", "bad_abi_plugin"}},
      {"plugins_not_array", scene3(kBall, R"({ "dt": 0.1, "steps": 10 })", "  \"plugins\": \"x.so\",\n"), "plugins",
       {"an array of plugin names or paths"}},
      {"unknown_plugin_name", scene3(kBall, R"({ "dt": 0.1, "steps": 10 })", "  \"plugins\": [\"wind_dragg\"],\n"),
       "plugins[0]", {"a plugin that can be found", "no plugin wind_dragg.so in", "MONOLITH_PLUGIN_PATH"}},
      // --- --set overrides -----------------------------------------------------------------
      {"set_unknown_entity", scene3(kBall), "--set entities.nobody.rigid_body.mass",
       {"an index or entity name that exists at 'entities'", "got 'nobody'"},
       {{"entities.nobody.rigid_body.mass", "2"}}},
      {"set_huge_index", scene3(kBall), "--set entities.99999999999999999999999.rigid_body.mass",
       {"an index or entity name that exists", "'99999999999999999999999'"},
       {{"entities.99999999999999999999999.rigid_body.mass", "2"}}},
      {"set_overflowing_value", scene3(kBall), "--set entities.ball.rigid_body.mass", {"a finite number", "'1e999'"},
       {{"entities.ball.rigid_body.mass", "1e999"}}},
      {"set_bad_value", scene3(kBall), "entities[0].rigid_body.mass", {"a positive finite number", "got -3"},
       {{"entities.ball.rigid_body.mass", "-3"}}},
      // --- collision geometry and contact ------------------------------------------
      {"collider_without_shape", scene3(R"({ "name": "b", "rigid_body": { "mass": 1, "inertia": [1, 1, 1] }, "collider": {} })"),
       "entities[0].collider", {"a \"shape\" component on the same entity", "no shape"}},
      {"collider_restitution_2",
       scene3(R"({ "name": "b", "shape": { "type": "sphere", "radius": 0.5 }, "rigid_body": { "mass": 1 }, "collider": { "restitution": 2 } })"),
       "entities[0].collider.restitution", {"a restitution in [0, 1]"}},
      {"collider_negative_friction",
       scene3(R"({ "name": "b", "shape": { "type": "sphere", "radius": 0.5 }, "rigid_body": { "mass": 1 }, "collider": { "friction": -0.1 } })"),
       "entities[0].collider.friction", {"a non-negative finite number", "-0.1"}},
      {"dynamic_plane", scene3(R"({ "name": "g", "shape": { "type": "plane" }, "rigid_body": { "mass": 1, "inertia": [1, 1, 1] } })"),
       "entities[0].rigid_body.static", {"can only be static"}},
      {"mesh_file_missing",
       scene3(R"({ "name": "m", "shape": { "type": "mesh", "file": "no_such_mesh.obj" }, "rigid_body": { "static": true } })"),
       "entities[0].shape.file", {"a readable Wavefront OBJ mesh file", "no_such_mesh.obj", "cannot be opened"}},
      {"mesh_index_out_of_range",
       scene3(R"({ "name": "m", "shape": { "type": "mesh", "vertices": [[0, 0, 0], [1, 0, 0], [0, 0, 1]], "triangles": [[0, 1, 5]] }, "rigid_body": { "static": true } })"),
       "entities[0].shape.triangles[0]", {"indices of existing vertices", "index 5 (the mesh has 3 vertices)"}},
      {"convex_flat_hull",
       scene3(R"({ "name": "c", "shape": { "type": "convex", "vertices": [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]] }, "rigid_body": { "static": true } })"),
       "entities[0].shape", {"a valid convex geometry"}},
      {"convex_dynamic_without_inertia",
       scene3(R"({ "name": "c", "shape": { "type": "convex", "vertices": [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]] }, "rigid_body": { "mass": 1 } })"),
       "entities[0].rigid_body.inertia", {"an explicit inertia"}},
      {"kinematic_on_static",
       scene3(R"({ "name": "k", "shape": { "type": "box", "half_extents": [1, 1, 1] }, "rigid_body": { "static": true }, "kinematic": { "velocity": [0, 1, 0] } })"),
       "entities[0].kinematic", {"a non-static rigid_body"}},
      {"kinematic_schedule_without_until",
       scene3(R"({ "name": "k", "shape": { "type": "box", "half_extents": [1, 1, 1] }, "rigid_body": { "mass": 1 }, "kinematic": { "schedule": [ { "velocity": [0, 1, 0] }, { "velocity": [0, 0, 0] } ] } })"),
       "entities[0].kinematic.schedule[0].until", {"all but the last need one"}},
      {"fluid_obstacle_dynamic",
       scene3(R"({ "name": "o", "shape": { "type": "sphere", "radius": 0.5 }, "rigid_body": { "mass": 1 }, "fluid_obstacle": {} })"),
       "entities[0].fluid_obstacle", {"a static rigid_body", "or a kinematic one", "a dynamic rigid_body"}},
      {"fluid_obstacle_convex_hull",
       scene3(R"({ "name": "o", "shape": { "type": "convex", "vertices": [[0,0,0], [1,0,0], [0,1,0], [0,0,1]] }, "rigid_body": { "static": true, "inertia": [1, 1, 1] }, "fluid_obstacle": {} })"),
       "entities[0].fluid_obstacle", {"a box, sphere, cylinder or capsule shape", "\"level_set\"", "another shape type"}},
      {"fluid_obstacle_without_geometry",
       scene2(R"({ "name": "o", "rigid_body": { "static": true }, "fluid_obstacle": {} })"),
       "entities[0].fluid_obstacle", {"a \"level_set\" or a \"shape\"", "neither"}},
      // --- level sets (components/level_set.h) ---------------------------------------------
      {"level_set_value_count",
       scene2(R"({ "name": "o", "level_set": { "origin": [0, 0], "spacing": 0.1, "samples": [3, 3], "values": [1, 1, 1, 1, -1, 1, 1, 1] } })"),
       "entities[0].level_set.values", {"an array of 9 numbers", "an array of 8 elements"}},
      {"level_set_value_not_a_number",
       scene2(R"({ "name": "o", "level_set": { "origin": [0, 0], "spacing": 0.1, "samples": [3, 3], "values": [1, 1, 1, 1, null, 1, 1, 1, 1] } })"),
       "entities[0].level_set.values[4]", {"a finite number", "null"}},
      {"level_set_body_reaches_the_boundary",
       scene2(R"({ "name": "o", "level_set": { "origin": [0, 0], "spacing": 0.1, "samples": [3, 3], "values": [1, 1, 1, 1, -1, -0.5, 1, 1, 1] } })"),
       "entities[0].level_set.values", {"every sample on the sampled box's boundary > 0", "sample [2, 1] = -0.5"}},
      {"level_set_empty",
       scene2(R"({ "name": "o", "level_set": { "origin": [0, 0], "spacing": 0.1, "samples": [2, 2], "values": [1, 1, 1, 1] } })"),
       "entities[0].level_set.values", {"some sample <= 0", "every sample positive"}},
      {"level_set_one_sample_per_axis",
       scene2(R"({ "name": "o", "level_set": { "origin": [0, 0], "spacing": 0.1, "samples": [1, 3], "values": [1, 1, 1] } })"),
       "entities[0].level_set.samples", {"integers >= 2"}},
      {"level_set_two_forms",
       scene2(R"({ "name": "o", "level_set": { "file": "x.json", "polygon": [[0, 0], [1, 0], [0, 1]], "spacing": 0.1 } })"),
       "entities[0].level_set", {"exactly one of", "2 of them"}},
      {"level_set_missing_file",
       scene2(R"({ "name": "o", "level_set": { "file": "no_such_level_set.json" } })"),
       "entities[0].level_set.file", {"a readable level-set JSON file", "no_such_level_set.json", "cannot be opened"}},
      {"polygon_concave",  // an arrowhead: the collision shape would be its hull, the inertia not
       scene2(R"({ "name": "p", "shape": { "type": "polygon", "vertices": [[0, 0], [2, -1], [1, 0], [2, 1]] } })"),
       "entities[0].shape.vertices", {"a convex polygon's vertices in order around it", "inward turn at vertices[2]"}},
      {"polygon_crossed",  // a pentagram: every turn to the left, twice around
       scene2(R"({ "name": "p", "shape": { "type": "polygon", "vertices": [[1, 0], [-0.809, 0.588], [0.309, -0.951], [0.309, 0.951], [-0.809, -0.588]] } })"),
       "entities[0].shape.vertices", {"a convex polygon's vertices in order around it", "winds around more than once"}},
      {"level_set_degenerate_polygon",
       scene2(R"({ "name": "o", "level_set": { "polygon": [[0, 0], [1, 1], [2, 2]], "spacing": 0.1 } })"),
       "entities[0].level_set.polygon", {"a closed outline of non-zero area"}},
      {"level_set_missing_mesh",
       scene3(R"({ "name": "o", "level_set": { "mesh": "no_such_mesh.obj", "spacing": 0.1 } })"),
       "entities[0].level_set.mesh", {"a readable Wavefront OBJ mesh file", "cannot be opened"}},
      {"level_set_polygon_in_3d",
       scene3(R"({ "name": "o", "level_set": { "polygon": [[0, 0], [1, 0], [0, 1]], "spacing": 0.1 } })"),
       "entities[0].level_set", {"exactly one of", "\"mesh\"", "none of them"}},
      {"contact_iterations_negative", scene3(kBall, R"({ "dt": 0.1, "steps": 10 })",
                                             "  \"solvers\": { \"contact\": { \"collision_iterations\": -1 } },\n"),
       "solvers.contact.collision_iterations", {"an integer in [0, 100000]", "-1"}},
      {"push_out_rounds_zero", scene3(kBall, R"({ "dt": 0.1, "steps": 10 })",
                                      "  \"solvers\": { \"contact\": { \"push_out_rounds\": 0 } },\n"),
       "solvers.contact.push_out_rounds", {"an integer in [1, 100000]", "0"}},
      {"exact_manifold_finish_not_a_boolean", scene3(kBall, R"({ "dt": 0.1, "steps": 10 })",
                                                     "  \"solvers\": { \"contact\": { \"exact_manifold_finish\": \"yes\" } },\n"),
       "solvers.contact.exact_manifold_finish", {"true or false", "\"yes\""}},
      {"contact_schedule_unknown", scene3(kBall, R"({ "dt": 0.1, "steps": 10 })",
                                          "  \"solvers\": { \"contact\": { \"schedule\": \"fast\" } },\n"),
       "solvers.contact.schedule", {"\"short\"", "\"thesis\"", "\"fast\""}},
      {"sleep_speed_negative", scene3(kBall, R"({ "dt": 0.1, "steps": 10 })",
                                      "  \"solvers\": { \"contact\": { \"sleep\": true, \"sleep_speed\": -0.01 } },\n"),
       "solvers.contact.sleep_speed", {"positive", "-0.01"}},
      {"sleep_time_zero", scene3(kBall, R"({ "dt": 0.1, "steps": 10 })",
                                 "  \"solvers\": { \"contact\": { \"sleep\": true, \"sleep_time\": 0 } },\n"),
       "solvers.contact.sleep_time", {"positive", "0"}},
      {"sleep_state_without_sleeping",
       scene3(R"({ "name": "box", "shape": { "type": "box", "half_extents": [0.5, 0.5, 0.5] }, "rigid_body": { "mass": 1 },
                   "collider": {}, "sleep": { "asleep": true } })"),
       "entities[0].sleep", {"\"sleep\": true", "sleeping off"}},
      {"sleep_state_on_a_static_body",
       scene3(R"({ "name": "floor", "shape": { "type": "box", "half_extents": [5, 0.5, 5] }, "rigid_body": { "static": true },
                   "collider": {}, "sleep": { "asleep": true } })",
              R"({ "dt": 0.1, "steps": 10 })", "  \"solvers\": { \"contact\": { \"sleep\": true } },\n"),
       "entities[0].sleep", {"a dynamic rigid_body with a collider", "a static body"}},
      {"asleep_while_moving",
       scene3(R"({ "name": "box", "shape": { "type": "box", "half_extents": [0.5, 0.5, 0.5] },
                   "rigid_body": { "mass": 1, "velocity": [1, 0, 0] }, "collider": {}, "sleep": { "asleep": true } })",
              R"({ "dt": 0.1, "steps": 10 })", "  \"solvers\": { \"contact\": { \"sleep\": true } },\n"),
       "entities[0].sleep.asleep", {"false for a moving body", "true with a velocity"}},
      {"sleep_not_boolean", scene3(kBall, R"({ "dt": 0.1, "steps": 10 })",
                                   "  \"solvers\": { \"contact\": { \"sleep\": 1 } },\n"),
       "solvers.contact.sleep", {"true or false", "1"}},
      {"advection_wall_surface_without_wall_distances",
       scene3(kBall, R"({ "dt": 0.1, "steps": 10 })",
              "  \"solvers\": { \"fluid\": { \"obstacle_wall\": \"face\", \"advection_wall\": \"surface\" } },\n"),
       "solvers.fluid.advection_wall", {"\"face\" unless \"obstacle_wall\" is \"surface\" or \"cell_boundary\"", "\"surface\""}},
      {"obstacle_wall_cell_boundary_on_cut_faces",
       scene3(kBall, R"({ "dt": 0.1, "steps": 10 })",
              "  \"solvers\": { \"fluid\": { \"obstacle_cells\": \"cut\", \"obstacle_wall\": \"cell_boundary\" } },\n"),
       "solvers.fluid.obstacle_wall", {"\"face\" or \"surface\" with \"obstacle_cells\": \"cut\"", "\"cell_boundary\""}},
      {"coupled_preconditioner_unknown",
       scene3(kBall, R"({ "dt": 0.1, "steps": 10 })",
              "  \"solvers\": { \"fluid\": { \"coupled_preconditioner\": \"cut\" } },\n"),
       "solvers.fluid.coupled_preconditioner", {"one of \"block_diagonal\", \"cut_corrected\"", "the string \"cut\""}},
      // --- the file itself -----------------------------------------------------------------
      {"missing_scene_file", "", "", {"a readable scene file", "no such file"}, {}, Case::File::Missing},
      {"scene_is_directory", "", "", {"a scene file", "a directory"}, {}, Case::File::Directory},
  };
}

class SceneValidation : public ::testing::TestWithParam<Case> {};

TEST_P(SceneValidation, RejectedWithLocatedMessage) {
  const Case& c = GetParam();
  const fs::path dir = testDirectory();
  std::string file;
  switch (c.file) {
    case Case::File::Written:
      file = (dir / (c.name + ".json")).string();
      writeFile(file, c.text);
      break;
    case Case::File::Missing: file = (dir / "does_not_exist.json").string(); break;
    case Case::File::Directory: file = dir.string(); break;
  }

  // The code path of `monolith validate`.
  Registry registry;
  registerBuiltins(registry);
  PluginLoader loader;
  World<2> world2;
  World<3> world3;
  SceneSpec scene;
  bool loaded = false;
  bool thrown = false;
  try {
    scene = loadScene(file, c.overrides);
    loaded = true;
    loadScenePlugins(scene, loader, registry);
    if (scene.dimension == 2) populateWorld(scene, registry, world2);
    else populateWorld(scene, registry, world3);
  } catch (const SceneError& e) {
    thrown = true;
    EXPECT_EQ(e.file(), file);
    EXPECT_EQ(e.path(), c.path) << e.what();
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(file + ": ", 0), 0u) << "message must start with the file: " << what;
    for (const auto& s : c.contains) EXPECT_NE(what.find(s), std::string::npos) << "'" << s << "' not in: " << what;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not a SceneError: " << e.what();
  }
  EXPECT_TRUE(thrown) << "the scene was accepted";
  // A rejected scene leaves no half-built world behind.
  EXPECT_EQ(world2.entityCount(), 0u);
  EXPECT_EQ(world3.entityCount(), 0u);

  // Nothing is simulated: the runner refuses it before writing any output.
  if (loaded) {
    Registry runRegistry;
    registerBuiltins(runRegistry);
    PluginLoader runLoader;
    RunOptions options;
    options.outDir = (dir / "run").string();
    options.progress = false;
    const RunResult r = runScene(scene, runRegistry, runLoader, options);
    EXPECT_EQ(r.exitCode, kExitInvalidScene) << r.message;
    EXPECT_EQ(r.stepsCompleted, 0);
    EXPECT_FALSE(fs::exists(dir / "run" / "metrics.csv"));
    EXPECT_NE(r.message.find(c.path), std::string::npos) << r.message;
  }
}

INSTANTIATE_TEST_SUITE_P(BrokenScenes, SceneValidation, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<Case>& info) { return info.param.name; });

TEST(SceneValidationTable, HasEnoughCases) { EXPECT_GE(cases().size(), 24u); }

// --- CLI ---------------------------------------------------------------------------------

struct Command {
  int status = -1;
  std::string output;  // stdout and stderr
};

Command runCommand(const std::string& command) {
  Command result;
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return result;
  std::array<char, 512> buffer{};
  while (std::fgets(buffer.data(), buffer.size(), pipe)) result.output += buffer.data();
  const int raw = ::pclose(pipe);
  result.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return result;
}

std::string quoted(const std::string& s) { return "'" + s + "'"; }

TEST(SceneValidationCli, ValidateRejectsBrokenSceneWithExitStatus3) {
  const fs::path dir = testDirectory();
  const std::string file = (dir / "negative_mass.json").string();
  writeFile(file, scene3(body(R"({ "mass": -1, "inertia": [1, 1, 1] })")));
  const Command c = runCommand(quoted(MONOLITH_CLI) + " validate " + quoted(file));
  EXPECT_EQ(c.status, 3) << c.output;
  EXPECT_NE(c.output.find(file + ": entities[0].rigid_body.mass: expected a positive finite number, got -1"),
            std::string::npos)
      << c.output;
}

TEST(SceneValidationCli, ValidateRejectsSyntaxErrorWithLineAndColumn) {
  const fs::path dir = testDirectory();
  const std::string file = (dir / "nan.json").string();
  writeFile(file, scene3(body(R"({ "mass": NaN, "inertia": [1, 1, 1] })")));
  const Command c = runCommand(quoted(MONOLITH_CLI) + " validate " + quoted(file));
  EXPECT_EQ(c.status, 3) << c.output;
  EXPECT_NE(c.output.find(file + ": line 5, column 44: expected a finite number"), std::string::npos) << c.output;
}

TEST(SceneValidationCli, RunRejectsBrokenSceneWithoutSimulating) {
  const fs::path dir = testDirectory();
  const std::string file = (dir / "singular.json").string();
  writeFile(file, scene3(body(R"({ "mass": 1, "inertia": [1, 1, 0] })")));
  const fs::path out = dir / "run";
  const Command c =
      runCommand(quoted(MONOLITH_CLI) + " run " + quoted(file) + " --quiet --out " + quoted(out.string()));
  EXPECT_EQ(c.status, 3) << c.output;
  EXPECT_NE(c.output.find(file + ": entities[0].rigid_body.inertia:"), std::string::npos) << c.output;
  EXPECT_FALSE(fs::exists(out / "metrics.csv"));
  EXPECT_FALSE(fs::exists(out / "summary.json"));
}

TEST(SceneValidationCli, RunWithBadSetOverrideIsRejected) {
  const fs::path dir = testDirectory();
  const std::string file = (dir / "ball.json").string();
  writeFile(file, scene3(kBall));
  const fs::path out = dir / "run";
  const Command c = runCommand(quoted(MONOLITH_CLI) + " run " + quoted(file) +
                               " --quiet --set entities.nobody.rigid_body.mass=2 --out " + quoted(out.string()));
  EXPECT_EQ(c.status, 3) << c.output;
  EXPECT_NE(c.output.find("--set entities.nobody.rigid_body.mass"), std::string::npos) << c.output;
  EXPECT_FALSE(fs::exists(out / "metrics.csv"));
}

TEST(SceneValidationCli, ValidateAcceptsShippedScene) {
  const std::string file = std::string(MONOLITH_SOURCE_DIR) + "/scenarios/scenes/spin_sliver.json";
  const Command c = runCommand(quoted(MONOLITH_CLI) + " validate " + quoted(file));
  EXPECT_EQ(c.status, 0) << c.output;
  EXPECT_NE(c.output.find("valid (3-D, 300 steps"), std::string::npos) << c.output;
}

TEST(SceneValidationCli, EveryShippedSceneIsValid) {
  // The scenes users start from: a settings change that one of them no longer satisfies (e.g. a
  // combination made illegal) must fail here, not in a user's first run. Scenes name plugins by
  // bare name, so they load this build's own plugins in any build directory (a sanitizer
  // build, say), with no path into build/.
  int scenes = 0;
  for (const auto& entry : fs::directory_iterator(std::string(MONOLITH_SOURCE_DIR) + "/scenarios/scenes")) {
    if (entry.path().extension() != ".json") continue;
    std::ifstream in(entry.path());
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(text.find(".so\""), std::string::npos) << entry.path() << ": name plugins, do not give a path";
    const Command c = runCommand(quoted(MONOLITH_CLI) + " validate " + quoted(entry.path().string()));
    EXPECT_EQ(c.status, 0) << entry.path() << "\n" << c.output;
    ++scenes;
  }
  EXPECT_GE(scenes, 20);
}

TEST(SceneValidationCli, ValidateAcceptsTheValidBaseScenes) {
  // The broken cases above are small edits of these: they must be valid as they stand.
  const fs::path dir = testDirectory();
  const std::string f3 = (dir / "ok3.json").string(), f2 = (dir / "ok2.json").string();
  writeFile(f3, scene3(kBall + ",\n    " + body(R"({ "mass": 1, "inertia": [1, 1, 1] })")));
  writeFile(f2, scene2(R"({ "name": "d", "shape": { "type": "disk", "radius": 1 }, "rigid_body": { "mass": 1 } })"));
  for (const auto& f : {f3, f2}) {
    const Command c = runCommand(quoted(MONOLITH_CLI) + " validate " + quoted(f));
    EXPECT_EQ(c.status, 0) << c.output;
  }
}

}  // namespace
