// Volume-weighted MAC operators G, beta, G_mu (thesis Sec. 5.2, 5.4.2, 5.7; notes 4.3).
#include "solvers/fluid/operators.h"

#include "solvers/fluid/parallel.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace monolith::solvers {

template <int d>
FluidDofs numberFluidDofs(const FluidDomain<d>& domain) {
  const auto& layout = domain.layout;
  FluidDofs dofs;
  dofs.cellToPressure.assign(layout.cellCount(), -1);
  for (int c = 0; c < layout.cellCount(); ++c) {
    if (domain.cells[c] != CellKind::Fluid) continue;
    dofs.cellToPressure[c] = dofs.pressureCount();
    dofs.pressureToCell.push_back(c);
  }
  dofs.faceToVelocity.assign(layout.totalFaces(), -1);
  for (int f = 0; f < layout.totalFaces(); ++f) {
    if (domain.faces[f] != FaceKind::Free) continue;
    dofs.faceToVelocity[f] = dofs.velocityCount();
    dofs.velocityToFace.push_back(f);
  }
  // Connected regions through free faces (breadth-first, in index order: deterministic). A region
  // with a free face whose other side is not an unknown (Dirichlet cell or outflow ghost) pins the
  // pressure; the others make G singular (pure Neumann, e.g. a closed box, Sec. 6.2.6).
  const int np = dofs.pressureCount();
  std::vector<int> region(np, -1);
  std::vector<uint8_t> pinned;
  std::vector<int> queue;
  int regions = 0;
  for (int seed = 0; seed < np; ++seed) {
    if (region[seed] >= 0) continue;
    region[seed] = regions;
    pinned.push_back(0);
    queue.assign(1, seed);
    for (size_t q = 0; q < queue.size(); ++q) {
      const auto c = layout.cellCoord(dofs.pressureToCell[queue[q]]);
      for (int a = 0; a < d; ++a)
        for (int side = 0; side < 2; ++side) {
          auto f = c;
          f[a] += side;
          const int face = layout.faceIndex(a, f);
          if (domain.faces[face] != FaceKind::Free) continue;
          int other = -1;
          if (!domain.faceCell(face, side, other) || dofs.cellToPressure[other] < 0) {
            pinned[regions] = 1;
            continue;
          }
          const int po = dofs.cellToPressure[other];
          if (region[po] < 0) {
            region[po] = regions;
            queue.push_back(po);
          }
        }
    }
    ++regions;
  }
  std::vector<int> closedId(regions, -1);
  for (int r = 0; r < regions; ++r)
    if (!pinned[r]) closedId[r] = dofs.closedComponentCount++;
  dofs.closedComponent.resize(np);
  for (int p = 0; p < np; ++p) dofs.closedComponent[p] = closedId[region[p]];
  return dofs;
}

