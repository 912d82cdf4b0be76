#include "scenarios/body_surfaces.h"

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>
#include <utility>

#include "solvers/collision/collision_impl.h"
#include "solvers/mac_layout.h"

namespace monolith {

namespace {

// Adds body-frame points to the output at the body's pose, tagged with its id.
template <int d>
class PosedSurface {
 public:
  using VecD = Eigen::Matrix<double, d, 1>;

  PosedSurface(const RigidBody<d>& body, int bodyId, SurfacePolygons& out)
      : x_(body.x), R_(body.rotation()), bodyId_(bodyId), out_(out) {}

  int point(const VecD& local) {
    out_.points.push_back(lift(VecD(x_ + R_ * local)));
    out_.pointBody.push_back(bodyId_);
    return static_cast<int>(out_.points.size()) - 1;
  }
  void face(std::vector<int> f) { out_.faces.push_back(std::move(f)); }
  // One polygon through new points at `corners`, in order.
  void polygon(const std::vector<VecD>& corners) {
    std::vector<int> f;
    for (const auto& c : corners) f.push_back(point(c));
    face(std::move(f));
  }

 private:
  VecD x_;
  Eigen::Matrix<double, d, d> R_;
  int bodyId_;
  SurfacePolygons& out_;
};

// --- 3-D shapes -------------------------------------------------------------------------------

void addBox(const Eigen::Vector3d& h, PosedSurface<3>& s) {
  int corner[8];
  for (int k = 0; k < 8; ++k)
    corner[k] = s.point(Eigen::Vector3d((k & 1) ? h.x() : -h.x(), (k & 2) ? h.y() : -h.y(), (k & 4) ? h.z() : -h.z()));
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) s.face({corner[q[0]], corner[q[1]], corner[q[2]], corner[q[3]]});
}

// Faces between two neighbouring rings of a surface of revolution, the upper one first; a ring
// of one point is a pole (triangles). Counter-clockwise seen from outside.
void joinRings(const std::vector<int>& upper, const std::vector<int>& lower, int segments, PosedSurface<3>& s) {
  const std::size_t nu = upper.size(), nl = lower.size();
  for (int j = 0; j < segments; ++j) {
    const int next = (j + 1) % segments;
    std::vector<int> f = {upper[j % nu], lower[j % nl]};
    if (nl > 1) f.push_back(lower[next]);
    if (nu > 1) f.push_back(upper[next]);
    s.face(std::move(f));
  }
}

// A surface of revolution about body z. `profile` holds (rho, z) from top to bottom: rho = 0 is a
// pole (one point), any other rho a ring of `segments` points. An end that is not a pole is
// closed by a flat polygon, so the surface is always closed.
void addRevolution(const std::vector<Eigen::Vector2d>& profile, int segments, PosedSurface<3>& s) {
  std::vector<std::vector<int>> rings;
  for (const Eigen::Vector2d& rz : profile) {
    std::vector<int> ring;
    for (int j = 0; j < (rz.x() == 0 ? 1 : segments); ++j) {
      const double angle = 2 * M_PI * j / segments;
      ring.push_back(s.point(Eigen::Vector3d(rz.x() * std::cos(angle), rz.x() * std::sin(angle), rz.y())));
    }
    rings.push_back(std::move(ring));
  }
  for (std::size_t k = 0; k + 1 < rings.size(); ++k) joinRings(rings[k], rings[k + 1], segments, s);
  if (rings.front().size() > 1) s.face(rings.front());  // counter-clockwise seen from +z
  if (rings.back().size() > 1) s.face({rings.back().rbegin(), rings.back().rend()});
}

// Latitude rings first..last of a sphere of radius r centred at height zCentre, whose meridian
// is cut into `bands` equal angles from the north pole (0) to the south pole (bands). The poles
// get rho = 0 exactly (sin(pi) is not 0 in floating point).
std::vector<Eigen::Vector2d> latitudes(double r, double zCentre, int first, int last, int bands) {
  std::vector<Eigen::Vector2d> profile;
  for (int i = first; i <= last; ++i) {
    const double theta = M_PI * i / bands;
    profile.emplace_back(i == 0 || i == bands ? 0.0 : r * std::sin(theta), zCentre + r * std::cos(theta));
  }
  return profile;
}

// Capsule: the upper hemisphere about z = h, then the lower one about z = -h; the band between
// their equators is the cylinder side.
std::vector<Eigen::Vector2d> capsuleProfile(double r, double h) {
  std::vector<Eigen::Vector2d> profile = latitudes(r, h, 0, kCapsuleRings, 2 * kCapsuleRings);
  const auto lower = latitudes(r, -h, kCapsuleRings, 2 * kCapsuleRings, 2 * kCapsuleRings);
  profile.insert(profile.end(), lower.begin(), lower.end());
  return profile;
}

// Triangles over the given body-frame vertices (counter-clockwise seen from outside).
void addTriangles(const std::vector<Eigen::Vector3d>& vertices, const std::vector<std::array<int, 3>>& triangles,
                  PosedSurface<3>& s) {
  std::vector<int> index;
  for (const auto& v : vertices) index.push_back(s.point(v));
  for (const auto& t : triangles) s.face({index[t[0]], index[t[1]], index[t[2]]});
}

// The hull routine the collision code uses, so the drawing shows exactly the collision shape.
// A flat vertex set has no hull (the scene reader rejects it): nothing is drawn.
void addConvexHull(const Shape<3>& shape, PosedSurface<3>& s) {
  std::vector<Eigen::Vector3d> vertices;
  for (int i = 0; i < shape.vertexCount(); ++i) vertices.push_back(shape.vertex(i));
  try {
    const solvers::collision::Hull3 hull = solvers::collision::convexHull3(vertices);
    addTriangles(hull.vertices, hull.triangles, s);
  } catch (const std::invalid_argument&) {
  }
}

void addMesh(const Shape<3>& shape, PosedSurface<3>& s) {
  std::vector<Eigen::Vector3d> vertices;
  for (int i = 0; i < shape.vertexCount(); ++i) vertices.push_back(shape.vertex(i));
  std::vector<std::array<int, 3>> triangles;
  for (std::size_t k = 0; k + 2 < shape.triangles.size(); k += 3)
    triangles.push_back({shape.triangles[k], shape.triangles[k + 1], shape.triangles[k + 2]});
  addTriangles(vertices, triangles, s);
}

// A half-space has no finite surface: a square of its boundary, centred on the body (the plane
// passes through the body origin), counter-clockwise about the outward normal.
void addPlanePatch(const Eigen::Vector3d& normal, PosedSurface<3>& s) {
  const Eigen::Vector3d n = normal.normalized(), u = n.unitOrthogonal(), v = n.cross(u);  // u x v = n
  const double a = kPlanePatchSize / 2;
  s.polygon({a * (-u - v), a * (u - v), a * (u + v), a * (-u + v)});
}

void addShape3(const Shape<3>& shape, PosedSurface<3>& s) {
  const double r = shape.radius, h = shape.halfHeight;
  switch (shape.type) {
    case ShapeType::Box: return addBox(shape.halfExtents, s);
    case ShapeType::Sphere: return addRevolution(latitudes(r, 0, 0, kSphereRings, kSphereRings), kSphereSegments, s);
    case ShapeType::Cylinder: return addRevolution({{r, h}, {r, -h}}, kRoundSegments, s);
    case ShapeType::Capsule: return addRevolution(capsuleProfile(r, h), kRoundSegments, s);
    case ShapeType::Convex: return addConvexHull(shape, s);
    case ShapeType::Mesh: return addMesh(shape, s);
    case ShapeType::Plane: return addPlanePatch(shape.normal, s);
  }
}

// --- 2-D shapes: one counter-clockwise outline each -------------------------------------------

std::vector<Eigen::Vector2d> outline2(const Shape<2>& shape) {
  std::vector<Eigen::Vector2d> corners;
  if (shape.type == ShapeType::Box) {
    const Eigen::Vector2d h = shape.halfExtents;
    corners = {{-h.x(), -h.y()}, {h.x(), -h.y()}, {h.x(), h.y()}, {-h.x(), h.y()}};
  } else if (shape.type == ShapeType::Convex) {
    for (int i = 0; i < shape.vertexCount(); ++i) corners.push_back(shape.vertex(i));
  } else if (shape.type == ShapeType::Plane) {
    // A half-plane is unbounded: a strip of it, kPlanePatchSize along the boundary line (centred
    // on the body, through which the line passes) and kPlaneStripDepth deep on the solid side.
    const Eigen::Vector2d n = shape.normal.normalized(), t(n.y(), -n.x());  // t: n turned clockwise
    const double a = kPlanePatchSize / 2, depth = kPlaneStripDepth;
    corners = {-a * t - depth * n, a * t - depth * n, a * t, -a * t};
  } else {  // disk
    for (int j = 0; j < kRoundSegments; ++j) {
      const double angle = 2 * M_PI * j / kRoundSegments;
      corners.push_back(shape.radius * Eigen::Vector2d(std::cos(angle), std::sin(angle)));
    }
  }
  return corners;
}

// --- level-set contours -----------------------------------------------------------------------

// The zero of phi between body-frame points a and b whose samples fa, fb lie on either side
// (one <= 0, the other > 0), by regula falsi with the Illinois modification. On a cell edge the
// multilinear phi is linear and the first step is exact; on the cell diagonals the tetrahedra
// use, it is a quadratic or cubic and a few more steps reach it to rounding.
template <int d>
Eigen::Matrix<double, d, 1> zeroOnSegment(const LevelSet<d>& ls, const Eigen::Matrix<double, d, 1>& a,
                                          const Eigen::Matrix<double, d, 1>& b, double fa, double fb) {
  const double tolerance = 1e-14 * (std::abs(fa) + std::abs(fb));
  double t0 = 0, t1 = 1, f0 = fa, f1 = fb, t = 0;
  int kept = -1;  // the end the last step kept: halving its value when kept twice avoids slow one-sided steps
  for (int step = 0; step < 100; ++step) {
    t = (f0 * t1 - f1 * t0) / (f0 - f1);
    const double f = ls.value(a + t * (b - a));
    if (std::abs(f) <= tolerance || t1 - t0 <= 1e-15) break;
    if ((f > 0) == (f1 > 0)) {
      t1 = t, f1 = f;
      if (kept == 0) f0 /= 2;
      kept = 0;
    } else {
      t0 = t, f0 = f;
      if (kept == 1) f1 /= 2;
      kept = 1;
    }
  }
  return a + t * (b - a);
}

// Contour points on the segments between two samples, each computed once: the cells and
// tetrahedra sharing a segment share its point, so 3-D contours are connected surfaces and 2-D
// ones closed loops.
template <int d>
class ContourPoints {
 public:
  using Index = Eigen::Matrix<int, d, 1>;

