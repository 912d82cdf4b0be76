#include "solvers/advection/velocity_sampling.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace monolith::solvers {
namespace {

int wrapIndex(long long i, int n) { return static_cast<int>(((i % n) + n) % n); }

// The (up to two) cells sharing face f of `axis`: f - e_axis and f. On a periodic axis they wrap;
// on a non-periodic axis a boundary face has only one. Returns the count written to `out`.
template <int d>
int faceNeighbourCells(const MacLayout<d>& layout, int axis, typename MacLayout<d>::Index f, int out[2]) {
  const int n = layout.cells[axis];
  int count = 0;
  for (int side = 0; side < 2; ++side) {
    typename MacLayout<d>::Index c = f;
    c[axis] = f[axis] - 1 + side;
    if (layout.periodic[axis]) {
      c[axis] = wrapIndex(c[axis], n);
    } else if (c[axis] < 0 || c[axis] >= n) {
      continue;
    }
    out[count++] = layout.cellIndex(c);
  }
  return count;
}

template <int d>
bool anyNeighbourSolid(const MacLayout<d>& layout, const std::vector<std::uint8_t>& solid, int axis,
                       const typename MacLayout<d>::Index& f) {
  int cells[2];
  const int count = faceNeighbourCells(layout, axis, f, cells);
  for (int k = 0; k < count; ++k)
    if (solid[cells[k]]) return true;
  return false;
}

// visit(g, axis, f) for the 2d faces of every solid cell (a face between two solid cells twice):
// the faces a structure touches, found without a pass over all faces.
template <int d, class Visit>
void forEachFaceOfSolidCells(const MacLayout<d>& layout, const std::vector<std::uint8_t>& solid, Visit&& visit) {
  for (int c = 0; c < layout.cellCount(); ++c) {
    if (!solid[c]) continue;
    const auto ci = layout.cellCoord(c);
    for (int axis = 0; axis < d; ++axis)
      for (int side = 0; side < 2; ++side) {
        auto f = ci;
        f[axis] += side;  // f[axis] == cells[axis] on a periodic axis: faceIndex wraps it
        visit(layout.faceIndex(axis, f), axis, f);
      }
  }
}

// Two raster scans with the 3^d - 1 neighbours (forward: those before a cell in scan order;
// backward: those after) give the exact chessboard distance on a grid without periodic seams.
// Only the box of the solid cells grown by `cap` is scanned: a shortest path to the nearest
// solid cell stays inside it, and every cell outside is at least `cap` away.
template <int d>
std::vector<std::uint8_t> chessboardDistanceToSolid(const MacLayout<d>& layout, const std::vector<std::uint8_t>& solid,
                                                    std::uint8_t cap) {
  using Index = typename MacLayout<d>::Index;
  const int cells = layout.cellCount();
  std::vector<std::uint8_t> dist(cells, cap);
  Index lo = layout.cells, hi = Index::Constant(-1);
  for (int c = 0; c < cells; ++c)
    if (solid[c]) {
      const Index ci = layout.cellCoord(c);
      lo = lo.cwiseMin(ci), hi = hi.cwiseMax(ci);
      dist[c] = 0;
    }
  if ((hi.array() < 0).any()) return dist;
  for (int a = 0; a < d; ++a) lo[a] = std::max(lo[a] - cap, 0), hi[a] = std::min(hi[a] + cap, layout.cells[a] - 1);
  constexpr int kNeighbourhood = d == 2 ? 9 : 27;
  auto relax = [&](const Index& ci, bool forward) {
    const int c = layout.cellIndex(ci);
    int best = dist[c];
    for (int k = 0; k < kNeighbourhood; ++k) {
      Index n = ci;
      int rem = k;
      bool inside = true;
      for (int a = 0; a < d; ++a, rem /= 3) {
        n[a] += rem % 3 - 1;
        inside = inside && n[a] >= lo[a] && n[a] <= hi[a];
      }
      if (!inside) continue;
      const int linear = layout.cellIndex(n);
      if ((forward && linear < c) || (!forward && linear > c)) best = std::min(best, dist[linear] + 1);
    }
    dist[c] = static_cast<std::uint8_t>(std::min<int>(best, cap));
  };
  forEachIndexIn<d>(lo, hi, [&](const Index& ci) { relax(ci, true); });
  forEachIndexIn<d>(lo, hi, [&](const Index& ci) { relax(ci, false); }, /*backwards=*/true);
  return dist;
}

}  // namespace