namespace {

// One end of a viscous pair: an unknown, a known value, or "no row" (inactive face, zero shear).
struct PairEnd {
  enum Kind { Unknown, Known, Drop } kind = Drop;
  int velocity = -1;
  double value = 0;
  bool ghost = false;  // a mirrored ghost across a domain side (row weight sqrt(2) w)
};

template <int d>
PairEnd pairEnd(const FluidDomain<d>& domain, const FluidDofs& dofs, int a, int b,
                typename MacLayout<d>::Index f) {
  const auto& layout = domain.layout;
  const auto dims = layout.faceDims(a);
  PairEnd end;
  if (f[b] < 0 || f[b] >= dims[b]) {
    if (layout.periodic[b]) {
      f[b] = (f[b] + dims[b]) % dims[b];
    } else {
      // Outside the box across side (b, lower/upper). Along the face axis there is never a row.
      const int side = 2 * b + (f[b] < 0 ? 0 : 1);
      if (b == a || !domain.sides[side].tangentialDirichlet()) return end;
      auto inside = f;
      inside[b] = f[b] < 0 ? 0 : dims[b] - 1;
      auto x = layout.faceCenter(a, inside);
      x[b] = layout.origin[b] + (f[b] < 0 ? 0.0 : layout.cells[b] * layout.dx);
      end.kind = PairEnd::Known;
      end.value = domain.sides[side].velocityAt(x)[a];
      end.ghost = true;
      return end;
    }
  }
  const int face = layout.faceIndex(a, f);
  switch (domain.faces[face]) {
    case FaceKind::Free:
      end.kind = PairEnd::Unknown;
      end.velocity = dofs.faceToVelocity[face];
      break;
    case FaceKind::Prescribed:
      end.kind = PairEnd::Known;
      end.value = domain.faceVelocity[face];
      break;
    case FaceKind::Inactive:
      break;
  }
  return end;
}

template <int d>
void buildViscousRows(FluidOperators<d>& ops) {
  const auto& domain = ops.domain;
  const auto& layout = domain.layout;
  const int nu = ops.velocityCount();
  std::array<int, 2 * d> none;
  none.fill(-1);
  ops.faceViscousRows.assign(nu, none);
  std::vector<double> known;
  if (ops.params.viscosity == 0) {
    ops.viscousKnown.resize(0);
    return;
  }
  const double w = ops.viscousWeight;
  // Free cut faces whose centre lies inside an obstacle (wallDistance 0, boundary.h): the
  // obstacle's wall for the viscous rows.
  std::vector<uint8_t> inside(nu, 0);
  if (!domain.wallDistance.empty())
    for (int v = 0; v < nu; ++v) {
      const int face = ops.dofs.velocityToFace[v];
      if (!domain.structureFace.empty() && domain.structureFace[face]) continue;
      for (int k = 0; k < 2 * d; ++k) inside[v] |= domain.wallDistance[static_cast<std::size_t>(face) * 2 * d + k] == 0;
    }
  for (int a = 0; a < d; ++a)
    for (int b = 0; b < d; ++b) {
      // Pair k = (f1 - e_b, f1) for f1 over the face index space of axis a, extended by one layer
      // along b on a non-periodic axis so that both boundary pairs are visited.
      auto ext = layout.faceDims(a);
      if (!layout.periodic[b]) ext[b] += 1;
      const int count = ext.prod();
      for (int k = 0; k < count; ++k) {
        typename MacLayout<d>::Index f1;
        int rest = k;
        for (int e = 0; e < d; ++e) {
          f1[e] = rest % ext[e];
          rest /= ext[e];
        }
        auto f0 = f1;
        f0[b] -= 1;
        PairEnd e0 = pairEnd<d>(domain, ops.dofs, a, b, f0);
        PairEnd e1 = pairEnd<d>(domain, ops.dofs, a, b, f1);
        if (e0.kind == PairEnd::Drop || e1.kind == PairEnd::Drop) continue;
        // A pair with a face inside an obstacle: the wall lies between the two faces. The other
        // face, if it is outside, sees it as it sees a covered face (below); the inside face has
        // its own row (after the loop).
        const bool in0 = e0.kind == PairEnd::Unknown && inside[e0.velocity];
        const bool in1 = e1.kind == PairEnd::Unknown && inside[e1.velocity];
        if (in0 && in1) continue;
        if (in0) {
          if (e1.kind != PairEnd::Unknown) continue;
          e0.kind = PairEnd::Known;
          e0.value = domain.faceVelocity[ops.dofs.velocityToFace[e0.velocity]];
        }
        if (in1) {
          if (e0.kind != PairEnd::Unknown) continue;
          e1.kind = PairEnd::Known;
          e1.value = domain.faceVelocity[ops.dofs.velocityToFace[e1.velocity]];
        }
        if (e0.kind != PairEnd::Unknown && e1.kind != PairEnd::Unknown) continue;
        if (!domain.structureFace.empty() && e0.kind == PairEnd::Unknown && e1.kind == PairEnd::Unknown &&
            domain.structureFace[ops.dofs.velocityToFace[e0.velocity]] &&
            domain.structureFace[ops.dofs.velocityToFace[e1.velocity]])
          continue;  // both ends move with structures (structure_coupling.h)
        double c = (e0.ghost || e1.ghost) ? std::sqrt(2.0) * w : w;
        if (!domain.wallDistance.empty()) {
          // A pair ending on an obstacle face: the wall sits theta cells from the free face
          // instead of one, so the row is w (U - u_f) / sqrt(theta) (theta = 1/2 is the mirrored
          // ghost above); G_mu^T G_mu keeps its symmetric form. (Pairs ending on a domain wall's
          // normal face have theta = 1: the wall is at that face.)
          // (A coupling face inside an obstacle keeps the marker 0 of an inside face: the closest wall.)
          const auto theta = [&](const PairEnd& unknown, int towardsUpper) {
            return std::max(FluidDomain<d>::kMinWallDistance,
                            domain.wallDistance[FluidDomain<d>::wallDistanceIndex(ops.dofs.velocityToFace[unknown.velocity], b,
                                                                                  towardsUpper)]);
          };
          // A moving wall: its velocity where it is (domain.wallVelocity), not at the face beyond.
          const auto wallVelocity = [&](const PairEnd& unknown, int towardsUpper, double faceValue) {
            if (domain.wallVelocity.empty()) return faceValue;
            const double v = domain.wallVelocity[FluidDomain<d>::wallDistanceIndex(ops.dofs.velocityToFace[unknown.velocity],
                                                                                 b, towardsUpper)];
            return v == FluidDomain<d>::kNoWallVelocity ? faceValue : v;
          };
          if (e0.kind == PairEnd::Unknown && e1.kind == PairEnd::Known && !e1.ghost) {
            c = w / std::sqrt(theta(e0, 1));
            e1.value = wallVelocity(e0, 1, e1.value);
          }
          if (e1.kind == PairEnd::Unknown && e0.kind == PairEnd::Known && !e0.ghost) {
            c = w / std::sqrt(theta(e1, 0));
            e0.value = wallVelocity(e1, 0, e0.value);
          }
          // A pair from a fluid face to a coupled structure's face: the same, the wall moving with
          // the structure face (theta = 1 unless the coupling asked for its walls at the surface).
          if (!domain.structureFace.empty() && e0.kind == PairEnd::Unknown && e1.kind == PairEnd::Unknown) {
            const bool s0 = domain.structureFace[ops.dofs.velocityToFace[e0.velocity]];
            const bool s1 = domain.structureFace[ops.dofs.velocityToFace[e1.velocity]];
            if (!s0 && s1) c = w / std::sqrt(theta(e0, 1));
            if (s0 && !s1) c = w / std::sqrt(theta(e1, 0));
          }
        }
        ViscousRow row;
        double h = 0;
        if (e0.kind == PairEnd::Unknown) {
          row.u0 = e0.velocity;
          row.c0 = -c;
        } else {
          h -= c * e0.value;
        }
        if (e1.kind == PairEnd::Unknown) {
          row.u1 = e1.velocity;
          row.c1 = c;
        } else {
          h += c * e1.value;
        }
        const int r = static_cast<int>(ops.viscousRows.size());
        if (row.u0 >= 0) ops.faceViscousRows[row.u0][2 * b + 1] = r;
        if (row.u1 >= 0) ops.faceViscousRows[row.u1][2 * b] = r;
        ops.viscousRows.push_back(row);
        known.push_back(h);
      }
    }
  // A face inside an obstacle moves with it: one row w (U - u) / sqrt(kMinWallDistance), as if the
  // wall were at the closest distance any row measures (the open part of such a face lies within
  // half a cell of the surface). Its pairs were dropped above, so the row takes the first slot.
  for (int v = 0; v < nu; ++v) {
    if (!inside[v]) continue;
    const std::size_t k = static_cast<std::size_t>(ops.dofs.velocityToFace[v]) * 2 * d;
    const double U = domain.wallVelocity.empty() || domain.wallVelocity[k] == FluidDomain<d>::kNoWallVelocity
                         ? domain.faceVelocity[ops.dofs.velocityToFace[v]]
                         : domain.wallVelocity[k];
    const double c = w / std::sqrt(FluidDomain<d>::kMinWallDistance);
    ViscousRow row;
    row.u1 = v;
    row.c1 = c;
    ops.faceViscousRows[v][0] = static_cast<int>(ops.viscousRows.size());
    ops.viscousRows.push_back(row);
    known.push_back(-c * U);
  }
  ops.viscousKnown = Eigen::Map<Eigen::VectorXd>(known.data(), static_cast<Eigen::Index>(known.size()));
}

}  // namespace

