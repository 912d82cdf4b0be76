// The monolithic fluid-structure system (5.30) applied matrix-free (see fsi_system.h).
#include "solvers/fluid/fsi_system.h"

#include "solvers/fluid/parallel.h"
#include "solvers/fluid/spd_systems.h"

#include <stdexcept>

namespace monolith::solvers {

std::string toString(FsiPreconditionerKind kind) {
  switch (kind) {
    case FsiPreconditionerKind::None: return "none";
    case FsiPreconditionerKind::BlockJacobi: return "block_jacobi";
    case FsiPreconditionerKind::BlockExact: return "block_exact";
    case FsiPreconditionerKind::Schur: return "schur";
  }
  return "?";
}

template <int d>
FsiOperator<d>::FsiOperator(const FluidOperators<d>& ops, const StructureCoupling& coupling)
    : ops_(&ops),
      coupling_(&coupling),
      np_(ops.pressureCount()),
      nr_(ops.viscousCount()),
      nc_(coupling.constraintCount()),
      nd_(coupling.dampingRows),
      JT_(coupling.J.transpose()),
      faces_(ops.velocityCount()),
      structure_(coupling.structureCount()) {
  if (coupling.J.rows() != nc_ || coupling.J.cols() != coupling.structureCount() ||
      coupling.massInverse.rows() != coupling.structureCount() || coupling.massInverse.cols() != coupling.structureCount())
    throw std::invalid_argument("FsiOperator: J must be constraints x structure dofs and M^-1 square");
  if (nd_ > 0 && (!coupling.damping || !coupling.dampingTranspose))
    throw std::invalid_argument("FsiOperator: damping rows without the damping operator C");
  for (int v : coupling.constrainedVelocities)
    if (v < 0 || v >= ops.velocityCount() || ops.openFraction[v] != 1.0)
      throw std::invalid_argument("FsiOperator: a coupling face must be a whole (uncut) velocity unknown");
}

template <int d>
void FsiOperator<d>::velocityChange(const Eigen::VectorXd& z, Eigen::VectorXd& fluid, Eigen::VectorXd& structure) const {
  const FluidOperators<d>& ops = *ops_;
  const auto p = z.head(np_);
  const auto lambda = z.segment(np_ + nr_, nc_);
  fluid.resize(ops.velocityCount());
  applyGradient(ops, p, fluid);
  if (nr_ > 0) {
    Eigen::VectorXd visc(ops.velocityCount());
    applyViscousGradientTranspose(ops, z.segment(np_, nr_), visc);
    fluid += visc;
  }
  const double* binv = ops.faceBetaInv.data();
  parallel::forRows(ops.velocityCount(), [&](int v) { fluid[v] *= binv[v]; });
  for (int k = 0; k < nc_; ++k) fluid[coupling_->constrainedVelocities[k]] -= ops.betaInv * lambda[k];
  Eigen::VectorXd impulse = JT_ * lambda;
  if (nd_ > 0) {
    Eigen::VectorXd ct;
    coupling_->dampingTranspose(z.tail(nd_), ct);
    impulse += ct;
  }
  structure = coupling_->massInverse * impulse;
}

template <int d>
void FsiOperator<d>::apply(const Eigen::VectorXd& z, Eigen::VectorXd& out) const {
  const FluidOperators<d>& ops = *ops_;
  velocityChange(z, faces_, structure_);
  out.resize(size());
  applyGradientTranspose(ops, faces_, out.head(np_));
  if (nr_ > 0) {
    applyViscousGradient(ops, faces_, out.segment(np_, nr_));
    out.segment(np_, nr_) += z.segment(np_, nr_);
  }
  if (nc_ > 0) {
    out.segment(np_ + nr_, nc_) = coupling_->J * structure_;
    for (int k = 0; k < nc_; ++k) out[np_ + nr_ + k] -= faces_[coupling_->constrainedVelocities[k]];
  }
  if (nd_ > 0) {  // C (B^-1 K^T z)_structure + v_hat
    Eigen::VectorXd y;
    coupling_->damping(structure_, y);
    out.tail(nd_) = y + z.tail(nd_);
  }
}

template <int d>
Eigen::VectorXd FsiOperator<d>::rightHandSide(const Eigen::VectorXd& uStar, const Eigen::VectorXd& vStar) const {
  const FluidOperators<d>& ops = *ops_;
  Eigen::VectorXd rhs(size());
  applyGradientTranspose(ops, uStar, rhs.head(np_));
  rhs.head(np_) -= ops.prescribedDivergence;
  if (nr_ > 0) {
    applyViscousGradient(ops, uStar, rhs.segment(np_, nr_));
    rhs.segment(np_, nr_) += ops.viscousKnown;
  }
  if (nc_ > 0) {
    rhs.segment(np_ + nr_, nc_) = coupling_->J * vStar;
    for (int k = 0; k < nc_; ++k) rhs[np_ + nr_ + k] -= uStar[coupling_->constrainedVelocities[k]];
  }
  if (nd_ > 0) {
    Eigen::VectorXd y;
    coupling_->damping(vStar, y);
    rhs.tail(nd_) = y;
  }
  return rhs;
}

template <int d>
Eigen::VectorXd FsiOperator<d>::constraintDiagonal() const {
  const SparseMatrixR JM = coupling_->J * coupling_->massInverse;
  Eigen::VectorXd diag = Eigen::VectorXd::Constant(nc_, ops_->betaInv);
  for (int k = 0; k < nc_; ++k)
    for (SparseMatrixR::InnerIterator it(JM, k); it; ++it) diag[k] += it.value() * coupling_->J.coeff(k, it.col());
  return diag;
}

template <int d>
LinearOperator FsiOperator<d>::asOperator() const {
  const FsiOperator* self = this;
  return [self](const Eigen::VectorXd& in, Eigen::VectorXd& out) { self->apply(in, out); };
}

template <int d>
FsiPreconditioner<d>::FsiPreconditioner(const FsiOperator<d>& system, const FluidOperators<d>& ops,
                                        const StructureCoupling& coupling, const CoupledPreconditioner<d>* fluid,
                                        FsiPreconditionerKind kind, PoissonPreconditionerKind pressureKind)
    : kind_(kind), ops_(&ops), coupling_(&coupling), fluid_(fluid), nf_(ops.pressureCount() + ops.viscousCount()),
      nc_(coupling.constraintCount()), b_(ops.betaInv) {
  if (kind == FsiPreconditionerKind::None) return;
  if (kind == FsiPreconditionerKind::BlockJacobi) {
    if (!fluid) throw std::invalid_argument("FsiPreconditioner: the block variants need the fluid's preconditioner");
    constraintInverse_ = system.constraintDiagonal().cwiseInverse();
    return;
  }
  if (kind == FsiPreconditionerKind::BlockExact && !fluid)
    throw std::invalid_argument("FsiPreconditioner: the block variants need the fluid's preconditioner");
  J_ = coupling.J;
  JT_ = coupling.J.transpose();
  Eigen::SparseMatrix<double> S = Eigen::SparseMatrix<double>(coupling.mass) * b_;
  S += Eigen::SparseMatrix<double>(JT_ * J_);
  schur_.compute(S);
  if (schur_.info() != Eigen::Success) throw std::runtime_error("FsiPreconditioner: M + b^-1 J^T J is not SPD");
  if (kind == FsiPreconditionerKind::Schur) {
    // The same fluid with every coupling face closed (prescribed, at rest): the same pressure
    // unknowns, numbered alike (numberFluidDofs numbers the fluid cells in index order).
    FluidDomain<d> closed = ops.domain;
    for (std::size_t f = 0; f < closed.structureFace.size(); ++f)
      if (closed.structureFace[f]) {
        closed.faces[f] = FaceKind::Prescribed;
        closed.faceVelocity[f] = 0;
      }
    closed.structureFace.clear();
    FluidParameters params = ops.params;
    params.viscosity = 0;  // only its pressure block is used
    closed_ = std::make_unique<FluidOperators<d>>(buildFluidOperators(closed, params));
    if (closed_->pressureCount() != ops.pressureCount())
      throw std::logic_error("FsiPreconditioner: the closed domain numbers its pressures differently");
    closedPoisson_ = std::make_unique<PoissonPreconditioner<d>>(*closed_, pressureKind);
    // The viscous block of the Schur complement: a row's end on a coupling face moves with the
    // structure (up to its rigid modes), so it adds no b c^2 to the row's diagonal (Jacobi on the
    // closed domain's viscous block; IC(0) of it was measured to save one iteration in 45).
    if (ops.viscousCount() > 0) {
      std::vector<std::uint8_t> coupled(ops.velocityCount(), 0);
      for (int v : coupling.constrainedVelocities) coupled[v] = 1;
      viscousInverse_.resize(ops.viscousCount());
      for (int r = 0; r < ops.viscousCount(); ++r) {
        const ViscousRow& row = ops.viscousRows[r];
        double diag = 1;
        if (row.u0 >= 0 && !coupled[row.u0]) diag += ops.faceBetaInv[row.u0] * row.c0 * row.c0;
        if (row.u1 >= 0 && !coupled[row.u1]) diag += ops.faceBetaInv[row.u1] * row.c1 * row.c1;
        viscousInverse_[r] = 1.0 / diag;
      }
    }
  }
}

template <int d>
FsiPreconditioner<d>::~FsiPreconditioner() = default;

template <int d>
void FsiPreconditioner<d>::applyConstraintInverse(const Eigen::VectorXd& rc, Eigen::VectorXd& z) const {
  // (b I + J M^-1 J^T)^-1 r = (r - J (b M + J^T J)^-1 J^T r) / b
  const Eigen::VectorXd y = schur_.solve(Eigen::VectorXd(JT_ * rc));
  z = (rc - J_ * y) / b_;
}

template <int d>
void FsiPreconditioner<d>::apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const {
  z.resize(r.size());
  if (kind_ == FsiPreconditionerKind::None) {
    z = r;
    return;
  }
  const int nd = static_cast<int>(r.size()) - nf_ - nc_;  // damping rows: identity
  if (nd > 0) z.tail(nd) = r.tail(nd);
  if (kind_ == FsiPreconditionerKind::Schur) {
    const FluidOperators<d>& ops = *ops_;
    const int np = ops.pressureCount(), nr = ops.viscousCount();
    const auto& W = coupling_->constrainedVelocities;
    Eigen::VectorXd y, faces = Eigen::VectorXd::Zero(ops.velocityCount());
    // r_F - A_Fl C^-1 r_l, with A_Fl y = K_F q, q = -beta^-1 W^T y.
    applyConstraintInverse(r.segment(nf_, nc_), y);
    for (int k = 0; k < nc_; ++k) faces[W[k]] = -b_ * y[k];
    rf_ = r.head(nf_);
    Eigen::VectorXd kq(nf_);
    applyGradientTranspose(ops, faces, kq.head(np));
    if (nr > 0) applyViscousGradient(ops, faces, kq.tail(nr));
    rf_ -= kq;
    // z_F = S~^-1 (...)
    Eigen::VectorXd zp(np), rp = rf_.head(np);
    closedPoisson_->apply(rp, zp);
    z.head(np) = zp;
    if (nr > 0) z.segment(np, nr) = rf_.tail(nr).cwiseProduct(viscousInverse_);
    // z_l = C^-1 (r_l - A_lF z_F), A_lF z_F = -b W (G z_p + G_mu^T z_u).
    applyGradient(ops, z.head(np), faces);
    if (nr > 0) {
      Eigen::VectorXd visc(ops.velocityCount());
      applyViscousGradientTranspose(ops, z.segment(np, nr), visc);
      faces += visc;
    }
    Eigen::VectorXd rl = r.segment(nf_, nc_);
    for (int k = 0; k < nc_; ++k) rl[k] += b_ * faces[W[k]];
    applyConstraintInverse(rl, y);
    z.segment(nf_, nc_) = y;
    return;
  }
  rf_ = r.head(nf_);
  zf_.resize(nf_);
  fluid_->apply(rf_, zf_);
  z.head(nf_) = zf_;
  if (nc_ == 0) return;
  const Eigen::VectorXd rc = r.segment(nf_, nc_);
  if (kind_ == FsiPreconditionerKind::BlockJacobi) {
    z.segment(nf_, nc_) = rc.cwiseProduct(constraintInverse_);
    return;
  }
  Eigen::VectorXd y;
  applyConstraintInverse(rc, y);
  z.segment(nf_, nc_) = y;
}

template <int d>
LinearOperator FsiPreconditioner<d>::asOperator() const {
  const FsiPreconditioner* self = this;
  return [self](const Eigen::VectorXd& in, Eigen::VectorXd& out) { self->apply(in, out); };
}

namespace {
template <int d>
double kineticEnergy(const FluidOperators<d>& ops, const StructureCoupling& coupling, const Eigen::VectorXd& u,
                     const Eigen::VectorXd& v) {
  const double fluid =
      0.5 * parallel::sum(ops.velocityCount(), [&](int i) { return u[i] * u[i] / ops.faceBetaInv[i]; });
  return fluid + (v.size() > 0 ? 0.5 * v.dot(coupling.mass * v) : 0.0);
}
}  // namespace

template <int d>
FsiReport fsiProjection(const FluidOperators<d>& ops, StructureCoupling& coupling, Eigen::VectorXd& faceVelocities,
                        const CgSettings& settings, const CoupledPreconditioner<d>* fluidPreconditioner,
                        FsiPreconditionerKind kind, PoissonPreconditionerKind pressureKind) {
  FsiOperator<d> system(ops, coupling);
  FsiPreconditioner<d> pre(system, ops, coupling, fluidPreconditioner, kind, pressureKind);
  const Eigen::VectorXd uStar = freeVelocities(ops, faceVelocities);
  const Eigen::VectorXd vStar = coupling.velocity;
  FsiReport report;
  report.kineticEnergyBefore = kineticEnergy(ops, coupling, uStar, vStar);
  const Eigen::VectorXd rhs = system.rightHandSide(uStar, vStar);
  Eigen::VectorXd z = Eigen::VectorXd::Zero(system.size());
  report.solve = conjugateGradient(system.asOperator(), pre.asOperator(), closedRegionProjector(ops.dofs, 0), rhs, z,
                                   settings);
  Eigen::VectorXd du, dv;
  system.velocityChange(z, du, dv);
  const Eigen::VectorXd u = uStar - du;
  coupling.velocity = vStar - dv;
  writeVelocities(ops, u, faceVelocities);
  report.kineticEnergyAfter = kineticEnergy(ops, coupling, u, coupling.velocity);
  const int np = ops.pressureCount(), nc = coupling.constraintCount();
  report.lambda = z.segment(np + ops.viscousCount(), nc);
  if (coupling.dampingRows > 0) report.dampingWork = z.tail(coupling.dampingRows).squaredNorm();
  report.structureImpulse = coupling.J.transpose() * report.lambda;
  report.pressure = Eigen::VectorXd::Zero(ops.domain.layout.cellCount());
  for (int i = 0; i < np; ++i) report.pressure[ops.dofs.pressureToCell[i]] = z[i] / ops.params.dt;
  return report;
}

template <int d>
Eigen::MatrixXd assembleFsiDense(const FluidOperators<d>& ops, const StructureCoupling& coupling) {
  FsiOperator<d> system(ops, coupling);
  const int n = system.size();
  Eigen::MatrixXd A(n, n);
  Eigen::VectorXd e = Eigen::VectorXd::Zero(n), col(n);
  for (int j = 0; j < n; ++j) {
    e[j] = 1;
    system.apply(e, col);
    A.col(j) = col;
    e[j] = 0;
  }
  return A;
}

template class FsiOperator<2>;
template class FsiOperator<3>;
template class FsiPreconditioner<2>;
template class FsiPreconditioner<3>;
template FsiReport fsiProjection<2>(const FluidOperators<2>&, StructureCoupling&, Eigen::VectorXd&, const CgSettings&,
                                    const CoupledPreconditioner<2>*, FsiPreconditionerKind, PoissonPreconditionerKind);
template FsiReport fsiProjection<3>(const FluidOperators<3>&, StructureCoupling&, Eigen::VectorXd&, const CgSettings&,
                                    const CoupledPreconditioner<3>*, FsiPreconditionerKind, PoissonPreconditionerKind);
template Eigen::MatrixXd assembleFsiDense<2>(const FluidOperators<2>&, const StructureCoupling&);
template Eigen::MatrixXd assembleFsiDense<3>(const FluidOperators<3>&, const StructureCoupling&);

}  // namespace monolith::solvers
