#include "scenarios/checks.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <set>
#include <sstream>

#include <Eigen/Geometry>

#include "components/mac_grid.h"
#include "components/rigid_body.h"
#include "scenarios/fluid_fields.h"
#include "scenarios/references.h"

namespace monolith {

namespace {

const std::vector<std::string> kKinds = {"diagnostic", "body", "probe", "profile"};
const std::vector<std::string> kBodyFields = {"position", "velocity", "angular_momentum", "displacement", "orientation"};
const std::vector<std::string> kFluidFields = {"u", "v", "w", "p"};
const std::vector<std::string> kStatistics = {"final", "max", "min", "max_change", "max_relative_change"};

std::vector<double> toVector(const Eigen::VectorXd& v) { return std::vector<double>(v.data(), v.data() + v.size()); }

void parseReference(const Config& c, CheckSpec& s) {
  if (!c.has("reference")) {
    if (s.statistic == "max_change" || s.statistic == "max_relative_change") {
      s.reference = {0.0};  // a quantity that should not change
      return;
    }
    c.failAt("reference", "a reference (number, array of numbers or {\"analytic\"|\"table\": name, ...})", "nothing");
  }
  c.markUsed("reference");
  const Json& r = c.raw()["reference"];
  const std::string at = c.pathOf("reference");
  if (r.is_number()) {
    s.reference = {r.get<double>()};
  } else if (r.is_array()) {
    for (std::size_t i = 0; i < r.size(); ++i) {
      if (!r[i].is_number()) throw SceneError(c.file(), at + "[" + std::to_string(i) + "]", "a number", r[i].dump());
      s.reference.push_back(r[i].get<double>());
    }
    if (s.reference.empty()) throw SceneError(c.file(), at, "at least one number", "[]");
  } else if (r.is_object() && (r.contains("analytic") || r.contains("table"))) {
    const char* key = r.contains("analytic") ? "analytic" : "table";
    if (!r[key].is_string()) throw SceneError(c.file(), at + "." + key, "a reference name", r[key].dump());
    s.referenceName = r[key].get<std::string>();
    s.referenceParameters = r;
    s.referenceParameters.erase(key);
    const bool profile = s.kind == "profile";
    if (s.referenceName == "torque_free_rotation") {
      if (s.kind != "body" || s.field != "orientation")
        throw SceneError(c.file(), at + "." + key, "torque_free_rotation only for a body's orientation", s.referenceName);
    } else if (profile ? !isProfileReference(s.referenceName) : !isScalarReference(s.referenceName)) {
      (profile ? (void)profileReference(s.referenceName, c.file(), at + "." + key)
               : (void)scalarReference(s.referenceName, s.referenceParameters, 0, c.file(), at + "." + key));
    } else if (!profile) {
      scalarReference(s.referenceName, s.referenceParameters, 0, c.file(), at);  // parameters present?
    }
  } else {
    throw SceneError(c.file(), at, "a number, an array of numbers or {\"analytic\"|\"table\": name, ...}", r.dump());
  }
  if (s.field == "orientation" && s.referenceName != "torque_free_rotation" && s.statistic != "max_change")
    c.failAt("reference", "{\"analytic\": \"torque_free_rotation\"} (or statistic max_change) for an orientation", r.dump());
}

}  // namespace

std::vector<CheckSpec> parseChecks(const Json& scene, const std::string& file, int dimension) {
  std::vector<CheckSpec> out;
  if (!scene.is_object() || !scene.contains("checks")) return out;
  const Json& list = scene["checks"];
  if (!list.is_array()) throw SceneError(file, "checks", "an array of checks", list.dump());
  std::set<std::string> names;
  const Config all(list, file, "checks");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const Config c = all.element(i);
    if (!c.raw().is_object()) c.fail("a check {\"name\", \"kind\", ..., \"reference\", \"tolerance\"}", c.raw().dump());
    CheckSpec s;
    s.path = c.path();
    s.name = c.string("name");
    if (s.name.empty() || s.name.find_first_of(" ,/\\\"") != std::string::npos)
      c.failAt("name", "a non-empty name without spaces, commas, slashes or quotes (it names columns)", "\"" + s.name + "\"");
    if (!names.insert(s.name).second) c.failAt("name", "a name no other check uses", "\"" + s.name + "\" again");
    s.kind = c.oneOf("kind", kKinds, "");
    if (s.kind.empty()) c.failAt("kind", "one of diagnostic, body, probe, profile", "nothing");
    if (s.kind == "diagnostic") {
      s.target = c.string("diagnostic");
    } else if (s.kind == "body") {
      s.target = c.string("body");
      s.field = c.oneOf("field", kBodyFields, "position");
    } else if (s.kind == "probe") {
      s.position = toVector(c.vector("position", dimension));
      s.field = c.oneOf("field", kFluidFields, "u");
    } else {
      s.from = toVector(c.vector("from", dimension));
      s.to = toVector(c.vector("to", dimension));
      s.points = static_cast<int>(c.integer("points", 33, 2, 100000));
      s.field = c.oneOf("field", kFluidFields, "u");
    }
    if ((s.field == "w" && dimension == 2)) c.failAt("field", "u, v or p in 2-D", "\"w\"");
    if (c.has("axis")) s.axis = static_cast<int>(c.integer("axis", 0, dimension - 1));
    if (c.has("direction")) s.direction = toVector(c.vector("direction", dimension));
    if (s.kind == "profile" && c.has("statistic")) c.failAt("statistic", "no statistic for a profile (its final state is compared)", "");
    s.statistic = c.oneOf("statistic", kStatistics, "final");
    s.at = c.number("at", -1.0, Bound::Any);
    if (c.has("at") && s.at < 0) c.failAt("at", "a time >= 0", std::to_string(s.at));
    if (c.has("at") && s.statistic != "final") c.failAt("at", "\"at\" only with the statistic final", s.statistic);
    s.after = c.number("after", 0.0, Bound::NonNegative);
    s.scale = c.number("scale", 1.0, Bound::Any);
    s.norm = c.oneOf("norm", s.kind == "profile" ? std::vector<std::string>{"max", "rms", "relative"}
                                                   : std::vector<std::string>{"absolute", "relative"},
                     s.kind == "profile" ? "max" : "absolute");
    s.tolerance = c.number("tolerance", Bound::NonNegative);
    parseReference(c, s);
    c.finish();
    out.push_back(std::move(s));
  }
  return out;
}


