#include "scenarios/references.h"

#include <cmath>

#include <Eigen/Geometry>

namespace monolith {

namespace {

double param(const Json& p, const std::string& key, const std::string& file, const std::string& path, double fallback,
             bool required) {
  if (p.is_object() && p.contains(key)) {
    if (!p[key].is_number()) throw SceneError(file, path + "." + key, "a number", p[key].dump());
    return p[key].get<double>();
  }
  if (required) throw SceneError(file, path + "." + key, "a number (this reference needs it)", "nothing");
  return fallback;
}

struct Table {
  const char* name;
  std::vector<double> coordinates, values;
};

// Ghia, Ghia & Shin (1982), Tables I and II, as listed in REFERENCES.md.
const std::vector<Table>& ghiaTables() {
  static const std::vector<double> uY = {1.0000, 0.9766, 0.9688, 0.9609, 0.9531, 0.8516, 0.7344, 0.6172, 0.5000,
                                         0.4531, 0.2813, 0.1719, 0.1016, 0.0703, 0.0625, 0.0547, 0.0000};
  static const std::vector<double> vX = {1.0000, 0.9688, 0.9609, 0.9531, 0.9453, 0.9063, 0.8594, 0.8047, 0.5000,
                                         0.2344, 0.2266, 0.1563, 0.0938, 0.0781, 0.0703, 0.0625, 0.0000};
  static const std::vector<Table> tables = {
      {"ghia_re100_u", uY, {1.00000, 0.84123, 0.78871, 0.73722, 0.68717, 0.23151, 0.00332, -0.13641, -0.20581,
                            -0.21090, -0.15662, -0.10150, -0.06434, -0.04775, -0.04192, -0.03717, 0.00000}},
      {"ghia_re1000_u", uY, {1.00000, 0.65928, 0.57492, 0.51117, 0.46604, 0.33304, 0.18719, 0.05702, -0.06080,
                             -0.10648, -0.27805, -0.38289, -0.29730, -0.22220, -0.20196, -0.18109, 0.00000}},
      {"ghia_re100_v", vX, {0.00000, -0.05906, -0.07391, -0.08864, -0.10313, -0.16914, -0.22445, -0.24533, 0.05454,
                            0.17527, 0.17507, 0.16077, 0.12317, 0.10890, 0.10091, 0.09233, 0.00000}},
      {"ghia_re1000_v", vX, {0.00000, -0.21388, -0.27669, -0.33714, -0.39188, -0.51550, -0.42665, -0.31966, 0.02526,
                             0.32235, 0.33075, 0.37095, 0.32627, 0.30353, 0.29012, 0.27485, 0.00000}},
  };
  return tables;
}

}  // namespace

bool isScalarReference(const std::string& name) {
  return name == "coulomb_incline" || name == "restitution_apex" || name == "free_fall" || name == "dfg_2d1_drag" ||
         name == "dfg_2d1_lift";
}

double scalarReference(const std::string& name, const Json& p, double t, const std::string& file,
                       const std::string& path) {
  if (name == "coulomb_incline") {
    const double a = param(p, "angle_degrees", file, path, 0, true) * M_PI / 180;
    const double mu = param(p, "friction", file, path, 0, true), g = param(p, "gravity", file, path, 9.81, false);
    return std::max(0.0, 0.5 * g * (std::sin(a) - mu * std::cos(a)) * t * t);
  }
  if (name == "restitution_apex") {
    const double e = param(p, "restitution", file, path, 0, true);
    return param(p, "floor", file, path, 0, false) + e * e * param(p, "drop_height", file, path, 0, true);
  }
  if (name == "free_fall")
    return param(p, "height", file, path, 0, true) - 0.5 * param(p, "gravity", file, path, 9.81, false) * t * t;
  if (name == "dfg_2d1_drag") return 5.57953523384;
  if (name == "dfg_2d1_lift") return 0.010618948146;
  throw SceneError(file, path, "a known scalar reference (coulomb_incline, restitution_apex, free_fall, dfg_2d1_drag, dfg_2d1_lift)",
                   "\"" + name + "\"");
}

bool isProfileReference(const std::string& name) {
  if (name == "poiseuille") return true;
  for (const auto& t : ghiaTables())
    if (name == t.name) return true;
  return false;
}

ProfileReference profileReference(const std::string& name, const std::string& file, const std::string& path) {
  if (name == "poiseuille") return {};
  for (const auto& t : ghiaTables())
    if (name == t.name) return {t.coordinates, t.values, true};
  throw SceneError(file, path, "a known profile reference (poiseuille, ghia_re100_u, ghia_re100_v, ghia_re1000_u, ghia_re1000_v)",
                   "\"" + name + "\"");
}

double profileValue(const std::string& name, const Json& p, const Eigen::VectorXd& x, const std::string& file,
                    const std::string& path) {
  if (name != "poiseuille") throw SceneError(file, path, "an analytic profile reference", "\"" + name + "\"");
  const double U = param(p, "peak_velocity", file, path, 0, true);
  const double a = param(p, "y_min", file, path, 0, false), b = param(p, "y_max", file, path, 1, false);
  return 4 * U * (x[1] - a) * (b - x[1]) / ((b - a) * (b - a));
}

Eigen::Vector4d torqueFreeOrientation(const Eigen::Vector4d& q0, const Eigen::Matrix3d& inertiaBody,
                                      const Eigen::Vector3d& L, double t) {
  const Eigen::Matrix3d Iinv = inertiaBody.inverse();
  // dq/dt = 1/2 (0, w) q with w = R I^{-1} R^T L: the body's own spin, L constant (no torque).
  auto rate = [&](const Eigen::Vector4d& qv) {
    const Eigen::Quaterniond q(qv[0], qv[1], qv[2], qv[3]);
    const Eigen::Matrix3d R = q.normalized().toRotationMatrix();
    const Eigen::Vector3d w = R * Iinv * R.transpose() * L;
    const Eigen::Quaterniond dq = Eigen::Quaterniond(0, w.x(), w.y(), w.z()) * q;
    return Eigen::Vector4d(0.5 * dq.w(), 0.5 * dq.x(), 0.5 * dq.y(), 0.5 * dq.z());
  };
  // 1e-4 s steps: RK4's error (h^4 |w|^5 t) stays below 1e-9 rad for |w| ~ 10 rad/s over 10 s.
  const long n = std::max(1L, static_cast<long>(std::ceil(t / 1e-4)));
  const double h = t / n;
  Eigen::Vector4d q = q0;
  for (long i = 0; i < n; ++i) {
    const Eigen::Vector4d k1 = rate(q), k2 = rate(q + 0.5 * h * k1), k3 = rate(q + 0.5 * h * k2), k4 = rate(q + h * k3);
    q += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    q.normalize();
  }
  return q;
}

}  // namespace monolith
