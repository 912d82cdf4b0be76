#include "scenarios/scene.h"
#include "scenarios/checks.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "components/fluid_obstacle.h"
#include "components/forces.h"
#include "components/rigid_body.h"
#include "components/sleep.h"
#include "ecs/plugin.h"
#include "solvers/contact/contact_settings.h"
#include "solvers/fluid/fluid_settings.h"
#include "solvers/rigid_rotation_settings.h"
#include "scenarios/plugin_search.h"
#include "systems/sleep.h"
#include "scenarios/joint_components.h"

namespace monolith {

namespace {

std::string directoryOf(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? std::string(".") : path.substr(0, slash == 0 ? 1 : slash);
}

std::string resolvePath(const std::string& directory, const std::string& p) {
  if (p.empty() || p[0] == '/') return p;
  return directory + "/" + p;
}

// "line L, column C" of a byte offset into the text.
std::string lineColumn(const std::string& text, std::size_t byte) {
  if (byte > text.size()) byte = text.size();
  std::size_t line = 1, column = 1;
  for (std::size_t i = 0; i < byte; ++i) {
    if (text[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(column);
}

// Short form of a number for messages (std::to_string would print 1e-9 as 0.000000).
std::string formatNumber(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

// Turns nlohmann's byte offset into line:column and names invalid number literals.
[[noreturn]] void throwSyntaxError(const std::string& text, const std::string& file, const Json::parse_error& e) {
  std::size_t byte = e.byte > 0 ? e.byte - 1 : 0;
  if (byte > text.size()) byte = text.size();
  // Word at the error, to explain the common mistake of writing NaN/Infinity.
  std::size_t start = byte;
  while (start > 0 && std::isalpha(static_cast<unsigned char>(text[start - 1]))) --start;
  std::size_t end = start;
  while (end < text.size() && std::isalpha(static_cast<unsigned char>(text[end]))) ++end;
  const std::string word = text.substr(start, end - start);
  std::string expected = "valid JSON (comments allowed)";
  if (word == "NaN" || word == "nan" || word == "Infinity" || word == "inf" || word == "infinity")
    expected = "a finite number (JSON has no NaN or Infinity)";
  std::string what = e.what();
  const auto colon = what.find("syntax error");
  if (colon != std::string::npos) what = what.substr(colon);
  throw SceneError(file, lineColumn(text, byte), expected, word.empty() ? what : "'" + word + "' (" + what + ")");
}

// nlohmann reports a literal beyond the range of a double (1e999) as out_of_range without a
// position; the literal is in the message, so locate its first occurrence in the text.
[[noreturn]] void throwNumberOverflow(const std::string& text, const std::string& file, const Json::out_of_range& e) {
  const std::string what = e.what();
  const auto open = what.find('\''), close = what.rfind('\'');
  const std::string literal = open != std::string::npos && close > open ? what.substr(open + 1, close - open - 1) : "";
  const auto at = literal.empty() ? std::string::npos : text.find(literal);
  throw SceneError(file, at == std::string::npos ? std::string() : lineColumn(text, at),
                   "a finite number (the literal is too large for a double)",
                   literal.empty() ? what : "'" + literal + "'");
}

// Parser callback that tracks the JSON path and rejects a key given twice in one object:
// nlohmann would silently keep the last value, hiding the first one from validation.
class DuplicateKeyCheck {
 public:
  explicit DuplicateKeyCheck(std::string file) : file_(std::move(file)) {}
  bool operator()(int, Json::parse_event_t event, Json& parsed) {
    switch (event) {
      case Json::parse_event_t::object_start:
      case Json::parse_event_t::array_start:
        if (!frames_.empty() && !frames_.back().object) ++frames_.back().index;
        frames_.push_back(Frame{event == Json::parse_event_t::object_start, {}, "", -1});
        break;
      case Json::parse_event_t::object_end:
      case Json::parse_event_t::array_end:
        if (!frames_.empty()) frames_.pop_back();
        break;
      case Json::parse_event_t::key: {
        Frame& top = frames_.back();
        top.key = parsed.get<std::string>();
        if (!top.keys.insert(top.key).second)
          throw SceneError(file_, path(), "a key given only once in its object",
                           "\"" + top.key + "\" given twice (the last value would silently win)");
        break;
      }
      case Json::parse_event_t::value:
        if (!frames_.empty() && !frames_.back().object) ++frames_.back().index;
        break;
    }
    return true;
  }

 private:
  struct Frame {
    bool object;
    std::set<std::string> keys;
    std::string key;
    long index;
  };
  std::string path() const {
    std::string p;
    for (const auto& f : frames_)
      p += f.object ? (p.empty() ? "" : ".") + f.key : "[" + std::to_string(f.index) + "]";
    return p;
  }
  std::string file_;
  std::vector<Frame> frames_;
};

Json parseOverrideValue(const std::string& value) {
  // A fraction of two numbers ("1/30") is that number: steps are naturally written so.
  const auto slash = value.find('/');
  if (slash != std::string::npos && slash > 0 && value.find('/', slash + 1) == std::string::npos) {
    try {
      std::size_t n = 0, m = 0;
      const std::string a = value.substr(0, slash), b = value.substr(slash + 1);
      const double num = std::stod(a, &n), den = std::stod(b, &m);
      if (n == a.size() && m == b.size() && den != 0 && std::isfinite(num / den)) return Json(num / den);
    } catch (const std::exception&) {
    }
  }
  try {
    return Json::parse(value);
  } catch (const Json::parse_error&) {
    return Json(value);  // plain strings need no quotes on the command line
  }
}

void applyOverride(Json& root, const Override& o, const std::string& file) {
  std::vector<std::string> parts;
  std::stringstream ss(o.first);
  for (std::string part; std::getline(ss, part, '.');) parts.push_back(part);
  if (parts.empty() || o.first.empty()) throw SceneError(file, "--set " + o.first, "key=value with a non-empty key", "");
  // The length of a run is given once: "--set time.end" replaces the scene's "steps" and
  // "--set time.steps" its "end" (so a sweep over dt can keep the simulated time fixed).
  if (o.first == "time.end" || o.first == "time.steps") {
    Json* time = root.is_object() && root.contains("time") && root["time"].is_object() ? &root["time"] : nullptr;
    if (time) time->erase(o.first == "time.end" ? "steps" : "end");
  }
  Json* node = &root;
  std::string path;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const std::string& part = parts[i];
    const bool last = i + 1 == parts.size();
    if (node->is_array()) {
      std::size_t index = node->size();
      if (!part.empty() && std::all_of(part.begin(), part.end(), ::isdigit)) {
        if (part.size() < 10) index = std::stoul(part);  // longer cannot exist (and could overflow stoul)
      } else {
        for (std::size_t k = 0; k < node->size(); ++k)
          if ((*node)[k].is_object() && (*node)[k].value("name", std::string()) == part) index = k;
      }
      if (index >= node->size())
        throw SceneError(file, "--set " + o.first, "an index or entity name that exists at '" + path + "'",
                         "'" + part + "'");
      path += "[" + part + "]";
      node = &(*node)[index];
    } else {
      if (!node->is_object()) *node = Json::object();
      path += (path.empty() ? "" : ".") + part;
      node = &(*node)[part];
    }
    if (last) {
      try {
        *node = parseOverrideValue(o.second);
      } catch (const Json::out_of_range&) {  // 1e999: beyond a double, not a plain string
        throw SceneError(file, "--set " + o.first, "a finite number (the literal is too large for a double)",
                         "'" + o.second + "'");
      }
    }
  }
}

// "time": {"dt", "steps" | "end", "frame_rate"}: a fixed step. "steps" counts from step 0; "end"
// from the clock's origin (0 but after a resume that changed dt), so that the time left is a
// whole number of steps.
void parseFixedTime(const Config& time, const ClockOrigin& clock, SceneSpec& s) {
  s.dt = time.number("dt", Bound::Positive);
  s.clock = clock;
  if (time.has("steps") && time.has("end")) time.failAt("end", "either \"end\" or \"steps\", not both", "both");
  const long maxSteps = 1000000000L;
  if (!time.has("steps") && !time.has("end")) {
    // A misspelt "steps" or "end" is the likelier mistake: report it as the unknown key it is.
    time.markUsed("steps");
    time.markUsed("end");
    time.markUsed("frame_rate");
    time.finish();
    time.fail("a \"steps\" or an \"end\" key (neither is given)", "");
  }
  const bool resumed = clock.step > 0;
  const std::string after = resumed ? " after the checkpoint's t = " + formatNumber(clock.time) : "";
  if (time.has("steps")) {
    s.steps = time.integer("steps", 1, maxSteps);
  } else {
    const double end = time.number("end", Bound::Positive);
    const double n = (end - clock.time) / s.dt;
    const std::string ratio = resumed ? "(end - t)/dt" : "end/dt";
    // Checked before lround, which is undefined beyond the range of long.
    if (!(n <= static_cast<double>(maxSteps) + 0.5))
      time.failAt("end", "at most " + std::to_string(maxSteps) + " steps of dt = " + formatNumber(s.dt) + after +
                             " (" + ratio + " = " + formatNumber(n) + ")",
                  describeJson(time.raw()["end"]));
    if (resumed && n < 0.5)
      time.failAt("end", "an end after the checkpoint's t = " + formatNumber(clock.time), describeJson(time.raw()["end"]));
    const long left = std::lround(n);
    if (left < 1 || std::abs(n - static_cast<double>(left)) > 1e-6 * std::max(1.0, n))
      time.failAt("end",
                  "a whole number of steps of dt = " + formatNumber(s.dt) + after + " (" + ratio + " = " +
                      formatNumber(n) + ")",
                  describeJson(time.raw()["end"]));
    s.steps = clock.step + left;
  }
  const double frameRate = time.number("frame_rate", 30.0, Bound::NonNegative);
  // Capped before lround, which is undefined beyond the range of long (a tiny frame rate).
  s.frameEvery = frameRate > 0 ? std::max(1L, std::lround(std::min(1.0 / (frameRate * s.dt), 1e15))) : 0;
  s.endTime = clock.time + static_cast<double>(s.steps - clock.step) * s.dt;
}

// "time": {"cfl", "end", "dt" (largest step), "frame_rate"}: the step follows the CFL condition
// dt = cfl * min over systems of their unit-CFL step (e.g. dx / max|u| of a fluid), clipped so
// that every frame time and the end are hit exactly.
void parseCflTime(const Config& time, SceneSpec& s) {
  s.cfl = time.number("cfl", Bound::Positive);
  if (s.cfl > 10) time.failAt("cfl", "a CFL number in (0, 10]", formatNumber(s.cfl));
  if (time.has("steps")) time.failAt("steps", "no \"steps\" with \"cfl\" (the step count follows from the CFL condition)", "");
  s.endTime = time.number("end", Bound::Positive);
  const double frameRate = time.number("frame_rate", 30.0, Bound::NonNegative);
  s.frameInterval = frameRate > 0 ? 1.0 / frameRate : 0.0;
  s.dt = time.number("dt", s.frameInterval > 0 ? std::min(s.frameInterval, s.endTime) : s.endTime, Bound::Positive);
  s.steps = 0;  // not known in advance
  s.frameEvery = s.frameInterval > 0 ? 1 : 0;
}

// "output": {"probes": [{"name", "position"}], "profiles": [{"name", "from", "to", "points"}]}
void parseProbesAndProfiles(const Config& out, SceneSpec& s) {
  std::set<std::string> names;
  auto uniqueName = [&](const Config& c) {
    const std::string name = c.string("name");
    if (name.empty() || name.find_first_of("/\\ ,") != std::string::npos)
      c.failAt("name", "a non-empty name without '/', spaces or commas (it names files and columns)", "\"" + name + "\"");
    if (!names.insert(name).second) c.failAt("name", "a name no other probe or profile uses", "\"" + name + "\" again");
    return name;
  };
  const auto toVector = [](const Eigen::VectorXd& v) { return std::vector<double>(v.data(), v.data() + v.size()); };
  if (out.has("probes")) {
    out.markUsed("probes");
    const Config list(out.raw()["probes"], out.file(), out.pathOf("probes"));
    for (std::size_t i = 0; i < list.arraySize(); ++i) {
      const Config c = list.element(i);
      if (!c.raw().is_object()) c.fail("a probe {\"name\", \"position\"}", describeJson(c.raw()));
      ProbeSpec p{uniqueName(c), toVector(c.vector("position", s.dimension)), c.pathOf("position")};
      c.finish();
      s.probes.push_back(std::move(p));
    }
  }
  if (out.has("profiles")) {
    out.markUsed("profiles");
    const Config list(out.raw()["profiles"], out.file(), out.pathOf("profiles"));
    for (std::size_t i = 0; i < list.arraySize(); ++i) {
      const Config c = list.element(i);
      if (!c.raw().is_object()) c.fail("a profile {\"name\", \"from\", \"to\", \"points\"}", describeJson(c.raw()));
      ProfileSpec p;
      p.name = uniqueName(c);
      p.from = toVector(c.vector("from", s.dimension));
      p.to = toVector(c.vector("to", s.dimension));
      p.points = static_cast<int>(c.integer("points", 2, 100000));
      p.path = c.path();
      c.finish();
      s.profiles.push_back(std::move(p));
    }
  }
}

}  // namespace

SceneSpec parseScene(const std::string& text, const std::string& file, const std::vector<Override>& overrides,
                     const ClockOrigin& clock) {
  SceneSpec s;
  s.file = file;
  s.directory = directoryOf(file);
  try {
    s.json = Json::parse(text, DuplicateKeyCheck(file), /*allow_exceptions=*/true, /*ignore_comments=*/true);
  } catch (const Json::parse_error& e) {
    throwSyntaxError(text, file, e);
  } catch (const Json::out_of_range& e) {
    throwNumberOverflow(text, file, e);
  }
  if (!s.json.is_object()) throw SceneError(file, "", "a JSON object at the top level", describeJson(s.json));
  for (const auto& o : overrides) applyOverride(s.json, o, file);

  const Config top(s.json, file, "");
  s.description = top.string("description", "");
  s.dimension = static_cast<int>(top.integer("dimension", 2, 3));

  const Config time = top.child("time");
  if (time.has("cfl")) {
    parseCflTime(time, s);
  } else {
    parseFixedTime(time, clock, s);
  }
  time.finish();

  s.threads = static_cast<int>(top.integer("threads", 2, 1, 256));

  if (top.has("output")) {
    const Config out = top.child("output");
    s.outputDirectory = out.string("directory", "");
    parseProbesAndProfiles(out, s);
    if (!out.boolean("frames", true)) {
      s.frameEvery = 0;
      s.frameInterval = 0;
    }
    out.finish();
  }
  if (top.has("checkpoint")) {
    const Config ck = top.child("checkpoint");
    s.checkpointEvery = ck.integer("every", 0, 0, 1000000000L);
    ck.finish();
  }
  if (top.has("stop")) {
    const Config stop = top.child("stop");
    s.stopDiagnostic = stop.string("diagnostic");
    s.stopBelow = stop.number("below", Bound::Positive);
    stop.finish();
  }
  if (top.has("guard")) {
    const Config guard = top.child("guard");
    s.guardMaxAbs = guard.number("max_abs_value", s.guardMaxAbs, Bound::Positive);
    guard.finish();
  }
  if (top.has("plugins")) {
    top.markUsed("plugins");
    const Json& list = s.json["plugins"];
    if (!list.is_array()) top.failAt("plugins", "an array of plugin names or paths", describeJson(list));
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::string at = "plugins[" + std::to_string(i) + "]";
      if (!list[i].is_string() || list[i].get<std::string>().empty())
        top.failAt(at, "a plugin name or path (string)", describeJson(list[i]));
      const std::string entry = list[i].get<std::string>();
      if (!isPluginName(entry)) {
        s.plugins.push_back(resolvePath(s.directory, entry));
        continue;
      }
      try {
        s.plugins.push_back(findPlugin(entry));
      } catch (const std::runtime_error& e) {
        top.failAt(at, "a plugin that can be found", e.what());
      }
    }
  }
  // Validated with the world (they depend on the dimension): checked by populateWorld.
  top.markUsed("gravity");
  top.markUsed("solvers");
  top.markUsed("entities");
  top.markUsed("checks");
  parseChecks(s.json, file, s.dimension);  // validated here, evaluated by the run (checks.h)
  if (!s.json.contains("entities")) top.failAt("entities", "an array of entities (required key is missing)", "");
  if (!s.json["entities"].is_array()) top.failAt("entities", "an array of entities", describeJson(s.json["entities"]));
  top.finish();
  return s;
}

SceneSpec loadScene(const std::string& path, const std::vector<Override>& overrides) {
  // An ifstream opens a directory without error and reads nothing: say what it is instead of
  // reporting a syntax error in an empty file.
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw SceneError(path, "", "a scene file", "a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw SceneError(path, "", "a readable scene file",
                     std::filesystem::exists(path, ec) ? "a file that cannot be read (permissions?)" : "no such file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return parseScene(buffer.str(), path, overrides);
}

void loadScenePlugins(const SceneSpec& scene, PluginLoader& loader, Registry& registry) {
  for (std::size_t i = 0; i < scene.plugins.size(); ++i) {
    try {
      loader.load(scene.plugins[i], registry);
    } catch (const PluginError& e) {
      throw SceneError(scene.file, "plugins[" + std::to_string(i) + "]", "a loadable Monolith plugin", e.what());
    }
  }
}

namespace {
void parseFluidSolverSettings(const Config& c, FluidSolverSettings& f) {
  using S = FluidSolverSettings;
  const std::string advection = c.oneOf("advection", {"semi_lagrangian", "maccormack", "eno3", "weno5", "none"}, "semi_lagrangian");
  f.advection = advection == "eno3"         ? S::Advection::Eno3
                : advection == "weno5"      ? S::Advection::Weno5
                : advection == "maccormack" ? S::Advection::MacCormack
                : advection == "none"       ? S::Advection::None
                                            : S::Advection::SemiLagrangian;
  const std::string wall = c.oneOf("obstacle_wall", {"face", "surface", "cell_boundary"}, "face");
  f.obstacleWall = wall == "surface"         ? S::ObstacleWall::Surface
                   : wall == "cell_boundary" ? S::ObstacleWall::CellBoundary
                                             : S::ObstacleWall::Face;
  f.advectionWallAtSurface = c.oneOf("advection_wall", {"face", "surface"}, "face") == "surface";
  if (f.advectionWallAtSurface && !f.obstacleWallDistances())
    c.failAt("advection_wall",
             "\"face\" unless \"obstacle_wall\" is \"surface\" or \"cell_boundary\" (the ghost values need its wall distances)",
             "\"surface\"");
  f.cutCells = c.oneOf("obstacle_cells", {"staircase", "cut"}, "staircase") == "cut";
  if (f.cutCells && f.obstacleWall == S::ObstacleWall::CellBoundary)
    c.failAt("obstacle_wall", "\"face\" or \"surface\" with \"obstacle_cells\": \"cut\" (cut faces have no cell boundary to put the wall on)",
             "\"cell_boundary\"");
  f.projection = c.oneOf("projection", {"coupled", "chorin"}, "coupled") == "chorin" ? S::Projection::Chorin : S::Projection::Coupled;
  const std::string pc = c.oneOf("preconditioner", {"none", "jacobi", "ic0", "mic0", "multigrid"}, "multigrid");
  f.preconditioner = pc == "none"     ? S::Preconditioner::None
                     : pc == "jacobi" ? S::Preconditioner::Jacobi
                     : pc == "ic0"    ? S::Preconditioner::IC0
                     : pc == "mic0"   ? S::Preconditioner::MIC0
                                      : S::Preconditioner::Multigrid;
  f.coupledCutCorrection =
      c.oneOf("coupled_preconditioner", {"block_diagonal", "cut_corrected"}, "cut_corrected") == "cut_corrected";
  f.tolerance = c.number("tolerance", f.tolerance, Bound::Positive);
  if (f.tolerance >= 1) c.failAt("tolerance", "a relative tolerance below 1", formatNumber(f.tolerance));
  f.maxIterations = static_cast<int>(c.integer("max_iterations", f.maxIterations, 1, 1000000));
  c.finish();
}

// "solvers": {"contact": {...}}: iteration counts and switches of the contact stages
// (solvers/contact/contact_settings.h).
void parseContactSettings(const Config& c, ContactSettings& s) {
  auto count = [&](const char* key, int& value, int min) {
    value = static_cast<int>(c.integer(key, value, min, 100000));
  };
  // The schedule first (a row of kContactSchedules; an unknown name is refused with the names
  // allowed): the keys below adjust it.
  std::vector<std::string> schedules;
  for (const auto& row : kContactSchedules) schedules.push_back(row.name);
  s.useSchedule(*findContactSchedule(c.oneOf("schedule", schedules, schedules.front()).c_str()));
  count("collision_iterations", s.collisionIterations, 0);
  count("collision_pair_iterations", s.collisionPairIterations, 1);
  count("contact_iterations", s.contactIterations, 0);
  count("contact_level_iterations", s.contactLevelIterations, 1);
  count("contact_pair_iterations", s.contactPairIterations, 1);
  s.shockPropagation = c.boolean("shock_propagation", s.shockPropagation);
  count("shock_level_iterations", s.shockLevelIterations, 1);
  count("shock_pair_iterations", s.shockPairIterations, 1);
  s.exactManifoldFinish = c.boolean("exact_manifold_finish", s.exactManifoldFinish);
  s.pushOut = c.boolean("push_out", s.pushOut);
  count("push_out_level_iterations", s.pushOutLevelIterations, 1);
  count("push_out_body_iterations", s.pushOutBodyIterations, 1);
  s.pushOutNewOverlaps = c.boolean("push_out_new_overlaps", s.pushOutNewOverlaps);
  count("push_out_rounds", s.pushOutRounds, 1);
  s.pushOutRoundOverlap = c.number("push_out_round_overlap", s.pushOutRoundOverlap, Bound::NonNegative);
  s.pushOutJoint = c.boolean("push_out_joint", s.pushOutJoint);
  s.pushOutJointOverlap = c.number("push_out_joint_overlap", s.pushOutJointOverlap, Bound::NonNegative);
  s.pushOutJointRegrowOverlap =
      c.number("push_out_joint_regrow_overlap", s.pushOutJointRegrowOverlap, Bound::NonNegative);
  s.velocityContact = c.boolean("velocity_contact", s.velocityContact);
  s.energyClamp = c.boolean("energy_clamp", s.energyClamp);
  s.stepEnergyClamp = c.boolean("step_energy_clamp", s.stepEnergyClamp);
  s.closeGaps = c.boolean("close_gaps", s.closeGaps);
  s.sweptCollisions = c.boolean("swept_collisions", s.sweptCollisions);
  s.thickness = c.number("thickness", s.thickness, Bound::NonNegative);
  s.pushOutTolerance = c.number("push_out_tolerance", s.pushOutTolerance, Bound::NonNegative);
  s.approachTolerance = c.number("approach_tolerance", s.approachTolerance, Bound::NonNegative);
  s.sleep = c.boolean("sleep", s.sleep);
  s.sleepSpeed = c.number("sleep_speed", s.sleepSpeed, Bound::Positive);
  s.sleepTime = c.number("sleep_time", s.sleepTime, Bound::Positive);
  c.finish();
}
}  // namespace

template <int d>
void populateWorld(const SceneSpec& scene, const Registry& registry, World<d>& world) {
  if (scene.dimension != d) throw std::logic_error("populateWorld: dimension mismatch");
  const Config top(scene.json, scene.file, "");
  // Settings and entities are kept only when the whole scene is valid: a caller that catches
  // the SceneError is never left with a half-built world it could simulate by mistake.
  WorldSettings<d> settings = world.settings();
  ContactSettings contact = world.template resource<ContactSettings>();
  FluidSolverSettings fluid = world.template resource<FluidSolverSettings>();
  RigidRotationSettings rotation = world.template resource<RigidRotationSettings>();
  if (scene.json.contains("gravity")) settings.gravity = top.vector("gravity", d);

  if (scene.json.contains("solvers")) {
    const Config solvers = top.child("solvers");
    if (solvers.has("rigid_rotation")) {
      const Config rr = solvers.child("rigid_rotation");
      rotation.order = static_cast<int>(rr.integer("order", 2, 1, 3));
      rotation.energyFix = rr.boolean("energy_fix", true);
      rr.finish();
    }
    if (solvers.has("fluid")) parseFluidSolverSettings(solvers.child("fluid"), fluid);
    if (solvers.has("contact")) parseContactSettings(solvers.child("contact"), contact);
    solvers.finish();
  }

  std::vector<std::string> componentNames;
  for (const auto& c : registry.components<d>())
    if (c.parse) componentNames.push_back(c.name);

  const Config entities(scene.json["entities"], scene.file, "entities");
  std::set<std::string> names;
  std::vector<Entity> created;
  try {
    for (std::size_t i = 0; i < entities.arraySize(); ++i) {
      const Config entity = entities.element(i);
      if (!entity.raw().is_object()) entity.fail("an entity object", describeJson(entity.raw()));
      const std::string name = entity.string("name", "");
      if (!name.empty() && !names.insert(name).second)
        entity.failAt("name", "a name not used by another entity", "\"" + name + "\" again");
      // Every other key must name a component this dimension knows.
      for (const auto& key : entity.keys()) {
        if (key == "name") continue;
        if (!registry.findComponent<d>(key) || !registry.findComponent<d>(key)->parse) {
          const std::string guess = closestMatch(key, componentNames);
          std::string known;
          for (const auto& n : componentNames) known += (known.empty() ? "" : ", ") + n;
          entity.failAt(key, "a component name for a " + std::to_string(d) + "-D scene (one of: " + known + ")",
                        "\"" + key + "\"" + (guess.empty() ? "" : " (did you mean \"" + guess + "\"?)"));
        }
      }
      const Entity e = world.create(name);
      created.push_back(e);
      // Registry order, not file order: a component may rely on one registered before it
      // (rigid_body derives its inertia from shape).
      for (const auto& type : registry.components<d>()) {
        if (!type.parse || !entity.raw().contains(type.name)) continue;
        const Config config = entity.child(type.name);
        type.parse(world, e, config);
        config.finish();
      }
    }
    resolveJoints<d>(world, scene.file, created);
    // A body's sleep state needs the scene's sleeping on; a fluid obstacle never sleeps (the
    // fluid's forces on it change while it rests).
    for (std::size_t i = 0; i < created.size(); ++i) {
      if (!world.template get<Sleep<d>>(created[i])) continue;
      const std::string path = "entities[" + std::to_string(i) + "].sleep";
      if (!contact.sleep)
        throw SceneError(scene.file, path, "\"solvers\": {\"contact\": {\"sleep\": true}} in the scene (sleeping on)",
                         "sleeping off");
      if (world.template get<FluidObstacle>(created[i]))
        throw SceneError(scene.file, path, "no sleep state on a fluid obstacle (the fluid's forces on it change while it rests)",
                         "a fluid_obstacle");
    }
  } catch (...) {
    for (const Entity e : created) world.destroy(e);
    throw;
  }
  world.settings() = settings;
  world.template mutableResource<ContactSettings>() = contact;
  world.template mutableResource<FluidSolverSettings>() = fluid;
  world.template mutableResource<RigidRotationSettings>() = rotation;
  if (contact.sleep) enableSleeping(world);
}

template void populateWorld<2>(const SceneSpec&, const Registry&, World<2>&);
template void populateWorld<3>(const SceneSpec&, const Registry&, World<3>&);

}  // namespace monolith
