// The damping solve with rigid bodies among its unknowns (solvers/deformable/coupled_damping.h,
// thesis Sec. 4.7.3): the projected operator P^T A P is symmetric and positive on the constrained
// subspace, P is the M-orthogonal projection onto the held contacts' relative normal velocities,
// the solve keeps linear and angular momentum to round-off with a bound and a held rigid body,
// and a light body bound to a damped bar follows it without overshooting (with the body's
// velocity fixed inside the solve and the damping handed over afterwards, it overshoots).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cstdio>
#include <random>

#include "solvers/deformable/coupled_damping.h"
#include "solvers/deformable/simplex_mesh.h"

using namespace monolith;
namespace dm = solvers::deformable;
namespace rm = solvers::contact;

namespace {

template <int d>
struct Scene {
  dm::ForceModel<d> fm;
  std::vector<dm::MatD<d>> R;
  std::vector<double> x, v, f;
  std::vector<dm::ParticleRole> role;
  std::vector<int> rigid;
  std::vector<dm::DampingRigid<d>> rigids;
  std::vector<dm::DampingHold<d>> holds;
  std::vector<dm::DampingRigidRow<d>> rows;  // the rigid bodies' own constraints

  dm::DampingBody<d> body() const {
    dm::DampingBody<d> b;
    b.fm = &fm;
    b.rotations = &R;
    b.x = x.data();
    b.v = v.data();
    b.m = fm.mass.data();
    b.f = f.data();
    b.role = role;
    b.rigid = rigid;
    return b;
  }
  dm::CoupledDampingSystem<d> system(double h) const {
    return dm::CoupledDampingSystem<d>({body()}, rigids, holds, h, rows);
  }
  // The target of constraint k in constraintResiduals' order (holds, then rigid rows).
  double target(std::size_t k) const { return k < holds.size() ? holds[k].target : rows[k - holds.size()].target; }
};

// A block of particles (a box mesh), randomly deformed and moving: particles with x < -0.3 L bound
// to rigid body 0, those with y < -0.3 L held against rigid body 1 (a dynamic body below), those
// with y > 0.3 L and x > 0 held against a static body, one particle fixed (if `withFixed`).
template <int d>
Scene<d> block(dm::Model model, unsigned seed, bool withFixed = true) {
  Scene<d> s;
  const dm::MeshData<d> mesh = dm::boxMesh<d>(dm::VecD<d>::Constant(0.2), 0.1);
  std::vector<double> X;
  for (const auto& x : mesh.x)
    for (int a = 0; a < d; ++a) X.push_back(x(a));
  dm::Material mat;
  mat.model = model;
  mat.youngsModulus = 1e5;
  mat.poissonRatio = 0.3;
  mat.density = 1000;
  if (model == dm::Model::Springs) mat.overdamping = 0.5;
  else mat.rayleighBeta = 0.01;
  s.fm = dm::prepareForceModel<d>(X, mesh.elements, mat);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  const int n = static_cast<int>(mesh.x.size());
  s.role.assign(n, dm::ParticleRole::Free);
  s.rigid.assign(n, -1);
  double bodyMass = 0;
  for (int i = 0; i < n; ++i) {
    for (int a = 0; a < d; ++a) {
      s.x.push_back(mesh.x[i](a) * (1 + 0.05 * u(rng)) + 0.002 * u(rng));
      s.v.push_back(0.3 * u(rng));
      s.f.push_back(0.0);
    }
    const auto& x = mesh.x[i];
    if (x(0) < -0.06) {
      s.role[i] = dm::ParticleRole::Bound;
      s.rigid[i] = 0;
      bodyMass += s.fm.mass[i];
    }
  }
  s.R = dm::dampingRotations<d>(s.fm, s.x.data());
  for (int c = 0; c < 2; ++c) {
    dm::DampingRigid<d> r;
    r.mass = c == 0 ? 0.5 + bodyMass : 2.0;
    rm::AngMat<d> A;
    for (int a = 0; a < rm::kAngularDim<d>; ++a)
      for (int b = 0; b < rm::kAngularDim<d>; ++b) A(a, b) = u(rng);
    r.inertia = 0.01 * (A * A.transpose() + rm::AngMat<d>::Identity());
    r.x = c == 0 ? dm::VecD<d>(dm::VecD<d>::Unit(0) * -0.25) : dm::VecD<d>(dm::VecD<d>::Unit(1) * -0.4);
    for (int a = 0; a < d; ++a) r.v(a) = u(rng);
    for (int a = 0; a < rm::kAngularDim<d>; ++a) r.omega(a) = u(rng);
    s.rigids.push_back(r);
  }
  bool fixedOne = !withFixed;
  for (int i = 0; i < n; ++i) {
    const auto& x = mesh.x[i];
    if (s.role[i] != dm::ParticleRole::Free) continue;
    dm::VecD<d> normal;
    for (int a = 0; a < d; ++a) normal(a) = u(rng);
    normal.normalize();
    if (x(1) < -0.06) s.holds.push_back({0, i, normal, 0.1 * u(rng), 1});
    else if (x(1) > 0.06 && x(0) > 0) s.holds.push_back({0, i, normal, 0.1 * u(rng), -1});
    else if (!fixedOne) {
      s.role[i] = dm::ParticleRole::Prescribed;
      fixedOne = true;
    }
  }
  return s;
}

// The rigid bodies' own constraints added to a block scene: body 1 resting on a static ground at
// four coplanar points (rank d - 1 + (d - 2) of four rows: dependent rows), body 0 touching body 1
// at four coplanar points of a random plane, and one angular joint row between them. Targets
// from random twists, so that the rows are consistent (dependent rows agree).
template <int d>
void addRigidRows(Scene<d>& s, unsigned seed) {
  using Twist = dm::DampingTwist<d>;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  Twist xi0, xi1;
  for (int a = 0; a < Twist::RowsAtCompileTime; ++a) {
    xi0(a) = 0.2 * u(rng);
    xi1(a) = 0.2 * u(rng);
  }
  auto row = [](const dm::VecD<d>& n, const dm::VecD<d>& r) {
    Twist g;
    g.template head<d>() = n;
    g.template tail<rm::kAngularDim<d>>() = rm::cross<d>(r, n);
    return g;
  };
  dm::VecD<d> tangent = dm::VecD<d>::Unit(0), other = dm::VecD<d>::Zero();
  if constexpr (d == 3) other = dm::VecD<d>::Unit(2);
  const double offsets[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  for (const auto& o : offsets) {  // ground under body 1
    const dm::VecD<d> p = s.rigids[1].x + 0.1 * (o[0] * tangent + o[1] * other) - 0.1 * dm::VecD<d>::Unit(1);
    dm::DampingRigidRow<d> r;
    r.a = 1;
    r.ga = row(dm::VecD<d>::Unit(1), p - s.rigids[1].x);
    r.target = r.ga.dot(xi1);
    s.rows.push_back(r);
  }
  dm::VecD<d> n;
  for (int a = 0; a < d; ++a) n(a) = u(rng);
  n.normalize();
  dm::VecD<d> t1 = dm::VecD<d>::Unit(0) - n.x() * n, t2 = dm::VecD<d>::Zero();
  t1.normalize();
  if constexpr (d == 3) t2 = n.cross(t1);
  const dm::VecD<d> centre = 0.5 * (s.rigids[0].x + s.rigids[1].x);
  for (const auto& o : offsets) {  // body 0 on body 1, normal n out of body 1
    const dm::VecD<d> p = centre + 0.05 * (o[0] * t1 + o[1] * t2);
    dm::DampingRigidRow<d> r;
    r.a = 0;
    r.b = 1;
    r.ga = row(n, p - s.rigids[0].x);
    r.gb = -row(n, p - s.rigids[1].x);
    r.target = r.ga.dot(xi0) + r.gb.dot(xi1);
    s.rows.push_back(r);
  }
  dm::DampingRigidRow<d> joint;  // the relative turn about e (about z in 2-D)
  joint.a = 0;
  joint.b = 1;
  rm::AngVec<d> e;
  for (int a = 0; a < rm::kAngularDim<d>; ++a) e(a) = u(rng);
  e.normalize();
  joint.ga.template tail<rm::kAngularDim<d>>() = -e;
  joint.gb.template tail<rm::kAngularDim<d>>() = e;
  joint.target = joint.ga.dot(xi0) + joint.gb.dot(xi1);
  s.rows.push_back(joint);
}

template <int d>
void expectProjectedOperatorSymmetric(bool withRows) {
  Scene<d> s = block<d>(dm::Model::Corotated, 7);
  if (withRows) addRigidRows<d>(s, 11);
  ASSERT_GE(s.holds.size(), 4u);
  const dm::CoupledDampingSystem<d> sys = s.system(2e-3);
  const int n = sys.size();
  std::mt19937 rng(3);
  std::normal_distribution<double> g;
  auto random = [&] {
    Eigen::VectorXd v(n);
    for (int i = 0; i < n; ++i) v(i) = g(rng);
    return v;
  };
  double worstSymmetry = 0, worstProjection = 0, worstMassSymmetry = 0, worstConstraint = 0;
  for (int trial = 0; trial < 10; ++trial) {
    const Eigen::VectorXd a = random(), b = random();
    Eigen::VectorXd Aa(n), Ab(n);
    sys.applyProjected(a, Aa);
    sys.applyProjected(b, Ab);
    const double scale = Aa.norm() * b.norm() + Ab.norm() * a.norm();
    worstSymmetry = std::max(worstSymmetry, std::abs(b.dot(Aa) - a.dot(Ab)) / scale);
    // P P = P; M P = P^T M (P symmetric in the mass inner product); P^T = M P M^-1.
    Eigen::VectorXd Pa = a, PPa, Pb = b, MPb, Ma, PtMa;
    sys.projectVelocity(Pa);
    PPa = Pa;
    sys.projectVelocity(PPa);
    worstProjection = std::max(worstProjection, (PPa - Pa).norm() / Pa.norm());
    sys.projectVelocity(Pb);
    sys.applyMass(Pb, MPb);
    sys.applyMass(a, Ma);
    PtMa = Ma;
    sys.projectForce(PtMa);
    worstMassSymmetry = std::max(worstMassSymmetry, std::abs(a.dot(MPb) - b.dot(PtMa)) / (Ma.norm() * b.norm()));
    // The projected velocity meets the homogeneous constraints (targets subtracted back).
    const std::vector<double> residual = sys.constraintResiduals(Pa);
    for (std::size_t k = 0; k < residual.size(); ++k)
      worstConstraint = std::max(worstConstraint, std::abs(residual[k] + s.target(k)) / Pa.norm());
    // Positive on the constrained subspace.
    Eigen::VectorXd APa(n);
    sys.applyProjected(Pa, APa);
    EXPECT_GT(Pa.dot(APa), 0);
  }
  std::printf("d = %d, %zu rigid rows: symmetry %.1e, P P - P %.1e, M-symmetry of P %.1e, constraints %.1e\n", d,
              s.rows.size(), worstSymmetry, worstProjection, worstMassSymmetry, worstConstraint);
  // With the rigid rows the projection goes through S = G K^-1 G^T, whose kept eigenvalues span
  // about three decades here (2-D: 1.5e-3 to 1 after scaling), so round-off grows by as much.
  const double tolerance = withRows ? 1e-12 : 1e-14;
  EXPECT_LT(worstSymmetry, 1e-14);
  EXPECT_LT(worstProjection, tolerance);
  EXPECT_LT(worstMassSymmetry, 1e-14);
  EXPECT_LT(worstConstraint, tolerance);
}

// Linear momentum sum m u + m_c v_c and angular momentum sum x m u + x_c m_c v_c + I_c w_c of the
// free particles and the rigid bodies (bound particles' mass is their body's).
template <int d>
struct Momenta {
  Eigen::Vector3d linear = Eigen::Vector3d::Zero(), angular = Eigen::Vector3d::Zero();
};

template <int d>
Eigen::Vector3d lift(const dm::VecD<d>& v) {
  Eigen::Vector3d out = Eigen::Vector3d::Zero();
  out.template head<d>() = v;
  return out;
}
template <int d>
Eigen::Vector3d liftAngular(const rm::AngVec<d>& w) {
  if constexpr (d == 3) return w;
  else return Eigen::Vector3d(0, 0, w(0));
}

template <int d>
Momenta<d> momenta(const Scene<d>& s, const std::vector<double>& u, const std::vector<dm::VecD<d>>& v,
                   const std::vector<rm::AngVec<d>>& L) {
  Momenta<d> out;
  for (std::size_t i = 0; i < s.role.size(); ++i) {
    if (s.role[i] == dm::ParticleRole::Bound) continue;
    const Eigen::Vector3d p = s.fm.mass[i] * lift<d>(Eigen::Map<const dm::VecD<d>>(&u[d * i]));
    out.linear += p;
    out.angular += lift<d>(Eigen::Map<const dm::VecD<d>>(&s.x[d * i])).cross(p);
  }
  for (std::size_t c = 0; c < s.rigids.size(); ++c) {
    const Eigen::Vector3d p = s.rigids[c].mass * lift<d>(v[c]);
    out.linear += p;
    out.angular += lift<d>(s.rigids[c].x).cross(p) + liftAngular<d>(L[c]);
  }
  return out;
}

template <int d>
void expectMomentumKept(bool withRows) {
  // Spring dampers (central forces, torque-free) with overdamping 0.5; no explicit force, no
  // fixed particle (it would take momentum). The rigid rows only steer the velocity at which the
  // damping forces are evaluated, so momentum is kept with them too.
  Scene<d> s = block<d>(dm::Model::Springs, 5, false);
  if (withRows) addRigidRows<d>(s, 13);
  const double h = 4e-3;
  std::vector<dm::VecD<d>> v0, v1;
  std::vector<rm::AngVec<d>> L0, L1;
  for (const auto& r : s.rigids) {
    v0.push_back(r.v);
    L0.push_back(r.inertia * r.omega);
  }
  const dm::CoupledDampingResult<d> r = dm::solveCoupledDamping<d>({s.body()}, s.rigids, s.holds, h, s.rows);
  ASSERT_TRUE(r.report.converged);
  for (std::size_t c = 0; c < s.rigids.size(); ++c) {
    v1.push_back(v0[c] + h * r.force[c] / s.rigids[c].mass);
    L1.push_back(L0[c] + h * r.torque[c]);
  }
  const Momenta<d> before = momenta<d>(s, s.v, v0, L0), after = momenta<d>(s, r.u[0], v1, L1);
  double dissipated = 0;  // the damping does work: the bound body really exchanged momentum
  for (std::size_t i = 0; i < s.role.size(); ++i)
    if (s.role[i] == dm::ParticleRole::Free)
      for (int a = 0; a < d; ++a)
        dissipated += 0.5 * s.fm.mass[i] * (s.v[d * i + a] * s.v[d * i + a] - r.u[0][d * i + a] * r.u[0][d * i + a]);
  const double dl = (after.linear - before.linear).norm() / before.linear.norm();
  const double da = (after.angular - before.angular).norm() / before.angular.norm();
  std::printf("d = %d: %d iterations; linear momentum %.2e, angular %.2e relative; body 0 impulse %.3e N s\n", d,
              r.report.iterations, dl, da, h * r.force[0].norm());
  EXPECT_GT(h * r.force[0].norm(), 1e-3 * before.linear.norm());
  EXPECT_LT(dl, 1e-13);
  EXPECT_LT(da, 1e-13);
  (void)dissipated;
}

}  // namespace

TEST(CoupledDamping, ProjectedOperatorSymmetricWithRigidUnknowns3d) { expectProjectedOperatorSymmetric<3>(false); }
TEST(CoupledDamping, ProjectedOperatorSymmetricWithRigidUnknowns2d) { expectProjectedOperatorSymmetric<2>(false); }
TEST(CoupledDamping, ProjectedOperatorSymmetricWithRigidRows3d) { expectProjectedOperatorSymmetric<3>(true); }
TEST(CoupledDamping, ProjectedOperatorSymmetricWithRigidRows2d) { expectProjectedOperatorSymmetric<2>(true); }

TEST(CoupledDamping, MomentumKeptWithBoundAndHeldRigidBodies3d) { expectMomentumKept<3>(false); }
TEST(CoupledDamping, MomentumKeptWithBoundAndHeldRigidBodies2d) { expectMomentumKept<2>(false); }
TEST(CoupledDamping, MomentumKeptWithRigidRows3d) { expectMomentumKept<3>(true); }
TEST(CoupledDamping, MomentumKeptWithRigidRows2d) { expectMomentumKept<2>(true); }

// The solution against a dense solve of the same constrained system with the rigid twists as
// unknowns (the null space of C^T taken numerically), unprojected afterwards.
namespace {
void expectMatchesDenseSolve(bool withRows) {
  Scene<3> s = block<3>(dm::Model::Corotated, 9);
  if (withRows) addRigidRows<3>(s, 17);
  const double h = 2e-3;
  const dm::CoupledDampingSystem<3> sys = s.system(h);
  const int n = sys.size();
  Eigen::MatrixXd A(n, n), M(n, n);
  for (int j = 0; j < n; ++j) {
    Eigen::VectorXd e = Eigen::VectorXd::Unit(n, j), col(n);
    sys.apply(e, col);
    A.col(j) = col;
    sys.applyMass(e, col);
    M.col(j) = col;
  }
  // The unknowns: free particle components and the twists (bound and prescribed ones are not).
  std::vector<int> free;
  for (int i = 0; i < static_cast<int>(s.role.size()); ++i)
    if (s.role[i] == dm::ParticleRole::Free)
      for (int a = 0; a < 3; ++a) free.push_back(3 * i + a);
  for (int k = 3 * static_cast<int>(s.role.size()); k < n; ++k) free.push_back(k);
  // C^T y = t on the free unknowns, from the residual function (affine in y).
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
  const std::vector<double> c0 = sys.constraintResiduals(zero);
  const int rows = static_cast<int>(c0.size());
  Eigen::MatrixXd Ct(rows, free.size());
  for (std::size_t j = 0; j < free.size(); ++j) {
    const std::vector<double> cj = sys.constraintResiduals(Eigen::VectorXd::Unit(n, free[j]));
    for (int k = 0; k < rows; ++k) Ct(k, j) = cj[k] - c0[k];
  }
  Eigen::VectorXd t(rows);
  for (int k = 0; k < rows; ++k) t(k) = -c0[k];
  Eigen::MatrixXd Af(free.size(), free.size());
  for (std::size_t i = 0; i < free.size(); ++i)
    for (std::size_t j = 0; j < free.size(); ++j) Af(i, j) = A(free[i], free[j]);
  // b = M y0 + h f - A y_prescribed on the free unknowns.
  Eigen::VectorXd y0 = Eigen::VectorXd::Zero(n), ypre = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < static_cast<int>(s.role.size()); ++i)
    for (int a = 0; a < 3; ++a) {
      if (s.role[i] != dm::ParticleRole::Bound) y0(3 * i + a) = s.v[3 * i + a];
      if (s.role[i] == dm::ParticleRole::Prescribed) ypre(3 * i + a) = s.v[3 * i + a];
    }
  for (std::size_t c = 0; c < s.rigids.size(); ++c) {
    y0.segment<3>(3 * s.role.size() + 6 * c) = s.rigids[c].v;
    y0.segment<3>(3 * s.role.size() + 6 * c + 3) = s.rigids[c].omega;
  }
  const Eigen::VectorXd full = M * y0 - A * ypre;
  Eigen::VectorXd bf(free.size());
  for (std::size_t i = 0; i < free.size(); ++i) bf(i) = full(free[i]);
  // KKT: [Af C; C^T 0] [y; mu] = [bf; t].
  const int m = static_cast<int>(free.size());
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(m + rows, m + rows);
  K.topLeftCorner(m, m) = Af;
  K.topRightCorner(m, rows) = Ct.transpose();
  K.bottomLeftCorner(rows, m) = Ct;
  Eigen::VectorXd rhs(m + rows);
  rhs << bf, t;
  const Eigen::VectorXd sol = K.fullPivLu().solve(rhs);
  Eigen::VectorXd y = ypre;
  for (int i = 0; i < m; ++i) y(free[i]) = sol(i);
  // Unprojected velocities from D at y: A y = M y - h J^T D J y, so h J^T D J y = M y - A y.
  Eigen::VectorXd My(n), Ay(n);
  sys.applyMass(y, My);
  sys.apply(y, Ay);
  const Eigen::VectorXd hDy = My - Ay;