template <int d>
FluidOperators<d> buildFluidOperators(const FluidDomain<d>& domain, const FluidParameters& params) {
  if (!(params.density > 0) || !(params.dt > 0) || !(params.viscosity >= 0))
    throw std::invalid_argument("buildFluidOperators: need density > 0, dt > 0, viscosity >= 0");
  const auto& layout = domain.layout;
  if (static_cast<int>(domain.cells.size()) != layout.cellCount() ||
      static_cast<int>(domain.faces.size()) != layout.totalFaces() ||
      static_cast<int>(domain.faceVelocity.size()) != layout.totalFaces() ||
      !(domain.wallDistance.empty() || domain.wallDistance.size() == static_cast<std::size_t>(layout.totalFaces()) * 2 * d) ||
      !(domain.wallVelocity.empty() || domain.wallVelocity.size() == domain.wallDistance.size()) ||
      !(domain.openFraction.empty() || static_cast<int>(domain.openFraction.size()) == layout.totalFaces()))
    throw std::invalid_argument("buildFluidOperators: domain arrays do not match its layout");
  FluidOperators<d> ops;
  ops.domain = domain;
  ops.params = params;
  ops.dofs = numberFluidDofs(domain);
  ops.area = layout.faceArea();
  ops.volume = layout.cellVolume();
  ops.betaInv = 1.0 / (params.density * ops.volume);
  ops.viscousWeight = std::sqrt(params.dt * params.viscosity / ops.volume) * ops.area;
  const int np = ops.pressureCount(), nu = ops.velocityCount();
  ops.openFraction.setOnes(nu);
  if (!domain.openFraction.empty())
    for (int v = 0; v < nu; ++v) {
      const double theta = domain.openFraction[ops.dofs.velocityToFace[v]];
      if (!(theta > 0 && theta <= 1)) throw std::invalid_argument("buildFluidOperators: a free face's open fraction must lie in (0, 1]");
      ops.openFraction[v] = theta;
      ops.cut |= theta != 1;
    }
  ops.faceBetaInv = ops.betaInv * ops.openFraction.cwiseInverse();

  // G: per free face the unknown cells on either side (Dirichlet / ghost: p = 0, no entry).
  ops.gradientCells.resize(nu);
  std::vector<Eigen::Triplet<double>> triplets;
  for (int v = 0; v < nu; ++v) {
    const int face = ops.dofs.velocityToFace[v];
    const double area = ops.area * ops.openFraction[v];
    for (int which = 0; which < 2; ++which) {
      int cell = -1;
      const int p = domain.faceCell(face, which, cell) ? ops.dofs.cellToPressure[cell] : -1;
      ops.gradientCells[v][which] = p;
      if (p >= 0) triplets.emplace_back(v, p, which == 0 ? -area : area);
    }
  }
  ops.G.resize(nu, np);
  ops.G.setFromTriplets(triplets.begin(), triplets.end());

  // G^T stencil and the prescribed fluxes g = D_prescribed u_prescribed.
  ops.divergenceFaces.resize(np);
  ops.prescribedDivergence.setZero(np);
  for (int p = 0; p < np; ++p) {
    const auto c = layout.cellCoord(ops.dofs.pressureToCell[p]);
    for (int a = 0; a < d; ++a)
      for (int side = 0; side < 2; ++side) {
        auto f = c;
        f[a] += side;
        const int face = layout.faceIndex(a, f);
        const int v = ops.dofs.faceToVelocity[face];
        ops.divergenceFaces[p][2 * a + side] = v;
        // The covered part of a face (all of a prescribed one) moves with what covers it.
        const double covered = domain.faces[face] == FaceKind::Prescribed ? 1.0 : v >= 0 ? 1.0 - ops.openFraction[v] : 0.0;
        if (covered > 0) ops.prescribedDivergence[p] += (side == 1 ? ops.area : -ops.area) * covered * domain.faceVelocity[face];
      }
  }

  buildViscousRows(ops);
  triplets.clear();
  for (int r = 0; r < ops.viscousCount(); ++r) {
    const ViscousRow& row = ops.viscousRows[r];
    if (row.u0 >= 0) triplets.emplace_back(r, row.u0, row.c0);
    if (row.u1 >= 0) triplets.emplace_back(r, row.u1, row.c1);
  }
  ops.Gmu.resize(ops.viscousCount(), nu);
  ops.Gmu.setFromTriplets(triplets.begin(), triplets.end());
  return ops;
}

