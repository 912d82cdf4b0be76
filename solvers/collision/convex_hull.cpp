// Convex hulls for the Convex geometry type: the user gives vertices in any order, the
// narrow phase needs the hull's vertices and faces. Inputs are small (up to a few hundred points),
// so simple O(n^2) algorithms are used; both visit points in a fixed order, so equal inputs give
// equal hulls.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <stdexcept>
#include <unordered_map>

#include "solvers/collision/collision_impl.h"

namespace monolith::solvers::collision {

namespace {

// Relative tolerance for "on the plane/line": a point closer than this times the point set's
// size does not change the hull (it would only add slivers that make face normals noisy).
constexpr double kRelativeFlatness = 1e-10;

double cross2(const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return (a - o).x() * (b - o).y() - (a - o).y() * (b - o).x();
}

}  // namespace

// Andrew's monotone chain; strictly convex turns only, so collinear points are dropped.
std::vector<Eigen::Vector2d> convexHull2(const std::vector<Eigen::Vector2d>& points) {
  const int n = static_cast<int>(points.size());
  if (n < 3) throw std::invalid_argument("convex polygon needs at least 3 vertices");
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int i, int j) {
    if (points[i].x() != points[j].x()) return points[i].x() < points[j].x();
    if (points[i].y() != points[j].y()) return points[i].y() < points[j].y();
    return i < j;
  });
  Eigen::AlignedBox2d box;
  for (const auto& p : points) box.extend(p);
  const double size = box.diagonal().norm();
  const double tolerance = kRelativeFlatness * size * size;  // cross products are areas
  std::vector<Eigen::Vector2d> hull(2 * n);
  int k = 0;
  for (int pass = 0; pass < 2; ++pass) {  // lower chain left to right, then upper right to left
    const int start = k;
    for (int m = 0; m < n; ++m) {
      const Eigen::Vector2d& p = points[order[pass == 0 ? m : n - 1 - m]];
      while (k >= start + 2 && cross2(hull[k - 2], hull[k - 1], p) <= tolerance) --k;
      hull[k++] = p;
    }
    --k;  // the last point of each chain starts the other one
  }
  hull.resize(std::max(k, 0));
  double area2 = 0;
  for (int i = 0; i < static_cast<int>(hull.size()); ++i) {
    const auto& p = hull[i];
    const auto& q = hull[(i + 1) % hull.size()];
    area2 += p.x() * q.y() - p.y() * q.x();
  }
  if (hull.size() < 3 || !(area2 > 2 * tolerance))
    throw std::invalid_argument("convex polygon vertices are collinear or coincide (zero area)");
  return hull;
}

namespace {

struct Face {
  std::array<int, 3> v;
  Eigen::Vector3d normal;
  double offset = 0;
  bool alive = true;
};

std::uint64_t edgeKey(int a, int b) { return (static_cast<std::uint64_t>(a) << 32) | static_cast<std::uint32_t>(b); }

// Incremental hull: a tetrahedron, then every further point replaces the faces it sees by a cone
// over their horizon. Directed edges map to their face, so the face across an edge is its
// reverse's.
class IncrementalHull {
 public:
  explicit IncrementalHull(const std::vector<Eigen::Vector3d>& p) : p_(p) {}

  Hull3 run() {
    const int n = static_cast<int>(p_.size());
    if (n < 4) throw std::invalid_argument("convex hull needs at least 4 vertices");
    Eigen::AlignedBox3d box;
    for (const auto& q : p_) box.extend(q);
    const double size = box.diagonal().norm();
    if (!(size > 0)) throw std::invalid_argument("convex hull vertices all coincide");
    eps_ = kRelativeFlatness * size;
    const std::array<int, 4> t = initialTetrahedron();
    const Eigen::Vector3d inside = 0.25 * (p_[t[0]] + p_[t[1]] + p_[t[2]] + p_[t[3]]);
    for (const auto& f : {std::array<int, 3>{t[0], t[1], t[2]}, std::array<int, 3>{t[0], t[1], t[3]},
                          std::array<int, 3>{t[0], t[2], t[3]}, std::array<int, 3>{t[1], t[2], t[3]}}) {
      // Orient outwards: the tetrahedron's centroid must be behind the face.
      const Eigen::Vector3d n0 = (p_[f[1]] - p_[f[0]]).cross(p_[f[2]] - p_[f[0]]);
      if (n0.dot(inside - p_[f[0]]) > 0) addFace(f[0], f[2], f[1]);
      else addFace(f[0], f[1], f[2]);
    }
    for (int i = 0; i < n; ++i) {
      if (i == t[0] || i == t[1] || i == t[2] || i == t[3]) continue;
      addPoint(i);
    }
    return collect();
  }