namespace {
template <int d>
const MacGrid<d>* gridOf(const World<d>& w) {
  const auto* pool = w.template findPool<MacGrid<d>>();
  return pool && pool->size() > 0 ? &pool->components()[0] : nullptr;
}
template <int d>
double sampleField(const MacGrid<d>& g, const Eigen::VectorXd& x, const std::string& field) {
  const Eigen::Matrix<double, d, 1> p = x.head<d>();
  if (field == "p") return samplePressure(g, p);
  return sampleVelocity(g, p)[field == "u" ? 0 : field == "v" ? 1 : 2];
}
Eigen::VectorXd vec(const std::vector<double>& v) { return Eigen::Map<const Eigen::VectorXd>(v.data(), v.size()); }

template <int d>
Eigen::Vector4d quaternionOf(const RigidBody<d>& b) {
  if constexpr (d == 3) return Eigen::Vector4d(b.orientation.w(), b.orientation.x(), b.orientation.y(), b.orientation.z());
  else return Eigen::Vector4d(std::cos(b.orientation / 2), 0, 0, std::sin(b.orientation / 2));
}
double angleBetween(const Eigen::Vector4d& a, const Eigen::Vector4d& b) {
  return 2 * std::acos(std::min(1.0, std::abs(a.normalized().dot(b.normalized()))));
}
}  // namespace

template <int d>
CheckEvaluator<d>::CheckEvaluator(std::vector<CheckSpec> checks, const World<d>& world, const std::string& file,
                                  double startTime)
    : checks_(std::move(checks)), states_(checks_.size()), file_(file), startTime_(startTime) {
  for (std::size_t i = 0; i < checks_.size(); ++i) {
    const CheckSpec& c = checks_[i];
    if (c.kind == "body") {
      const auto e = world.find(c.target);
      if (!e || !world.template get<RigidBody<d>>(*e))
        throw SceneError(file, c.path + ".body", "the name of an entity with a rigid_body", "\"" + c.target + "\"");
      const RigidBody<d>& b = *world.template get<RigidBody<d>>(*e);
      states_[i].q0 = quaternionOf(b);
      if constexpr (d == 3) {
        states_[i].inertia = b.inertiaBody;
        states_[i].L = b.L;
      }
      if (c.referenceName == "torque_free_rotation" && d != 3)
        throw SceneError(file, c.path + ".reference", "torque_free_rotation in a 3-D scene", "a 2-D scene");
    }
    if ((c.kind == "probe" || c.kind == "profile") && !gridOf(world))
      throw SceneError(file, c.path + ".kind", "probe and profile checks only in a scene with a mac_grid", c.kind);
    if (!c.direction.empty() && c.kind != "body")
      throw SceneError(file, c.path + ".direction", "a direction only for a body's vector field", "");
    // A quantity with a start value (a change, a displacement) takes it now.
    bool available = false;
    if (c.kind == "body" || c.kind == "probe") {
      states_[i].initial = quantity(c, world, {}, available);
      states_[i].started = true;
    }
  }
}

