// Matrix-free SPD systems (see spd_systems.h).
#include "solvers/fluid/spd_systems.h"

#include "solvers/fluid/parallel.h"

namespace monolith::solvers {

template <int d>
PoissonOperator<d>::PoissonOperator(const FluidOperators<d>& ops)
    : ops_(&ops), neighbours_(ops.pressureCount()), freeFaces_(ops.pressureCount(), 0) {
  for (int c = 0; c < ops.pressureCount(); ++c)
    for (int e = 0; e < 2 * d; ++e) {
      const int v = ops.divergenceFaces[c][e];
      neighbours_[c][e] = v >= 0 ? ops.gradientCells[v][e % 2 == 0 ? 0 : 1] : -1;
      freeFaces_[c] += v >= 0;
    }
  if (ops.cut) {
    weights_.resize(ops.pressureCount());
    for (int c = 0; c < ops.pressureCount(); ++c)
      for (int e = 0; e < 2 * d; ++e) {
        const int v = ops.divergenceFaces[c][e];
        weights_[c][e] = v >= 0 ? ops.openFraction[v] : 0.0;
      }
  }
}

template <int d>
void PoissonOperator<d>::apply(const Eigen::VectorXd& p, Eigen::VectorXd& out) const {
  // Stencil of G^T beta^-1 G: every free face of a cell adds A^2 beta^-1 (p_c - p_other), with
  // p_other = 0 for a Dirichlet cell or ghost.
  const FluidOperators<d>& ops = *ops_;
  const double k = ops.area * ops.area * ops.betaInv;
  out.resize(ops.pressureCount());
  const double* pp = p.data();
  double* po = out.data();
  if (ops.cut) {  // A^2 beta^-1 = k theta on a cut face
    parallel::forRows(ops.pressureCount(), [&](int c) {
      double s = 0;
      for (int e = 0; e < 2 * d; ++e) {
        const int other = neighbours_[c][e];
        s += weights_[c][e] * (pp[c] - (other >= 0 ? pp[other] : 0.0));
      }
      po[c] = k * s;
    });
    return;
  }
  parallel::forRows(ops.pressureCount(), [&](int c) {
    double s = freeFaces_[c] * pp[c];
    for (int other : neighbours_[c])
      if (other >= 0) s -= pp[other];
    po[c] = k * s;
  });
}

template <int d>
Eigen::VectorXd PoissonOperator<d>::diagonal() const {
  const FluidOperators<d>& ops = *ops_;
  const double k = ops.area * ops.area * ops.betaInv;
  Eigen::VectorXd diag(ops.pressureCount());
  for (int c = 0; c < ops.pressureCount(); ++c) {
    if (!ops.cut) {
      diag[c] = k * freeFaces_[c];
      continue;
    }
    double w = 0;
    for (double x : weights_[c]) w += x;
    diag[c] = k * w;
  }
  return diag;
}

template <int d>
LinearOperator PoissonOperator<d>::asOperator() const {
  const PoissonOperator* self = this;
  return [self](const Eigen::VectorXd& in, Eigen::VectorXd& out) { self->apply(in, out); };
}

template <int d>
CoupledOperator<d>::CoupledOperator(const FluidOperators<d>& ops) : ops_(&ops), faces_(ops.velocityCount()) {}

template <int d>
void CoupledOperator<d>::apply(const Eigen::VectorXd& z, Eigen::VectorXd& out) const {
  // A z = K beta^-1 K^T z + P z: gather to faces, scale by beta^-1, scatter to the rows (notes 4.4).
  const FluidOperators<d>& ops = *ops_;
  const int np = ops.pressureCount(), nr = ops.viscousCount();
  const auto p = z.head(np);
  const auto uhat = z.segment(np, nr);
  const double A = ops.area, binv = ops.betaInv;
  const double* theta = ops.cut ? ops.openFraction.data() : nullptr;
  parallel::forRows(ops.velocityCount(), [&](int v) {
    // beta^-1 (G p_hat + G_mu^T u_hat); on a cut face beta^-1 G p_hat is still binv A dp.
    const auto& cells = ops.gradientCells[v];
    const double pressure = A * ((cells[1] >= 0 ? p[cells[1]] : 0.0) - (cells[0] >= 0 ? p[cells[0]] : 0.0));
    double viscous = 0;
    if (nr > 0) {
      const auto& rows = ops.faceViscousRows[v];
      for (int b = 0; b < d; ++b) {
        if (rows[2 * b] >= 0) viscous += ops.viscousRows[rows[2 * b]].c1 * uhat[rows[2 * b]];
        if (rows[2 * b + 1] >= 0) viscous += ops.viscousRows[rows[2 * b + 1]].c0 * uhat[rows[2 * b + 1]];
      }
    }
    faces_[v] = theta ? binv * (pressure + viscous / theta[v]) : binv * (pressure + viscous);
  });
  out.resize(np + nr);
  applyGradientTranspose(ops, faces_, out.head(np));
  if (nr > 0) {
    parallel::forRows(nr, [&](int r) {
      const ViscousRow& row = ops.viscousRows[r];
      double s = uhat[r];
      if (row.u0 >= 0) s += row.c0 * faces_[row.u0];
      if (row.u1 >= 0) s += row.c1 * faces_[row.u1];
      out[np + r] = s;
    });
  }
}

template <int d>
Eigen::VectorXd CoupledOperator<d>::viscousDiagonal() const {
  const FluidOperators<d>& ops = *ops_;
  Eigen::VectorXd diag(ops.viscousCount());
  for (int r = 0; r < ops.viscousCount(); ++r) {
    const ViscousRow& row = ops.viscousRows[r];
    const double w0 = row.u0 >= 0 ? row.c0 * row.c0 / ops.openFraction[row.u0] : 0.0;
    const double w1 = row.u1 >= 0 ? row.c1 * row.c1 / ops.openFraction[row.u1] : 0.0;
    diag[r] = 1.0 + ops.betaInv * (w0 + w1);
  }
  return diag;
}

template <int d>
LinearOperator CoupledOperator<d>::asOperator() const {
  const CoupledOperator* self = this;
  return [self](const Eigen::VectorXd& in, Eigen::VectorXd& out) { self->apply(in, out); };
}

template <int d>
ViscousOperator<d>::ViscousOperator(const FluidOperators<d>& ops) : ops_(&ops), rows_(ops.viscousCount()) {}

template <int d>
void ViscousOperator<d>::apply(const Eigen::VectorXd& u, Eigen::VectorXd& out) const {
  const FluidOperators<d>& ops = *ops_;
  out.resize(ops.velocityCount());
  applyViscousGradient(ops, u, rows_);
  applyViscousGradientTranspose(ops, rows_, out);
  const double binv = ops.betaInv;
  const double* theta = ops.openFraction.data();
  parallel::forRows(ops.velocityCount(), [&](int v) { out[v] = theta[v] * u[v] + binv * out[v]; });
}

template <int d>
Eigen::VectorXd ViscousOperator<d>::diagonal() const {
  const FluidOperators<d>& ops = *ops_;
  Eigen::VectorXd diag = ops.openFraction;
  for (const ViscousRow& row : ops.viscousRows) {
    if (row.u0 >= 0) diag[row.u0] += ops.betaInv * row.c0 * row.c0;
    if (row.u1 >= 0) diag[row.u1] += ops.betaInv * row.c1 * row.c1;
  }
  return diag;
}

template <int d>
LinearOperator ViscousOperator<d>::asOperator() const {
  const ViscousOperator* self = this;
  return [self](const Eigen::VectorXd& in, Eigen::VectorXd& out) { self->apply(in, out); };
}

Projector closedRegionProjector(const FluidDofs& dofs, int offset) {
  if (dofs.closedComponentCount == 0) return {};
  const int np = dofs.pressureCount();
  const std::vector<int> component = dofs.closedComponent;  // copied: the projector may outlive dofs
  const int count = dofs.closedComponentCount;
  std::vector<double> sizes(count, 0.0);
  for (int c : dofs.closedComponent)
    if (c >= 0) sizes[c] += 1;
  const bool single = count == 1 && sizes[0] == np;
  return [=](Eigen::VectorXd& v) {
    double* x = v.data() + offset;
    if (single) {  // common case (closed box): one deterministic parallel mean
      const double mean = parallel::sum(np, [x](int i) { return x[i]; }) / np;
      parallel::forRows(np, [x, mean](int i) { x[i] -= mean; });
      return;
    }
    std::vector<double> means(count, 0.0);
    for (int i = 0; i < np; ++i)
      if (component[i] >= 0) means[component[i]] += x[i];
    for (int c = 0; c < count; ++c) means[c] /= sizes[c];
    for (int i = 0; i < np; ++i)
      if (component[i] >= 0) x[i] -= means[component[i]];
  };
}

template class PoissonOperator<2>;
template class PoissonOperator<3>;
template class CoupledOperator<2>;
template class CoupledOperator<3>;
template class ViscousOperator<2>;
template class ViscousOperator<3>;

}  // namespace monolith::solvers
