#include "solvers/surface_tension/front.h"

#include <cmath>
#include <stdexcept>

namespace monolith::solvers {

Front2 closedPolyline(const std::vector<Eigen::Vector2d>& points) {
  Front2 front;
  front.points = points;
  const int n = static_cast<int>(points.size());
  for (int k = 0; k < n; ++k) front.elements.push_back({k, (k + 1) % n});
  return front;
}

Front2 perturbedCircle(const Eigen::Vector2d& centre, double radius, double epsilon, int m, int n, double offset) {
  if (n < 4) throw std::invalid_argument("perturbedCircle: need at least 4 points");
  const double step = 2 * M_PI / n;
  if (offset < 0) offset = 0.5 * step;
  std::vector<Eigen::Vector2d> points;
  for (int k = 0; k < n; ++k) {
    const double theta = offset + k * step;
    const double r = radius * (1 + epsilon * std::cos(m * theta));
    points.push_back(centre + r * Eigen::Vector2d(std::cos(theta), std::sin(theta)));
  }
  return closedPolyline(points);
}

std::vector<std::array<int, 2>> pointSegments(const Front2& front) {
  std::vector<std::array<int, 2>> incident(front.points.size(), {-1, -1});
  for (int s = 0; s < front.elementCount(); ++s) {
    const auto& e = front.elements[s];
    if (incident[e[1]][0] >= 0 || incident[e[0]][1] >= 0)
      throw std::invalid_argument("front: a point has two incoming or two outgoing segments");
    incident[e[1]][0] = s;
    incident[e[0]][1] = s;
  }
  return incident;
}

std::vector<Eigen::Vector2d> curvatureNormals(const Front2& front) {
  const auto incident = pointSegments(front);
  std::vector<Eigen::Vector2d> kn(front.points.size(), Eigen::Vector2d::Zero());
  for (int k = 0; k < front.pointCount(); ++k) {
    const int a = incident[k][0], b = incident[k][1];
    if (a < 0 || b < 0) continue;
    const Eigen::Vector2d in = front.points[k] - front.points[front.elements[a][0]];
    const Eigen::Vector2d out = front.points[front.elements[b][1]] - front.points[k];
    const double la = in.norm(), lb = out.norm();
    kn[k] = (out / lb - in / la) / (0.5 * (la + lb));
  }
  return kn;
}

std::vector<Eigen::Vector2d> surfaceTensionForces(const Front2& front, double sigma) {
  std::vector<Eigen::Vector2d> f(front.points.size(), Eigen::Vector2d::Zero());
  for (const auto& e : front.elements) {
    const Eigen::Vector2d t = (front.points[e[1]] - front.points[e[0]]).normalized();
    f[e[0]] += sigma * t;  // (6.36): f_k = sigma t, f_{k+1} = -sigma t
    f[e[1]] -= sigma * t;
  }
  return f;
}

double enclosedArea(const Front2& front) {
  double area = 0;
  for (const auto& e : front.elements) {
    const auto& a = front.points[e[0]];
    const auto& b = front.points[e[1]];
    area += 0.5 * (a.x() * b.y() - b.x() * a.y());
  }
  return area;
}

double frontLength(const Front2& front) {
  double length = 0;
  for (const auto& e : front.elements) length += (front.points[e[1]] - front.points[e[0]]).norm();
  return length;
}

namespace {
// The loops of a closed front as ordered point lists.
std::vector<std::vector<int>> loopsOf(const Front2& front) {
  const auto incident = pointSegments(front);
  std::vector<char> seen(front.points.size(), 0);
  std::vector<std::vector<int>> loops;
  for (int start = 0; start < front.pointCount(); ++start) {
    if (seen[start] || incident[start][1] < 0) continue;
    std::vector<int> loop;
    int k = start;
    while (!seen[k]) {
      seen[k] = 1;
      loop.push_back(k);
      const int s = incident[k][1];
      if (s < 0) throw std::invalid_argument("remeshClosedFront: the front has an open end");
      k = front.elements[s][1];
    }
    loops.push_back(loop);
  }
  return loops;
}
}  // namespace

int remeshClosedFront(Front2& front, double minLength, double maxLength) {
  if (!(minLength > 0) || !(maxLength > 2 * minLength))
    throw std::invalid_argument("remeshClosedFront: need 0 < minLength < maxLength / 2");
  int changes = 0;
  std::vector<std::vector<Eigen::Vector2d>> loops;
  for (const auto& indices : loopsOf(front)) {
    std::vector<Eigen::Vector2d> x;
    for (int k : indices) x.push_back(front.points[k]);
    // Split long segments with the third-order stencil (needs the neighbours on both sides). On a
    // wildly distorted loop the stencil need not shorten a segment: the splits are capped.
    const std::size_t cap = 16 * x.size() + 64;
    for (std::size_t k = 0; k < x.size() && x.size() >= 4 && x.size() < cap;) {
      const std::size_t n = x.size(), k1 = (k + 1) % n;
      if ((x[k1] - x[k]).norm() > maxLength) {
        const Eigen::Vector2d mid = -x[(k + n - 1) % n] / 16 + 9 * x[k] / 16 + 9 * x[k1] / 16 - x[(k + 2) % n] / 16;
        x.insert(x.begin() + static_cast<long>(k + 1), mid);
        ++changes;
        continue;  // the first half may still be too long
      }
      ++k;
    }
    // Merge short segments: delete the endpoint that leaves the shorter merged segment.
    for (std::size_t k = 0; k < x.size() && x.size() >= 4;) {
      const std::size_t n = x.size(), k1 = (k + 1) % n;
      if ((x[k1] - x[k]).norm() < minLength) {
        const double dropK = (x[k1] - x[(k + n - 1) % n]).norm();   // k-1 -> k+1
        const double dropK1 = (x[(k + 2) % n] - x[k]).norm();       // k -> k+2
        const std::size_t drop = dropK <= dropK1 ? k : k1;
        x.erase(x.begin() + static_cast<long>(drop));
        ++changes;
        if (drop < k && k > 0) --k;
        continue;
      }
      ++k;
    }
    if (x.size() >= 4) loops.push_back(std::move(x));
    else changes += static_cast<int>(x.size());
  }
  if (changes == 0) return 0;
  Front2 rebuilt;
  for (const auto& x : loops) {
    const int base = rebuilt.pointCount(), n = static_cast<int>(x.size());
    for (int k = 0; k < n; ++k) {
      rebuilt.points.push_back(x[k]);
      rebuilt.elements.push_back({base + k, base + (k + 1) % n});
    }
  }
  front = std::move(rebuilt);
  return changes;
}

bool insideFront(const Front2& front, const Eigen::Vector2d& x) {
  bool inside = false;
  for (const auto& e : front.elements) {
    const auto& a = front.points[e[0]];
    const auto& b = front.points[e[1]];
    if ((a.y() <= x.y() && x.y() < b.y()) || (b.y() <= x.y() && x.y() < a.y())) {
      const double xc = a.x() + (x.y() - a.y()) / (b.y() - a.y()) * (b.x() - a.x());
      if (xc < x.x()) inside = !inside;
    }
  }
  return inside;
}

}  // namespace monolith::solvers
