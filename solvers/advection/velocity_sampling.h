#pragma once
// Point sampling of a MAC face-velocity field (thesis Sec. 5.2: velocity component a lives at
// the centres of the faces normal to axis a) with domain-boundary and structure handling, shared
// by the semi-Lagrangian and ENO advection of this directory.
//
// Boundary / structure description (FaceBoundary):
//   * solidCell[c] != 0 marks a cell covered by a structure (empty vector: no structures).
//   * prescribedFace[f] != 0 marks a face whose velocity is given, prescribedVelocity[f]: the
//     normal velocity of a non-periodic domain wall, or the structure velocity at a face with a
//     solid neighbour cell (the first-order equal-velocity constraint of thesis Sec. 5.4.1 sits at
//     exactly these face centres). Every face with at least one solid neighbour cell MUST be
//     prescribed (checked by validateBoundary): the field values there are never read.
//
// Sampling rule (component a at point x), the "fluid-only multilinear" rule:
//   1. Multilinear interpolation on the face grid of axis a (2^d faces).
//   2. Periodic axes wrap. Non-periodic axes clamp x to the domain: the normal component then
//      uses the boundary faces themselves, a tangential component is held constant in the half
//      cell between the wall and the first row of face centres (zero-gradient extrapolation).
//   3. A face is read as prescribedVelocity if prescribed, else from the field.
//   3b. A face with ghost rules (FaceBoundary::ghosts, set when the no-slip wall sits at the
//      obstacle's true surface or cell boundary; only faces inside the obstacle) is read as its
//      ghost value instead: the linear extension of the fluid velocity through the wall, so an
//      interpolated sample falls to the wall velocity at the wall itself rather than at the
//      obstacle face's centre (thesis Sec. 5.2: "ghost cells or clipping"; Gibou et al. 2002
//      place the wall the same way). Such faces count as fluid
//      faces below, also when they lie inside a structure. A ghost value lies between the wall
//      velocity u_w and its mirror 2 u_w - u_from, so samples stay within the range of the fluid
//      values reflected about the wall's.
//   4. Other faces "inside" a structure (all existing neighbour cells solid) are dropped from the
//      stencil and the remaining weights renormalised, so a sample never pulls velocity from the
//      interior of an obstacle; faces with one solid neighbour (the coupling faces) do contribute
//      their prescribed structure velocity. For x in a fluid cell the faces of that cell carry
//      weight >= 2^-(d-1), so the renormalisation never divides by zero and the sample is a convex
//      combination of fluid, coupling-face and ghost values (bounded by them). Only if x is itself deep
//      inside a structure (every stencil face interior) is the prescribed structure velocity
//      interpolated instead.
//   5. Traced points are first clipped to the fluid region (clipToFluid): the segment from the
//      start point to the traced point is walked in quarter-cell steps and cut, by bisection, at
//      the first entry into a solid cell, as in the clipping variant of thesis Sec. 5.2 ("back-cast
//      rays may intersect the solid ... ghost cells or clipping"). Like that first-order
//      treatment this is O(dx) accurate next to structures.
#include "solvers/mac_layout.h"

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

namespace monolith::solvers {

// A no-slip wall crosses the segment from the centre of the free face `from` to the centre of the
// prescribed face `face` (same axis, one cell apart), theta cells from `from`. The ghost value of
// `face` extends the velocity linearly through the wall:
//     u_ghost = u_w + factor (u_from - u_w),  factor = -(1 - theta) / theta,
// u_w being `face`'s prescribed velocity (the wall's). ghostFactor clamps the factor to [-1, 0]
// (theta >= 1/2): a steeper extension would leave the range of the fluid values and make the
// advection's samples unbounded. The rules of one face are averaged.
struct GhostRule {
  int face = 0;
  int from = 0;
  double factor = 0;
};
double ghostFactor(double theta);

struct FaceBoundary {
  std::vector<std::uint8_t> solidCell;       // empty, or one flag per cell (layout.cellCount())
  std::vector<std::uint8_t> prescribedFace;  // empty, or one flag per face (layout.totalFaces())
  Eigen::VectorXd prescribedVelocity;        // per face; read only where prescribedFace != 0
  std::vector<GhostRule> ghosts;             // rule 3b; `face` prescribed, `from` not
};

// Throws std::invalid_argument on wrong sizes, non-finite prescribed values, a face next to a
// solid cell that is not prescribed, or a ghost rule whose faces are out of range, whose `face`
// is not prescribed or whose `from` is, or whose factor lies outside [-1, 0].
template <int d>
void validateBoundary(const MacLayout<d>& layout, const FaceBoundary& boundary);

// Static obstacles and walls: prescribes zero normal velocity on the boundary faces of every
// non-periodic axis and on every face with a solid neighbour cell (solidCell may be empty).
template <int d>
FaceBoundary staticObstacleBoundary(const MacLayout<d>& layout, std::vector<std::uint8_t> solidCell);

// Samples one face-velocity field. Keeps pointers to `u` and `boundary` (temporaries are refused
// at compile time); both must outlive the sampler and keep their values while it is used (the
// values a sample reads are tabulated at construction). Thread-safe for concurrent reads.
template <int d>
class FaceVelocitySampler {
 public:
  using Index = typename MacLayout<d>::Index;
  using Vec = typename MacLayout<d>::Vec;

