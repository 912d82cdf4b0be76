// Fluid domain description: see boundary.h (thesis Sec. 5.2, 5.4.2, 5.7).
#include "solvers/fluid/boundary.h"

#include <stdexcept>
#include <string>

namespace monolith::solvers {

template <int d>
SideSpec<d> SideSpec<d>::wall(bool noSlip, const Vec& wallVelocity) {
  SideSpec s;
  s.kind = Kind::Wall;
  s.noSlip = noSlip;
  if (!wallVelocity.isZero(0)) s.velocity = [wallVelocity](const Vec&) { return wallVelocity; };
  return s;
}

template <int d>
SideSpec<d> SideSpec<d>::movingWall(bool noSlip, VelocityField<d> wallVelocity) {
  SideSpec s;
  s.kind = Kind::Wall;
  s.noSlip = noSlip;
  s.velocity = std::move(wallVelocity);
  return s;
}

template <int d>
SideSpec<d> SideSpec<d>::inflow(VelocityField<d> inflowVelocity) {
  SideSpec s;
  s.kind = Kind::Inflow;
  s.velocity = std::move(inflowVelocity);
  return s;
}

template <int d>
SideSpec<d> SideSpec<d>::inflow(const Vec& inflowVelocity) {
  return inflow([inflowVelocity](const Vec&) { return inflowVelocity; });
}

template <int d>
SideSpec<d> SideSpec<d>::outflow() {
  SideSpec s;
  s.kind = Kind::Outflow;
  s.noSlip = false;
  return s;
}

template <int d>
SideSpec<d> SideSpec<d>::periodic() {
  SideSpec s;
  s.kind = Kind::Periodic;
  s.noSlip = false;
  return s;
}

template <int d>
bool FluidDomain<d>::faceCell(int face, int which, int& cell) const {
  auto [axis, f] = layout.faceCoord(face);
  Index c = f;
  if (which == 0) c[axis] -= 1;
  if (c[axis] < 0 || c[axis] >= layout.cells[axis]) {
    if (!layout.periodic[axis]) return false;
    c[axis] = (c[axis] + layout.cells[axis]) % layout.cells[axis];
  }
  cell = layout.cellIndex(c);
  return true;
}

template <int d>
FaceKind FluidDomain<d>::classifyFace(int face) const {
  const int axis = layout.faceCoord(face).first;
  bool solid = false, fluid = false;
  for (int which = 0; which < 2; ++which) {
    int c = -1;
    if (faceCell(face, which, c)) {
      solid |= cells[c] == CellKind::Solid;
      fluid |= cells[c] == CellKind::Fluid;
    } else {
      solid |= sides[2 * axis + which].normalPrescribed();
    }
  }
  if (solid) return FaceKind::Prescribed;
  return fluid ? FaceKind::Free : FaceKind::Inactive;
}

template <int d>
FluidDomain<d> boxDomain(const MacLayout<d>& layout, const BoxSpec<d>& sides) {
  using Kind = typename SideSpec<d>::Kind;
  for (int a = 0; a < d; ++a) {
    const bool lo = sides[2 * a].kind == Kind::Periodic, hi = sides[2 * a + 1].kind == Kind::Periodic;
    if (lo != hi || lo != layout.periodic[a])
      throw std::invalid_argument("boxDomain: axis " + std::to_string(a) +
                                  " must be periodic on both sides exactly when the layout axis is periodic");
  }
  FluidDomain<d> domain;
  domain.layout = layout;
  domain.sides = sides;
  domain.cells.assign(layout.cellCount(), CellKind::Fluid);
  domain.faces.resize(layout.totalFaces());
  domain.faceVelocity.assign(layout.totalFaces(), 0.0);
  for (int face = 0; face < layout.totalFaces(); ++face) {
    domain.faces[face] = domain.classifyFace(face);
    if (domain.faces[face] != FaceKind::Prescribed) continue;
    // Only boundary faces can be prescribed in a plain box; pick the side they lie on.
    auto [axis, f] = layout.faceCoord(face);
    const int side = 2 * axis + (f[axis] == 0 ? 0 : 1);
    domain.faceVelocity[face] = sides[side].velocityAt(layout.faceCenter(axis, f))[axis];
  }
  return domain;
}

namespace {
template <int d, class Visit>
void forFacesOfCell(const MacLayout<d>& layout, int cell, const Visit& visit) {
  const auto c = layout.cellCoord(cell);
  for (int a = 0; a < d; ++a) {
    auto f = c;
    visit(a, layout.faceIndex(a, f));
    f[a] += 1;
    visit(a, layout.faceIndex(a, f));
  }
}
}  // namespace

template <int d>
void markSolid(FluidDomain<d>& domain, const std::vector<uint8_t>& solidMask, const VelocityField<d>& obstacleVelocity) {
  const auto& layout = domain.layout;
  if (static_cast<int>(solidMask.size()) != layout.cellCount())
    throw std::invalid_argument("markSolid: mask size must equal the cell count");
  for (int c = 0; c < layout.cellCount(); ++c)
    if (solidMask[c]) domain.cells[c] = CellKind::Solid;
  for (int c = 0; c < layout.cellCount(); ++c) {
    if (!solidMask[c]) continue;
    forFacesOfCell<d>(layout, c, [&](int axis, int face) {
      domain.faces[face] = FaceKind::Prescribed;
      const auto x = layout.faceCenter(axis, layout.faceCoord(face).second);
      domain.faceVelocity[face] = obstacleVelocity ? obstacleVelocity(x)[axis] : 0.0;
    });
  }
}

template <int d>
void cutFaces(FluidDomain<d>& domain, const std::vector<double>& openFraction, const VelocityField<d>& obstacleVelocity) {
  const auto& layout = domain.layout;
  if (static_cast<int>(openFraction.size()) != layout.totalFaces())
    throw std::invalid_argument("cutFaces: expected one open fraction per face");
  for (double theta : openFraction)
    if (!(theta >= 0 && theta <= 1)) throw std::invalid_argument("cutFaces: open fractions must lie in [0, 1]");
  domain.openFraction.assign(layout.totalFaces(), 1.0);
  for (int face = 0; face < layout.totalFaces(); ++face) {
    if (domain.faces[face] != FaceKind::Free || openFraction[face] == 1) continue;
    const auto [axis, f] = layout.faceCoord(face);
    domain.faceVelocity[face] = obstacleVelocity ? obstacleVelocity(layout.faceCenter(axis, f))[axis] : 0.0;
    if (openFraction[face] == 0) domain.faces[face] = FaceKind::Prescribed;
    else domain.openFraction[face] = openFraction[face];
  }
  // A fluid cell whose faces are all covered holds no fluid a pressure could act on.
  for (int c = 0; c < layout.cellCount(); ++c) {
    if (domain.cells[c] != CellKind::Fluid) continue;
    bool anyFree = false;
    forFacesOfCell<d>(layout, c, [&](int, int face) { anyFree |= domain.faces[face] == FaceKind::Free; });
    if (!anyFree) domain.cells[c] = CellKind::Solid;
  }
}

template <int d>
void markDirichlet(FluidDomain<d>& domain, const std::vector<uint8_t>& mask) {
  const auto& layout = domain.layout;
  if (static_cast<int>(mask.size()) != layout.cellCount())
    throw std::invalid_argument("markDirichlet: mask size must equal the cell count");
  for (int c = 0; c < layout.cellCount(); ++c)
    if (mask[c]) domain.cells[c] = CellKind::Dirichlet;
  for (int c = 0; c < layout.cellCount(); ++c) {
    if (!mask[c]) continue;
    forFacesOfCell<d>(layout, c, [&](int, int face) {
      // Faces already prescribed by a wall or an obstacle keep their velocity.
      const FaceKind kind = domain.classifyFace(face);
      if (kind != FaceKind::Prescribed) {
        domain.faces[face] = kind;
        domain.faceVelocity[face] = 0;
      }
    });
  }
}

template struct SideSpec<2>;
template struct SideSpec<3>;
template struct FluidDomain<2>;
template struct FluidDomain<3>;
template FluidDomain<2> boxDomain<2>(const MacLayout<2>&, const BoxSpec<2>&);
template FluidDomain<3> boxDomain<3>(const MacLayout<3>&, const BoxSpec<3>&);
template void markSolid<2>(FluidDomain<2>&, const std::vector<uint8_t>&, const VelocityField<2>&);
template void markSolid<3>(FluidDomain<3>&, const std::vector<uint8_t>&, const VelocityField<3>&);
template void cutFaces<2>(FluidDomain<2>&, const std::vector<double>&, const VelocityField<2>&);
template void cutFaces<3>(FluidDomain<3>&, const std::vector<double>&, const VelocityField<3>&);
template void markDirichlet<2>(FluidDomain<2>&, const std::vector<uint8_t>&);
template void markDirichlet<3>(FluidDomain<3>&, const std::vector<uint8_t>&);

}  // namespace monolith::solvers