template <int d>
void validateBoundary(const MacLayout<d>& layout, const FaceBoundary& boundary) {
  const int faces = layout.totalFaces();
  if (!boundary.solidCell.empty() && static_cast<int>(boundary.solidCell.size()) != layout.cellCount())
    throw std::invalid_argument("FaceBoundary: solidCell needs one flag per cell");
  const bool anyPrescribed = !boundary.prescribedFace.empty();
  if (anyPrescribed) {
    if (static_cast<int>(boundary.prescribedFace.size()) != faces ||
        boundary.prescribedVelocity.size() != faces)
      throw std::invalid_argument("FaceBoundary: prescribedFace/prescribedVelocity need one entry per face");
    for (int g = 0; g < faces; ++g)
      if (boundary.prescribedFace[g] && !std::isfinite(boundary.prescribedVelocity[g]))
        throw std::invalid_argument("FaceBoundary: non-finite prescribed velocity at face " + std::to_string(g));
  }
  for (const GhostRule& rule : boundary.ghosts) {
    const bool inRange = rule.face >= 0 && rule.face < faces && rule.from >= 0 && rule.from < faces;
    if (!inRange || !anyPrescribed || !boundary.prescribedFace[rule.face] || boundary.prescribedFace[rule.from])
      throw std::invalid_argument("FaceBoundary: a ghost rule needs a prescribed face and a free face to extend from");
    if (layout.faceCoord(rule.face).first != layout.faceCoord(rule.from).first)
      throw std::invalid_argument("FaceBoundary: a ghost rule joins faces of different axes");
    if (!(rule.factor >= -1 && rule.factor <= 0))
      throw std::invalid_argument("FaceBoundary: ghost factor must lie in [-1, 0]");
  }
  if (boundary.solidCell.empty()) return;
  // The sampler and ENO never read the field on faces touching a structure, so those faces need
  // a prescribed (structure) velocity: thesis Sec. 5.4.1 places the constraints exactly there.
  int firstUnprescribed = faces;
  forEachFaceOfSolidCells(layout, boundary.solidCell, [&](int g, int, const typename MacLayout<d>::Index&) {
    if (!(anyPrescribed && boundary.prescribedFace[g])) firstUnprescribed = std::min(firstUnprescribed, g);
  });
  if (firstUnprescribed < faces)
    throw std::invalid_argument("FaceBoundary: face " + std::to_string(firstUnprescribed) +
                                " touches a solid cell but has no prescribed velocity");
}

double ghostFactor(double theta) {
  if (!(theta > 0) || !std::isfinite(theta)) throw std::invalid_argument("ghostFactor: theta must be finite and > 0");
  return std::clamp(-(1.0 - theta) / theta, -1.0, 0.0);
}

template <int d>
FaceBoundary staticObstacleBoundary(const MacLayout<d>& layout, std::vector<std::uint8_t> solidCell) {
  if (!solidCell.empty() && static_cast<int>(solidCell.size()) != layout.cellCount())
    throw std::invalid_argument("staticObstacleBoundary: solidCell needs one flag per cell");
  FaceBoundary boundary;
  const int faces = layout.totalFaces();
  boundary.prescribedFace.assign(faces, 0);
  boundary.prescribedVelocity = Eigen::VectorXd::Zero(faces);
  for (int g = 0; g < faces; ++g) {
    const auto [axis, f] = layout.faceCoord(g);
    const bool wall = !layout.periodic[axis] && (f[axis] == 0 || f[axis] == layout.cells[axis]);
    const bool touchesSolid = !solidCell.empty() && anyNeighbourSolid(layout, solidCell, axis, f);
    boundary.prescribedFace[g] = (wall || touchesSolid) ? 1 : 0;
  }
  boundary.solidCell = std::move(solidCell);
  return boundary;
}