  const dm::CoupledDampingResult<3> r = sys.solve();
  ASSERT_TRUE(r.report.converged);
  double worst = 0, scale = 0;
  for (int i = 0; i < static_cast<int>(s.role.size()); ++i) {
    if (s.role[i] != dm::ParticleRole::Free) continue;
    for (int a = 0; a < 3; ++a) {
      const double expected = s.v[3 * i + a] + hDy(3 * i + a) / s.fm.mass[i];
      worst = std::max(worst, std::abs(r.u[0][3 * i + a] - expected));
      scale = std::max(scale, std::abs(expected));
    }
  }
  const int ro = 3 * static_cast<int>(s.role.size());
  const double forceError = (h * r.force[0] - hDy.segment<3>(ro)).norm() / hDy.segment<3>(ro).norm();
  // The solution meets every constraint, the rigid rows included (dependent ones too).
  double worstRow = 0;
  const std::vector<double> res = sys.constraintResiduals(y);
  for (double v : res) worstRow = std::max(worstRow, std::abs(v));
  std::printf("dense comparison (%zu rigid rows): %d iterations, velocities %.1e relative, body force %.1e, "
              "dense constraint residual %.1e\n",
              s.rows.size(), r.report.iterations, worst / scale, forceError, worstRow);
  EXPECT_LT(worst / scale, 1e-8);
  EXPECT_LT(forceError, 1e-7);
  EXPECT_LT(worstRow, 1e-10);
}
}  // namespace

