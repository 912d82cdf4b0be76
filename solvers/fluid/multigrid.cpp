// Geometric multigrid V-cycle for the pressure Poisson block (see multigrid.h).
#include "solvers/fluid/multigrid.h"

#include "solvers/fluid/parallel.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <cmath>

namespace monolith::solvers {

namespace {

enum : uint8_t { kUnknown = 0, kDirichlet = 1, kSolid = 2 };
constexpr int kDenseLimit = 1024;
constexpr int kCoarseSmoothingPairs = 20;
constexpr double kJacobiWeight = 2.0 / 3.0;

template <int d>
struct Level {
  using Index = typename MacLayout<d>::Index;
  MacLayout<d> layout;
  std::vector<uint8_t> type;  // per cell
  std::vector<uint8_t> open;  // per face
  // Per face, the open fraction weighting coef (cut faces, multigrid.h); empty: every open face
  // has weight 1 (the staircase, no per-face tables in the smoother).
  std::vector<double> weight;
  double coef = 0;            // h^(d-2) / rho
  std::vector<int> cellToUnknown, unknownToCell;
  std::vector<double> diag;                  // per unknown
  std::vector<std::array<int, 2 * d>> nbr;   // per unknown: unknown across an open face, else -1
  std::vector<std::array<double, 2 * d>> nbrWeight;  // per unknown, with weight: that face's weight
  std::array<std::vector<int>, 2> colour;    // unknowns by parity of the coordinate sum
  bool redBlack = true;
  SparseMatrixR P, R;                        // to / from the next coarser level (R = P^T)
  Eigen::MatrixXd pinv;                      // coarsest level only, when small enough
  Eigen::VectorXd x, b, r;

  int unknowns() const { return static_cast<int>(unknownToCell.size()); }

  // Neighbour cell of c across its face (a, side); false if outside a non-periodic side.
  bool neighbour(Index c, int a, int side, int& cell) const {
    c[a] += side == 0 ? -1 : 1;
    if (c[a] < 0 || c[a] >= layout.cells[a]) {
      if (!layout.periodic[a]) return false;
      c[a] = (c[a] + layout.cells[a]) % layout.cells[a];
    }
    cell = layout.cellIndex(c);
    return true;
  }
  int faceOf(Index c, int a, int side) const {
    c[a] += side;
    return layout.faceIndex(a, c);
  }

  // Numbering, diagonal, neighbour table and colouring from type/open/coef.
  void finalize() {
    const int n = layout.cellCount();
    cellToUnknown.assign(n, -1);
    unknownToCell.clear();
    for (int c = 0; c < n; ++c) {
      if (type[c] != kUnknown) continue;
      const Index ci = layout.cellCoord(c);
      bool anyOpen = false;
      for (int a = 0; a < d; ++a)
        for (int side = 0; side < 2; ++side) anyOpen |= open[faceOf(ci, a, side)] != 0;
      if (!anyOpen) continue;  // isolated cell: zero row, left out (its value is in the null space)
      cellToUnknown[c] = unknowns();
      unknownToCell.push_back(c);
    }
    const int m = unknowns();
    diag.assign(m, 0.0);
    nbr.resize(m);
    nbrWeight.assign(weight.empty() ? 0 : m, {});
    colour[0].clear();
    colour[1].clear();
    for (int u = 0; u < m; ++u) {
      const Index ci = layout.cellCoord(unknownToCell[u]);
      for (int a = 0; a < d; ++a)
        for (int side = 0; side < 2; ++side) {
          int& k = nbr[u][2 * a + side];
          k = -1;
          const int face = faceOf(ci, a, side);
          if (!open[face]) continue;
          diag[u] += weight.empty() ? coef : coef * weight[face];
          int other = -1;
          if (neighbour(ci, a, side, other)) k = cellToUnknown[other];
          if (!weight.empty()) nbrWeight[u][2 * a + side] = weight[face];
        }
      colour[ci.sum() % 2].push_back(u);
    }
    redBlack = true;
    for (int a = 0; a < d; ++a)
      if (layout.periodic[a] && layout.cells[a] % 2 != 0) redBlack = false;
    x.setZero(m);
    b.setZero(m);
    r.setZero(m);
  }

