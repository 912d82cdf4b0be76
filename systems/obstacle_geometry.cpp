#include "systems/obstacle_geometry.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

namespace monolith {

namespace {

// Clips [lo, hi] to the slab |p[i] + t q[i]| <= h; false when nothing is left.
bool clipToSlab(double p, double q, double h, double& lo, double& hi) {
  if (std::abs(q) < 1e-15) return std::abs(p) <= h;
  double t0 = (-h - p) / q, t1 = (h - p) / q;
  if (t0 > t1) std::swap(t0, t1);
  lo = std::max(lo, t0), hi = std::min(hi, t1);
  return lo <= hi;
}

// Clips [lo, hi] to |(p + t q) - c| <= r (a ball) or, for the first `dims` coordinates only, to an
// infinite cylinder about the remaining axis; false when nothing is left.
template <class V>
bool clipToBall(const V& p, const V& q, double r, int dims, double& lo, double& hi) {
  const double a = q.head(dims).squaredNorm(), b = p.head(dims).dot(q.head(dims));
  const double c = p.head(dims).squaredNorm() - r * r;
  if (a < 1e-30) return c <= 0;  // the segment runs along the cylinder's axis
  const double disc = b * b - a * c;
  if (disc < 0) return false;
  const double root = std::sqrt(disc);
  lo = std::max(lo, (-b - root) / a), hi = std::min(hi, (-b + root) / a);
  return lo <= hi;
}

// FNV-1a over the samples' bits: the level set's part of the rasterization key, so a run keyed on
// a large level set does not copy it every step.
double sampleHash(const std::vector<double>& values) {
  std::uint64_t h = 1469598103934665603ull;
  for (double v : values) {
    std::uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    h = (h ^ bits) * 1099511628211ull;
  }
  return static_cast<double>(h >> 11);  // 53 bits: exact in a double
}

}  // namespace

template <int d>
bool ObstacleGeometry<d>::supports(ShapeType type) {
  if (type == ShapeType::Box || type == ShapeType::Sphere) return true;
  if constexpr (d == 2) return type == ShapeType::Convex;
  else return type == ShapeType::Cylinder || type == ShapeType::Capsule;
}

template <int d>
std::string ObstacleGeometry<d>::supportedNames() {
  return d == 2 ? "box, disk or polygon" : "box, sphere, cylinder or capsule";
}

template <int d>
bool ObstacleGeometry<d>::contains(const Vec& x) const {
  const Vec local = toBody(x);
  if (levelSet_) return levelSet_->value(local) <= 0;
  const Shape<d>& s = *shape_;
  switch (s.type) {
    case ShapeType::Box:
      return (local.cwiseAbs().array() <= s.halfExtents.array()).all();
    case ShapeType::Convex: {  // counter-clockwise polygon (2-D): left of every edge
      const int n = s.vertexCount();
      for (int i = 0; i < n; ++i) {
        const Vec a = s.vertex(i), edge = s.vertex((i + 1) % n) - a, r = local - a;
        if (edge[0] * r[1] - edge[1] * r[0] < 0) return false;
      }
      return true;
    }
    case ShapeType::Cylinder:
      return std::abs(local[d - 1]) <= s.halfHeight && local.head(2).squaredNorm() <= s.radius * s.radius;
    case ShapeType::Capsule: {
      Vec axisPoint = Vec::Zero();
      axisPoint[d - 1] = std::clamp(local[d - 1], -s.halfHeight, s.halfHeight);
      return (local - axisPoint).squaredNorm() <= s.radius * s.radius;
    }
    default:
      return local.squaredNorm() <= s.radius * s.radius;
  }
}

template <int d>
void ObstacleGeometry<d>::segmentInside(const Vec& x, const Vec& e, double tMax, std::vector<Interval>& out) const {
  const Vec p = toBody(x), q = body_->rotation().transpose() * e;
  if (levelSet_) return levelSetInside(p, q, tMax, out);
  const Shape<d>& s = *shape_;
  double lo = 0, hi = tMax;
  bool hit = true;
  switch (s.type) {
    case ShapeType::Box:
      for (int i = 0; i < d && hit; ++i) hit = clipToSlab(p[i], q[i], s.halfExtents[i], lo, hi);
      break;
    case ShapeType::Convex: {  // Cyrus-Beck: the half-planes left of the edges
      const int n = s.vertexCount();
      for (int i = 0; i < n && hit; ++i) {
        const Vec a = s.vertex(i), edge = s.vertex((i + 1) % n) - a;
        const double nx = -edge[1], ny = edge[0];  // inward normal
        const double at = nx * (p[0] - a[0]) + ny * (p[1] - a[1]), rate = nx * q[0] + ny * q[1];
        if (std::abs(rate) < 1e-15) hit = at >= 0;
        else if (rate > 0) lo = std::max(lo, -at / rate);
        else hi = std::min(hi, -at / rate);
        hit = hit && lo <= hi;
      }
      break;
    }
    case ShapeType::Cylinder:
      hit = clipToSlab(p[d - 1], q[d - 1], s.halfHeight, lo, hi) && clipToBall(p, q, s.radius, 2, lo, hi);
      break;
    case ShapeType::Capsule: {
      // Convex: its chord is the hull of the chords of its side and its two end balls.
      double outLo = std::numeric_limits<double>::infinity(), outHi = -outLo;
      const auto take = [&](double a, double b) { outLo = std::min(outLo, a), outHi = std::max(outHi, b); };
      double sLo = 0, sHi = tMax;
      if (clipToSlab(p[d - 1], q[d - 1], s.halfHeight, sLo, sHi) && clipToBall(p, q, s.radius, 2, sLo, sHi)) take(sLo, sHi);
      for (double end : {-s.halfHeight, s.halfHeight}) {
        Vec c = p;
        c[d - 1] -= end;
        double bLo = 0, bHi = tMax;
        if (clipToBall(c, q, s.radius, d, bLo, bHi)) take(bLo, bHi);
      }
      lo = outLo, hi = outHi;
      hit = lo <= hi;
      break;
    }
    default: {
      const double r = s.radius, b = p.dot(q), c = p.squaredNorm() - r * r;
      const double disc = b * b - c;
      hit = disc >= 0;
      if (hit) {
        const double root = std::sqrt(disc);
        lo = std::max(lo, -b - root), hi = std::min(hi, -b + root);
        hit = lo <= hi;
      }
    }
  }
  if (hit) out.emplace_back(lo, hi);
}

template <int d>
void ObstacleGeometry<d>::levelSetInside(const Vec& p, const Vec& q, double tMax, std::vector<Interval>& out) const {
  const LevelSet<d>& ls = *levelSet_;
  const auto phi = [&](double t) { return ls.value(p + t * q); };
  const double minStep = 0.25 * ls.spacing, tolerance = 1e-12 * ls.spacing;
  // The crossing in [a, b] (phi(a) on the `inside` side, phi(b) not) by bisection.
  const auto crossing = [&](double a, double b, bool inside) {
    while (b - a > tolerance) {
      const double m = 0.5 * (a + b);
      if ((phi(m) <= 0) == inside) a = m;
      else b = m;
    }
    return 0.5 * (a + b);
  };
  double t = 0, value = phi(0), start = 0;
  bool inside = value <= 0;
  while (t < tMax) {
    const double next = std::min(tMax, t + std::max(std::abs(value) / ls.lipschitz, minStep));
    const double nextValue = phi(next);
    const bool nextInside = nextValue <= 0;
    if (nextInside != inside) {
      const double c = crossing(t, next, inside);
      if (inside) out.emplace_back(start, c);
      else start = c;
      inside = nextInside;
    }
    t = next, value = nextValue;
  }
  if (inside) out.emplace_back(start, tMax);
}

template <int d>
double ObstacleGeometry<d>::rayEntry(const Vec& x, const Vec& e, double tMax) const {
  thread_local std::vector<Interval> parts;
  parts.clear();
  segmentInside(x, e, tMax, parts);
  return parts.empty() ? std::numeric_limits<double>::infinity() : parts.front().first;
}

template <int d>
double ObstacleGeometry<d>::signedDistance(const Vec& x) const {
  const Vec p = toBody(x);
  if (levelSet_) return levelSet_->value(p);
  const Shape<d>& s = *shape_;
  // A box-like solid from per-axis excesses q (positive outside): outside, the distance to the
  // nearest point; inside, the largest (least negative) excess.
  const auto fromExcess = [](const auto& q) { return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0); };
  switch (s.type) {
    case ShapeType::Box:
      return fromExcess((p.cwiseAbs() - s.halfExtents).eval());
    case ShapeType::Convex: {
      const int n = s.vertexCount();
      double nearest = std::numeric_limits<double>::infinity();
      for (int i = 0; i < n; ++i) {
        const Vec a = s.vertex(i), edge = s.vertex((i + 1) % n) - a;
        const double t = std::clamp((p - a).dot(edge) / edge.squaredNorm(), 0.0, 1.0);
        nearest = std::min(nearest, (a + t * edge - p).norm());
      }
      return contains(x) ? -nearest : nearest;
    }
    case ShapeType::Cylinder:
      return fromExcess(Eigen::Vector2d(p.head(2).norm() - s.radius, std::abs(p[d - 1]) - s.halfHeight));
    case ShapeType::Capsule: {
      Vec axisPoint = Vec::Zero();
      axisPoint[d - 1] = std::clamp(p[d - 1], -s.halfHeight, s.halfHeight);
      return (p - axisPoint).norm() - s.radius;
    }
    default:
      return p.norm() - s.radius;
  }
}