TEST(CoupledDamping, MatchesDenseSolveWithRigidUnknowns) { expectMatchesDenseSolve(false); }
TEST(CoupledDamping, MatchesDenseSolveWithRigidRows) { expectMatchesDenseSolve(true); }

// A bar of springs (overdamping 5, strongly damped) moving at 1 m/s along its axis with its left
// end bound to a light rigid body at rest (0.5 kg added to its bound particles' mass). One Step I
// damping solve at dt = 4 ms: the body is pulled along and ends between rest and the bar's speed,
// and the kinetic energy falls (backward Euler on damping alone dissipates). With the body's velocity fixed inside the
// solve and the damping force on its particles given to it afterwards (the bound particles
// prescribed), the body overshoots the bar and the energy rises.
TEST(CoupledDamping, LightBoundBodyFollowsDampedBarWithoutOvershoot) {
  const dm::MeshData<3> mesh = dm::boxMesh<3>(Eigen::Vector3d(0.5, 0.05, 0.05), 0.05);
  std::vector<double> X;
  for (const auto& x : mesh.x)
    for (int a = 0; a < 3; ++a) X.push_back(x(a));
  dm::Material mat;
  mat.model = dm::Model::Springs;
  mat.youngsModulus = 1e6;
  mat.density = 1000;
  mat.overdamping = 5;
  Scene<3> s;
  s.fm = dm::prepareForceModel<3>(X, mesh.elements, mat);
  const int n = static_cast<int>(mesh.x.size());
  s.x = X;
  s.role.assign(n, dm::ParticleRole::Free);
  s.rigid.assign(n, -1);
  s.f.assign(3 * n, 0.0);
  dm::DampingRigid<3> body;
  body.mass = 0.5;
  body.x = Eigen::Vector3d(-0.5, 0, 0);
  body.inertia = 0.5 * 0.01 * Eigen::Matrix3d::Identity();
  for (int i = 0; i < n; ++i) {
    const bool bound = mesh.x[i].x() < -0.49;
    s.v.insert(s.v.end(), {bound ? 0.0 : 1.0, 0.0, 0.0});
    if (bound) {
      s.role[i] = dm::ParticleRole::Bound;
      s.rigid[i] = 0;
      body.mass += s.fm.mass[i];
    }
  }
  s.rigids.push_back(body);
  const double h = 0.5 * 4e-3;
  auto kinetic = [&](const std::vector<double>& u, double vBody) {
    double e = 0.5 * body.mass * vBody * vBody;
    for (int i = 0; i < n; ++i)
      if (s.role[i] == dm::ParticleRole::Free)
        for (int a = 0; a < 3; ++a) e += 0.5 * s.fm.mass[i] * u[3 * i + a] * u[3 * i + a];
    return e;
  };
  const double e0 = kinetic(s.v, 0);
  const dm::CoupledDampingResult<3> coupled = dm::solveCoupledDamping<3>({s.body()}, s.rigids, {}, h);
  const double vCoupled = h * coupled.force[0].x() / body.mass;
  const double eCoupled = kinetic(coupled.u[0], vCoupled);
  // The same with the body's velocity prescribed in the solve (its particles at rest).
  Scene<3> fixedBody = s;
  for (int i = 0; i < n; ++i)
    if (fixedBody.role[i] == dm::ParticleRole::Bound) fixedBody.role[i] = dm::ParticleRole::Prescribed;
  const dm::CoupledDampingResult<3> prescribed = dm::solveCoupledDamping<3>({fixedBody.body()}, {}, {}, h);
  Eigen::Vector3d impulse = Eigen::Vector3d::Zero();
  for (int i = 0; i < n; ++i)
    if (s.role[i] == dm::ParticleRole::Bound) impulse += h * Eigen::Vector3d::Map(&prescribed.Du[0][3 * i]);
  const double vPrescribed = impulse.x() / body.mass;
  const double ePrescribed = kinetic(prescribed.u[0], vPrescribed);
  std::printf("light bound body (%.3f kg; bar %.2f kg at 1 m/s): coupled v = %.4f m/s, energy %.4f -> %.4f J; "
              "prescribed v = %.4f m/s, energy -> %.4f J\n",
              body.mass, 10.0, vCoupled, e0, eCoupled, vPrescribed, ePrescribed);
  EXPECT_GT(vCoupled, 0.05);
  EXPECT_LE(vCoupled, 1.0);
  EXPECT_LT(eCoupled, e0);
  EXPECT_GT(vPrescribed, 1.0);  // the alternative overshoots ...
  EXPECT_GT(ePrescribed, e0);   // ... and gains energy
}

