#pragma once
// Elastic and damping forces of deformable solids, entity-free (thesis Sec. 4.3, 5.5.1).
// Positions, velocities and forces are flat arrays of d numbers per particle.
//
// Finite elements (simplices: triangles in 2-D, tetrahedra in 3-D) use the deformation gradient
// F = Ds Dm^{-1} and its rotated SVD F = U diag(s) V^T with U, V proper rotations; an inverted
// element then has exactly one negative singular value (the smallest), and the first
// Piola-Kirchhoff stress P = U P(s) V^T stays defined through inversion (Irving, Teran, Fedkiw
// 2004 [81]). Models:
//  * corotated: psi = mu sum (s_i - 1)^2 + lambda/2 (sum (s_i - 1))^2;
//  * neo-Hookean: psi = mu/2 (sum s_i^2 - d) - mu ln J + lambda/2 (ln J)^2, J = prod s_i, with
//    the singular values clamped below at `clamp` in the stress ([81] Sec. 5: the force keeps
//    pushing a crushed element back instead of blowing up at J -> 0).
// Mass-spring: edge springs k (|l| - L), damping c (v_rel . n) n with c a fraction of the
// critical damping 2 sqrt(k m1 m2 / (m1 + m2)) (the over-damping fraction of Sec. 5.11.5);
// optionally altitude springs (Sec. 5.11.5, [102]): in every element, from each particle to its
// projection on the opposite side, k (h - H) on the signed altitude h, which keeps the element
// from collapsing or inverting; damped like the edge springs with the effective mass of that
// relative motion.
//
// Damping forces f = D v are linear in v at fixed x, symmetric negative semidefinite, and each
// applies its factor C with C^T C = -dt D (Sec. 5.5.1):
//  * Rayleigh stiffness damping of an element: the corotated strain rate e = sym(R^T dF/dt)
//    (R = U V^T, so rigid motion is not damped) with stress beta (2 mu e + lambda tr(e) I);
//    its dissipation beta (2 mu |dev e|^2 + (2 mu / d + lambda) tr(e)^2) gives C's d^2 + 1 rows;
//  * Rayleigh mass damping -alpha m v (d rows per particle);
//  * spring dampers (one row per spring, edge springs first, then altitude springs).
#include <Eigen/Core>
#include <Eigen/LU>
#include <vector>

namespace monolith::solvers::deformable {

template <int d>
using MatD = Eigen::Matrix<double, d, d>;
template <int d>
using VecD = Eigen::Matrix<double, d, 1>;

enum class Model : int { Corotated = 0, NeoHookean = 1, Springs = 2 };

struct Lame {
  double mu = 0, lambda = 0;
  static Lame fromYoung(double E, double nu) {
    return {E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))};
  }
};

// F = U diag(s) V^T with det U = det V = 1; s sorted descending, only s[d-1] may be negative.
template <int d>
void rotatedSvd(const MatD<d>& F, MatD<d>& U, VecD<d>& s, MatD<d>& V);

template <int d>
double energyDensity(Model m, const Lame& lame, const VecD<d>& s, double clamp);
template <int d>
VecD<d> diagonalStress(Model m, const Lame& lame, const VecD<d>& s, double clamp);

// The elements and springs of one body, with their rest data. `elements` holds d+1 particle
// indices per element, `DmInv` and `restVolume` one entry per element; `springs` 2 indices per
// spring with rest length, stiffness and damping coefficient.
template <int d>
struct ForceModel {
  Model model = Model::Corotated;
  Lame lame;
  double clamp = 0.3;           // neo-Hookean singular value clamp
  double rayleighAlpha = 0;     // mass damping (1/s)
  double rayleighBeta = 0;      // stiffness damping (s)
  std::vector<int> elements;
  std::vector<MatD<d>> DmInv;
  std::vector<double> restVolume;
  std::vector<int> springs;
  std::vector<double> springRest, springK, springC;
  // Altitude springs: d+1 indices each, the particle first, then the opposite side's d particles
  // ordered so that the rest altitude is positive; rest altitude, stiffness, damping coefficient.
  std::vector<int> altitudes;
  std::vector<double> altitudeRest, altitudeK, altitudeC;
  std::vector<double> mass;     // per particle

  int elementCount() const { return static_cast<int>(restVolume.size()); }
  int springCount() const { return static_cast<int>(springRest.size()); }
  int altitudeCount() const { return static_cast<int>(altitudeRest.size()); }
  bool finiteElements() const { return model != Model::Springs; }
  // Rows of C: (d^2 + 1) per element with stiffness damping, d per particle with mass damping,
  // one per spring with a damper.
  int dampingRows() const;
};

// Signed distance h of particle idx[0] from the line (2-D) or plane (3-D) through the particles
// idx[1..d], positive on the side the normal (x2 - x1) rotated by +90 degrees, or
// (x2 - x1) x (x3 - x1), points to; gradient[a] = dh/dx_{idx[a]} (the particle: the unit normal n;
// the side's particles: -b_a n with b the barycentric coordinates of the projection).
template <int d>
double signedAltitude(const double* x, const int* idx, VecD<d>* gradient);

template <int d>
MatD<d> deformationGradient(const ForceModel<d>& fm, int e, const double* x);

// Elastic potential energy of the whole body at x.
template <int d>
double elasticEnergy(const ForceModel<d>& fm, const double* x);
// f += elastic forces at x (= -dE/dx). Deterministic on any thread count. With `rotations`
// given, also the damping rotations at x from the same decompositions (what dampingRotations
// returns, without decomposing every element again).
template <int d>
void addElasticForces(const ForceModel<d>& fm, const double* x, double* f, std::vector<MatD<d>>* rotations = nullptr);

// The rotations R = U V^T of every element at x, on which the damping operator depends (empty
// without finite-element stiffness damping).
template <int d>
std::vector<MatD<d>> dampingRotations(const ForceModel<d>& fm, const double* x);

// f += D v (damping forces; x enters through R and the spring directions).
template <int d>
void addDampingForces(const ForceModel<d>& fm, const std::vector<MatD<d>>& R, const double* x, const double* v,
                      double* f);
// y = C v (dampingRows() entries), with C^T C = -dt D.
template <int d>
void applyDampingFactor(const ForceModel<d>& fm, const std::vector<MatD<d>>& R, const double* x, double dt,
                        const double* v, double* y);
// f += C^T y.
template <int d>
void applyDampingFactorTranspose(const ForceModel<d>& fm, const std::vector<MatD<d>>& R, const double* x, double dt,
                                 const double* y, double* f);

}  // namespace monolith::solvers::deformable
