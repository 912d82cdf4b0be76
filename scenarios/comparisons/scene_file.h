#pragma once
// What compare_bullet and compare_box2d share: reading a Monolith scene file for another engine
// (what carries over is read strictly, anything else is refused with its JSON path, so that the
// other engine never runs a different scene), and the command line they have in common.
// Errors name the program (glibc's program_invocation_short_name) and exit with the codes of
// `monolith`: 2 for a bad command line, 3 for a scene that is refused.
#include <errno.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

namespace comparisons {

using nlohmann::json;

[[noreturn]] inline void fail(const std::string& why) {
  std::fprintf(stderr, "%s: %s\n", program_invocation_short_name, why.c_str());
  std::exit(3);
}

[[noreturn]] inline void commandLineError(const std::string& why, const char* usage) {
  std::fprintf(stderr, "%s: %s\nusage: %s %s\n", program_invocation_short_name, why.c_str(),
               program_invocation_short_name, usage);
  std::exit(2);
}

// A positive finite number from the command line, written as a number or a fraction ("1/60").
inline double positive(const std::string& text, const char* what, const char* usage) {
  const auto slash = text.find('/');
  const std::string numerator = text.substr(0, slash);
  const std::string denominator = slash == std::string::npos ? "1" : text.substr(slash + 1);
  char* endA = nullptr;
  char* endB = nullptr;
  const double value = std::strtod(numerator.c_str(), &endA) / std::strtod(denominator.c_str(), &endB);
  if (numerator.empty() || denominator.empty() || *endA != '\0' || *endB != '\0' || !std::isfinite(value) ||
      value <= 0)
    commandLineError(std::string(what) + " must be a positive number, got '" + text + "'", usage);
  return value;
}

// The scene file as JSON (Monolith's scene files may hold // comments).
inline json readSceneFile(const std::string& file) {
  std::ifstream in(file);
  if (!in) fail(file + ": cannot open");
  std::stringstream text;
  text << in.rdbuf();
  try {
    return json::parse(text.str(), nullptr, true, /*ignore_comments=*/true);
  } catch (const std::exception& e) {
    fail(file + ": not JSON: " + e.what());
  }
}

// Fails naming the first key of `object` not in `known`. `path` is "FILE:" for the file's top
// level, else a JSON path ("FILE: entities[3]").
inline void refuseOtherKeys(const json& object, std::initializer_list<const char*> known, const std::string& path,
                            const char* engine) {
  if (!object.is_object()) fail(path + ": expected an object");
  for (const auto& item : object.items()) {
    bool listed = false;
    for (const char* k : known) listed = listed || item.key() == k;
    if (!listed)
      fail(path + (path.back() == ':' ? " " : ".") + item.key() + ": not carried over to " + engine);
  }
}

// object[key], a finite number, or `fallback` when absent.
inline double number(const json& object, const char* key, double fallback, const std::string& path) {
  if (!object.contains(key)) return fallback;
  const json& j = object.at(key);
  if (!j.is_number() || !std::isfinite(j.get<double>())) fail(path + "." + key + ": expected a finite number");
  return j.get<double>();
}

// object[key], a positive finite number, or `fallback` when absent.
inline double positiveNumber(const json& object, const char* key, double fallback, const std::string& path) {
  const double value = number(object, key, fallback, path);
  if (!(value > 0)) fail(path + "." + key + ": expected a positive number");
  return value;
}

// An array of n finite numbers.
template <std::size_t n>
std::array<double, n> numbers(const json& j, const std::string& path) {
  if (!j.is_array() || j.size() != n) fail(path + ": expected an array of " + std::to_string(n) + " numbers");
  std::array<double, n> v{};
  for (std::size_t k = 0; k < n; ++k) {
    if (!j[k].is_number() || !std::isfinite(j[k].get<double>())) fail(path + ": expected finite numbers");
    v[k] = j[k].get<double>();
  }
  return v;
}

// The options every comparison takes; `extra(argument, next)` handles the engine's own and
// returns false for one it does not know.
struct CommonOptions {
  std::string scene;
  double dt = 0, end = 0;  // 0: the scene's
  bool sleep = false;      // the engine's sleeping (off: Monolith has none, and a sleeping body costs nothing)
};

template <typename Extra>
CommonOptions parseCommon(int argc, char** argv, const char* usage, Extra&& extra) {
  CommonOptions o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (++i == argc) commandLineError(a + " needs a value", usage);
      return argv[i];
    };
    if (a == "--sleep") o.sleep = true;
    else if (a == "--dt") o.dt = positive(next(), "--dt", usage);
    else if (a == "--end") o.end = positive(next(), "--end", usage);
    else if (extra(a, next)) continue;
    else if (o.scene.empty() && a.rfind("--", 0) != 0) o.scene = a;
    else commandLineError("unexpected argument " + a, usage);
  }
  if (o.scene.empty()) commandLineError("no scene file", usage);
  return o;
}

// The step, the end time and the step count: the scene's, or the command line's.
struct SceneTime {
  double dt = 0, end = 0;
  long steps = 0;
};
inline SceneTime sceneTime(const json& root, const CommonOptions& o) {
  const json time = root.value("time", json::object());
  SceneTime t;
  t.dt = o.dt > 0 ? o.dt : number(time, "dt", 0, o.scene + ": time");
  t.end = o.end > 0 ? o.end : number(time, "end", 0, o.scene + ": time");
  if (!(t.dt > 0) || !(t.end > 0)) fail(o.scene + ": time: expected positive dt and end");
  t.steps = std::lround(t.end / t.dt);
  return t;
}

inline std::string fileName(const std::string& path) { return path.substr(path.find_last_of('/') + 1); }

// The largest rise of the total energy over its initial value: relative (the project's 0.1 % rule), or in
// joules when the initial total is zero (a scene whose bodies start at rest at height 0).
inline std::string energyRise(double highest, double initial) {
  char text[64];
  if (initial != 0) std::snprintf(text, sizeof text, "%.3g %%", 100 * (highest - initial) / std::abs(initial));
  else std::snprintf(text, sizeof text, "%.3g J", highest - initial);
  return text;
}

}  // namespace comparisons
