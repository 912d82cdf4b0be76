#pragma once
// Closest points on a surface face (a triangle in 3-D, a segment in 2-D) as the weights of its
// vertices, shared by the surface collisions (proximity.cpp) and the rigid-body/face contact
// (rigid_face_contact.cpp).
#include <Eigen/Core>

namespace monolith::solvers::deformable {

// Ericson, Real-Time Collision Detection, 5.1.5: barycentric coordinates of the point of
// triangle abc closest to p.
inline Eigen::Vector3d closestOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                         const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return {1, 0, 0};
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return {0, 1, 0};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    return {1 - v, v, 0};
  }
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return {0, 0, 1};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 / (d2 - d6);
    return {1 - w, 0, w};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {0, 1 - w, w};
  }
  const double denom = 1 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  return {1 - v - w, v, w};
}

inline double clamp01(double s) { return s < 0 ? 0 : s > 1 ? 1 : s; }

// The parameter t in [0, 1] of the point (1 - t) a + t b of segment ab closest to p.
template <int d>
double closestOnSegment(const Eigen::Matrix<double, d, 1>& p, const Eigen::Matrix<double, d, 1>& a,
                        const Eigen::Matrix<double, d, 1>& b) {
  const double len2 = (b - a).squaredNorm();
  return len2 > 0 ? clamp01((p - a).dot(b - a) / len2) : 0.0;
}

}  // namespace monolith::solvers::deformable
