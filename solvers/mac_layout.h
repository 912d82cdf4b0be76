#pragma once
// Index arithmetic of a uniform MAC grid (thesis Sec. 5.2/5.4, 6.3.3): pressures at cell
// centres, velocity components at the centres of the faces normal to their axis.
//
// Cells: c = (i, j[, k]), 0 <= c_a < cells[a], linear index x-fastest.
// Faces of axis a: f = (i, j[, k]) with 0 <= f_a <= cells[a] (cells[a] + 1 layers) and the other
// coordinates as for cells; face f of axis a sits between cells f - e_a and f. On a periodic axis
// the last layer (f_a == cells[a]) is the same face as f_a == 0 and is not stored.
// All faces are numbered in one vector: axis 0 first, then axis 1 (, then axis 2).
// Knows nothing of entities; used by the fluid operators, solvers and advection.
#include <Eigen/Core>
#include <array>
#include <cmath>
#include <utility>
#include <stdexcept>

namespace monolith::solvers {

template <int d>
struct MacLayout {
  using Index = Eigen::Matrix<int, d, 1>;
  using Vec = Eigen::Matrix<double, d, 1>;

  Index cells = Index::Ones();
  double dx = 1;
  Vec origin = Vec::Zero();  // lower corner of the domain
  std::array<bool, d> periodic{};

  MacLayout() = default;
  MacLayout(const Index& n, double h, const Vec& lower = Vec::Zero(), std::array<bool, d> per = {})
      : cells(n), dx(h), origin(lower), periodic(per) {
    if (n.minCoeff() < 1 || !(h > 0)) throw std::invalid_argument("MacLayout: need >= 1 cell per axis and dx > 0");
  }

  int cellCount() const { return cells.prod(); }
  int cellIndex(const Index& c) const {
    int index = 0;
    for (int a = d - 1; a >= 0; --a) index = index * cells[a] + c[a];
    return index;
  }
  Index cellCoord(int index) const {
    Index c;
    for (int a = 0; a < d; ++a) {
      c[a] = index % cells[a];
      index /= cells[a];
    }
    return c;
  }
  bool cellInside(const Index& c) const { return (c.array() >= 0).all() && (c.array() < cells.array()).all(); }

  // Number of stored face layers along `axis` for faces of that axis.
  int faceLayers(int axis) const { return periodic[axis] ? cells[axis] : cells[axis] + 1; }
  Index faceDims(int axis) const {
    Index n = cells;
    n[axis] = faceLayers(axis);
    return n;
  }
  int faceCount(int axis) const { return faceDims(axis).prod(); }
  int faceOffset(int axis) const {
    int offset = 0;
    for (int a = 0; a < axis; ++a) offset += faceCount(a);
    return offset;
  }
  int totalFaces() const { return faceOffset(d - 1) + faceCount(d - 1); }
  // Global index of face f of `axis` (f_a may equal cells[a] on a periodic axis: wrapped).
  int faceIndex(int axis, Index f) const {
    if (periodic[axis] && f[axis] == cells[axis]) f[axis] = 0;
    const Index n = faceDims(axis);
    int index = 0;
    for (int a = d - 1; a >= 0; --a) index = index * n[a] + f[a];
    return faceOffset(axis) + index;
  }
  // Inverse of faceIndex: the axis and the face coordinate.
  std::pair<int, Index> faceCoord(int global) const {
    int axis = 0;
    while (axis + 1 < d && global >= faceOffset(axis + 1)) ++axis;
    int local = global - faceOffset(axis);
    const Index n = faceDims(axis);
    Index f;
    for (int a = 0; a < d; ++a) {
      f[a] = local % n[a];
      local /= n[a];
    }
    return {axis, f};
  }

  Vec cellCenter(const Index& c) const { return origin + dx * (c.template cast<double>().array() + 0.5).matrix(); }
  Vec faceCenter(int axis, const Index& f) const {
    Vec x = cellCenter(f);
    x[axis] -= 0.5 * dx;
    return x;
  }
  double cellVolume() const { return std::pow(dx, d); }
  double faceArea() const { return std::pow(dx, d - 1); }

  // Linear-index step per axis of a grid of `dims` nodes numbered x-fastest (cells: dims =
  // cells; faces of axis a: dims = faceDims(a), to be added to faceOffset(a)).
  static std::array<int, d> strides(const Index& dims) {
    std::array<int, d> s{};
    for (int a = 0, stride = 1; a < d; stride *= dims[a], ++a) s[a] = stride;
    return s;
  }
};

// visit(i) for every index with lo <= i <= hi (componentwise), x fastest: in increasing linear
// index, or decreasing with `backwards`. Nothing is visited if the box is empty.
template <int d, class Visit>
void forEachIndexIn(const Eigen::Matrix<int, d, 1>& lo, const Eigen::Matrix<int, d, 1>& hi, Visit&& visit,
                    bool backwards = false) {
  if ((hi.array() < lo.array()).any()) return;
  Eigen::Matrix<int, d, 1> i = backwards ? hi : lo;
  while (true) {
    visit(static_cast<const Eigen::Matrix<int, d, 1>&>(i));
    int a = 0;
    for (; a < d; ++a) {
      if (backwards ? --i[a] >= lo[a] : ++i[a] <= hi[a]) break;
      i[a] = backwards ? hi[a] : lo[a];
    }
    if (a == d) return;
  }
}

}  // namespace monolith::solvers