template <int d>
FaceVelocitySampler<d>::FaceVelocitySampler(const MacLayout<d>& layout, const Eigen::VectorXd& u,
                                            const FaceBoundary& boundary)
    : layout_(layout), u_(&u), boundary_(&boundary) {
  if (u.size() != layout.totalFaces())
    throw std::invalid_argument("FaceVelocitySampler: field needs one value per face");
  for (int axis = 0; axis < d; ++axis) {
    faceOffset_[axis] = layout.faceOffset(axis);
    faceStride_[axis] = MacLayout<d>::strides(layout.faceDims(axis));
  }
  validateBoundary(layout, boundary);
  if (!boundary.ghosts.empty()) {
    std::vector<double> sum(layout.totalFaces(), 0.0);
    std::vector<int> count(layout.totalFaces(), 0);
    for (const GhostRule& rule : boundary.ghosts) {  // in list order: the sums do not depend on threads
      const double wall = boundary.prescribedVelocity[rule.face];
      sum[rule.face] += wall + rule.factor * (u[rule.from] - wall);
      ++count[rule.face];
    }
    ghost_.assign(layout.totalFaces(), std::numeric_limits<double>::quiet_NaN());
    for (int g = 0; g < layout.totalFaces(); ++g)
      if (count[g] > 0) ghost_[g] = sum[g] / count[g];
  }
  read_.resize(layout.totalFaces());
  dropped_.assign(layout.totalFaces(), 0);
  for (int g = 0; g < layout.totalFaces(); ++g)
    read_[g] = hasGhost(g) ? ghost_[g] : faceValue(g);
  if (!hasSolids()) return;
  insideSolid_.assign(layout.totalFaces(), 0);
  forEachFaceOfSolidCells(layout, boundary.solidCell, [&](int g, int axis, const Index& f) {
    int cells[2];
    const int count = faceNeighbourCells(layout, axis, f, cells);
    bool inside = count > 0;
    for (int k = 0; k < count; ++k) inside = inside && boundary.solidCell[cells[k]];
    insideSolid_[g] = inside;
    dropped_[g] = inside && !hasGhost(g);
  });
  bool periodic = false;
  for (int a = 0; a < d; ++a) periodic = periodic || layout.periodic[a];
  if (!periodic) solidDistance_ = chessboardDistanceToSolid(layout, boundary.solidCell, kFarFromSolid);
}

template <int d>
FaceVelocitySampler<d>::FaceVelocitySampler(const MacLayout<d>& layout, const Eigen::VectorXd& u)
    : FaceVelocitySampler(layout, u, [] () -> const FaceBoundary& {
        static const FaceBoundary none;
        return none;
      }()) {}

template <int d>
bool FaceVelocitySampler<d>::faceInsideSolid(int axis, const Index& f) const {
  return insideSolid(layout_.faceIndex(axis, f));
}

template <int d>
typename FaceVelocitySampler<d>::Index FaceVelocitySampler<d>::cellOf(const Vec& x) const {
  Index c;
  for (int a = 0; a < d; ++a) {
    const double s = std::floor((x[a] - layout_.origin[a]) / layout_.dx);
    if (!std::isfinite(s)) throw std::domain_error("FaceVelocitySampler: non-finite sample position");
    const int n = layout_.cells[a];
    if (layout_.periodic[a]) {
      c[a] = wrapIndex(static_cast<long long>(s), n);
    } else {
      c[a] = static_cast<int>(std::clamp(s, 0.0, static_cast<double>(n - 1)));
    }
  }
  return c;
}

template <int d>
bool FaceVelocitySampler<d>::pointInSolid(const Vec& x) const {
  return hasSolids() && boundary_->solidCell[layout_.cellIndex(cellOf(x))] != 0;
}

