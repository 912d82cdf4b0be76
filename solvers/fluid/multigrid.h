#pragma once
// Geometric multigrid V-cycle preconditioner for the pressure Poisson block G^T beta^-1 G on a
// uniform MAC grid (constant density). The goal is iteration counts of the preconditioned CG that
// barely grow with resolution (the thesis lists a better preconditioner as future work, notes 4.4).
//
//  * Level 0 is exactly the assembled Poisson block: a face is open iff it is Free, with coefficient
//    A^2 beta^-1 = h^(d-2) / rho, times its open fraction theta if faces are cut ((theta A)^2 /
//    (theta rho V), operators.h); open faces to a non-unknown cell (Dirichlet cell, outflow ghost)
//    add to the diagonal only.
//  * Coarsening by 2 per axis (while every count is >= 3, and even on periodic axes): n cells become
//    (n + 1) / 2, so on an odd axis the last coarse cell has one child and the coarse grid overhangs
//    the box by one fine cell (its boundary face copies the fine boundary face). A coarse cell is
//    Dirichlet if any child is, else a pressure unknown if any child is, else solid; a coarse face
//    is open if any of the existing fine faces it covers is open; the operator is rediscretized
//    with h^(d-2) / rho. With cut faces a coarse face's coefficient is also weighted, by the mean
//    weight of the existing fine faces it covers (closed ones count 0): the mean conductance. This
//    halved the gap to the staircase's iteration counts (DFG 2D-2 at 880 x 164: Chorin's Poisson
//    solve 20 -> 11 iterations, the coupled solve 123 -> 90; docs/benchmarks.md).
//  * Prolongation P: cell-centred (bi/tri)linear interpolation, weights 3/4 and 1/4 per axis; a
//    weight that would refer to a solid coarse cell or to a closed side of the box moves to the
//    parent (constant extrapolation = Neumann), one referring to a Dirichlet cell or an open side is
//    dropped (p = 0). Restriction R = P^T exactly (full weighting scaled to volume-weighted
//    residuals: the weights of a coarse cell sum to 2^d).
//  * Smoothing: red-black Gauss-Seidel (red then black before the coarse correction, black then
//    red after it: the post-smoother is the adjoint of the pre-smoother) - parallel over the cells of
//    one colour, deterministic. On a level with a periodic axis of odd length (where red-black
//    colouring is impossible) weighted Jacobi (omega = 2/3) is used instead.
//  * Coarsest level: dense pseudo-inverse (symmetric eigendecomposition, eigenvalues below 1e-10
//    of the largest treated as the null space) when it has <= 1024 unknowns, else 20 extra
//    symmetric smoothing pairs.
// With R = P^T, adjoint smoothers and a symmetric coarse solve the V-cycle is a symmetric positive
// (semi)definite operator, so it is a valid CG preconditioner.
// apply() uses internal buffers: one PoissonMultigrid must not be applied from two threads at once.
#include "solvers/fluid/operators.h"

#include <memory>
#include <vector>

namespace monolith::solvers {

struct MultigridSettings {
  int smoothingSweeps = 2;  // red-black sweep pairs before and after each coarse correction
  int coarsestUnknowns = 64;  // stop coarsening once a level has at most this many unknowns
};

template <int d>
class PoissonMultigrid {
 public:
  explicit PoissonMultigrid(const FluidOperators<d>& ops, const MultigridSettings& settings = {});
  ~PoissonMultigrid();
  PoissonMultigrid(PoissonMultigrid&&) noexcept;
  PoissonMultigrid& operator=(PoissonMultigrid&&) noexcept;

  // z ~ (G^T beta^-1 G)^-1 r by one V-cycle from a zero initial guess (pressure-unknown vectors).
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const;
  int levelCount() const;
  // Unknowns per level, finest first.
  std::vector<int> levelSizes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace monolith::solvers