template <int d>
Eigen::VectorXd CheckEvaluator<d>::quantity(const CheckSpec& c, const World<d>& world,
                                            const std::map<std::string, double>& diag, bool& available) const {
  available = true;
  if (c.kind == "diagnostic") {
    const auto it = diag.find(c.target);
    if (it == diag.end()) {
      available = false;
      return Eigen::VectorXd::Zero(1);
    }
    return Eigen::VectorXd::Constant(1, it->second);
  }
  if (c.kind == "probe") return Eigen::VectorXd::Constant(1, sampleField(*gridOf(world), vec(c.position), c.field));
  const RigidBody<d>& b = *world.template get<RigidBody<d>>(*world.find(c.target));
  if (c.field == "position" || c.field == "displacement") return Eigen::VectorXd(b.x);
  if (c.field == "velocity") return Eigen::VectorXd(b.v);
  if (c.field == "angular_momentum") return Eigen::VectorXd(b.L);
  return quaternionOf(b);  // orientation
}

template <int d>
void CheckEvaluator<d>::observe(const World<d>& world, const std::map<std::string, double>& diagnostics, double time) {
  for (std::size_t i = 0; i < checks_.size(); ++i) {
    const CheckSpec& c = checks_[i];
    State& s = states_[i];
    if (c.kind == "profile") continue;
    bool available = false;
    const Eigen::VectorXd q = quantity(c, world, diagnostics, available);
    if (!available) continue;
    if (!s.started) {  // diagnostics exist from the first step on: that is their start value
      s.initial = q;
      s.started = true;
    }
    // A scalar: the component, the projection on a direction, or the quantity itself.
    auto scalarOf = [&](const Eigen::VectorXd& v) {
      if (c.field == "orientation") return angleBetween(v, s.q0);
      const Eigen::VectorXd w = c.field == "displacement" ? Eigen::VectorXd(v - s.initial) : v;
      if (c.axis >= 0) return w[c.axis] * c.scale;
      if (!c.direction.empty()) return w.dot(vec(c.direction).normalized()) * c.scale;
      return (w.size() == 1 ? w[0] : w.norm()) * c.scale;
    };
    const double value = scalarOf(q);
    s.last = value;
    s.haveLast = true;
    if (c.at >= 0 && !s.haveAt && time >= c.at - 1e-9 * std::max(1.0, c.at)) {
      s.atValue = value;
      s.haveAt = true;
    }
    if (time < c.after - 1e-12) continue;
    if (c.statistic == "max" || c.statistic == "min") {
      if (!s.haveExtreme || (c.statistic == "max" ? value > s.extreme : value < s.extreme)) s.extreme = value;
      s.haveExtreme = true;
    } else if (c.statistic == "max_change" || c.statistic == "max_relative_change") {
      double change = c.field == "orientation" ? angleBetween(q, s.initial) : (q - s.initial).norm() * std::abs(c.scale);
      if (c.statistic == "max_relative_change") change /= std::max(s.initial.norm() * std::abs(c.scale), 1e-300);
      s.change = std::max(s.change, change);
      s.haveExtreme = true;
    }
  }
}