  // Sum over the open faces of u of (weight x) v at the neighbour unknown.
  double offSum(int u, const Eigen::VectorXd& v) const {
    double s = 0;
    if (weight.empty()) {
      for (int k : nbr[u])
        if (k >= 0) s += v[k];
      return s;
    }
    for (int j = 0; j < 2 * d; ++j)
      if (nbr[u][j] >= 0) s += nbrWeight[u][j] * v[nbr[u][j]];
    return s;
  }
  void residual() {
    parallel::forRows(unknowns(), [&](int u) { r[u] = b[u] - (diag[u] * x[u] - coef * offSum(u, x)); });
  }
  void gaussSeidel(int c) {
    const auto& list = colour[c];
    parallel::forRows(static_cast<int>(list.size()), [&](int k) {
      const int u = list[k];
      x[u] = (b[u] + coef * offSum(u, x)) / diag[u];
    });
  }
  void jacobi() {
    residual();
    parallel::forRows(unknowns(), [&](int u) { x[u] += kJacobiWeight * r[u] / diag[u]; });
  }
  // forward: red then black; backward: black then red (its adjoint).
  void smooth(bool forward) {
    if (!redBlack) {
      jacobi();
      return;
    }
    gaussSeidel(forward ? 0 : 1);
    gaussSeidel(forward ? 1 : 0);
  }
};

template <int d>
Level<d> coarsen(const Level<d>& fine) {
  using Index = typename MacLayout<d>::Index;
  Level<d> coarse;
  MacLayout<d> layout = fine.layout;
  // An odd count n coarsens to (n + 1) / 2 cells: the last coarse cell has one fine child, its
  // missing half counts as solid (closed), and the coarse boundary face takes the fine one's
  // state. The coarse grid then overhangs the domain by one fine cell; a preconditioner only
  // needs a symmetric positive coarse operator with R = P^T, which this keeps. Without it a
  // 220 x 41 channel could not coarsen at all and "multigrid" degenerated to 20 Gauss-Seidel
  // sweeps per application on the full grid (measured 5 ms per CG iteration at 9k cells).
  for (int a = 0; a < d; ++a) layout.cells[a] = (fine.layout.cells[a] + 1) / 2;
  layout.dx = 2 * fine.layout.dx;
  coarse.layout = layout;
  coarse.coef = fine.coef * std::pow(2.0, d - 2);
  coarse.type.assign(layout.cellCount(), kSolid);
  for (int c = 0; c < fine.layout.cellCount(); ++c) {
    const Index ci = fine.layout.cellCoord(c);
    const int parent = layout.cellIndex(ci / 2);
    const uint8_t t = fine.type[c];
    uint8_t& pt = coarse.type[parent];
    if (t == kDirichlet) pt = kDirichlet;
    else if (t == kUnknown && pt != kDirichlet) pt = kUnknown;
  }
  coarse.open.assign(layout.totalFaces(), 0);
  if (!fine.weight.empty()) coarse.weight.assign(layout.totalFaces(), 0.0);
  for (int f = 0; f < layout.totalFaces(); ++f) {
    auto [a, F] = layout.faceCoord(f);
    double weightSum = 0;
    int counted = 0;
    for (int k = 0; k < (1 << (d - 1)) && (!coarse.open[f] || !fine.weight.empty()); ++k) {
      Index ff = 2 * F;
      ff[a] = std::min(ff[a], fine.layout.cells[a]);  // the upper boundary face of an odd axis
      int bit = 0;
      bool exists = true;
      for (int b = 0; b < d; ++b) {
        if (b == a) continue;
        ff[b] += (k >> bit++) & 1;
        exists &= ff[b] < fine.layout.cells[b];  // the missing half of an odd axis' last cell
      }
      if (!exists) continue;
      const int fineFace = fine.layout.faceIndex(a, ff);
      if (fine.open[fineFace]) coarse.open[f] = 1;
      if (!fine.weight.empty()) {  // a closed fine face counts with weight 0
        weightSum += fine.open[fineFace] ? fine.weight[fineFace] : 0.0;
        ++counted;
      }
    }
    // The coarse face carries the mean conductance of the fine faces it covers (rediscretization:
    // with weights 1 this is the staircase's coefficient).
    if (!fine.weight.empty() && coarse.open[f]) coarse.weight[f] = weightSum / counted;
  }
  coarse.finalize();
  return coarse;
}

// P: fine unknowns x coarse unknowns, cell-centred linear interpolation with the boundary rules of
// multigrid.h.
template <int d>
SparseMatrixR prolongation(const Level<d>& fine, const Level<d>& coarse) {
  using Index = typename MacLayout<d>::Index;
  std::vector<Eigen::Triplet<double>> t;
  const auto& cl = coarse.layout;
  for (int u = 0; u < fine.unknowns(); ++u) {
    const Index f = fine.layout.cellCoord(fine.unknownToCell[u]);
    const Index I = f / 2;
    Index s;
    for (int a = 0; a < d; ++a) s[a] = (f[a] % 2) ? 1 : -1;
    double toParent = 0;
    for (int delta = 0; delta < (1 << d); ++delta) {
      double w = 1;
      bool neumann = false, dirichlet = false;
      Index C = I;
      for (int a = 0; a < d; ++a) {
        if (!((delta >> a) & 1)) {
          w *= 0.75;
          continue;
        }
        w *= 0.25;
        // The coarse face between I and I + s_a e_a decides: closed -> Neumann, open to outside ->
        // Dirichlet ghost.
        if (!coarse.open[coarse.faceOf(I, a, s[a] > 0 ? 1 : 0)]) {
          neumann = true;
          continue;
        }
        C[a] += s[a];
        if (C[a] < 0 || C[a] >= cl.cells[a]) {
          if (cl.periodic[a]) C[a] = (C[a] + cl.cells[a]) % cl.cells[a];
          else dirichlet = true;
        }
      }
      if (neumann) {
        toParent += w;
        continue;
      }
      if (dirichlet) continue;
      const int cell = cl.cellIndex(C);
      const uint8_t type = coarse.type[cell];
      if (type == kSolid || (type == kUnknown && coarse.cellToUnknown[cell] < 0)) {
        toParent += w;
      } else if (type == kUnknown) {
        t.emplace_back(u, coarse.cellToUnknown[cell], w);
      }  // Dirichlet: p = 0, weight dropped
    }
    const int parent = coarse.cellToUnknown[cl.cellIndex(I)];
    if (toParent > 0 && parent >= 0) t.emplace_back(u, parent, toParent);
  }
  SparseMatrixR P(fine.unknowns(), coarse.unknowns());
  P.setFromTriplets(t.begin(), t.end());
  return P;
}

// out = M in, parallel over rows (each row by one task).
void multiply(const SparseMatrixR& M, const Eigen::VectorXd& in, Eigen::VectorXd& out) {
  parallel::forRows(static_cast<int>(M.rows()), [&](int i) {
    double s = 0;
    for (SparseMatrixR::InnerIterator it(M, i); it; ++it) s += it.value() * in[it.col()];
    out[i] = s;
  });
}

}  // namespace

template <int d>
struct PoissonMultigrid<d>::Impl {
  MultigridSettings settings;
  std::vector<Level<d>> levels;
  std::vector<int> pressureToLevel0;  // ops pressure unknown -> level-0 unknown (-1: isolated)

