#pragma once
// Small rigid-body algebra shared by the contact solvers, for d = 2 and 3.
// In 2-D angular quantities are 1-vectors (about z): r x j is a number and w x r = w (-r_y, r_x).
#include <Eigen/Core>
#include <type_traits>

namespace monolith::solvers::contact {

template <int d>
using Vec = Eigen::Matrix<double, d, 1>;
template <int d>
using Mat = Eigen::Matrix<double, d, d>;
template <int d>
constexpr int kAngularDim = d == 3 ? 3 : 1;
template <int d>
using AngVec = Eigen::Matrix<double, kAngularDim<d>, 1>;
template <int d>
using AngMat = Eigen::Matrix<double, kAngularDim<d>, kAngularDim<d>>;
// The linear map j -> r x j (the thesis's r^*), kAngularDim x d.
template <int d>
using CrossMat = Eigen::Matrix<double, kAngularDim<d>, d>;

template <int d>
CrossMat<d> crossMatrix(const Vec<d>& r) {
  CrossMat<d> m;
  if constexpr (d == 3) {
    m << 0, -r.z(), r.y(), r.z(), 0, -r.x(), -r.y(), r.x(), 0;
  } else {
    m << -r.y(), r.x();
  }
  return m;
}
template <int d>
AngVec<d> cross(const Vec<d>& r, const Vec<d>& j) {
  return crossMatrix<d>(r) * j;
}
// w x r = r*^T w (the thesis's r*^T Delta omega: the velocity at r of a rotation w).
template <int d>
Vec<d> angularCross(const AngVec<d>& w, const Vec<d>& r) {
  return crossMatrix<d>(r).transpose() * w;
}

}  // namespace monolith::solvers::contact