  // Validates sizes (u.size() == layout.totalFaces()) and the boundary; throws std::invalid_argument.
  FaceVelocitySampler(const MacLayout<d>& layout, const Eigen::VectorXd& u, const FaceBoundary& boundary);
  FaceVelocitySampler(const MacLayout<d>& layout, const Eigen::VectorXd& u);  // no walls, no structures
  FaceVelocitySampler(const MacLayout<d>& layout, Eigen::VectorXd&& u) = delete;
  FaceVelocitySampler(const MacLayout<d>& layout, Eigen::VectorXd&& u, const FaceBoundary& boundary) = delete;
  FaceVelocitySampler(const MacLayout<d>& layout, const Eigen::VectorXd& u, FaceBoundary&& boundary) = delete;

  const MacLayout<d>& layout() const { return layout_; }
  bool hasSolids() const { return !boundary_->solidCell.empty(); }
  bool isPrescribed(int face) const { return !boundary_->prescribedFace.empty() && boundary_->prescribedFace[face]; }
  // Value of a stored face: the prescribed velocity if prescribed, else the field (rule 3).
  double faceValue(int face) const { return isPrescribed(face) ? boundary_->prescribedVelocity[face] : (*u_)[face]; }
  // Value a sample or a stencil reads at a stored face: the ghost value if the face has ghost
  // rules (rule 3b), else faceValue.
  double sampleValue(int face) const { return read_[face]; }
  bool hasGhost(int face) const { return !ghost_.empty() && !std::isnan(ghost_[face]); }
  // True if every existing neighbour cell of face f of `axis` is solid (rule 4).
  bool faceInsideSolid(int axis, const Index& f) const;
  // Cell containing x (periodic axes wrapped, others clamped to the domain).
  Index cellOf(const Vec& x) const;
  bool pointInSolid(const Vec& x) const;

  // rules 1-4. If range is given it receives the smallest and largest of the face values that
  // entered the sample (the bounds a limiter may clamp a higher-order correction to).
  double component(int axis, const Vec& x, std::pair<double, double>* range = nullptr) const;
  Vec velocity(const Vec& x) const;                // all components at x
  // The point of segment [from, to] where it first enters a solid cell (its fluid side), or `to`
  // if it stays in fluid (rule 5). If `from` itself lies in a solid cell, returns `from`.
  Vec clipToFluid(const Vec& from, const Vec& to) const;

 private:
  MacLayout<d> layout_;
  // layout_.faceIndex(axis, f) = faceOffset_[axis] + sum_b f[b] faceStride_[axis][b] for f inside
  // the stored face grid, tabulated because a sample computes 2^d face indices.
  std::array<int, d> faceOffset_{};
  std::array<std::array<int, d>, d> faceStride_{};
  const Eigen::VectorXd* u_;
  const FaceBoundary* boundary_;
  // Rule 4's test per face, tabulated once per sampler (empty without structures): it is asked
  // for every corner of every sample, and the neighbour-cell lookup was the advection's hot spot.
  std::vector<std::uint8_t> insideSolid_;
  bool insideSolid(int face) const { return !insideSolid_.empty() && insideSolid_[face]; }
  // Rule 3b's values for this field, NaN where a face has no rule (empty without rules).
  std::vector<double> ghost_;
  // sampleValue of every face, tabulated once (rules 3 and 3b), and whether rule 4 drops the
  // face from a stencil: a sample's 2^d corners then cost two loads each.
  std::vector<double> read_;
  std::vector<std::uint8_t> dropped_;
  // Chessboard distance, in cells, from each cell to the nearest solid cell, capped at
  // kFarFromSolid (empty without structures, or on a periodic grid, where the raster scan
  // below would not see across the seam). clipToFluid returns a trace whose cells all lie
  // nearer than that without walking it: exactly what the walk would return.
  static constexpr std::uint8_t kFarFromSolid = 32;
  std::vector<std::uint8_t> solidDistance_;
};

}  // namespace monolith::solvers