template <int d>
void applyGradient(const FluidOperators<d>& ops, const Eigen::Ref<const Eigen::VectorXd>& p, Eigen::Ref<Eigen::VectorXd> out) {
  const double A = ops.area;
  const double* theta = ops.cut ? ops.openFraction.data() : nullptr;
  parallel::forRows(ops.velocityCount(), [&](int v) {
    const auto& cells = ops.gradientCells[v];
    const double lo = cells[0] >= 0 ? p[cells[0]] : 0.0;
    const double hi = cells[1] >= 0 ? p[cells[1]] : 0.0;
    out[v] = (theta ? A * theta[v] : A) * (hi - lo);
  });
}

template <int d>
void applyGradientTranspose(const FluidOperators<d>& ops, const Eigen::Ref<const Eigen::VectorXd>& u,
                            Eigen::Ref<Eigen::VectorXd> out) {
  const double A = ops.area;
  if (ops.cut) {
    const double* theta = ops.openFraction.data();
    parallel::forRows(ops.pressureCount(), [&](int p) {
      const auto& faces = ops.divergenceFaces[p];
      double s = 0;
      for (int a = 0; a < d; ++a) {
        if (faces[2 * a] >= 0) s += theta[faces[2 * a]] * u[faces[2 * a]];
        if (faces[2 * a + 1] >= 0) s -= theta[faces[2 * a + 1]] * u[faces[2 * a + 1]];
      }
      out[p] = A * s;
    });
    return;
  }
  parallel::forRows(ops.pressureCount(), [&](int p) {
    const auto& faces = ops.divergenceFaces[p];
    double s = 0;
    for (int a = 0; a < d; ++a) {
      if (faces[2 * a] >= 0) s += u[faces[2 * a]];
      if (faces[2 * a + 1] >= 0) s -= u[faces[2 * a + 1]];
    }
    out[p] = A * s;
  });
}

