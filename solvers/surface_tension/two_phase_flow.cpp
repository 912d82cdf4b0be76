#include "solvers/surface_tension/two_phase_flow.h"

#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "solvers/advection/eno.h"
#include "solvers/advection/semi_lagrangian.h"
#include "solvers/fluid/parallel.h"
#include "solvers/surface_tension/face_extrapolation.h"
#include "solvers/surface_tension/level_set_front.h"
#include "solvers/surface_tension/fast_marching.h"
#include "solvers/surface_tension/level_set_tracking.h"

namespace monolith::solvers {

using Index2 = Eigen::Vector2i;
using Triplets = std::vector<Eigen::Triplet<double>>;

TwoPhaseState makeTwoPhaseState(const MacLayout<2>& layout, Front2 front) {
  if (layout.periodic[0] || layout.periodic[1]) throw std::invalid_argument("two-phase flow: periodic axes are not supported");
  TwoPhaseState s;
  s.layout = layout;
  s.u = Eigen::VectorXd::Zero(layout.totalFaces());
  s.front = std::move(front);
  s.pInside.assign(layout.cellCount(), 0.0);
  s.pOutside.assign(layout.cellCount(), 0.0);
  return s;
}

double sampleFaceVelocity(const MacLayout<2>& layout, const Eigen::VectorXd& u, int axis, const Eigen::Vector2d& x) {
  const Index2 dims = layout.faceDims(axis);
  // Face (i, j) of `axis` sits at origin + dx (i, j) + dx/2 on the other axis.
  Eigen::Vector2d g = (x - layout.origin) / layout.dx;
  g[1 - axis] -= 0.5;
  double w[2];
  int lo[2];
  for (int a = 0; a < 2; ++a) {
    const double c = std::clamp(g[a], 0.0, static_cast<double>(dims[a] - 1));
    lo[a] = std::min(static_cast<int>(std::floor(c)), dims[a] - 2 < 0 ? 0 : dims[a] - 2);
    w[a] = dims[a] > 1 ? c - lo[a] : 0.0;
  }
  double sum = 0;
  for (int dj = 0; dj < 2; ++dj)
    for (int di = 0; di < 2; ++di) {
      const double weight = (di ? w[0] : 1 - w[0]) * (dj ? w[1] : 1 - w[1]);
      if (weight == 0) continue;
      sum += weight * u[layout.faceIndex(axis, Index2(lo[0] + di, lo[1] + dj))];
    }
  return sum;
}

std::pair<double, double> velocityNorms(const Eigen::VectorXd& u) {
  if (u.size() == 0) return {0, 0};
  return {u.cwiseAbs().mean(), u.cwiseAbs().maxCoeff()};
}

namespace {

struct Piece {
  int cell, segment;
  double alpha, beta;
};

// The parts of every segment inside each cell (the alpha/beta of Sec. 6.3.5), and the crossings of
// the grid lines: per x-face (vertical line pieces) and y-face the fractions along the face where a
// segment crosses, by the half-open rule of insideFront.
struct FrontOnGrid {
  std::vector<Piece> pieces;
  std::vector<std::vector<double>> faceCrossings;  // per grid face
};

FrontOnGrid placeFront(const MacLayout<2>& layout, const Front2& front) {
  FrontOnGrid g;
  g.faceCrossings.resize(layout.totalFaces());
  const double dx = layout.dx;
  const Index2 n = layout.cells;
  for (int s = 0; s < front.elementCount(); ++s) {
    const Eigen::Vector2d a = front.points[front.elements[s][0]], b = front.points[front.elements[s][1]];
    const Eigen::Vector2d ga = (a - layout.origin) / dx, gb = (b - layout.origin) / dx;
    std::vector<double> ts{0.0, 1.0};
    for (int axis = 0; axis < 2; ++axis) {
      const double lo = std::max(std::min(ga[axis], gb[axis]), 0.0), hi = std::min(std::max(ga[axis], gb[axis]), 1.0 * n[axis]);
      for (int line = static_cast<int>(std::ceil(lo)); line <= static_cast<int>(std::floor(hi)); ++line) {
        if (line < 0 || line > n[axis]) continue;
        const double A = ga[axis], B = gb[axis], L = line;
        const bool crossing = (A <= L && L < B) || (B <= L && L < A);
        if (A != B) {
          const double t = (L - A) / (B - A);
          if (t > 0 && t < 1) ts.push_back(t);
        }
        if (!crossing) continue;
        const double t = (L - A) / (B - A);
        const double other = ga[1 - axis] + t * (gb[1 - axis] - ga[1 - axis]);
        const int k = static_cast<int>(std::floor(other));
        if (k < 0 || k >= n[1 - axis]) continue;
        Index2 f;
        f[axis] = line;
        f[1 - axis] = k;
        g.faceCrossings[layout.faceIndex(axis, f)].push_back(other - k);
      }
    }
    std::sort(ts.begin(), ts.end());
    for (std::size_t q = 0; q + 1 < ts.size(); ++q) {
      if (!(ts[q + 1] > ts[q])) continue;
      const Eigen::Vector2d mid = ga + 0.5 * (ts[q] + ts[q + 1]) * (gb - ga);
      Index2 c(std::clamp(static_cast<int>(std::floor(mid.x())), 0, n.x() - 1),
               std::clamp(static_cast<int>(std::floor(mid.y())), 0, n.y() - 1));
      g.pieces.push_back({layout.cellIndex(c), s, ts[q], ts[q + 1]});
    }
  }
  for (auto& c : g.faceCrossings) std::sort(c.begin(), c.end());
  return g;
}

}  // namespace

InterfaceDiscretization discretizeInterface(const MacLayout<2>& layout, const Front2& front,
                                            const TwoPhaseSettings& settings, double dt) {
  InterfaceDiscretization D;
  const double dx = layout.dx;
  const int nc = layout.cellCount(), nf = layout.totalFaces();
  const Index2 n = layout.cells;
  const FrontOnGrid placed = placeFront(layout, front);
  const bool two = !settings.onePhase;
  const double rhoIn = settings.densityInside, rhoOut = two ? settings.densityOutside : 0.0;

  // Inside status of the nodes on each horizontal grid line: parity of the y-face crossings left of them.
  std::vector<char> nodeInside(static_cast<std::size_t>(n.x() + 1) * (n.y() + 1), 0);
  for (int j = 0; j <= n.y(); ++j) {
    bool inside = false;
    for (int i = 0; i <= n.x(); ++i) {
      nodeInside[static_cast<std::size_t>(j) * (n.x() + 1) + i] = inside;
      if (i < n.x()) inside ^= (placed.faceCrossings[layout.faceIndex(1, Index2(i, j))].size() % 2) == 1;
    }
  }
  // Inside length of every grid face: start from its lower/left node, toggle at each crossing.
  D.insideLength.assign(nf, 0.0);
  for (int f = 0; f < nf; ++f) {
    const auto [axis, idx] = layout.faceCoord(f);
    bool inside = nodeInside[static_cast<std::size_t>(idx.y()) * (n.x() + 1) + idx.x()];
    double last = 0, length = 0;
    for (double t : placed.faceCrossings[f]) {
      if (inside) length += t - last;
      inside = !inside;
      last = t;
    }
    if (inside) length += 1 - last;
    D.insideLength[f] = length * dx;
  }
  // Cut cells and their coupling faces.
  D.cutCell.assign(nc, 0);
  std::vector<Eigen::Vector2d> normalSum(nc, Eigen::Vector2d::Zero()), centroid(nc, Eigen::Vector2d::Zero());
  std::vector<double> pieceLength(nc, 0.0);
  for (const Piece& p : placed.pieces) {
    const Eigen::Vector2d a = front.points[front.elements[p.segment][0]], b = front.points[front.elements[p.segment][1]];
    const Eigen::Vector2d e = b - a;
    normalSum[p.cell] += (p.beta - p.alpha) * Eigen::Vector2d(e.y(), -e.x());
    const double len = (p.beta - p.alpha) * e.norm();
    centroid[p.cell] += len * (a + 0.5 * (p.alpha + p.beta) * e);
    pieceLength[p.cell] += len;
    D.cutCell[p.cell] = 1;
  }
  // The node parity above is ambiguous at a node the front passes through (a front point on a grid
  // node: the node counts as on one side, and a face that only touches the front there gets the
  // wrong phase). Next to cut cells each stretch of a face between crossings is therefore classified
  // by the inside test of its midpoint instead.
  for (int f = 0; f < nf; ++f) {
    const auto [axis, idx] = layout.faceCoord(f);
    Index2 lower = idx;
    lower[axis] -= 1;
    const bool nearCut = (idx[axis] < n[axis] && D.cutCell[layout.cellIndex(idx)]) ||
                         (lower[axis] >= 0 && D.cutCell[layout.cellIndex(lower)]);
    if (!nearCut) continue;
    const Eigen::Vector2d start = layout.origin + dx * idx.cast<double>();
    Eigen::Vector2d along = Eigen::Vector2d::Zero();
    along[1 - axis] = dx;
    double last = 0, length = 0;
    std::vector<double> ends = placed.faceCrossings[f];
    ends.push_back(1.0);
    for (double t : ends) {
      if (t > last && insideFront(front, start + 0.5 * (last + t) * along)) length += t - last;
      last = t;
    }
    D.insideLength[f] = length * dx;
  }
  // Pressure unknowns. An uncut cell's phase is its left face's (all its faces are uncut).
  D.insideDof.assign(nc, -1);
  D.outsideDof.assign(nc, -1);
  for (int c = 0; c < nc; ++c) {
    const Index2 ci = layout.cellCoord(c);
    const bool inside = D.cutCell[c] || D.insideLength[layout.faceIndex(0, ci)] > 0.5 * dx;
    const bool outside = D.cutCell[c] || !inside;
    if (inside) D.insideDof[c] = D.pressureCount++;
    if (outside && two) D.outsideDof[c] = D.pressureCount++;
  }
  // Velocity unknowns: interior grid faces (with an inside part in one phase), then coupling faces.
  D.faceUnknown.assign(nf, -1);
  for (int f = 0; f < nf; ++f) {
    const auto [axis, idx] = layout.faceCoord(f);
    if (idx[axis] == 0 || idx[axis] == n[axis]) continue;  // walls
    if (!two && !(D.insideLength[f] > 0)) continue;
    D.faceUnknown[f] = static_cast<int>(D.unknownFace.size());
    D.unknownFace.push_back(f);
  }
  D.gridUnknowns = static_cast<int>(D.unknownFace.size());
  std::vector<int> cellCoupling(nc, -1);
  for (int c = 0; c < nc; ++c) {
    if (!D.cutCell[c]) continue;
    const double length = normalSum[c].norm();
    if (!(length > 1e-12 * dx)) continue;
    cellCoupling[c] = D.gridUnknowns + static_cast<int>(D.couplingCell.size());
    D.couplingCell.push_back(c);
    D.couplingNormal.push_back(normalSum[c] / length);
    D.couplingLength.push_back(length);
    D.couplingCentre.push_back(centroid[c] / pieceLength[c]);
  }
  const int nu = D.gridUnknowns + static_cast<int>(D.couplingCell.size());
  D.beta.resize(nu);
  Triplets g;
  auto dofOf = [&](int cell, bool insidePart) {
    const int want = insidePart ? D.insideDof[cell] : D.outsideDof[cell];
    if (want >= 0) return want;
    // A part the classification missed (a front touching a corner): use the cell's other phase in
    // two-phase flow; in one phase the missing outside part is the Dirichlet air.
    return two || insidePart ? (insidePart ? D.outsideDof[cell] : D.insideDof[cell]) : -1;
  };
  for (int q = 0; q < D.gridUnknowns; ++q) {
    const int f = D.unknownFace[q];
    const auto [axis, idx] = layout.faceCoord(f);
    Index2 lower = idx;
    lower[axis] -= 1;
    const int cu = layout.cellIndex(idx), cl = layout.cellIndex(lower);
    const double lin = D.insideLength[f], lout = dx - lin;
    D.beta[q] = (rhoIn * lin + rhoOut * lout) * dx;
    if (lin > 0) {
      const int u = dofOf(cu, true), l = dofOf(cl, true);
      if (u >= 0) g.emplace_back(q, u, lin);
      if (l >= 0) g.emplace_back(q, l, -lin);
    }
    if (two && lout > 0) {
      const int u = dofOf(cu, false), l = dofOf(cl, false);
      if (u >= 0) g.emplace_back(q, u, lout);
      if (l >= 0) g.emplace_back(q, l, -lout);
    }
  }
  for (std::size_t k = 0; k < D.couplingCell.size(); ++k) {
    const int q = D.gridUnknowns + static_cast<int>(k), c = D.couplingCell[k];
    const double l = D.couplingLength[k];
    D.beta[q] = 0.5 * l * dx * (rhoIn + rhoOut);
    g.emplace_back(q, D.insideDof[c], -l);
    if (two) g.emplace_back(q, D.outsideDof[c], l);
  }
  // A phase part whose faces are all of roundoff length (a front through a cell corner) would
  // put a ~1e-30 entry on the diagonal and break the Jacobi-preconditioned CG: such parts get no
  // faces (their pressure unknown is left out of every row; its zero column is harmless).
  {
    std::vector<double> column(D.pressureCount, 0.0);
    for (const auto& t : g) column[t.col()] += t.value() * t.value() / D.beta[t.row()];
    const double full = 4.0 / std::max(rhoIn, rhoOut);  // a whole cell's G^T beta^-1 G diagonal
    Triplets kept;
    for (const auto& t : g)
      if (column[t.col()] > 1e-12 * full) kept.push_back(t);
    g.swap(kept);
  }
  D.G.resize(nu, D.pressureCount);
  D.G.setFromTriplets(g.begin(), g.end());

  // Viscous rows on the grid faces.
  Triplets v;
  int rows = 0;
  if (settings.viscosity > 0) {
    const double w = std::sqrt(dt * settings.viscosity);
    for (int q = 0; q < D.gridUnknowns; ++q) {
      const auto [axis, idx] = layout.faceCoord(D.unknownFace[q]);
      const Index2 dims = layout.faceDims(axis);
      for (int b = 0; b < 2; ++b)
        for (int dir : {-1, 1}) {
          Index2 m = idx;
          m[b] += dir;
          if (m[b] < 0 || m[b] >= dims[b]) {  // beyond a side (b != axis): no-slip mirrored ghost
            v.emplace_back(rows++, q, -std::sqrt(2.0) * w);
            continue;
          }
          const int other = layout.faceIndex(axis, m);
          if (b == axis && (m[axis] == 0 || m[axis] == n[axis])) {  // a wall face: its velocity is 0
            v.emplace_back(rows++, q, -w);
            continue;
          }
          const int r = D.faceUnknown[other];
          if (r < 0 || dir < 0) continue;  // air (one phase: no row) / the pair is counted from below
          v.emplace_back(rows, q, -w);
          v.emplace_back(rows++, r, w);
        }
    }
  }
  D.Gmu.resize(rows, nu);
  D.Gmu.setFromTriplets(v.begin(), v.end());

  // H^T: force density integrated over each piece, on the coupling face of its cell.
  std::vector<double> segLength(front.elementCount()), pointLength(front.pointCount(), 0.0);
  for (int s = 0; s < front.elementCount(); ++s) {
    segLength[s] = (front.points[front.elements[s][1]] - front.points[front.elements[s][0]]).norm();
    pointLength[front.elements[s][0]] += 0.5 * segLength[s];
    pointLength[front.elements[s][1]] += 0.5 * segLength[s];
  }
  Triplets h;
  for (const Piece& p : placed.pieces) {
    const int q = cellCoupling[p.cell];
    if (q < 0) continue;
    const Eigen::Vector2d nh = D.couplingNormal[q - D.gridUnknowns];
    const int k0 = front.elements[p.segment][0], k1 = front.elements[p.segment][1];
    const double span = p.beta - p.alpha, mid = 0.5 * (p.alpha + p.beta);
    const double w0 = segLength[p.segment] * span * (1 - mid) / pointLength[k0];
    const double w1 = segLength[p.segment] * span * mid / pointLength[k1];
    for (int a = 0; a < 2; ++a) {
      h.emplace_back(q, 2 * k0 + a, w0 * nh[a]);
      h.emplace_back(q, 2 * k1 + a, w1 * nh[a]);
    }
  }
  D.Ht.resize(nu, 2 * front.pointCount());
  D.Ht.setFromTriplets(h.begin(), h.end());

  // C H: per segment, dt sqrt(sigma / l) n^T (H_{k0} - H_{k1}).
  D.CH.resize(settings.implicitSurfaceTension && settings.sigma > 0 ? front.elementCount() : 0, nu);
  if (D.CH.rows() > 0) {
    const Eigen::SparseMatrix<double, Eigen::RowMajor> H = D.Ht.transpose();  // 2 points x unknowns
    Triplets ch;
    for (int s = 0; s < front.elementCount(); ++s) {
      const int k0 = front.elements[s][0], k1 = front.elements[s][1];
      const Eigen::Vector2d t = (front.points[k1] - front.points[k0]) / segLength[s];
      const Eigen::Vector2d ns(t.y(), -t.x());
      const double c = dt * std::sqrt(settings.sigma / segLength[s]);
      // Rows of H for the two points: columns of H^T 2k+a.
      for (int a = 0; a < 2; ++a) {
        using It = Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator;
        for (It it(H, 2 * k0 + a); it; ++it) ch.emplace_back(s, it.col(), c * ns[a] * it.value());
        for (It it(H, 2 * k1 + a); it; ++it) ch.emplace_back(s, it.col(), -c * ns[a] * it.value());
      }
    }
    D.CH.setFromTriplets(ch.begin(), ch.end());
  }
  return D;
}

namespace {

// One phase: give the air faces velocities for the advection from their known neighbours
// (face_extrapolation.h).
void extrapolateToAir(const MacLayout<2>& layout, const InterfaceDiscretization& D, Eigen::VectorXd& u) {
  std::vector<char> known(layout.totalFaces(), 0);
  for (int f = 0; f < layout.totalFaces(); ++f) {
    const auto [axis, idx] = layout.faceCoord(f);
    known[f] = D.faceUnknown[f] >= 0 || idx[axis] == 0 || idx[axis] == layout.cells[axis];
  }
  extrapolateToUnknownFaces(layout, std::move(known), u);
}

// ENO/RK3 is stable up to CFL ~1: with a CFL bound, the step is split into that many substeps.
int advectionSubsteps(const MacLayout<2>& layout, const Eigen::VectorXd& u, double dt, double cflBound) {
  if (!(cflBound > 0) || u.size() == 0) return 1;
  const double cfl = u.cwiseAbs().maxCoeff() * dt / layout.dx;
  return std::max(1, static_cast<int>(std::ceil(cfl / cflBound)));
}

// u* of each coupling face i from the front points' carried velocities v_k:
// n^_i . sum_k w_ik v_k / sum_k w_ik, w_ik the weights of H^T (6.38; H^T_{i,k} = w_ik n^_i), plus
// the gravity increment. A face whose weights vanish keeps its sampled u*.
void carriedCouplingVelocities(const InterfaceDiscretization& D, const std::vector<Eigen::Vector2d>& v,
                               const Eigen::Vector2d& gravityIncrement, Eigen::VectorXd& ustar) {
  const Eigen::SparseMatrix<double, Eigen::RowMajor> rows = D.Ht;
  for (int q = D.gridUnknowns; q < rows.rows(); ++q) {
    const Eigen::Vector2d& normal = D.couplingNormal[q - D.gridUnknowns];
    double weight = 0, sum = 0;
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(rows, q); it; ++it) {
      const int k = static_cast<int>(it.col()) / 2, axis = static_cast<int>(it.col()) % 2;
      weight += it.value() * normal[axis];
      sum += it.value() * v[k][axis];
    }
    if (weight > 1e-12) ustar[q] = sum / weight + gravityIncrement.dot(normal);
  }
}

// Marks the step as blown up, with a reason that names the variant ("implicit surface tension blew
// up ..."); `write` appends when and why.
template <class Write>
void reportBlowUp(TwoPhaseStepReport& report, const TwoPhaseSettings& settings, Write write) {
  report.blewUp = true;
  std::ostringstream why;
  why << (settings.implicitSurfaceTension ? "implicit" : "explicit") << " surface tension blew up ";
  write(why);
  report.blowUpReason = why.str();
}

// The level set's mesh; a level set so distorted that its marching-squares segments no longer
// chain into curves (two segments leaving one crossing) is a blow-up, reported as such.
bool rebuildFront(TwoPhaseState& state, const MacLayout<2>& layout, const TwoPhaseSettings& settings,
                  TwoPhaseStepReport& report) {
  try {
    state.front = frontFromLevelSet(layout, state.phi, CrossingOrder::Fourth, 0.1,
                                    settings.onePhase ? 0.0 : settings.levelSetNodeSnap);
    return true;
  } catch (const std::invalid_argument&) {
    reportBlowUp(report, settings, [&](std::ostream& why) {
      why << "at step " << state.step + 1 << " (t = " << state.time << "): the level set's mesh no longer forms closed curves";
    });
    return false;
  }
}

// A moved level set made a distance again beyond levelSetKeep cells (the particles correct it once
// more after fast marching and take their new radii), and the mesh rebuilt from it; the particles
// are reseeded every particleSettings.reseedEvery steps.
void redistanceLevelSet(TwoPhaseState& state, const MacLayout<2>& layout, const TwoPhaseSettings& settings,
                        TwoPhaseStepReport& report) {
  if (settings.levelSetRedistancing == LevelSetRedistancing::FastMarching) {
    fastMarchingRedistance(layout, state.phi, 5, settings.levelSetKeep);
    if (settings.particleLevelSet) correctWithParticles(layout, state.levelSetParticles, state.phi);
  }
  if (settings.particleLevelSet) adjustParticleRadii(layout, state.phi, state.levelSetParticles, settings.particleSettings);
  if (rebuildFront(state, layout, settings, report) && settings.levelSetRedistancing == LevelSetRedistancing::ToMesh)
    redistanceToFront(layout, state.front, state.phi, 5, settings.levelSetKeep);
  // Reseeding against the redistanced phi; the step number seeds it, so restarts reseed alike.
  const int reseedEvery = settings.particleSettings.reseedEvery;
  if (settings.particleLevelSet && reseedEvery > 0 && (state.step + 1) % reseedEvery == 0)
    reseedParticles(layout, state.phi, state.levelSetParticles, static_cast<std::uint64_t>(state.step + 1),
                    settings.particleSettings);
}
}  // namespace

