#include "solvers/deformable/coupled_damping.h"

#include <Eigen/Dense>
#include <cmath>
#include <stdexcept>

#include "solvers/fluid/krylov.h"

namespace monolith::solvers::deformable {

namespace {

template <int d>
constexpr int kTwist = d + rm::kAngularDim<d>;

template <int d>
using Twist = DampingTwist<d>;

// g = (n, r x n): the constraint's row on the rigid twist (the body point's normal velocity g . xi).
template <int d>
Twist<d> jointRow(const VecD<d>& n, const VecD<d>& r) {
  Twist<d> g;
  g.template head<d>() = n;
  g.template tail<rm::kAngularDim<d>>() = rm::cross<d>(r, n);
  return g;
}

}  // namespace

template <int d>
CoupledDampingSystem<d>::CoupledDampingSystem(std::vector<DampingBody<d>> bodies, std::vector<DampingRigid<d>> rigids,
                                              std::vector<DampingHold<d>> holds, double h,
                                              std::vector<DampingRigidRow<d>> rows)
    : bodies_(std::move(bodies)), rigids_(std::move(rigids)), h_(h), rows_(std::move(rows)) {
  int n = 0;
  for (const DampingBody<d>& b : bodies_) {
    offset_.push_back(n);
    n += d * static_cast<int>(b.role.size());
  }
  rigidStart_ = n;
  size_ = n + kTwist<d> * static_cast<int>(rigids_.size());
  // A hold on a particle that is not free is dropped (its velocity is not an unknown), as is a
  // second hold on the same particle (one contact per particle).
  std::vector<std::vector<char>> taken(bodies_.size());
  for (std::size_t k = 0; k < bodies_.size(); ++k) taken[k].assign(bodies_[k].role.size(), 0);
  holdsOfRigid_.resize(rigids_.size());
  for (const DampingBody<d>& b : bodies_)
    for (const EmbeddedWeight& e : b.embedded)
      if (e.hostBody < 0 || e.hostBody >= static_cast<int>(bodies_.size()) || b.role[e.particle] != ParticleRole::Embedded ||
          bodies_[e.hostBody].role[e.hostParticle] == ParticleRole::Embedded)
        throw std::invalid_argument("CoupledDampingSystem: an embedded weight names no host body, a particle not "
                                    "embedded, or an embedded host particle");
  for (const DampingHold<d>& c : holds) {
    const DampingBody<d>& b = bodies_[c.body];
    if (b.role[c.particle] != ParticleRole::Free || taken[c.body][c.particle]) continue;
    taken[c.body][c.particle] = 1;
    const int k = static_cast<int>(holds_.size());
    holds_.push_back(c);
    if (c.rigid >= 0) holdsOfRigid_[c.rigid].push_back(k);
    else staticHolds_.push_back(k);
  }
  for (std::size_t c = 0; c < rigids_.size(); ++c) {
    const DampingRigid<d>& r = rigids_[c];
    inverseInertia_.push_back(r.inertia.inverse());
    Eigen::Matrix<double, kTwist<d>, kTwist<d>> K = Eigen::Matrix<double, kTwist<d>, kTwist<d>>::Zero();
    K.template topLeftCorner<d, d>() = r.mass * MatD<d>::Identity();
    K.template bottomRightCorner<rm::kAngularDim<d>, rm::kAngularDim<d>>() = r.inertia;
    for (int k : holdsOfRigid_[c]) {
      const DampingHold<d>& o = holds_[k];
      const Twist<d> g = jointRow<d>(o.normal, arm(o.body, o.particle, static_cast<int>(c)));
      K += bodies_[o.body].m[o.particle] * g * g.transpose();
    }
    Eigen::Matrix<double, kTwist<d>, kTwist<d>> Kinv = K.ldlt().solve(Eigen::Matrix<double, kTwist<d>, kTwist<d>>::Identity());
    centralInverse_.push_back(0.5 * (Kinv + Kinv.transpose()));  // exactly symmetric
  }
  if (rows_.empty()) return;
  // The rigid rows: S = G K^{-1} G^T, scaled to unit diagonal (rows of metres and radians
  // side by side), its pseudo-inverse on the scaled matrix (dependent rows: a zero eigenvalue),
  // S^- = D S~^+ D, symmetric and reflexive (S S^- S = S, S^- S S^- = S^-).
  const int twists = kTwist<d> * static_cast<int>(rigids_.size());
  const int count = static_cast<int>(rows_.size());
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(count, twists), KinvGt = Eigen::MatrixXd::Zero(twists, count);
  for (int k = 0; k < count; ++k) {
    const DampingRigidRow<d>& r = rows_[k];
    if (r.a < 0 || r.a >= static_cast<int>(rigids_.size()) || r.b >= static_cast<int>(rigids_.size()) || r.a == r.b)
      throw std::invalid_argument("CoupledDampingSystem: a rigid row names no rigid unknown, or one twice");
    G.row(k).template segment<kTwist<d>>(kTwist<d> * r.a) = r.ga.transpose();
    KinvGt.col(k).template segment<kTwist<d>>(kTwist<d> * r.a) = centralInverse_[r.a] * r.ga;
    if (r.b >= 0) {
      G.row(k).template segment<kTwist<d>>(kTwist<d> * r.b) = r.gb.transpose();
      KinvGt.col(k).template segment<kTwist<d>>(kTwist<d> * r.b) = centralInverse_[r.b] * r.gb;
    }
  }
  Eigen::MatrixXd S = G * KinvGt;
  S = 0.5 * (S + S.transpose());
  Eigen::VectorXd scale(count);
  for (int k = 0; k < count; ++k) scale(k) = S(k, k) > 0 ? 1 / std::sqrt(S(k, k)) : 0.0;
  const Eigen::MatrixXd scaled = scale.asDiagonal() * S * scale.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(scaled);
  const double largest = eig.eigenvalues().cwiseAbs().maxCoeff();
  Eigen::VectorXd inverse = Eigen::VectorXd::Zero(count);
  for (int k = 0; k < count; ++k)
    if (eig.eigenvalues()(k) > 1e-10 * largest) inverse(k) = 1 / eig.eigenvalues()(k);
  Eigen::MatrixXd Sminus = eig.eigenvectors() * inverse.asDiagonal() * eig.eigenvectors().transpose();
  Sminus = scale.asDiagonal() * Sminus * scale.asDiagonal();
  Sminus = 0.5 * (Sminus + Sminus.transpose());
  rowParticular_ = KinvGt * Sminus;
  rowCorrection_ = rowParticular_ * G;
}

template <int d>
VecD<d> CoupledDampingSystem<d>::arm(int body, int particle, int c) const {
  return VecD<d>(Eigen::Map<const VecD<d>>(bodies_[body].x + d * particle)) - rigids_[c].x;
}

template <int d>
void CoupledDampingSystem<d>::expand(const Eigen::VectorXd& in, std::vector<std::vector<double>>& w) const {
  w.resize(bodies_.size());
  for (std::size_t k = 0; k < bodies_.size(); ++k) {
    const DampingBody<d>& b = bodies_[k];
    const int count = static_cast<int>(b.role.size());
    w[k].assign(d * count, 0.0);
    const int o = offset_[k];
    for (int i = 0; i < count; ++i) {
      if (b.role[i] == ParticleRole::Bound) {
        const int c = b.rigid[i];
        const int ro = rigidOffset(c);
        const VecD<d> v = in.template segment<d>(ro);
        const rm::AngVec<d> omega = in.template segment<rm::kAngularDim<d>>(ro + d);
        const VecD<d> vi = v + rm::angularCross<d>(omega, arm(static_cast<int>(k), i, c));
        for (int a = 0; a < d; ++a) w[k][d * i + a] = vi(a);
      } else if (b.role[i] != ParticleRole::Embedded) {
        for (int a = 0; a < d; ++a) w[k][d * i + a] = in(o + d * i + a);
      }
    }
  }
  // Embedded particles from their hosts' expanded velocities (hosts are never embedded).
  for (std::size_t k = 0; k < bodies_.size(); ++k)
    for (const EmbeddedWeight& e : bodies_[k].embedded)
      for (int a = 0; a < d; ++a) w[k][d * e.particle + a] += e.weight * w[e.hostBody][d * e.hostParticle + a];
}

template <int d>
void CoupledDampingSystem<d>::dampingForces(const std::vector<std::vector<double>>& w,
                                            std::vector<std::vector<double>>& Dw) const {
  Dw.resize(bodies_.size());
  for (std::size_t k = 0; k < bodies_.size(); ++k) {
    const DampingBody<d>& b = bodies_[k];
    Dw[k].assign(w[k].size(), 0.0);
    if (b.fm->dampingRows() > 0) addDampingForces<d>(*b.fm, *b.rotations, b.x, w[k].data(), Dw[k].data());
  }
  // The force on an embedded particle acts on its host particles with its weights (J^T).
  for (std::size_t k = 0; k < bodies_.size(); ++k) {
    const DampingBody<d>& b = bodies_[k];
    for (const EmbeddedWeight& e : b.embedded)
      for (int a = 0; a < d; ++a) Dw[e.hostBody][d * e.hostParticle + a] += e.weight * Dw[k][d * e.particle + a];
    for (const EmbeddedWeight& e : b.embedded)
      for (int a = 0; a < d; ++a) Dw[k][d * e.particle + a] = 0;
  }
}

template <int d>
void CoupledDampingSystem<d>::apply(const Eigen::VectorXd& in, Eigen::VectorXd& out) const {
  std::vector<std::vector<double>>& w = expanded_;
  std::vector<std::vector<double>>& Dw = forces_;
  expand(in, w);
  dampingForces(w, Dw);
  out.setZero(size_);
  for (std::size_t k = 0; k < bodies_.size(); ++k) {
    const DampingBody<d>& b = bodies_[k];
    const int o = offset_[k];
    for (int i = 0; i < static_cast<int>(b.role.size()); ++i) {
      if (b.role[i] == ParticleRole::Bound) {
        // J_i^T: the damping force on a bound particle acts on its body.
        const int c = b.rigid[i];
        const int ro = rigidOffset(c);
        const VecD<d> f = Eigen::Map<const VecD<d>>(&Dw[k][d * i]);
        out.template segment<d>(ro) -= h_ * f;
        out.template segment<rm::kAngularDim<d>>(ro + d) -= h_ * rm::cross<d>(arm(static_cast<int>(k), i, c), f);
      } else if (b.role[i] != ParticleRole::Embedded) {
        for (int a = 0; a < d; ++a) out(o + d * i + a) = b.m[i] * in(o + d * i + a) - h_ * Dw[k][d * i + a];
      }
    }
  }
  for (std::size_t c = 0; c < rigids_.size(); ++c) {
    const int ro = rigidOffset(static_cast<int>(c));
    out.template segment<d>(ro) += rigids_[c].mass * in.template segment<d>(ro);
    out.template segment<rm::kAngularDim<d>>(ro + d) += rigids_[c].inertia * in.template segment<rm::kAngularDim<d>>(ro + d);
  }
}

template <int d>
void CoupledDampingSystem<d>::applyMass(const Eigen::VectorXd& in, Eigen::VectorXd& out) const {
  out.setZero(size_);
  for (std::size_t k = 0; k < bodies_.size(); ++k)
    for (int i = 0; i < static_cast<int>(bodies_[k].role.size()); ++i)
      if (bodies_[k].role[i] != ParticleRole::Embedded)  // its mass is its hosts'
        for (int a = 0; a < d; ++a) out(offset_[k] + d * i + a) = bodies_[k].m[i] * in(offset_[k] + d * i + a);
  for (std::size_t c = 0; c < rigids_.size(); ++c) {
    const int ro = rigidOffset(static_cast<int>(c));
    out.template segment<d>(ro) = rigids_[c].mass * in.template segment<d>(ro);
    out.template segment<rm::kAngularDim<d>>(ro + d) = rigids_[c].inertia * in.template segment<rm::kAngularDim<d>>(ro + d);
  }
}

template <int d>
void CoupledDampingSystem<d>::applyInverseMass(const Eigen::VectorXd& in, Eigen::VectorXd& out) const {
  out.setZero(size_);
  for (std::size_t k = 0; k < bodies_.size(); ++k)
    for (int i = 0; i < static_cast<int>(bodies_[k].role.size()); ++i)
      if (bodies_[k].role[i] != ParticleRole::Embedded)
        for (int a = 0; a < d; ++a) out(offset_[k] + d * i + a) = in(offset_[k] + d * i + a) / bodies_[k].m[i];
  for (std::size_t c = 0; c < rigids_.size(); ++c) {
    const int ro = rigidOffset(static_cast<int>(c));
    out.template segment<d>(ro) = in.template segment<d>(ro) / rigids_[c].mass;
    out.template segment<rm::kAngularDim<d>>(ro + d) = inverseInertia_[c] * in.template segment<rm::kAngularDim<d>>(ro + d);
  }
}

template <int d>
void CoupledDampingSystem<d>::centralSolution(int c, const Eigen::VectorXd& y, bool forceSide, Twist<d>& xi,
                                              Twist<d>& dxi) const {
  const std::vector<int>& held = holdsOfRigid_[c];
  const int ro = rigidOffset(c);
  // Velocities: y itself; forces: y = M^{-1} r on the blocks involved, and P^T r = M P M^{-1} r.
  xi = y.template segment<kTwist<d>>(ro);
  if (forceSide) {
    xi.template head<d>() /= rigids_[c].mass;
    xi.template tail<rm::kAngularDim<d>>() = inverseInertia_[c] * xi.template tail<rm::kAngularDim<d>>();
  }
  Twist<d> rhs = Twist<d>::Zero();
  rows6_.resize(held.size());
  normalSpeeds_.resize(held.size());
  for (std::size_t k = 0; k < held.size(); ++k) {
    const DampingHold<d>& o = holds_[held[k]];
    const double m = bodies_[o.body].m[o.particle];
    rows6_[k] = jointRow<d>(o.normal, arm(o.body, o.particle, c));
    const VecD<d> uo = y.template segment<d>(offset_[o.body] + d * o.particle);
    normalSpeeds_[k] = o.normal.dot(uo) / (forceSide ? m : 1.0);
    rhs += m * (normalSpeeds_[k] - rows6_[k].dot(xi)) * rows6_[k];
  }
  dxi = centralInverse_[c] * rhs;
}

template <int d>
void CoupledDampingSystem<d>::projectRigidHolds(int c, Eigen::VectorXd& y, bool forceSide,
                                                const Twist<d>* correction) const {
  const std::vector<int>& held = holdsOfRigid_[c];
  if (held.empty() && !correction) return;
  const int ro = rigidOffset(c);
  Twist<d> xi, dxi;
  centralSolution(c, y, forceSide, xi, dxi);  // fills rows6_ and normalSpeeds_ for c
  if (correction) dxi += *correction;
  for (std::size_t k = 0; k < held.size(); ++k) {
    const DampingHold<d>& o = holds_[held[k]];
    const double m = bodies_[o.body].m[o.particle];
    const double lambda = m * (rows6_[k].dot(xi + dxi) - normalSpeeds_[k]);
    // Velocities: u_o += lambda n / m; forces: r_o += m (lambda n / m).
    y.template segment<d>(offset_[o.body] + d * o.particle) += (forceSide ? lambda : lambda / m) * o.normal;
  }
  if (forceSide) {
    y.template segment<d>(ro) += rigids_[c].mass * dxi.template head<d>();
    y.template segment<rm::kAngularDim<d>>(ro + d) += rigids_[c].inertia * dxi.template tail<rm::kAngularDim<d>>();
  } else {
    y.template segment<kTwist<d>>(ro) += dxi;
  }
}

template <int d>
void CoupledDampingSystem<d>::project(Eigen::VectorXd& v, bool force) const {
  for (std::size_t k = 0; k < bodies_.size(); ++k)
    for (int i = 0; i < static_cast<int>(bodies_[k].role.size()); ++i)
      if (bodies_[k].role[i] != ParticleRole::Free) v.template segment<d>(offset_[k] + d * i).setZero();
  for (int k : staticHolds_) {
    const DampingHold<d>& c = holds_[k];
    auto vi = v.template segment<d>(offset_[c.body] + d * c.particle);
    vi -= vi.dot(c.normal) * c.normal;
  }
  const int rigidCount = static_cast<int>(rigids_.size());
  if (rows_.empty()) {
    for (int c = 0; c < rigidCount; ++c) projectRigidHolds(c, v, force, nullptr);
    return;
  }
  // With rigid rows: every body's central solution xi*, the rows' correction of all of them at
  // once, then each body and its held particles moved to the corrected twist.
  stars_.resize(kTwist<d> * rigidCount);
  for (int c = 0; c < rigidCount; ++c) {
    Twist<d> xi, dxi;
    centralSolution(c, v, force, xi, dxi);
    stars_.template segment<kTwist<d>>(kTwist<d> * c) = xi + dxi;
  }
  corrections_.noalias() = -rowCorrection_ * stars_;
  for (int c = 0; c < rigidCount; ++c) {
    const Twist<d> correction = corrections_.template segment<kTwist<d>>(kTwist<d> * c);
    projectRigidHolds(c, v, force, &correction);
  }
}

template <int d>
void CoupledDampingSystem<d>::applyProjected(const Eigen::VectorXd& in, Eigen::VectorXd& out) const {
  scratch_ = in;  // no allocation once sized
  projectVelocity(scratch_);
  apply(scratch_, out);
  projectForce(out);
}

template <int d>
std::vector<double> CoupledDampingSystem<d>::constraintResiduals(const Eigen::VectorXd& y) const {
  std::vector<double> out;
  for (const DampingHold<d>& c : holds_) {
    double rel = c.normal.dot(VecD<d>(y.template segment<d>(offset_[c.body] + d * c.particle)));
    if (c.rigid >= 0)
      rel -= jointRow<d>(c.normal, arm(c.body, c.particle, c.rigid)).dot(y.template segment<kTwist<d>>(rigidOffset(c.rigid)));
    out.push_back(rel - c.target);
  }
  for (const DampingRigidRow<d>& r : rows_) {
    double rel = r.ga.dot(y.template segment<kTwist<d>>(rigidOffset(r.a)));
    if (r.b >= 0) rel += r.gb.dot(y.template segment<kTwist<d>>(rigidOffset(r.b)));
    out.push_back(rel - r.target);
  }
  return out;
}

template <int d>
CoupledDampingResult<d> CoupledDampingSystem<d>::solve() const {
  CoupledDampingResult<d> result;
  const int n = size_;
  // y0: the velocities at the start of the stage; yp: the prescribed values and held targets.
  Eigen::VectorXd y0 = Eigen::VectorXd::Zero(n), yp = Eigen::VectorXd::Zero(n), hf = Eigen::VectorXd::Zero(n);
  bool damped = false;
  for (std::size_t k = 0; k < bodies_.size(); ++k) {
    const DampingBody<d>& b = bodies_[k];
    damped = damped || b.fm->dampingRows() > 0;
    for (int i = 0; i < static_cast<int>(b.role.size()); ++i)
      for (int a = 0; a < d; ++a) {
        const int j = offset_[k] + d * i + a;
        if (b.role[i] == ParticleRole::Bound || b.role[i] == ParticleRole::Embedded) continue;
        y0(j) = b.v[d * i + a];
        if (b.role[i] == ParticleRole::Prescribed) yp(j) = b.v[d * i + a];
        else hf(j) = h_ * b.f[d * i + a];
      }
  }
  for (std::size_t c = 0; c < rigids_.size(); ++c) {
    const int ro = rigidOffset(static_cast<int>(c));
    y0.template segment<d>(ro) = rigids_[c].v;
    y0.template segment<rm::kAngularDim<d>>(ro + d) = rigids_[c].omega;
  }
  // A particular solution: the rigid rows' targets met by the K-smallest twists, and each held
  // particle's normal velocity at its target relative to its body's point.
  if (!rows_.empty()) {
    Eigen::VectorXd t(rows_.size());
    for (std::size_t k = 0; k < rows_.size(); ++k) t(k) = rows_[k].target;
    yp.segment(rigidStart_, kTwist<d> * rigids_.size()) = rowParticular_ * t;
  }
  for (const DampingHold<d>& c : holds_) {
    double target = c.target;
    if (c.rigid >= 0)
      target += jointRow<d>(c.normal, arm(c.body, c.particle, c.rigid)).dot(yp.template segment<kTwist<d>>(rigidOffset(c.rigid)));
    yp.template segment<d>(offset_[c.body] + d * c.particle) = target * c.normal;
  }

  Eigen::VectorXd y = y0;
  if (damped) {
    Eigen::VectorXd b(n), Ayp(n), My0(n);
    applyMass(y0, My0);
    apply(yp, Ayp);
    b = My0 + hf - Ayp;
    projectForce(b);
    Eigen::VectorXd x = y0 - yp;
    projectVelocity(x);
    solvers::CgSettings settings;
    settings.relativeTolerance = 1e-10;
    settings.maxIterations = 2000;
    const solvers::LinearOperator op = [&](const Eigen::VectorXd& in, Eigen::VectorXd& out) { applyProjected(in, out); };
    // P M^{-1} P^T: symmetric, and it keeps the search directions in the range of P.
    Eigen::VectorXd rp(n);
    const solvers::LinearOperator precondition = [&](const Eigen::VectorXd& r, Eigen::VectorXd& z) {
      rp = r;
      projectForce(rp);
      applyInverseMass(rp, z);
      projectVelocity(z);
    };
    const solvers::CgReport r = solvers::conjugateGradient(op, precondition, nullptr, b, x, settings);
    result.report.iterations = r.iterations;
    result.report.relativeResidual = r.relativeResidual();
    result.report.converged = r.converged;
    y = x + yp;
  }
  std::vector<std::vector<double>> w;
  expand(y, w);
  dampingForces(w, result.Du);
  result.u.resize(bodies_.size());
  result.force.assign(rigids_.size(), VecD<d>::Zero());
  result.torque.assign(rigids_.size(), rm::AngVec<d>::Zero());
  for (std::size_t k = 0; k < bodies_.size(); ++k) {
    const DampingBody<d>& b = bodies_[k];
    std::vector<double>& u = result.u[k];
    u.assign(b.v, b.v + d * b.role.size());
    for (int i = 0; i < static_cast<int>(b.role.size()); ++i) {
      const VecD<d> Dw = Eigen::Map<const VecD<d>>(&result.Du[k][d * i]);
      if (b.role[i] == ParticleRole::Bound) {
        const int c = b.rigid[i];
        result.force[c] += Dw;
        result.torque[c] += rm::cross<d>(arm(static_cast<int>(k), i, c), Dw);
      } else if (b.role[i] == ParticleRole::Free) {
        // Unprojected (Sec. 4.7.2, step 3): held particles get back their constraint's share.
        for (int a = 0; a < d; ++a) u[d * i + a] = b.v[d * i + a] + h_ * (b.f[d * i + a] + Dw(a)) / b.m[i];
      }
    }
  }
  return result;
}

template <int d>
CoupledDampingResult<d> solveCoupledDamping(std::vector<DampingBody<d>> bodies, std::vector<DampingRigid<d>> rigids,
                                            std::vector<DampingHold<d>> holds, double h,
                                            std::vector<DampingRigidRow<d>> rows) {
  return CoupledDampingSystem<d>(std::move(bodies), std::move(rigids), std::move(holds), h, std::move(rows)).solve();
}

template class CoupledDampingSystem<2>;
template class CoupledDampingSystem<3>;
template CoupledDampingResult<2> solveCoupledDamping<2>(std::vector<DampingBody<2>>, std::vector<DampingRigid<2>>,
                                                        std::vector<DampingHold<2>>, double,
                                                        std::vector<DampingRigidRow<2>>);
template CoupledDampingResult<3> solveCoupledDamping<3>(std::vector<DampingBody<3>>, std::vector<DampingRigid<3>>,
                                                        std::vector<DampingHold<3>>, double,
                                                        std::vector<DampingRigidRow<3>>);

}  // namespace monolith::solvers::deformable
