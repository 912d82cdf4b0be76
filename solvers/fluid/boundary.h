#pragma once
// Which fluid degrees of freedom exist on a MAC grid and what is known at the others (thesis
// Sec. 5.2, 5.4.2, 5.7): per cell fluid / solid / Dirichlet, per face a free velocity unknown, a
// prescribed normal velocity, or inactive, and per domain side the condition used by the pressure
// (normal) and viscous (tangential) operators. Knows nothing of entities.
//
// Sides are numbered side = 2 * axis + (0 lower, 1 upper).
#include "solvers/mac_layout.h"

#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

namespace monolith::solvers {

enum class CellKind : uint8_t {
  Fluid,      // a pressure unknown
  Solid,      // inside an obstacle: its faces carry the obstacle velocity
  Dirichlet,  // p = 0 (e.g. air); faces between it and fluid are free
};

enum class FaceKind : uint8_t {
  Free,        // velocity unknown
  Prescribed,  // normal velocity known (domain wall, inflow, obstacle): moved to the RHS
  Inactive,    // touches no fluid cell and no solid: not used by any operator
};

template <int d>
using VelocityField = std::function<Eigen::Matrix<double, d, 1>(const Eigen::Matrix<double, d, 1>&)>;

// Condition at one side of the box.
//  * Wall: normal velocity = velocity(x)·n on the boundary faces (0 for a wall at rest; a lid moves
//    tangentially so its normal velocity is 0). Tangentially, noSlip: the viscous operator sees the
//    wall velocity at the wall (mirrored ghost, see operators.h); slip: zero shear (row dropped).
//  * Inflow: boundary faces prescribed with velocity(x)·n; tangential: Dirichlet velocity(x), or
//    with noSlip = false zero shear (the thesis's "slipping u_2" inflow of Sec. 5.11.3-4).
//  * Outflow: ghost cells outside have p = 0, so the boundary faces are free; zero shear.
//  * Periodic: both sides of the axis, and the layout's axis must be periodic.
template <int d>
struct SideSpec {
  using Vec = Eigen::Matrix<double, d, 1>;
  enum class Kind : uint8_t { Wall, Inflow, Outflow, Periodic };

  Kind kind = Kind::Wall;
  bool noSlip = true;
  VelocityField<d> velocity;  // empty means zero

  static SideSpec wall(bool noSlip = true, const Vec& wallVelocity = Vec::Zero());
  static SideSpec movingWall(bool noSlip, VelocityField<d> wallVelocity);
  static SideSpec inflow(VelocityField<d> inflowVelocity);
  static SideSpec inflow(const Vec& inflowVelocity);
  static SideSpec outflow();
  static SideSpec periodic();

  Vec velocityAt(const Vec& x) const { return velocity ? velocity(x) : Vec::Zero(); }
  // Tangential velocity is Dirichlet for the viscous operator (else the row is dropped).
  bool tangentialDirichlet() const { return (kind == Kind::Inflow || kind == Kind::Wall) && noSlip; }
  // Boundary faces of this side are prescribed (else free, or periodic interior faces).
  bool normalPrescribed() const { return kind == Kind::Wall || kind == Kind::Inflow; }
};

template <int d>
using BoxSpec = std::array<SideSpec<d>, 2 * d>;

template <int d>
struct FluidDomain {
  using Vec = Eigen::Matrix<double, d, 1>;
  using Index = typename MacLayout<d>::Index;