TwoPhaseStepReport advanceTwoPhase(TwoPhaseState& state, const TwoPhaseSettings& settings, double dt) {
  if (!(dt > 0) || !std::isfinite(dt)) throw std::invalid_argument("advanceTwoPhase: dt must be positive and finite");
  TwoPhaseStepReport report;
  const MacLayout<2>& layout = state.layout;
  const double dx = layout.dx;
  // The guard's second half: a front that left the domain (or is no longer finite) is not stepped.
  const Eigen::Vector2d upper = layout.origin + dx * layout.cells.cast<double>();
  for (const auto& x : state.front.points)
    if (!x.allFinite() || (x.array() < layout.origin.array()).any() || (x.array() > upper.array()).any()) {
      reportBlowUp(report, settings, [&](std::ostream& why) {
        why << "before step " << state.step + 1 << " (t = " << state.time << "): the front left the domain";
      });
      return report;
    }
  if (settings.levelSetFront) {
    if (static_cast<int>(state.phi.size()) != layout.cellCount())
      throw std::invalid_argument("advanceTwoPhase: a level-set front needs phi on every cell");
    if (!rebuildFront(state, layout, settings, report)) return report;
  }
  const InterfaceDiscretization D = discretizeInterface(layout, state.front, settings, dt);
  const int nu = D.unknowns(), np = D.pressureCount;

  // u*: advection, gravity, then the coupling faces' normal velocity and the explicit force.
  Eigen::VectorXd u = state.u;
  if (settings.onePhase) extrapolateToAir(layout, D, u);
  if (settings.advection == TwoPhaseAdvection::SemiLagrangian) u = advectFacesSemiLagrangian(layout, u, dt);
  if (settings.advection == TwoPhaseAdvection::EnoRk3) {
    const int substeps = advectionSubsteps(layout, u, dt, settings.advectionCfl);
    for (int k = 0; k < substeps; ++k) u = advectFacesEnoRk3(layout, u, dt / substeps);
  }
  Eigen::VectorXd ustar(nu);
  for (int q = 0; q < D.gridUnknowns; ++q) {
    const int f = D.unknownFace[q];
    ustar[q] = u[f] + dt * settings.gravity[layout.faceCoord(f).first];
  }
  for (int q = D.gridUnknowns; q < nu; ++q) {
    const int k = q - D.gridUnknowns;
    const Eigen::Vector2d x = D.couplingCentre[k];
    const Eigen::Vector2d velocity(sampleFaceVelocity(layout, u, 0, x), sampleFaceVelocity(layout, u, 1, x));
    ustar[q] = velocity.dot(D.couplingNormal[k]) + dt * settings.gravity.dot(D.couplingNormal[k]);
  }
  if (settings.carryCouplingVelocity && !settings.levelSetFront && !state.pointVelocity.empty() &&
      static_cast<int>(state.pointVelocity.size()) == state.front.pointCount())
    carriedCouplingVelocities(D, state.pointVelocity, dt * settings.gravity, ustar);
  if (settings.sigma > 0) {
    const auto forces = surfaceTensionForces(state.front, settings.sigma);
    Eigen::VectorXd f(2 * forces.size());
    for (std::size_t k = 0; k < forces.size(); ++k) f.segment<2>(2 * static_cast<long>(k)) = forces[k];
    ustar += dt * (D.Ht * f).cwiseQuotient(D.beta);
  }

  // (6.33): (P + K beta^-1 K^T) z = K u*.
  const int nv = static_cast<int>(D.Gmu.rows()), ns = static_cast<int>(D.CH.rows());
  Eigen::SparseMatrix<double> K(np + nv + ns, nu);
  {
    Triplets k;
    const Eigen::SparseMatrix<double> Gt = D.G.transpose();
    auto add = [&](const Eigen::SparseMatrix<double>& M, int offset) {
      for (int o = 0; o < M.outerSize(); ++o)
        for (Eigen::SparseMatrix<double>::InnerIterator it(M, o); it; ++it) k.emplace_back(offset + it.row(), it.col(), it.value());
    };
    add(Gt, 0);
    add(D.Gmu, np);
    add(D.CH, np + nv);
    K.setFromTriplets(k.begin(), k.end());
  }
  const Eigen::VectorXd betaInv = D.beta.cwiseInverse();
  // The operator is applied as P z + K (beta^-1 (K^T z)), not assembled: K has about 2-4 entries a
  // row and K beta^-1 K^T about 10-20 (each face couples its two pressures and its four viscous
  // rows), so the two products read a third of the memory, and the solve is most of a step's time.
  // Both are stored row-major and applied row by row (each row written by one task: deterministic).
  using RowMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;
  const RowMatrix Krows = K, KtRows = K.transpose();
  const int rows = np + nv + ns;
  const Eigen::VectorXd b = K * ustar;
  Eigen::VectorXd z = Eigen::VectorXd::Zero(rows);
  for (int c = 0; c < layout.cellCount(); ++c) {  // warm start from the last pressures
    if (D.insideDof[c] >= 0) z[D.insideDof[c]] = dt * state.pInside[c];
    if (D.outsideDof[c] >= 0) z[D.outsideDof[c]] = dt * state.pOutside[c];
  }
  // Two phases in a closed box: the constant pressure is the null space (Sec. 6.2.6).
  Projector project;
  if (!settings.onePhase) {
    project = [np](Eigen::VectorXd& x) {
      if (np == 0) return;
      x.head(np).array() -= x.head(np).mean();
    };
    project(z);
  }
  Eigen::VectorXd diagonal(rows);
  parallel::forRows(rows, [&](int r) {
    double sum = r >= np ? 1.0 : 0.0;
    for (RowMatrix::InnerIterator it(Krows, r); it; ++it) sum += it.value() * it.value() * betaInv[it.index()];
    diagonal[r] = sum > 0 ? sum : 1.0;
  });
  Eigen::VectorXd scaled(nu);
  const LinearOperator apply = [&](const Eigen::VectorXd& in, Eigen::VectorXd& out) {
    parallel::forRows(nu, [&](int q) {
      double sum = 0;
      for (RowMatrix::InnerIterator it(KtRows, q); it; ++it) sum += it.value() * in[it.index()];
      scaled[q] = sum * betaInv[q];
    });
    parallel::forRows(rows, [&](int r) {
      double sum = r >= np ? in[r] : 0.0;
      for (RowMatrix::InnerIterator it(Krows, r); it; ++it) sum += it.value() * scaled[it.index()];
      out[r] = sum;
    });
  };
  report.solve = conjugateGradient(apply, jacobiPreconditioner(diagonal), project, b, z, settings.solve);
  const Eigen::VectorXd unew = ustar - betaInv.cwiseProduct(K.transpose() * z);

  // Write back: grid faces, pressures, then move the front with H u^{n+1} and remesh.
  Eigen::VectorXd next = Eigen::VectorXd::Zero(layout.totalFaces());
  for (int q = 0; q < D.gridUnknowns; ++q) next[D.unknownFace[q]] = unew[q];
  if (settings.onePhase) extrapolateToAir(layout, D, next);
  state.u = next;
  for (int c = 0; c < layout.cellCount(); ++c) {
    state.pInside[c] = D.insideDof[c] >= 0 ? z[D.insideDof[c]] / dt : 0.0;
    state.pOutside[c] = D.outsideDof[c] >= 0 ? z[D.outsideDof[c]] / dt : 0.0;
  }
  if (settings.levelSetFront && settings.levelSetImplicitUpdate) {
    // phi moves with the Lagrangian velocity H u^{n+1}; the mesh is rebuilt from it and phi is
    // redistanced beyond levelSetKeep cells, as below.
    const Eigen::VectorXd v = D.Ht.transpose() * unew;
    std::vector<Eigen::Vector2d> velocity(state.front.pointCount());
    for (int k = 0; k < state.front.pointCount(); ++k) velocity[k] = v.segment<2>(2 * k);
    moveLevelSetWithFront(layout, state.front, velocity, dt, state.phi);
    redistanceLevelSet(state, layout, settings, report);
  } else if (settings.levelSetFront) {
    // The level set moves with the grid velocity (its particles too, with the particle level set,
    // and they correct it); it is redistanced and the mesh rebuilt from it.
    const std::vector<double> previousPhi = settings.particleLevelSet && state.levelSetParticles.empty() ? state.phi
                                                                                                        : std::vector<double>();
    if (settings.advection == TwoPhaseAdvection::EnoRk3) {
      const Eigen::VectorXd phi = Eigen::Map<const Eigen::VectorXd>(state.phi.data(), static_cast<Eigen::Index>(state.phi.size()));
      Eigen::VectorXd next = phi;
      const int substeps = advectionSubsteps(layout, state.u, dt, settings.advectionCfl);
      for (int k = 0; k < substeps; ++k) next = advectScalarEnoRk3(layout, next, state.u, dt / substeps);
      state.phi.assign(next.data(), next.data() + next.size());
    } else {
      state.phi = advectCellField(layout, state.phi, state.u, dt);
    }
    if (settings.particleLevelSet) {
      if (state.levelSetParticles.empty()) state.levelSetParticles = seedParticles(layout, previousPhi, settings.particleSettings);
      advectParticles(layout, state.u, dt, state.levelSetParticles);
      correctWithParticles(layout, state.levelSetParticles, state.phi);
    }
    redistanceLevelSet(state, layout, settings, report);
  } else {
    const Eigen::VectorXd v = D.Ht.transpose() * unew;  // H u^{n+1}
    for (int k = 0; k < state.front.pointCount(); ++k) state.front.points[k] += dt * v.segment<2>(2 * k);
    if (settings.remesh)
      report.remeshChanges = remeshClosedFront(state.front, settings.minSegment * dx, settings.maxSegment * dx);
    state.pointVelocity.clear();
    if (settings.carryCouplingVelocity && report.remeshChanges == 0)
      for (int k = 0; k < state.front.pointCount(); ++k) state.pointVelocity.push_back(v.segment<2>(2 * k));
  }
  state.time += dt;
  ++state.step;

  // Diagnostics and the blow-up guard.
  double maxSpeed = 0;
  bool finite = true;
  for (int q = 0; q < D.gridUnknowns; ++q) {
    if (!std::isfinite(unew[q])) finite = false;
    maxSpeed = std::max(maxSpeed, std::abs(unew[q]));
  }
  report.maxSpeed = maxSpeed;
  report.cfl = maxSpeed * dt / dx;
  const double rhoSum = settings.densityInside + (settings.onePhase ? 0.0 : settings.densityOutside);
  report.capillaryDt = settings.sigma > 0 ? std::sqrt(rhoSum * dx * dx * dx / (4 * M_PI * settings.sigma))
                                          : std::numeric_limits<double>::infinity();
  double sumIn = 0, sumOut = 0;
  int countIn = 0, countOut = 0;
  for (int c = 0; c < layout.cellCount(); ++c) {
    if (D.cutCell[c]) continue;
    if (D.insideDof[c] >= 0) sumIn += state.pInside[c], ++countIn;
    if (D.outsideDof[c] >= 0) sumOut += state.pOutside[c], ++countOut;
  }
  report.pressureJump = (countIn ? sumIn / countIn : 0.0) - (countOut ? sumOut / countOut : 0.0);
  report.area = enclosedArea(state.front);
  report.cutCells = static_cast<int>(std::count(D.cutCell.begin(), D.cutCell.end(), 1));
  if (!report.blewUp && (!finite || maxSpeed > settings.blowUpSpeed)) {
    reportBlowUp(report, settings, [&](std::ostream& why) {
      why << "at step " << state.step << " (t = " << state.time << "): max speed " << maxSpeed << " above the guard "
          << settings.blowUpSpeed << "; dt = " << dt << " is " << dt / report.capillaryDt << " x the capillary limit "
          << report.capillaryDt << ", CFL " << report.cfl;
    });
  }
  return report;
}

}  // namespace monolith::solvers
