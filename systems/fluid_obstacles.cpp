#include "systems/fluid_obstacles.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include "components/fluid_obstacle.h"
#include "components/level_set.h"
#include "solvers/fluid/fluid_settings.h"
#include "solvers/mac_layout.h"
#include "systems/fluid_domain.h"
#include "systems/obstacle_geometry.h"

namespace monolith {

namespace {

// The cell next to c along `axis` in direction dir (+-1); false outside a non-periodic domain.
template <int d>
bool neighbour(const solvers::MacLayout<d>& layout, typename solvers::MacLayout<d>::Index c, int axis, int dir,
               typename solvers::MacLayout<d>::Index& out) {
  c[axis] += dir;
  if (layout.periodic[axis]) c[axis] = (c[axis] + layout.cells[axis]) % layout.cells[axis];
  if (!layout.cellInside(c)) return false;
  out = c;
  return true;
}

// An inclusive range of cell coordinates, lo[a] <= c[a] <= hi[a]. The faces "in" a box are those
// of its cells (face coordinates lo[a] .. hi[a] + 1 along their own axis, within the grid).
template <int d>
struct CellBox {
  typename solvers::MacLayout<d>::Index lo, hi;
};

template <int d>
CellBox<d> wholeGrid(const solvers::MacLayout<d>& layout) {
  return {solvers::MacLayout<d>::Index::Zero(), layout.cells - solvers::MacLayout<d>::Index::Ones()};
}

// Cells within `margin` cells of the obstacle's bounding sphere (the reach the rasterization
// uses); the whole extent of a periodic axis, on which the obstacle may wrap.
template <int d>
CellBox<d> obstacleBox(const solvers::MacLayout<d>& layout, const ObstacleGeometry<d>& obstacle, int margin) {
  const double reach = obstacle.boundingRadius();
  const RigidBody<d>& body = obstacle.body();
  CellBox<d> box = wholeGrid(layout);
  for (int a = 0; a < d; ++a) {
    if (layout.periodic[a]) continue;
    const double lo = std::floor((body.x[a] - reach - layout.origin[a]) / layout.dx) - margin;
    const double hi = std::floor((body.x[a] + reach - layout.origin[a]) / layout.dx) + margin;
    box.lo[a] = static_cast<int>(std::clamp(lo, 0.0, static_cast<double>(layout.cells[a] - 1)));
    box.hi[a] = static_cast<int>(std::clamp(hi, 0.0, static_cast<double>(layout.cells[a] - 1)));
  }
  return box;
}

// visit(c, ci) for the cells of the box in increasing linear index (x fastest), so that sums
// over them add in the order of a loop over the whole grid.
template <int d, class Visit>
void forEachCellIn(const solvers::MacLayout<d>& layout, const CellBox<d>& box, Visit&& visit) {
  solvers::forEachIndexIn<d>(box.lo, box.hi, [&](const auto& c) { visit(layout.cellIndex(c), c); });
}

// visit(g, a, f) for the faces of the box in increasing global index (axis 0 first).
template <int d, class Visit>
void forEachFaceIn(const solvers::MacLayout<d>& layout, const CellBox<d>& box, Visit&& visit) {
  for (int a = 0; a < d; ++a) {
    auto hi = box.hi;
    hi[a] = std::min(box.hi[a] + 1, layout.faceLayers(a) - 1);
    solvers::forEachIndexIn<d>(box.lo, hi, [&](const auto& f) { visit(layout.faceIndex(a, f), a, f); });
  }
}

// Calls visit(g, a, f, b, dir) for every interior face g = (a, f) with isFree(g) and direction
// dir e_b whose next face of the same axis that way is marked (markedFace[face] != 0). These are
// the viscous pairs that end on an obstacle face (operators.h).
template <int d, class IsFree, class Visit>
void forEachPairIntoMarkedFaces(const solvers::MacLayout<d>& layout, IsFree&& isFree,
                                const std::vector<std::uint8_t>& markedFace, Visit&& visit,
                                const CellBox<d>* within = nullptr) {
  using Index = typename solvers::MacLayout<d>::Index;
  // Only the faces of `within` (when given; in the whole grid's order): the marked faces and
  // their partners must lie in it.
  forEachFaceIn(layout, within ? *within : wholeGrid(layout), [&](int g, int a, const Index& f) {
    Index c0;
    if (!layout.cellInside(f) || !neighbour(layout, f, a, -1, c0)) return;  // a domain boundary face
    if (!isFree(g)) return;
    const Index dims = layout.faceDims(a);
    for (int b = 0; b < d; ++b)
      for (int dir = -1; dir <= 1; dir += 2) {
        Index partner = f;
        partner[b] += dir;
        if (partner[b] < 0 || partner[b] >= dims[b]) {
          if (!layout.periodic[b]) continue;
          partner[b] = (partner[b] + layout.cells[b]) % layout.cells[b];
        }
        if (markedFace[layout.faceIndex(a, partner)]) visit(g, a, f, b, dir);
      }
  });
}

// Faces touching a cell with mask[c] != 0. `within`: the marked cells all lie in that box.
template <int d>
std::vector<std::uint8_t> facesOfMarkedCells(const solvers::MacLayout<d>& layout, const std::vector<std::uint8_t>& mask,
                                             const CellBox<d>* within = nullptr) {
  std::vector<std::uint8_t> marked(layout.totalFaces(), 0);
  forEachCellIn(layout, within ? *within : wholeGrid(layout), [&](int c, const typename solvers::MacLayout<d>::Index& ci) {
    if (!mask[c]) return;
    for (int a = 0; a < d; ++a)
      for (int side = 0; side < 2; ++side) {
        auto f = ci;
        f[a] += side;
        marked[layout.faceIndex(a, f)] = 1;
      }
  });
  return marked;
}

// A free face of the grid: both cells inside the domain and not solid, and (cut faces) some part
// of it open.
template <int d>
bool gridFaceFree(const solvers::MacLayout<d>& layout, const MacGrid<d>& grid, int g) {
  const auto [a, f] = layout.faceCoord(g);
  typename solvers::MacLayout<d>::Index c0;
  if (!layout.cellInside(f) || !neighbour(layout, f, a, -1, c0)) return false;
  if (grid.solid[layout.cellIndex(c0)] || grid.solid[layout.cellIndex(f)]) return false;
  return grid.openFraction.empty() || grid.openFraction[g] > 0;
}

template <int d>
using ObstacleList = std::vector<ObstacleGeometry<d>>;

// Part of every face outside all the given obstacles (solvers::cutFaces). A face is measured along
// exact segment-shape intersections: in 2-D the face is one segment; in 3-D the midpoint rule over
// kCutLines segments. Fractions below kMinOpenFraction count as covered (a sliver of a face would
// only slow the solves down), those within 1e-12 of 1 as open.
constexpr int kCutLines = 8;
constexpr double kMinOpenFraction = 0.01;

// `within`: only the faces of that box can be near the obstacles (the others stay open).
template <int d>
std::vector<double> openFractions(const solvers::MacLayout<d>& layout, const ObstacleList<d>& obstacles,
                                  const CellBox<d>* within = nullptr) {
  using Vec = Eigen::Matrix<double, d, 1>;
  std::vector<double> open(layout.totalFaces(), 1.0);
  const double h = layout.dx;
  std::vector<std::pair<double, double>> pieces;
  forEachFaceIn(layout, within ? *within : wholeGrid(layout), [&](int g, int a, const typename solvers::MacLayout<d>::Index& f) {
    const Vec x = layout.faceCenter(a, f);
    bool near = false;
    for (const auto& obstacle : obstacles) near |= (x - obstacle.body().x).norm() <= obstacle.boundingRadius() + h;
    if (!near) return;
    const int t1 = (a + 1) % d, t2 = (a + 2) % d;  // t2 == a in 2-D: one line
    const int lines = d == 2 ? 1 : kCutLines;
    Vec e = Vec::Zero();
    e[t1] = 1;
    double covered = 0;
    for (int k = 0; k < lines; ++k) {
      Vec start = x;
      start[t1] -= 0.5 * h;
      if (d == 3) start[t2] += ((k + 0.5) / lines - 0.5) * h;
      pieces.clear();
      for (const auto& obstacle : obstacles) obstacle.segmentInside(start, e, h, pieces);
      std::sort(pieces.begin(), pieces.end());
      double end = 0;  // union of the pieces along the line
      for (const auto& [lo, hi] : pieces) {
        covered += std::max(0.0, hi - std::max(lo, end));
        end = std::max(end, hi);
      }
    }
    const double theta = 1.0 - covered / (lines * h);
    open[g] = theta < kMinOpenFraction ? 0.0 : theta > 1 - 1e-12 ? 1.0 : theta;
  });
  return open;
}

// The geometry of an entity with a fluid_obstacle: its level_set if it has one, else its shape;
// false without a rigid_body or either geometry.
template <int d>
bool obstacleGeometryOf(const World<d>& world, Entity e, std::optional<ObstacleGeometry<d>>& out) {
  const RigidBody<d>* body = world.template get<RigidBody<d>>(e);
  const LevelSet<d>* levelSet = world.template get<LevelSet<d>>(e);
  const Shape<d>* shape = world.template get<Shape<d>>(e);
  if (!body || (!levelSet && !shape)) return false;
  out.emplace(shape, levelSet, *body);
  return true;
}

// Every entity with a fluid_obstacle, its geometry and rigid_body, in pool order.
template <int d, class F>
void forEachObstacle(const World<d>& world, F&& f) {
  const auto* pool = world.template findPool<FluidObstacle>();
  if (!pool) return;
  std::optional<ObstacleGeometry<d>> geometry;
  for (Entity e : pool->entities())
    if (obstacleGeometryOf(world, e, geometry)) f(e, *geometry);
}

// Everything rasterize_obstacles' output depends on, as numbers: equal keys give equal results.
template <int d>
std::vector<double> rasterizationKey(const World<d>& world, const MacGrid<d>& grid) {
  std::vector<double> key;
  const auto put = [&](const auto& v) { key.insert(key.end(), v.data(), v.data() + v.size()); };
  put(grid.cells.template cast<double>().eval());
  key.push_back(grid.dx);
  put(grid.origin);
  key.push_back(world.template resource<FluidSolverSettings>().cutCells);
  key.push_back(static_cast<double>(world.template resource<FluidSolverSettings>().obstacleWall));
  forEachObstacle(world, [&](Entity e, const ObstacleGeometry<d>& obstacle) {
    const RigidBody<d>& body = obstacle.body();
    key.push_back(e.index);
    obstacle.appendKey(key);
    put(body.x);
    if constexpr (d == 3) put(body.orientation.coeffs());
    else key.push_back(body.orientation);
    put(body.v);  // the wall velocities (a kinematic body may change speed where it stands)
    put(body.omega());
  });
  return key;
}

}  // namespace

namespace {

// Every obstacle's geometry, in pool order.
template <int d>
ObstacleList<d> obstacleList(const World<d>& world) {
  ObstacleList<d> obstacles;
  forEachObstacle(world, [&](Entity, const ObstacleGeometry<d>& obstacle) { obstacles.push_back(obstacle); });
  return obstacles;
}

// The cells within kRasterMargin cells of any obstacle's bounding sphere, as one box (empty, lo >
// hi, without obstacles): rasterization changes nothing outside it, so its passes skip the rest
// of the grid (a small moving body in a large grid is rasterized every step). Three cells: a
// face centre farther than reach + dx from a body (openFractions' "near" test) lies over two
// cells beyond its box, and the viscous pairs into obstacle faces reach one face further.
constexpr int kRasterMargin = 3;

template <int d>
CellBox<d> obstaclesBox(const solvers::MacLayout<d>& layout, const ObstacleList<d>& obstacles) {
  using Index = typename solvers::MacLayout<d>::Index;
  CellBox<d> box{layout.cells, Index::Constant(-1)};
  for (const auto& obstacle : obstacles) {
    const CellBox<d> one = obstacleBox(layout, obstacle, kRasterMargin);
    box.lo = box.lo.cwiseMin(one.lo);
    box.hi = box.hi.cwiseMax(one.hi);
  }
  return box;
}

// Staircase: cells whose centre lies inside some obstacle.
template <int d>
std::vector<std::uint8_t> staircaseMask(const solvers::MacLayout<d>& layout, const ObstacleList<d>& obstacles) {
  std::vector<std::uint8_t> mask(layout.cellCount(), 0);
  for (const auto& obstacle : obstacles)
    forEachCellIn(layout, obstacleBox(layout, obstacle, 1), [&](int c, const typename solvers::MacLayout<d>::Index& ci) {
      if (!mask[c] && obstacle.contains(layout.cellCenter(ci))) mask[c] = 1;
    });
  return mask;
}

// Cut faces: the cells whose faces are all covered (only cells of `box` can be).
template <int d>
std::vector<std::uint8_t> coveredCells(const solvers::MacLayout<d>& layout, const std::vector<double>& openFraction,
                                       const CellBox<d>& box) {
  std::vector<std::uint8_t> mask(layout.cellCount(), 0);
  forEachCellIn(layout, box, [&](int c, const typename solvers::MacLayout<d>::Index& ci) {
    bool covered = true;
    for (int a = 0; a < d && covered; ++a)
      for (int side = 0; side < 2; ++side) {
        auto f = ci;
        f[a] += side;
        covered = covered && openFraction[layout.faceIndex(a, f)] == 0;
      }
    mask[c] = covered;
  });
  return mask;
}

// The obstacle faces the viscous rows end on: faces of solid cells, and cut faces covered whole
// (all of them in `box`).
template <int d>
std::vector<std::uint8_t> obstacleFaces(const solvers::MacLayout<d>& layout, const MacGrid<d>& grid, const CellBox<d>& box) {
  std::vector<std::uint8_t> marked = facesOfMarkedCells(layout, grid.solid, &box);
  if (!grid.openFraction.empty())
    forEachFaceIn(layout, box, [&](int g, int, const auto&) { marked[g] |= grid.openFraction[g] == 0; });
  return marked;
}

// Free cut faces (open in part) whose centre lies inside some obstacle; all zero on a staircase.
// A centre on the surface (to rounding, kInsideMargin cells) counts as outside, so that faces placed
// symmetrically about a symmetric body are classified alike.
constexpr double kInsideMargin = 1e-9;
template <int d>
std::vector<std::uint8_t> insideCutFaces(const solvers::MacLayout<d>& layout, const MacGrid<d>& grid,
                                         const ObstacleList<d>& obstacles, const CellBox<d>& box) {
  std::vector<std::uint8_t> inside(layout.totalFaces(), 0);
  if (grid.openFraction.empty()) return inside;
  forEachFaceIn(layout, box, [&](int g, int a, const typename solvers::MacLayout<d>::Index& f) {
    if (!(grid.openFraction[g] < 1) || !gridFaceFree(layout, grid, g)) return;
    const auto x = layout.faceCenter(a, f);
    for (const auto& obstacle : obstacles) inside[g] |= obstacle.signedDistance(x) < -kInsideMargin * layout.dx;
  });
  return inside;
}

// Per free face and direction into an obstacle face: the distance in cells to the wall
// (FluidDomain::wallDistance) and, when some obstacle moves, the wall's velocity component along
// the face's axis at that wall point, from the obstacle of smallest signed distance there
// (grid.obstacleVelocityAt, from the motions of this step; FluidDomain::wallVelocity,
// kNoWallVelocity for the pairs that end elsewhere; empty otherwise).
template <int d>
struct WallGeometry {
  std::vector<double> distance, velocity;
};

template <int d>
WallGeometry<d> wallGeometry(const World<d>& world, const MacGrid<d>& grid, const ObstacleList<d>& obstacles,
                             const CellBox<d>& box) {
  using Index = typename solvers::MacLayout<d>::Index;
  const solvers::MacLayout<d> layout = macLayoutOf(grid);
  WallGeometry<d> wall;
  wall.distance.assign(static_cast<std::size_t>(layout.totalFaces()) * 2 * d, 1.0);
  if (grid.solid.empty()) return wall;
  if (grid.obstaclesMove()) wall.velocity.assign(wall.distance.size(), solvers::FluidDomain<d>::kNoWallVelocity);
  const auto isFree = [&](int g) { return gridFaceFree(layout, grid, g); };
  const bool cellBoundary = world.template resource<FluidSolverSettings>().obstacleWall == FluidSolverSettings::ObstacleWall::CellBoundary;
  const auto visit = [&](int g, int a, const Index& f, int b, int dir) {
    const std::size_t k = solvers::FluidDomain<d>::wallDistanceIndex(g, b, dir > 0);
    const auto x = layout.faceCenter(a, f);
    if (cellBoundary) {
      // The staircase's wall is the solid cells' boundary: half a cell across the face's control
      // volume (b != a); along the face's own axis the obstacle face lies on that boundary.
      wall.distance[k] = b == a ? 1.0 : 0.5;
    } else {
      Eigen::Matrix<double, d, 1> e = Eigen::Matrix<double, d, 1>::Zero();
      e[b] = dir;
      double t = std::numeric_limits<double>::infinity();
      for (const auto& obstacle : obstacles) t = std::min(t, obstacle.rayEntry(x, e, layout.dx));
      wall.distance[k] = std::clamp(t / layout.dx, solvers::FluidDomain<d>::kMinWallDistance, 1.0);
    }
    if (wall.velocity.empty()) return;
    Eigen::Matrix<double, d, 1> point = x;
    point[b] += dir * wall.distance[k] * layout.dx;
    wall.velocity[k] = grid.obstacleVelocityAt(point)[a];
  };
  // Cut faces: a free face whose centre lies inside an obstacle is the obstacle's wall for the
  // viscous rows (FluidDomain::wallDistance, 0 in every direction): its neighbours measure their
  // shear against the true surface between them, and it is held to the obstacle's velocity.
  const std::vector<std::uint8_t> inside = insideCutFaces(layout, grid, obstacles, box);
  std::vector<std::uint8_t> marked = obstacleFaces(layout, grid, box);
  for (std::size_t g = 0; g < marked.size(); ++g) marked[g] |= inside[g];
  const auto isOutsideFree = [&](int g) { return !inside[g] && isFree(g); };
  forEachPairIntoMarkedFaces(layout, isOutsideFree, marked, visit, &box);
  forEachFaceIn(layout, box, [&](int g, int a, const Index& f) {
    if (!inside[g]) return;
    for (int k = 0; k < 2 * d; ++k) {
      wall.distance[static_cast<std::size_t>(g) * 2 * d + k] = 0.0;
      if (!wall.velocity.empty())
        wall.velocity[static_cast<std::size_t>(g) * 2 * d + k] = grid.obstacleVelocityAt(layout.faceCenter(a, f))[a];
    }
  });
  return wall;
}

}  // namespace

template <int d>
std::vector<std::uint8_t> obstacleMask(const World<d>& world, const MacGrid<d>& grid) {
  return staircaseMask(macLayoutOf(grid), obstacleList(world));
}

template <int d>
std::vector<double> obstacleOpenFractions(const World<d>& world, const MacGrid<d>& grid) {
  const solvers::MacLayout<d> layout = macLayoutOf(grid);
  const ObstacleList<d> obstacles = obstacleList(world);
  const CellBox<d> box = obstaclesBox(layout, obstacles);
  return openFractions(layout, obstacles, &box);
}

template <int d>
std::vector<double> obstacleWallDistances(const World<d>& world, const MacGrid<d>& grid) {
  const ObstacleList<d> obstacles = obstacleList(world);
  return wallGeometry(world, grid, obstacles, obstaclesBox(macLayoutOf(grid), obstacles)).distance;
}

namespace {
// torque += r x (f e_axis), r lifted to 3-D.
template <int d>
void addTorque(Eigen::Vector3d& torque, const Eigen::Matrix<double, d, 1>& r, int axis, double f) {
  Eigen::Vector3d r3 = Eigen::Vector3d::Zero(), f3 = Eigen::Vector3d::Zero();
  r3.head<d>() = r;
  f3[axis] = f;
  torque += r3.cross(f3);
}
}  // namespace

template <int d>
ObstacleForce<d> obstacleForce(const World<d>& world, Entity obstacle, const MacGrid<d>& grid, double viscosity) {
  using Index = typename solvers::MacLayout<d>::Index;
  ObstacleForce<d> result;
  auto& force = result.pressure;
  std::optional<ObstacleGeometry<d>> geometry;
  if (!obstacleGeometryOf(world, obstacle, geometry) || grid.solid.empty()) return result;
  const solvers::MacLayout<d> layout = macLayoutOf(grid);
  const int n = layout.cellCount();
  // Everything below happens within a few cells of the obstacle: its faces, the fluid cells and
  // faces next to them. Looping over that box only, in the whole grid's order, gives the same
  // sums as a loop over the grid at a fraction of the cost (a large grid, a small obstacle).
  const CellBox<d> box = obstacleBox(layout, *geometry, 3);
  // Part of each face covered by this obstacle: staircase, every face of its solid cells (those
  // with the centre inside its shape); cut faces, the covered part of the face.
  std::vector<double> covered;
  std::vector<std::uint8_t> mine;  // faces this obstacle covers whole: the viscous rows' walls
  if (grid.openFraction.empty()) {
    std::vector<std::uint8_t> cells(n, 0);
    forEachCellIn(layout, box, [&](int c, const Index& ci) {
      cells[c] = grid.solid[c] && geometry->contains(layout.cellCenter(ci));
    });
    mine = facesOfMarkedCells(layout, cells, &box);
    covered.assign(mine.begin(), mine.end());
  } else {
    covered = openFractions(layout, ObstacleList<d>{*geometry}, &box);
    mine.resize(covered.size());
    for (std::size_t g = 0; g < covered.size(); ++g) {
      covered[g] = 1.0 - covered[g];
      mine[g] = covered[g] == 1;
    }
  }
  const double area = layout.faceArea();

  // Pressure: p of each fluid cell on the covered part of its faces, along the normal from the
  // fluid into the obstacle: the discrete momentum exchange of the constraint's obstacle terms.
  forEachCellIn(layout, box, [&](int c, const Index& ci) {
    if (grid.solid[c] || grid.p[c] == 0) return;
    for (int a = 0; a < d; ++a)
      for (int side = 0; side < 2; ++side) {
        Index fi = ci;
        fi[a] += side;
        const double part = covered[layout.faceIndex(a, fi)];
        if (part <= 0) continue;
        const double f = (side == 1 ? 1.0 : -1.0) * grid.p[c] * part * area;
        force[a] += f;
        addTorque<d>(result.pressureTorque, layout.faceCenter(a, fi) - geometry->body().x, a, f);
      }
  });

  // Viscous stress, exactly as the viscous operator applies it (operators.h): every free face of
  // axis a whose next face along axis b is one of this obstacle's faces has a row
  // mu (u - u_wall) / (theta dx) on the face area, theta dx being the distance to the wall (the
  // grid's wall distances; 1 cell when the wall sits at the obstacle face's centre; along the
  // face's own axis the row is the normal stress of the cell between). The fluid loses that
  // momentum to the body, so the sum is the body's share of the discrete momentum balance (on a
  // staircase the normal rows do not vanish as du_n/dn = 0 would make them on a smooth wall).
  if (viscosity > 0) {
    const std::vector<double>& wallDistance = grid.obstacleWallDistance;
    // Cut faces with the centre inside an obstacle (wall distance 0) are walls themselves: the
    // rows from outside faces into this obstacle's end there, and each of its own faces is held
    // to it by one row w (U - u) / sqrt(kMinWallDistance) (operators.cpp).
    std::vector<std::uint8_t> insideAny(layout.totalFaces(), 0);
    if (!wallDistance.empty() && !grid.openFraction.empty())
      forEachFaceIn(layout, box, [&](int g, int a, const Index& fi) {
        if (wallDistance[solvers::FluidDomain<d>::wallDistanceIndex(g, 0, 0)] != 0) return;
        insideAny[g] = 1;
        if (!(geometry->signedDistance(layout.faceCenter(a, fi)) < 0)) return;  // another obstacle's
        mine[g] = 1;
        const double theta = solvers::FluidDomain<d>::kMinWallDistance;
        const double wall = grid.obstacleWallVelocity.empty() ? grid.obstacleVelocityAt(layout.faceCenter(a, fi))[a]
                                                              : grid.obstacleWallVelocity[solvers::FluidDomain<d>::wallDistanceIndex(g, 0, 0)];
        const double f = viscosity * (grid.u[g] - wall) / (theta * layout.dx) * area;
        result.viscous[a] += f;
        addTorque<d>(result.viscousTorque, layout.faceCenter(a, fi) - geometry->body().x, a, f);
      });
    const auto isFree = [&](int g) { return !insideAny[g] && gridFaceFree(layout, grid, g); };
    Eigen::Vector3d spin = Eigen::Vector3d::Zero();  // the body's angular velocity (z only in 2-D)
    if (!geometry->body().isStatic) {
      if constexpr (d == 3) spin = geometry->body().omega();
      else spin.z() = geometry->body().omega()(0);
    }
    forEachPairIntoMarkedFaces(layout, isFree, mine, [&](int g, int a, const Index& fi, int b, int dir) {
      const double theta = wallDistance.empty() ? 1.0 : wallDistance[solvers::FluidDomain<d>::wallDistanceIndex(g, b, dir > 0)];
      // The operator's known value: the moving wall's velocity where it is (grid.obstacleWallVelocity),
      // else the obstacle face's prescribed velocity (its centre, one cell away).
      Eigen::Matrix<double, d, 1> wallPoint = layout.faceCenter(a, fi);
      wallPoint[b] += dir * layout.dx;
      const double wall = grid.obstacleWallVelocity.empty()
                              ? grid.obstacleVelocityAt(wallPoint)[a]
                              : grid.obstacleWallVelocity[solvers::FluidDomain<d>::wallDistanceIndex(g, b, dir > 0)];
      const double f = viscosity * (grid.u[g] - wall) / (theta * layout.dx) * area;
      result.viscous[a] += f;
      Eigen::Matrix<double, d, 1> onWall = layout.faceCenter(a, fi);
      onWall[b] += dir * theta * layout.dx;
      addTorque<d>(result.viscousTorque, onWall - geometry->body().x, a, f);
      // The rows are the vector Laplacian's, mu du/dn: on a wall spinning at w that traction
      // differs from the stress mu (grad u + grad u^T) n by mu (w x n), which sums to no force
      // over a closed surface but to a torque -2 mu V w (V the body's volume; rotating Couette
      // flow: tests LevelSets.CouetteTorqueOnTheSpinningAndTheStillCylinder, and in 3-D
      // LevelSets.SphericalCouetteTorqueOnTheSpinningSphereAndTheStillShell). So the torque adds
      // that part of every tangential row, n = -dir e_b pointing out of the body.
      if (b != a && spin.squaredNorm() > 0) {
        Eigen::Vector3d n = Eigen::Vector3d::Zero();
        n[b] = -dir;
        addTorque<d>(result.viscousTorque, onWall - geometry->body().x, a, -viscosity * spin.cross(n)[a] * area);
      }
    }, &box);
  }
  return result;
}

template <int d>
std::vector<std::string> RasterizeObstacles<d>::reads() const {
  return {Shape<d>::kName, LevelSet<d>::kName, RigidBody<d>::kName, FluidObstacle::kName};
}

template <int d>
bool RasterizeObstacles<d>::needed(const World<d>& w) const {
  return w.template count<MacGrid<d>>() > 0 && w.template count<FluidObstacle>() > 0;
}

// Pose and rigid velocity of every obstacle (static: at rest; kinematic: its scripted motion).
template <int d>
std::vector<ObstacleMotion<d>> obstacleMotions(const World<d>& world) {
  std::vector<ObstacleMotion<d>> motions;
  forEachObstacle(world, [&](Entity e, const ObstacleGeometry<d>& obstacle) {
    const RigidBody<d>& body = obstacle.body();
    ObstacleMotion<d> m;
    m.centre = body.x;
    m.reach = obstacle.boundingRadius();
    if constexpr (d == 3) m.orientation = body.orientation.coeffs();
    else m.orientation[0] = body.orientation;
    // Looked up again at every call: the motions outlive this step (a CFL step size is taken
    // from them before the next rasterization), and the components may have moved in memory.
    m.signedDistance = [&world, e](const Vec<d>& x) {
      std::optional<ObstacleGeometry<d>> geometry;
      return obstacleGeometryOf(world, e, geometry) ? geometry->signedDistance(x) : std::numeric_limits<double>::infinity();
    };
    if (!body.isStatic) {
      m.velocity = body.v;
      const AngularVec<d> w = body.omega();
      if constexpr (d == 3) m.angularVelocity = w;
      else m.angularVelocity.z() = w(0);
    }
    motions.push_back(m);
  });
  return motions;
}

template <int d>
void RasterizeObstacles<d>::run(World<d>& world, StepContext&) {
  auto& pool = world.template pool<MacGrid<d>>();
  const std::vector<ObstacleMotion<d>> motions = obstacleMotions(world);
  for (MacGrid<d>& grid : pool.components()) {
    grid.obstacleMotions = motions;
    // Static obstacles: the fractions, cells and wall distances of the last step still hold
    // (recomputing them cost about a twentieth of a DFG step at 440 x 82).
    std::vector<double> key = rasterizationKey(world, grid);
    if (key == grid.rasterizedFrom && grid.solid.size() == static_cast<std::size_t>(grid.cells.prod())) continue;
    grid.rasterizedFrom = std::move(key);
    const solvers::MacLayout<d> layout = macLayoutOf(grid);
    const ObstacleList<d> obstacles = obstacleList(world);
    const CellBox<d> box = obstaclesBox(layout, obstacles);
    std::vector<std::uint8_t> mask;
    if (world.template resource<FluidSolverSettings>().cutCells) {
      std::vector<double> open = openFractions(layout, obstacles, &box);
      mask = coveredCells(layout, open, box);
      if (open != grid.openFraction) grid.openFraction = std::move(open);
    } else {
      mask = staircaseMask(layout, obstacles);
      grid.openFraction.clear();
    }
    if (mask != grid.solid) grid.solid = std::move(mask);  // unchanged: keep the projection's cache
    if (world.template resource<FluidSolverSettings>().obstacleWallDistances()) {
      WallGeometry<d> wall = wallGeometry(world, grid, obstacles, box);
      grid.obstacleWallDistance = std::move(wall.distance);
      grid.obstacleWallVelocity = std::move(wall.velocity);
    } else {
      grid.obstacleWallDistance.clear();
      grid.obstacleWallVelocity.clear();
    }
  }
}

template <int d>
std::vector<std::string> ObstacleForces<d>::reads() const {
  return {Shape<d>::kName, LevelSet<d>::kName, RigidBody<d>::kName, FluidObstacle::kName, MacGrid<d>::kName,
          FluidMaterial::kName};
}

template <int d>
bool ObstacleForces<d>::needed(const World<d>& w) const {
  return w.template count<MacGrid<d>>() > 0 && w.template count<FluidObstacle>() > 0;
}

template <int d>
void ObstacleForces<d>::run(World<d>& world, StepContext& ctx) {
  const auto& pool = world.template pool<MacGrid<d>>();
  if (pool.size() == 0) return;
  const MacGrid<d>& grid = pool.components()[0];
  const FluidMaterial* material = world.template get<FluidMaterial>(pool.entities()[0]);
  const double mu = material ? material->viscosity : 0.0;
  const char* axes[] = {"x", "y", "z"};
  forEachObstacle(world, [&](Entity e, const ObstacleGeometry<d>&) {
    const ObstacleForce<d> f = obstacleForce(world, e, grid, mu);
    const std::string& name = world.name(e);
    const std::string prefix = "obstacle_" + (name.empty() ? std::to_string(e.index) : name);
    for (int a = 0; a < d; ++a) {
      ctx.diagnostics.set(prefix + "_force_" + axes[a], f.total()[a]);
      ctx.diagnostics.set(prefix + "_pressure_force_" + axes[a], f.pressure[a]);
    }
    for (int a = d == 2 ? 2 : 0; a < 3; ++a) {
      ctx.diagnostics.set(prefix + "_torque_" + axes[a], f.torque()[a]);
      ctx.diagnostics.set(prefix + "_pressure_torque_" + axes[a], f.pressureTorque[a]);
    }
  });
}

template std::vector<std::uint8_t> obstacleMask<2>(const World<2>&, const MacGrid<2>&);
template std::vector<std::uint8_t> obstacleMask<3>(const World<3>&, const MacGrid<3>&);
template std::vector<double> obstacleOpenFractions<2>(const World<2>&, const MacGrid<2>&);
template std::vector<double> obstacleOpenFractions<3>(const World<3>&, const MacGrid<3>&);
template std::vector<double> obstacleWallDistances<2>(const World<2>&, const MacGrid<2>&);
template std::vector<double> obstacleWallDistances<3>(const World<3>&, const MacGrid<3>&);
template ObstacleForce<2> obstacleForce<2>(const World<2>&, Entity, const MacGrid<2>&, double);
template ObstacleForce<3> obstacleForce<3>(const World<3>&, Entity, const MacGrid<3>&, double);
template class RasterizeObstacles<2>;
template class RasterizeObstacles<3>;
template class ObstacleForces<2>;
template class ObstacleForces<3>;

}  // namespace monolith