template <int d>
void applyViscousGradient(const FluidOperators<d>& ops, const Eigen::Ref<const Eigen::VectorXd>& u,
                          Eigen::Ref<Eigen::VectorXd> out) {
  parallel::forRows(ops.viscousCount(), [&](int r) {
    const ViscousRow& row = ops.viscousRows[r];
    double s = 0;
    if (row.u0 >= 0) s += row.c0 * u[row.u0];
    if (row.u1 >= 0) s += row.c1 * u[row.u1];
    out[r] = s;
  });
}

template <int d>
void applyViscousGradientTranspose(const FluidOperators<d>& ops, const Eigen::Ref<const Eigen::VectorXd>& r,
                                   Eigen::Ref<Eigen::VectorXd> out) {
  if (ops.viscousCount() == 0) {
    out.setZero();
    return;
  }
  parallel::forRows(ops.velocityCount(), [&](int v) {
    const auto& rows = ops.faceViscousRows[v];
    double s = 0;
    for (int b = 0; b < d; ++b) {
      if (rows[2 * b] >= 0) s += ops.viscousRows[rows[2 * b]].c1 * r[rows[2 * b]];
      if (rows[2 * b + 1] >= 0) s += ops.viscousRows[rows[2 * b + 1]].c0 * r[rows[2 * b + 1]];
    }
    out[v] = s;
  });
}

template <int d>
Eigen::VectorXd freeVelocities(const FluidOperators<d>& ops, const Eigen::VectorXd& faceVelocities) {
  if (faceVelocities.size() != ops.domain.layout.totalFaces())
    throw std::invalid_argument("freeVelocities: expected one value per face");
  Eigen::VectorXd u(ops.velocityCount());
  parallel::forRows(ops.velocityCount(), [&](int v) { u[v] = faceVelocities[ops.dofs.velocityToFace[v]]; });
  return u;
}

template <int d>
void writeVelocities(const FluidOperators<d>& ops, const Eigen::VectorXd& free, Eigen::VectorXd& faceVelocities) {
  faceVelocities.conservativeResize(ops.domain.layout.totalFaces());
  parallel::forRows(ops.domain.layout.totalFaces(), [&](int f) {
    if (ops.domain.faces[f] == FaceKind::Free)
      faceVelocities[f] = free[ops.dofs.faceToVelocity[f]];
    else if (ops.domain.faces[f] == FaceKind::Prescribed)
      faceVelocities[f] = ops.domain.faceVelocity[f];
  });
}

template <int d>
Eigen::VectorXd constraintDivergence(const FluidOperators<d>& ops, const Eigen::VectorXd& faceVelocities) {
  Eigen::VectorXd div(ops.pressureCount());
  applyGradientTranspose(ops, freeVelocities(ops, faceVelocities), div);
  return ops.prescribedDivergence - div;
}