template <int d>
std::vector<CheckResult> CheckEvaluator<d>::finish(const World<d>& world, double time) {
  std::vector<CheckResult> out;
  for (std::size_t i = 0; i < checks_.size(); ++i) {
    const CheckSpec& c = checks_[i];
    State& s = states_[i];
    CheckResult r;
    r.name = c.name;
    r.tolerance = c.tolerance;
    r.value = std::numeric_limits<double>::quiet_NaN();
    const double t = c.at >= 0 ? c.at : time;
    if (c.kind == "profile") {
      const MacGrid<d>& g = *gridOf(world);
      const Eigen::VectorXd a = vec(c.from), b = vec(c.to);
      std::vector<Eigen::VectorXd> xs;
      std::vector<double> refs;
      if (!c.referenceName.empty() && profileReference(c.referenceName, file_, c.path).tabulated) {
        const ProfileReference table = profileReference(c.referenceName, file_, c.path);
        int axis = 0;
        (b - a).cwiseAbs().maxCoeff(&axis);
        for (std::size_t k = 0; k < table.coordinates.size(); ++k) {
          xs.push_back(a + (table.coordinates[k] - a[axis]) / (b[axis] - a[axis]) * (b - a));
          refs.push_back(table.values[k]);
        }
      } else {
        for (int k = 0; k < c.points; ++k) {
          const Eigen::VectorXd x = a + double(k) / (c.points - 1) * (b - a);
          xs.push_back(x);
          refs.push_back(c.referenceName.empty() ? c.reference[std::min<std::size_t>(k, c.reference.size() - 1)]
                                                 : profileValue(c.referenceName, c.referenceParameters, x, file_, c.path));
        }
      }
      double worst = 0, sum2 = 0, refMax = 0, worstValue = 0, worstRef = 0;
      for (std::size_t k = 0; k < xs.size(); ++k) {
        const double v = sampleField(g, xs[k], c.field) * c.scale, e = std::abs(v - refs[k]);
        if (e >= worst) worst = e, worstValue = v, worstRef = refs[k];
        sum2 += e * e;
        refMax = std::max(refMax, std::abs(refs[k]));
      }
      r.value = worstValue;  // the sample farthest from the reference
      r.reference = worstRef;
      r.error = c.norm == "rms" ? std::sqrt(sum2 / xs.size()) : c.norm == "relative" ? worst / std::max(refMax, 1e-300) : worst;
    } else if (!s.started) {
      r.note = "the diagnostic '" + c.target + "' never appeared in metrics";
      r.error = std::numeric_limits<double>::infinity();
    } else {
      if (c.at >= 0) {
        if (!s.haveAt) r.note = "the run ended before t = " + std::to_string(c.at);
        else r.value = s.atValue;
      } else if (c.statistic == "max" || c.statistic == "min") {
        if (s.haveExtreme) r.value = s.extreme;
        else r.note = "no step after t = " + std::to_string(c.after);
      } else if (c.statistic == "max_change" || c.statistic == "max_relative_change") {
        r.value = s.change;
      } else if (s.haveLast) {  // final: the last observation
        r.value = s.last;
      } else {
        r.note = "no step was taken";
      }
      if (c.referenceName == "torque_free_rotation") {
        const Eigen::Vector4d exact = torqueFreeOrientation(s.q0, s.inertia, s.L, t - startTime_);
        bool available = false;
        r.value = angleBetween(quantity(c, world, {}, available), exact);  // the angle to the exact orientation
        r.reference = 0;
        r.error = r.value;
      } else {
        r.reference = c.referenceName.empty() ? c.reference[0]
                                              : scalarReference(c.referenceName, c.referenceParameters, t - startTime_,
                                                                file_, c.path);
        const double diff = std::abs(r.value - r.reference);
        r.error = c.norm == "relative" ? diff / std::max(std::abs(r.reference), 1e-300) : diff;
      }
    }
    r.pass = std::isfinite(r.error) && r.error <= c.tolerance;
    out.push_back(r);
  }
  return out;
}

Json checksToJson(const std::vector<CheckResult>& results) {
  Json a = Json::array();
  auto num = [](double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); };
  for (const auto& r : results) {
    Json j = {{"name", r.name}, {"value", num(r.value)}, {"reference", num(r.reference)}, {"error", num(r.error)},
              {"tolerance", r.tolerance}, {"pass", r.pass}};
    if (!r.note.empty()) j["note"] = r.note;
    a.push_back(j);
  }
  return a;
}

std::string formatChecks(const std::vector<CheckResult>& results) {
  std::ostringstream s;
  for (const auto& r : results) {
    char line[256];
    std::snprintf(line, sizeof line, "check %-28s %s  value %.6g  reference %.6g  error %.3g (tolerance %.3g)%s%s\n",
                  r.name.c_str(), r.pass ? "pass" : "FAIL", r.value, r.reference, r.error, r.tolerance,
                  r.note.empty() ? "" : ": ", r.note.c_str());
    s << line;
  }
  return s.str();
}

template class CheckEvaluator<2>;
template class CheckEvaluator<3>;

}  // namespace monolith