  void coarseSolve(Level<d>& L) {
    if (L.pinv.size() > 0) {
      L.x.noalias() = L.pinv * L.b;
      return;
    }
    L.x.setZero();
    for (int k = 0; k < kCoarseSmoothingPairs; ++k) L.smooth(true);
    for (int k = 0; k < kCoarseSmoothingPairs; ++k) L.smooth(false);
  }

  void vcycle(size_t l) {
    Level<d>& L = levels[l];
    if (l + 1 == levels.size()) {
      coarseSolve(L);
      return;
    }
    L.x.setZero();
    for (int k = 0; k < settings.smoothingSweeps; ++k) L.smooth(true);
    L.residual();
    Level<d>& C = levels[l + 1];
    multiply(L.R, L.r, C.b);
    vcycle(l + 1);
    multiply(L.P, C.x, L.r);  // r reused as the correction
    L.x += L.r;
    for (int k = 0; k < settings.smoothingSweeps; ++k) L.smooth(false);
  }
};

template <int d>
PoissonMultigrid<d>::PoissonMultigrid(const FluidOperators<d>& ops, const MultigridSettings& settings)
    : impl_(std::make_unique<Impl>()) {
  impl_->settings = settings;
  const auto& domain = ops.domain;
  Level<d> top;
  top.layout = domain.layout;
  top.coef = ops.area * ops.area * ops.betaInv;
  top.type.resize(domain.layout.cellCount());
  for (int c = 0; c < domain.layout.cellCount(); ++c)
    top.type[c] = ops.dofs.cellToPressure[c] >= 0 ? kUnknown
                  : domain.cells[c] == CellKind::Dirichlet ? kDirichlet
                                                           : kSolid;
  top.open.resize(domain.layout.totalFaces());
  for (int f = 0; f < domain.layout.totalFaces(); ++f) top.open[f] = domain.faces[f] == FaceKind::Free;
  // Cut faces: the Poisson block weights a free face by its open fraction (spd_systems.h).
  if (!domain.openFraction.empty()) {
    top.weight.assign(domain.layout.totalFaces(), 0.0);
    for (int f = 0; f < domain.layout.totalFaces(); ++f)
      if (top.open[f]) top.weight[f] = domain.openFraction[f];
  }
  top.finalize();
  impl_->pressureToLevel0.resize(ops.pressureCount());
  for (int p = 0; p < ops.pressureCount(); ++p) impl_->pressureToLevel0[p] = top.cellToUnknown[ops.dofs.pressureToCell[p]];
  auto& levels = impl_->levels;
  levels.push_back(std::move(top));
  for (;;) {
    const Level<d>& L = levels.back();
    bool canCoarsen = L.unknowns() > settings.coarsestUnknowns;
    for (int a = 0; a < d; ++a)
      canCoarsen &= L.layout.cells[a] >= 3 && (L.layout.cells[a] % 2 == 0 || !L.layout.periodic[a]);
    if (!canCoarsen) break;
    Level<d> next = coarsen(L);
    if (next.unknowns() == 0) break;
    levels.back().P = prolongation(levels.back(), next);
    levels.back().R = levels.back().P.transpose();
    levels.push_back(std::move(next));
  }
  Level<d>& C = levels.back();
  if (C.unknowns() <= kDenseLimit && C.unknowns() > 0) {
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(C.unknowns(), C.unknowns());
    for (int u = 0; u < C.unknowns(); ++u) {
      A(u, u) = C.diag[u];
      for (int j = 0; j < 2 * d; ++j)
        if (C.nbr[u][j] >= 0) A(u, C.nbr[u][j]) -= C.weight.empty() ? C.coef : C.coef * C.nbrWeight[u][j];
    }
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(A);
    const Eigen::VectorXd& lambda = eig.eigenvalues();
    const double cut = 1e-10 * lambda.cwiseAbs().maxCoeff();
    Eigen::VectorXd inv = lambda.unaryExpr([cut](double v) { return v > cut ? 1.0 / v : 0.0; });
    C.pinv = eig.eigenvectors() * inv.asDiagonal() * eig.eigenvectors().transpose();
  }
}

template <int d>
PoissonMultigrid<d>::~PoissonMultigrid() = default;
template <int d>
PoissonMultigrid<d>::PoissonMultigrid(PoissonMultigrid&&) noexcept = default;
template <int d>
PoissonMultigrid<d>& PoissonMultigrid<d>::operator=(PoissonMultigrid&&) noexcept = default;

template <int d>
void PoissonMultigrid<d>::apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const {
  Level<d>& top = impl_->levels.front();
  const auto& map = impl_->pressureToLevel0;
  const int n = static_cast<int>(map.size());
  parallel::forRows(n, [&](int p) {
    if (map[p] >= 0) top.b[map[p]] = r[p];
  });
  impl_->vcycle(0);
  z.resize(n);
  parallel::forRows(n, [&](int p) { z[p] = map[p] >= 0 ? top.x[map[p]] : 0.0; });
}

template <int d>
int PoissonMultigrid<d>::levelCount() const {
  return static_cast<int>(impl_->levels.size());
}

template <int d>
std::vector<int> PoissonMultigrid<d>::levelSizes() const {
  std::vector<int> sizes;
  for (const auto& L : impl_->levels) sizes.push_back(L.unknowns());
  return sizes;
}

template class PoissonMultigrid<2>;
template class PoissonMultigrid<3>;

}  // namespace monolith::solvers