// Embedded particles (Sifakis et al. 2007 hard binding) in the solve: the left end of a strongly
// damped bar of springs (overdamping 5, 1 m/s along its axis) embedded in a light block of
// springs without damping (0.42 kg with the embedded mass, at rest). One Step I damping solve at
// dt = 4 ms with the end following its host elements inside the solve: the operator is symmetric,
// the linear momentum is kept to round-off, the block is pulled to between rest and the bar's
// speed, and the kinetic energy falls. With the end prescribed at its start velocity inside the
// bar's solve and its damping force handed to the host particles afterwards, the block overshoots
// the bar and the energy rises.
TEST(CoupledDamping, EmbeddedEndFollowsItsHostInsideTheSolve) {
  auto prepare = [](const dm::MeshData<3>& mesh, double density, double overdamping) {
    std::vector<double> X;
    for (const auto& x : mesh.x)
      for (int a = 0; a < 3; ++a) X.push_back(x(a));
    dm::Material mat;
    mat.model = dm::Model::Springs;
    mat.youngsModulus = 1e6;
    mat.density = density;
    mat.overdamping = overdamping;
    return std::make_pair(X, dm::prepareForceModel<3>(X, mesh.elements, mat));
  };
  const dm::MeshData<3> barMesh = dm::boxMesh<3>(Eigen::Vector3d(0.5, 0.05, 0.05), 0.05);
  dm::MeshData<3> hostMesh = dm::boxMesh<3>(Eigen::Vector3d(0.06, 0.06, 0.06), 0.12);
  for (auto& x : hostMesh.x) x += Eigen::Vector3d(-0.5, 0.001, 0.002);
  auto [barX, barFm] = prepare(barMesh, 1000, 5);
  auto [hostX, hostFm] = prepare(hostMesh, 100, 0);
  const int nb = static_cast<int>(barMesh.x.size()), nh = static_cast<int>(hostMesh.x.size());
  std::vector<double> barV(3 * nb, 0.0), barF(3 * nb, 0.0), hostV(3 * nh, 0.0), hostF(3 * nh, 0.0);
  std::vector<double> hostM = hostFm.mass;
  std::vector<dm::ParticleRole> barRole(nb, dm::ParticleRole::Free);
  std::vector<dm::EmbeddedWeight> weights;
  for (int i = 0; i < nb; ++i) {
    if (barMesh.x[i].x() > -0.49) {
      barV[3 * i] = 1.0;
      continue;
    }
    // The host element containing the particle, and its barycentric weights.
    bool found = false;
    for (int e = 0; e < hostMesh.elementCount() && !found; ++e) {
      const int* v = &hostMesh.elements[4 * e];
      Eigen::Matrix3d D;
      for (int a = 0; a < 3; ++a) D.col(a) = hostMesh.x[v[a + 1]] - hostMesh.x[v[0]];
      const Eigen::Vector3d l = D.lu().solve(barMesh.x[i] - hostMesh.x[v[0]]);
      const Eigen::Vector4d w(1 - l.sum(), l(0), l(1), l(2));
      if (w.minCoeff() < -1e-12) continue;
      found = true;
      barRole[i] = dm::ParticleRole::Embedded;
      for (int a = 0; a < 4; ++a) {
        weights.push_back({i, 1, v[a], w(a)});
        hostM[v[a]] += w(a) * barFm.mass[i];
      }
    }
    ASSERT_TRUE(found) << "particle " << i;
  }
  const std::vector<dm::MatD<3>> barR = dm::dampingRotations<3>(barFm, barX.data());
  const std::vector<dm::MatD<3>> hostR;
  auto bodies = [&](bool embedded) {
    dm::DampingBody<3> bar, host;
    bar.fm = &barFm;
    bar.rotations = &barR;
    bar.x = barX.data();
    bar.v = barV.data();
    bar.m = barFm.mass.data();
    bar.f = barF.data();
    bar.role = barRole;
    bar.rigid.assign(nb, -1);
    if (embedded) bar.embedded = weights;
    else
      for (auto& r : bar.role)
        if (r == dm::ParticleRole::Embedded) r = dm::ParticleRole::Prescribed;
    host.fm = &hostFm;
    host.rotations = &hostR;
    host.x = hostX.data();
    host.v = hostV.data();
    host.m = hostM.data();
    host.f = hostF.data();
    host.role.assign(nh, dm::ParticleRole::Free);
    host.rigid.assign(nh, -1);
    return std::vector<dm::DampingBody<3>>{bar, host};
  };
  const double h = 0.5 * 4e-3;
  // Symmetry of the projected operator with the embedded end.
  const dm::CoupledDampingSystem<3> sys(bodies(true), {}, {}, h);
  std::mt19937 rng(5);
  std::normal_distribution<double> g;
  double worstSymmetry = 0;
  for (int trial = 0; trial < 5; ++trial) {
    Eigen::VectorXd a(sys.size()), b(sys.size()), Aa, Ab;
    for (int i = 0; i < sys.size(); ++i) a(i) = g(rng), b(i) = g(rng);
    sys.applyProjected(a, Aa);
    sys.applyProjected(b, Ab);
    worstSymmetry = std::max(worstSymmetry, std::abs(b.dot(Aa) - a.dot(Ab)) / (Aa.norm() * b.norm() + Ab.norm() * a.norm()));
  }
  auto measure = [&](const std::vector<double>& ub, const std::vector<double>& uh, double& energy) {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    energy = 0;
    for (int i = 0; i < nb; ++i)
      if (barRole[i] == dm::ParticleRole::Free) {
        p += barFm.mass[i] * Eigen::Vector3d::Map(&ub[3 * i]);
        energy += 0.5 * barFm.mass[i] * Eigen::Vector3d::Map(&ub[3 * i]).squaredNorm();
      }
    for (int j = 0; j < nh; ++j) {
      p += hostM[j] * Eigen::Vector3d::Map(&uh[3 * j]);
      energy += 0.5 * hostM[j] * Eigen::Vector3d::Map(&uh[3 * j]).squaredNorm();
    }
    return p;
  };
  double hostMass = 0;
  for (double m : hostM) hostMass += m;
  double e0, eCoupled, ePrescribed;
  const Eigen::Vector3d p0 = measure(barV, hostV, e0);
  const dm::CoupledDampingResult<3> coupled = sys.solve();
  ASSERT_TRUE(coupled.report.converged);
  const Eigen::Vector3d p1 = measure(coupled.u[0], coupled.u[1], eCoupled);
  Eigen::Vector3d hostP = Eigen::Vector3d::Zero();
  for (int j = 0; j < nh; ++j) hostP += hostM[j] * Eigen::Vector3d::Map(&coupled.u[1][3 * j]);
  // The former way: the end prescribed in the bar's solve, its damping force handed over.
  const dm::CoupledDampingResult<3> prescribed = dm::solveCoupledDamping<3>({bodies(false)[0]}, {}, {}, h);
  std::vector<double> uh = hostV;
  for (const dm::EmbeddedWeight& w : weights)
    for (int a = 0; a < 3; ++a) uh[3 * w.hostParticle + a] += h * w.weight * prescribed.Du[0][3 * w.particle + a] / hostM[w.hostParticle];
  Eigen::Vector3d hostPPrescribed = Eigen::Vector3d::Zero();
  for (int j = 0; j < nh; ++j) hostPPrescribed += hostM[j] * Eigen::Vector3d::Map(&uh[3 * j]);
  measure(prescribed.u[0], uh, ePrescribed);
  std::printf("embedded end (host %.3f kg): symmetry %.1e, %d iterations, momentum %.1e relative; host v = %.4f m/s, "
              "energy %.4f -> %.4f J; prescribed: host v = %.4f m/s, energy -> %.4f J\n",
              hostMass, worstSymmetry, coupled.report.iterations, (p1 - p0).norm() / p0.norm(), hostP.x() / hostMass, e0,
              eCoupled, hostPPrescribed.x() / hostMass, ePrescribed);
  EXPECT_LT(worstSymmetry, 1e-14);
  EXPECT_LT((p1 - p0).norm() / p0.norm(), 1e-13);
  EXPECT_GT(hostP.x() / hostMass, 0.05);
  EXPECT_LE(hostP.x() / hostMass, 1.0);
  EXPECT_LT(eCoupled, e0);
  EXPECT_GT(hostPPrescribed.x() / hostMass, 1.0);  // the former way overshoots ...
  EXPECT_GT(ePrescribed, e0);                       // ... and gains energy
}