 private:
  std::array<int, 4> initialTetrahedron() const {
    const int n = static_cast<int>(p_.size());
    int i0 = 0;
    for (int i = 1; i < n; ++i)
      if (p_[i].x() < p_[i0].x()) i0 = i;
    int i1 = -1;
    double best = eps_;
    for (int i = 0; i < n; ++i) {
      const double dist = (p_[i] - p_[i0]).norm();
      if (dist > best) {
        best = dist;
        i1 = i;
      }
    }
    if (i1 < 0) throw std::invalid_argument("convex hull vertices all coincide");
    const Eigen::Vector3d axis = (p_[i1] - p_[i0]).normalized();
    int i2 = -1;
    best = eps_;
    for (int i = 0; i < n; ++i) {
      const double dist = (p_[i] - p_[i0]).cross(axis).norm();
      if (dist > best) {
        best = dist;
        i2 = i;
      }
    }
    if (i2 < 0) throw std::invalid_argument("convex hull vertices are collinear (zero volume)");
    const Eigen::Vector3d normal = (p_[i1] - p_[i0]).cross(p_[i2] - p_[i0]).normalized();
    int i3 = -1;
    best = eps_;
    for (int i = 0; i < n; ++i) {
      const double dist = std::abs((p_[i] - p_[i0]).dot(normal));
      if (dist > best) {
        best = dist;
        i3 = i;
      }
    }
    if (i3 < 0) throw std::invalid_argument("convex hull vertices are coplanar (zero volume)");
    return {i0, i1, i2, i3};
  }

  void addFace(int a, int b, int c) {
    Face f;
    f.v = {a, b, c};
    f.normal = (p_[b] - p_[a]).cross(p_[c] - p_[a]).normalized();
    f.offset = f.normal.dot(p_[a]);
    const int id = static_cast<int>(faces_.size());
    faces_.push_back(f);
    edges_[edgeKey(a, b)] = id;
    edges_[edgeKey(b, c)] = id;
    edges_[edgeKey(c, a)] = id;
  }

  void addPoint(int i) {
    visible_.assign(faces_.size(), 0);
    bool any = false;
    for (std::size_t f = 0; f < faces_.size(); ++f) {
      if (faces_[f].alive && faces_[f].normal.dot(p_[i]) - faces_[f].offset > eps_) {
        visible_[f] = 1;
        any = true;
      }
    }
    if (!any) return;  // inside (or on) the current hull
    horizon_.clear();
    for (std::size_t f = 0; f < faces_.size(); ++f) {
      if (!visible_[f]) continue;
      const auto& v = faces_[f].v;
      for (int e = 0; e < 3; ++e) {
        const int a = v[e], b = v[(e + 1) % 3];
        const auto across = edges_.find(edgeKey(b, a));
        if (across != edges_.end() && !visible_[across->second]) horizon_.push_back({a, b});
      }
    }
    for (std::size_t f = 0; f < faces_.size(); ++f) {
      if (!visible_[f]) continue;
      faces_[f].alive = false;
      const auto& v = faces_[f].v;
      for (int e = 0; e < 3; ++e) edges_.erase(edgeKey(v[e], v[(e + 1) % 3]));
    }
    for (const auto& e : horizon_) addFace(e[0], e[1], i);
  }

  Hull3 collect() const {
    std::vector<int> newIndex(p_.size(), -1);
    for (const auto& f : faces_)
      if (f.alive)
        for (int v : f.v) newIndex[v] = 0;
    Hull3 hull;
    for (std::size_t i = 0; i < p_.size(); ++i) {
      if (newIndex[i] < 0) continue;
      newIndex[i] = static_cast<int>(hull.vertices.size());
      hull.vertices.push_back(p_[i]);
    }
    for (const auto& f : faces_)
      if (f.alive) hull.triangles.push_back({newIndex[f.v[0]], newIndex[f.v[1]], newIndex[f.v[2]]});
    return hull;
  }

  const std::vector<Eigen::Vector3d>& p_;
  double eps_ = 0;
  std::vector<Face> faces_;
  std::unordered_map<std::uint64_t, int> edges_;
  std::vector<char> visible_;
  std::vector<std::array<int, 2>> horizon_;
};

}  // namespace

Hull3 convexHull3(const std::vector<Eigen::Vector3d>& points) { return IncrementalHull(points).run(); }

}  // namespace monolith::solvers::collision