  MacLayout<d> layout;
  std::vector<CellKind> cells;        // layout.cellCount()
  std::vector<FaceKind> faces;        // layout.totalFaces()
  std::vector<double> faceVelocity;   // prescribed normal velocity of Prescribed faces, else 0
  BoxSpec<d> sides;
  // Optional; empty: every obstacle wall sits at the prescribed face centre (the thesis's
  // first-order staircase, Sec. 5.4.1). Else wallDistance[face * 2d + 2b + s] (s = 0 towards
  // -e_b, 1 towards +e_b) is the distance, in cells, from the centre of a Free face to an
  // obstacle's surface in that direction, in [kMinWallDistance, 1], 1 meaning "at the next face".
  // The viscous operator reads it for pairs whose other end is a prescribed face (operators.h).
  // With cut faces, 0 in every direction marks a Free face whose centre lies inside an obstacle:
  // the viscous operator takes it for the obstacle's wall (the pairs from outside faces into it
  // carry their distance to the surface between, and it is held to the obstacle's velocity).
  std::vector<double> wallDistance;
  static constexpr double kMinWallDistance = 0.1;  // bounds the wall term's weight by 1/0.1
  // Optional, with wallDistance; empty: the wall moves with the prescribed face's velocity. Else,
  // same layout, the velocity component (along the face's own axis) of the obstacle's surface
  // at the wall point: a moving body's wall sits theta cells away, not at the next face's centre.
  // kNoWallVelocity (+inf) where the pair ends on something else (a domain wall, an inflow).
  std::vector<double> wallVelocity;
  static constexpr double kNoWallVelocity = std::numeric_limits<double>::infinity();
  // Position in wallDistance of face `face`'s entry along axis b towards side s (0: -e_b, 1: +e_b).
  static std::size_t wallDistanceIndex(int face, int b, int s) {
    return static_cast<std::size_t>(face) * 2 * d + 2 * b + s;
  }
  // Optional cut faces (see cutFaces); empty: every face is wholly open or wholly covered (the
  // staircase). Else openFraction[face] in (0, 1] for Free faces: the part of the face's area
  // outside every obstacle. The rest of such a face moves with the obstacle: faceVelocity holds
  // that normal velocity.
  std::vector<double> openFraction;
  // Optional (structure_coupling.h, markStructure); empty: no finite-mass structure. Else 1 per
  // face that is a coupling face: a free velocity unknown constrained to move with a structure.
  // The viscous operator drops the pairs between two such faces (no fluid shear between them).
  std::vector<uint8_t> structureFace;

  // Classification of a face from its two cells and the sides (outside a Wall/Inflow side counts
  // as solid, outside an Outflow side as Dirichlet): solid on either side -> Prescribed, else a
  // fluid cell on either side -> Free, else Inactive.
  FaceKind classifyFace(int face) const;
  // Cell on the lower (side 0) or upper (side 1) side of a face; returns false if it lies outside
  // the box on a non-periodic axis (then `cell` is unchanged).
  bool faceCell(int face, int which, int& cell) const;
};

// A box with the given side conditions: all cells fluid, faces classified, boundary faces of
// Wall/Inflow sides prescribed with the side velocity's normal component at the face centre.
// Throws std::invalid_argument if a side is Periodic but the layout axis is not (or vice versa).
template <int d>
FluidDomain<d> boxDomain(const MacLayout<d>& layout, const BoxSpec<d>& sides);

// Marks cells with solidMask[c] != 0 as Solid (an obstacle) and prescribes every face touching
// them with the obstacle velocity's normal component at the face centre (thesis Sec. 5.4.2: the
// faces covered by a structure are not fluid unknowns; here the structure is kinematic).
template <int d>
void markSolid(FluidDomain<d>& domain, const std::vector<uint8_t>& solidMask,
               const VelocityField<d>& obstacleVelocity = {});

// Cut faces (Ng, Min & Gibou, J. Comput. Phys. 228, 2009; the thesis's code does the same for
// faces cut by its front, notes 5.2 "in-fluid length fraction"): openFraction[face] in [0, 1] is the
// part of each face outside the obstacles. A Free face with fraction 0 becomes Prescribed with the
// obstacle's normal velocity at its centre; one with fraction in (0, 1) stays Free, and its covered
// part carries the obstacle's normal velocity (faceVelocity) into the divergence. A Fluid cell left
// without any Free face becomes Solid. The operators then weight each free face's area and mass by
// its fraction (operators.h). Throws std::invalid_argument on a size mismatch or a fraction outside
// [0, 1].
template <int d>
void cutFaces(FluidDomain<d>& domain, const std::vector<double>& openFraction,
              const VelocityField<d>& obstacleVelocity = {});

// Marks cells with mask[c] != 0 as Dirichlet (p = 0) and reclassifies the faces around them.
template <int d>
void markDirichlet(FluidDomain<d>& domain, const std::vector<uint8_t>& mask);

}  // namespace monolith::solvers