template <int d>
double FaceVelocitySampler<d>::component(int axis, const Vec& x, std::pair<double, double>* range) const {
  Index lo, hi;
  double t[d];
  for (int b = 0; b < d; ++b) {
    // Face-grid coordinate: faces of `axis` sit at integer positions along `axis` and at cell
    // centres (half-integers) along the other axes.
    const double s = (x[b] - layout_.origin[b]) / layout_.dx - (b == axis ? 0.0 : 0.5);
    if (!std::isfinite(s)) throw std::domain_error("FaceVelocitySampler: non-finite sample position");
    if (layout_.periodic[b]) {
      const double fl = std::floor(s);
      const int n = layout_.cells[b];
      t[b] = s - fl;
      lo[b] = wrapIndex(static_cast<long long>(fl), n);
      hi[b] = lo[b] + 1 == n ? 0 : lo[b] + 1;
    } else {
      const int nodes = layout_.cells[b] + (b == axis ? 1 : 0);
      if (nodes == 1) {
        lo[b] = hi[b] = 0;
        t[b] = 0;
        continue;
      }
      const double clamped = std::clamp(s, 0.0, static_cast<double>(nodes - 1));  // rule 2
      lo[b] = std::min(static_cast<int>(clamped), nodes - 2);
      hi[b] = lo[b] + 1;
      t[b] = clamped - lo[b];
    }
  }
  double sum = 0, weightSum = 0, solidSum = 0;
  bool dropped = false;
  double fluidLo = std::numeric_limits<double>::infinity(), fluidHi = -fluidLo;
  double solidLo = fluidLo, solidHi = -fluidLo;
  // lo and hi lie inside the stored face grid (periodic axes wrapped above): the tabulated
  // strides give layout_.faceIndex(axis, corner) exactly.
  const std::array<int, d>& stride = faceStride_[axis];
  for (int corner = 0; corner < (1 << d); ++corner) {
    int face = faceOffset_[axis];
    double w = 1;
    for (int b = 0; b < d; ++b) {
      const bool upper = (corner >> b) & 1;
      face += (upper ? hi[b] : lo[b]) * stride[b];
      w *= upper ? t[b] : 1 - t[b];
    }
    if (w == 0) continue;  // also keeps exact face-centre samples free of neighbour values
    const double value = read_[face];  // rules 3, 3b
    if (!dropped_.empty() && dropped_[face]) {  // rule 4
      dropped = true;
      solidSum += w * value;
      solidLo = std::min(solidLo, value), solidHi = std::max(solidHi, value);
      continue;
    }
    sum += w * value;
    weightSum += w;
    fluidLo = std::min(fluidLo, value), fluidHi = std::max(fluidHi, value);
  }
  const bool fromFluid = !dropped || weightSum > 0;
  if (range) *range = fromFluid ? std::make_pair(fluidLo, fluidHi) : std::make_pair(solidLo, solidHi);
  if (!dropped) return sum;
  return weightSum > 0 ? sum / weightSum : solidSum;
}

template <int d>
typename FaceVelocitySampler<d>::Vec FaceVelocitySampler<d>::velocity(const Vec& x) const {
  Vec v;
  for (int a = 0; a < d; ++a) v[a] = component(a, x);
  return v;
}

template <int d>
typename FaceVelocitySampler<d>::Vec FaceVelocitySampler<d>::clipToFluid(const Vec& from, const Vec& to) const {
  if (!hasSolids()) return to;
  const int fromCell = layout_.cellIndex(cellOf(from));
  if (boundary_->solidCell[fromCell]) return from;
  // Every point of the segment lies in a cell at most floor(length / dx) + 1 cells from
  // `from`'s along each axis: if the nearest solid cell is farther, the walk below would find
  // none. Asked as length < (distance - 2) dx, squared (no root on this hot path), which keeps a
  // cell of margin for rounding; a non-finite trace fails the test and is caught below.
  if (!solidDistance_.empty()) {
    const int free = solidDistance_[fromCell] - 2;
    const double reach = free * layout_.dx;
    if (free > 0 && (to - from).squaredNorm() < reach * reach) return to;
  }
  const double length = (to - from).norm();
  if (!std::isfinite(length)) throw std::domain_error("FaceVelocitySampler: non-finite trace");
  // Quarter-cell steps: a cell can then only be missed by cutting one of its corners.
  const double steps = std::min(std::ceil(length / (0.25 * layout_.dx)), 1048576.0);
  const int n = std::max(1, static_cast<int>(steps));
  Vec previous = from;
  for (int k = 1; k <= n; ++k) {
    const Vec p = k == n ? to : Vec(from + (static_cast<double>(k) / n) * (to - from));
    if (pointInSolid(p)) {
      Vec fluid = previous, solid = p;
      for (int it = 0; it < 40; ++it) {  // interval shrinks to 2^-40 of a quarter cell
        const Vec mid = 0.5 * (fluid + solid);
        (pointInSolid(mid) ? solid : fluid) = mid;
      }
      return fluid;
    }
    previous = p;
  }
  return to;
}

template void validateBoundary<2>(const MacLayout<2>&, const FaceBoundary&);
template void validateBoundary<3>(const MacLayout<3>&, const FaceBoundary&);
template FaceBoundary staticObstacleBoundary<2>(const MacLayout<2>&, std::vector<std::uint8_t>);
template FaceBoundary staticObstacleBoundary<3>(const MacLayout<3>&, std::vector<std::uint8_t>);
template class FaceVelocitySampler<2>;
template class FaceVelocitySampler<3>;

}  // namespace monolith::solvers