template <int d>
Eigen::VectorXd volumeDivergence(const MacLayout<d>& layout, const Eigen::VectorXd& u) {
  Eigen::VectorXd div(layout.cellCount());
  const double A = layout.faceArea();
  parallel::forRows(layout.cellCount(), [&](int cell) {
    const auto c = layout.cellCoord(cell);
    double s = 0;
    for (int a = 0; a < d; ++a) {
      auto f = c;
      s -= u[layout.faceIndex(a, f)];
      f[a] += 1;
      s += u[layout.faceIndex(a, f)];
    }
    div[cell] = A * s;
  });
  return div;
}

template <int d>
SparseMatrixR assemblePoisson(const FluidOperators<d>& ops) {
  SparseMatrixR GT = ops.G.transpose();
  SparseMatrixR P = ops.cut ? SparseMatrixR(GT * faceBetaInverse(ops).asDiagonal() * ops.G) : SparseMatrixR(ops.betaInv * (GT * ops.G));
  P.prune(0.0);
  return P;
}

template <int d>
SparseMatrixR assembleCoupled(const FluidOperators<d>& ops) {
  // K = [G^T; G_mu] (rows: pressure unknowns then viscous rows), A = K beta^-1 K^T + diag(0, I).
  const int np = ops.pressureCount(), nr = ops.viscousCount();
  SparseMatrixR K(np + nr, ops.velocityCount());
  std::vector<Eigen::Triplet<double>> t;
  for (int k = 0; k < ops.G.outerSize(); ++k)
    for (SparseMatrixR::InnerIterator it(ops.G, k); it; ++it) t.emplace_back(it.col(), it.row(), it.value());
  for (int k = 0; k < ops.Gmu.outerSize(); ++k)
    for (SparseMatrixR::InnerIterator it(ops.Gmu, k); it; ++it) t.emplace_back(np + it.row(), it.col(), it.value());
  K.setFromTriplets(t.begin(), t.end());
  SparseMatrixR KT = K.transpose();
  SparseMatrixR A = ops.cut ? SparseMatrixR(K * faceBetaInverse(ops).asDiagonal() * KT) : SparseMatrixR(ops.betaInv * (K * KT));
  SparseMatrixR P(np + nr, np + nr);
  std::vector<Eigen::Triplet<double>> id;
  for (int r = 0; r < nr; ++r) id.emplace_back(np + r, np + r, 1.0);
  P.setFromTriplets(id.begin(), id.end());
  SparseMatrixR result = A + P;
  result.prune(0.0);
  return result;
}

#define MONOLITH_FLUID_OPS(D)                                                                                    \
  template FluidDofs numberFluidDofs<D>(const FluidDomain<D>&);                                                  \
  template FluidOperators<D> buildFluidOperators<D>(const FluidDomain<D>&, const FluidParameters&);             \
  template void applyGradient<D>(const FluidOperators<D>&, const Eigen::Ref<const Eigen::VectorXd>&,             \
                                 Eigen::Ref<Eigen::VectorXd>);                                                  \
  template void applyGradientTranspose<D>(const FluidOperators<D>&, const Eigen::Ref<const Eigen::VectorXd>&,    \
                                          Eigen::Ref<Eigen::VectorXd>);                                         \
  template void applyViscousGradient<D>(const FluidOperators<D>&, const Eigen::Ref<const Eigen::VectorXd>&,      \
                                        Eigen::Ref<Eigen::VectorXd>);                                           \
  template void applyViscousGradientTranspose<D>(const FluidOperators<D>&,                                       \
                                                 const Eigen::Ref<const Eigen::VectorXd>&,                       \
                                                 Eigen::Ref<Eigen::VectorXd>);                                  \
  template Eigen::VectorXd freeVelocities<D>(const FluidOperators<D>&, const Eigen::VectorXd&);                 \
  template void writeVelocities<D>(const FluidOperators<D>&, const Eigen::VectorXd&, Eigen::VectorXd&);          \
  template Eigen::VectorXd constraintDivergence<D>(const FluidOperators<D>&, const Eigen::VectorXd&);            \
  template Eigen::VectorXd volumeDivergence<D>(const MacLayout<D>&, const Eigen::VectorXd&);                    \
  template SparseMatrixR assemblePoisson<D>(const FluidOperators<D>&);                                          \
  template SparseMatrixR assembleCoupled<D>(const FluidOperators<D>&);

MONOLITH_FLUID_OPS(2)
MONOLITH_FLUID_OPS(3)
#undef MONOLITH_FLUID_OPS

}  // namespace monolith::solvers
