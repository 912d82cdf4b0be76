// Coupling operators W, J = N J_hat R and the structure cells of the domain (see structure_coupling.h).
#include "solvers/fluid/structure_coupling.h"

#include <stdexcept>

namespace monolith::solvers {

template <int d>
void rigidSampleRows(int sample, int dofOffset, const Eigen::Matrix<double, d, 1>& r,
                     std::vector<Eigen::Triplet<double>>& out) {
  // v_p = v + w x r (eq. 5.10).
  for (int a = 0; a < d; ++a) out.emplace_back(sample * d + a, dofOffset + a, 1.0);
  if constexpr (d == 2) {
    // (w e_z x r) = w (-r_y, r_x)
    out.emplace_back(sample * d + 0, dofOffset + 2, -r.y());
    out.emplace_back(sample * d + 1, dofOffset + 2, r.x());
  } else {
    // w x r = r*^T w with r* w = r x w: rows (0, r_z, -r_y), (-r_z, 0, r_x), (r_y, -r_x, 0).
    out.emplace_back(sample * d + 0, dofOffset + 4, r.z());
    out.emplace_back(sample * d + 0, dofOffset + 5, -r.y());
    out.emplace_back(sample * d + 1, dofOffset + 3, -r.z());
    out.emplace_back(sample * d + 1, dofOffset + 5, r.x());
    out.emplace_back(sample * d + 2, dofOffset + 3, r.y());
    out.emplace_back(sample * d + 2, dofOffset + 4, -r.x());
  }
}

template <int d>
SparseMatrixR faceNormalRows(const MacLayout<d>& layout, const std::vector<int>& faces) {
  std::vector<Eigen::Triplet<double>> t;
  for (std::size_t k = 0; k < faces.size(); ++k)
    t.emplace_back(static_cast<int>(k), static_cast<int>(k) * d + layout.faceCoord(faces[k]).first, 1.0);
  SparseMatrixR N(static_cast<int>(faces.size()), static_cast<int>(faces.size()) * d);
  N.setFromTriplets(t.begin(), t.end());
  return N;
}

template <int d>
std::vector<int> markStructure(FluidDomain<d>& domain, const std::vector<std::uint8_t>& structureCells, bool viscous) {
  const auto& layout = domain.layout;
  if (static_cast<int>(structureCells.size()) != layout.cellCount())
    throw std::invalid_argument("markStructure: expected one mask entry per cell");
  for (int c = 0; c < layout.cellCount(); ++c)
    if (structureCells[c] && domain.cells[c] == CellKind::Fluid) domain.cells[c] = CellKind::Solid;
  const int nf = layout.totalFaces();
  domain.structureFace.assign(nf, 0);
  std::vector<std::uint8_t> interior(nf, 0);  // touches a structure cell, no fluid cell
  for (int f = 0; f < nf; ++f) {
    bool structure = false, fluid = false;
    for (int which = 0; which < 2; ++which) {
      int c = -1;
      if (!domain.faceCell(f, which, c)) continue;
      structure = structure || structureCells[c];
      fluid = fluid || domain.cells[c] == CellKind::Fluid;
    }
    if (!structure || domain.faces[f] == FaceKind::Prescribed) continue;  // walls, obstacles: infinite mass
    domain.faceVelocity[f] = 0;
    if (fluid) {
      domain.faces[f] = FaceKind::Free;
      domain.structureFace[f] = 1;
      // A coupling face is whole: the structure covers it and its velocity is the structure's, also
      // where a cut-cell obstacle covers part of it (a flag's root inside a cut cylinder).
      if (!domain.openFraction.empty()) domain.openFraction[f] = 1.0;
    } else {
      domain.faces[f] = FaceKind::Inactive;
      interior[f] = 1;
    }
  }
  if (viscous) {
    // Faces inside a structure beside a fluid face along a viscous pair direction (Fig. 5.2).
    std::vector<std::uint8_t> add(nf, 0);
    for (int f = 0; f < nf; ++f) {
      if (domain.faces[f] != FaceKind::Free || domain.structureFace[f]) continue;
      const auto [a, fc] = layout.faceCoord(f);
      const auto dims = layout.faceDims(a);
      for (int b = 0; b < d; ++b)
        for (int s = -1; s <= 1; s += 2) {
          auto g = fc;
          g[b] += s;
          if (g[b] < 0 || g[b] >= dims[b]) {
            if (!layout.periodic[b]) continue;
            g[b] = (g[b] + dims[b]) % dims[b];
          }
          const int other = layout.faceIndex(a, g);
          if (interior[other]) add[other] = 1;
        }
    }
    for (int f = 0; f < nf; ++f)
      if (add[f]) {
        domain.faces[f] = FaceKind::Free;
        domain.structureFace[f] = 1;
        if (!domain.openFraction.empty()) domain.openFraction[f] = 1.0;
      }
  }
  std::vector<int> faces;
  for (int f = 0; f < nf; ++f)
    if (domain.structureFace[f]) faces.push_back(f);
  return faces;
}

#define MONOLITH_STRUCTURE_COUPLING(D)                                                                           \
  template void rigidSampleRows<D>(int, int, const Eigen::Matrix<double, D, 1>&, std::vector<Eigen::Triplet<double>>&); \
  template SparseMatrixR faceNormalRows<D>(const MacLayout<D>&, const std::vector<int>&);                        \
  template std::vector<int> markStructure<D>(FluidDomain<D>&, const std::vector<std::uint8_t>&, bool);

MONOLITH_STRUCTURE_COUPLING(2)
MONOLITH_STRUCTURE_COUPLING(3)
#undef MONOLITH_STRUCTURE_COUPLING

}  // namespace monolith::solvers