  ContourPoints(const LevelSet<d>& ls, PosedSurface<d>& s) : ls_(ls), s_(s) {}

  bool inside(const Index& i) const { return ls_.values[ls_.sampleIndex(i)] <= 0; }
  int on(Index i, Index j) {
    int a = ls_.sampleIndex(i), b = ls_.sampleIndex(j);
    if (a > b) std::swap(a, b), std::swap(i, j);  // the same point whichever cell asks
    const long long key = static_cast<long long>(a) * static_cast<long long>(ls_.values.size()) + b;
    auto [it, added] = points_.try_emplace(key, -1);
    if (added) it->second = s_.point(zeroOnSegment<d>(ls_, ls_.node(i), ls_.node(j), ls_.values[a], ls_.values[b]));
    return it->second;
  }
  // Visits the lowest corner of every sample cell, x fastest.
  template <class Visit>
  void forEachCell(Visit&& visit) const {
    solvers::forEachIndexIn<d>(Index::Zero(), (ls_.samples.array() - 2).matrix(), visit);
  }

 private:
  const LevelSet<d>& ls_;
  PosedSurface<d>& s_;
  std::unordered_map<long long, int> points_;
};

// (b - a) . ((c - a) x (e - a)): positive when the tetrahedron a, b, c, e is positively oriented.
double orientation(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                   const Eigen::Vector3d& e) {
  return (b - a).dot((c - a).cross(e - a));
}

// One tetrahedron of a cell: one triangle when one corner is alone on its side, else a quad
// (two triangles) across the four edges between the two inside and two outside corners. Each
// crossing lies inside its edge, so a face's orientation follows from the corners' (exact grid
// points): rounding cannot flip a nearly degenerate triangle. Faces look towards larger phi.
void addTetrahedron(const std::array<Eigen::Vector3i, 4>& corner, ContourPoints<3>& points, const LevelSet<3>& ls,
                    PosedSurface<3>& s) {
  std::vector<Eigen::Vector3i> in, out;
  for (const auto& c : corner) (points.inside(c) ? in : out).push_back(c);
  if (in.empty() || out.empty()) return;
  if (in.size() == 2) {
    const int p = points.on(in[0], out[0]), q = points.on(in[0], out[1]);
    const int r = points.on(in[1], out[1]), t = points.on(in[1], out[0]);
    if (orientation(ls.node(in[0]), ls.node(in[1]), ls.node(out[0]), ls.node(out[1])) > 0) {
      s.face({p, q, r});
      s.face({p, r, t});
    } else {
      s.face({p, r, q});
      s.face({p, t, r});
    }
    return;
  }
  const bool loneInside = in.size() == 1;
  const auto& lone = loneInside ? in[0] : out[0];
  const auto& rest = loneInside ? out : in;
  const int p = points.on(lone, rest[0]), q = points.on(lone, rest[1]), r = points.on(lone, rest[2]);
  // True when the normal of p, q, r points away from the corner `lone`.
  const bool awayFromLone = orientation(ls.node(lone), ls.node(rest[0]), ls.node(rest[1]), ls.node(rest[2])) > 0;
  if (awayFromLone == loneInside) s.face({p, q, r});
  else s.face({p, r, q});
}

// Marching tetrahedra: every cell split into the six tetrahedra around its diagonal from corner
// (0,0,0) to (1,1,1), the same way in every cell so that neighbouring cells' faces match.
void addMarchingTetrahedra(const LevelSet<3>& ls, PosedSurface<3>& s) {
  ContourPoints<3> points(ls, s);
  const int axisOrders[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  points.forEachCell([&](const Eigen::Vector3i& cell) {
    int insideCorners = 0;
    for (int k = 0; k < 8; ++k) insideCorners += points.inside(cell + Eigen::Vector3i(k & 1, (k >> 1) & 1, k >> 2));
    if (insideCorners == 0 || insideCorners == 8) return;
    for (const auto& order : axisOrders) {
      std::array<Eigen::Vector3i, 4> corner;
      corner[0] = cell;
      for (int k = 0; k < 3; ++k) corner[k + 1] = corner[k] + Eigen::Vector3i::Unit(order[k]);
      addTetrahedron(corner, points, ls, s);
    }
  });
}

// Polygons along the directed segments (start point -> end point); a chain that does not close
// (only when the body touches the sampled box, which the scene reader rejects) ends where its
// segments end.
void joinLoops(const std::vector<std::pair<int, int>>& segments, PosedSurface<2>& s) {
  std::unordered_map<int, int> next;
  for (const auto& [from, to] : segments) next[from] = to;
  std::unordered_set<int> used;
  for (const auto& segment : segments) {
    std::vector<int> loop;
    for (int p = segment.first; used.insert(p).second;) {
      loop.push_back(p);
      const auto it = next.find(p);
      if (it == next.end()) break;
      p = it->second;
    }
    if (loop.size() >= 2) s.face(std::move(loop));
  }
}

// Marching squares. Walking a cell's corners counter-clockwise, the contour leaves the inside
// across one edge and enters it across another; the segment from the leaving to the entering
// crossing has the inside on its left. With two diagonal inside corners the cell centre decides
// whether they are joined (pair each leaving edge with the next entering edge) or separate (the
// previous one).
void addMarchingSquares(const LevelSet<2>& ls, PosedSurface<2>& s) {
  ContourPoints<2> points(ls, s);
  std::vector<std::pair<int, int>> segments;
  points.forEachCell([&](const Eigen::Vector2i& cell) {
    const std::array<Eigen::Vector2i, 4> c = {cell, cell + Eigen::Vector2i(1, 0), cell + Eigen::Vector2i(1, 1),
                                              cell + Eigen::Vector2i(0, 1)};
    std::array<bool, 4> in;
    double centre = 0;
    for (int k = 0; k < 4; ++k) in[k] = points.inside(c[k]), centre += ls.values[ls.sampleIndex(c[k])] / 4;
    const bool saddle = in[0] == in[2] && in[1] == in[3] && in[0] != in[1];
    const int step = saddle && centre <= 0 ? 1 : 3;  // +1 or -1 around the four edges
    for (int leave = 0; leave < 4; ++leave) {
      if (!in[leave] || in[(leave + 1) % 4]) continue;
      int enter = (leave + step) % 4;
      while (in[enter] || !in[(enter + 1) % 4]) enter = (enter + step) % 4;
      segments.emplace_back(points.on(c[leave], c[(leave + 1) % 4]), points.on(c[enter], c[(enter + 1) % 4]));
    }
  });
  joinLoops(segments, s);
}

}  // namespace

template <int d>
void appendShapeSurface(const RigidBody<d>& body, const Shape<d>& shape, int bodyId, SurfacePolygons& out) {
  PosedSurface<d> s(body, bodyId, out);
  if constexpr (d == 3) addShape3(shape, s);
  else s.polygon(outline2(shape));
}

template <int d>
void appendLevelSetContour(const RigidBody<d>& body, const LevelSet<d>& levelSet, int bodyId, SurfacePolygons& out) {
  if ((levelSet.samples.array() < 2).any() || static_cast<long>(levelSet.values.size()) != levelSet.samples.prod())
    return;  // not a sampled grid (the scene reader never makes one)
  PosedSurface<d> s(body, bodyId, out);
  if constexpr (d == 3) addMarchingTetrahedra(levelSet, s);
  else addMarchingSquares(levelSet, s);
}

template void appendShapeSurface<2>(const RigidBody<2>&, const Shape<2>&, int, SurfacePolygons&);
template void appendShapeSurface<3>(const RigidBody<3>&, const Shape<3>&, int, SurfacePolygons&);
template void appendLevelSetContour<2>(const RigidBody<2>&, const LevelSet<2>&, int, SurfacePolygons&);
template void appendLevelSetContour<3>(const RigidBody<3>&, const LevelSet<3>&, int, SurfacePolygons&);

}  // namespace monolith
