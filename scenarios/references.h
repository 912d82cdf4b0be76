#pragma once
// Named references a scene's checks compare with (checks.h): closed-form results of the
// thesis's test problems and published tables. Each takes its parameters from the check's
// "reference" object, e.g. {"analytic": "coulomb_incline", "angle_degrees": 30, "friction": 0.3}.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "ecs/config.h"

namespace monolith {

// Scalar references at time t. Throws SceneError (at `path`) for an unknown name or parameter.
//  coulomb_incline   distance slid down an incline from rest, 1/2 g (sin a - mu cos a) t^2 (0 if it sticks)
//  restitution_apex  apex of a ball dropped from drop_height above the floor after one bounce:
//                    floor + e^2 drop_height (with floor = the centre height at contact)
//  free_fall         height of a body dropped from rest: height - 1/2 g t^2
//  dfg_2d1_drag, dfg_2d1_lift   Schäfer & Turek 1996 2D-1 coefficients, 5.57953523384 and 0.010618948146
double scalarReference(const std::string& name, const Json& parameters, double t, const std::string& file,
                       const std::string& path);
bool isScalarReference(const std::string& name);

// Profile references: the reference value at each point of a line.
//  poiseuille        u = 4 U (y - y_min)(y_max - y) / (y_max - y_min)^2 (peak_velocity U)
//  ghia_re100_u, ghia_re100_v, ghia_re1000_u, ghia_re1000_v   Ghia, Ghia & Shin 1982 centre lines
//                    of the unit lid-driven cavity (u along x = 0.5 at 17 y's; v along y = 0.5 at 17 x's)
struct ProfileReference {
  std::vector<double> coordinates;  // tables: where along the line's axis the values are given
  std::vector<double> values;       // tables: the values; analytic: filled by profileValue
  bool tabulated = false;
};
ProfileReference profileReference(const std::string& name, const std::string& file, const std::string& path);
bool isProfileReference(const std::string& name);
// Analytic profile value at a point (poiseuille).
double profileValue(const std::string& name, const Json& parameters, const Eigen::VectorXd& x, const std::string& file,
                    const std::string& path);

// The exact torque-free rotation of a rigid body (Euler's equations with L fixed in the world),
// integrated with classical RK4 at steps much finer than any simulation's: the orientation the
// body should have at time t. Used by the "torque_free_rotation" reference of orientation checks.
Eigen::Vector4d torqueFreeOrientation(const Eigen::Vector4d& q0 /* w, x, y, z */, const Eigen::Matrix3d& inertiaBody,
                                      const Eigen::Vector3d& L, double t);

}  // namespace monolith