template <int d>
double ObstacleGeometry<d>::boundingRadius() const {
  if (levelSet_) return levelSet_->reach;
  const Shape<d>& s = *shape_;
  switch (s.type) {
    case ShapeType::Box:
      return s.halfExtents.norm();
    case ShapeType::Convex: {
      double r = 0;
      for (int i = 0; i < s.vertexCount(); ++i) r = std::max(r, s.vertex(i).norm());
      return r;
    }
    case ShapeType::Cylinder:
      return std::hypot(s.radius, s.halfHeight);
    case ShapeType::Capsule:
      return s.radius + s.halfHeight;
    default:
      return s.radius;
  }
}

template <int d>
void ObstacleGeometry<d>::appendKey(std::vector<double>& key) const {
  const auto put = [&](const auto& v) { key.insert(key.end(), v.data(), v.data() + v.size()); };
  if (levelSet_) {
    key.push_back(-1);
    put(levelSet_->origin);
    key.push_back(levelSet_->spacing);
    put(levelSet_->samples.template cast<double>().eval());
    key.push_back(sampleHash(levelSet_->values));
    return;
  }
  key.push_back(static_cast<double>(shape_->type));
  put(shape_->halfExtents);
  key.push_back(shape_->radius);
  key.push_back(shape_->halfHeight);
  put(shape_->vertices);
}

template class ObstacleGeometry<2>;
template class ObstacleGeometry<3>;

}  // namespace monolith
