#include "solvers/surface_tension/level_set_front.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

namespace monolith::solvers {

namespace {
double lagrange(const std::vector<double>& t, const std::vector<double>& v, double x) {
  double sum = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    double w = 1;
    for (std::size_t j = 0; j < t.size(); ++j)
      if (j != i) w *= (x - t[j]) / (t[i] - t[j]);
    sum += w * v[i];
  }
  return sum;
}
}  // namespace

double crossingParameter(const std::vector<double>& t, const std::vector<double>& v) {
  double a = 0, b = 1, fa = lagrange(t, v, 0), fb = lagrange(t, v, 1);
  if (fa == 0) return 0;
  if (fb == 0) return 1;
  if ((fa < 0) == (fb < 0)) throw std::invalid_argument("crossingParameter: the end values do not bracket a root");
  int side = 0;
  for (int it = 0; it < 100; ++it) {
    const double c = (a * fb - b * fa) / (fb - fa);
    const double fc = lagrange(t, v, c);
    if (fc == 0 || std::abs(b - a) < 1e-15) return c;
    if ((fc < 0) == (fa < 0)) {
      a = c, fa = fc;
      if (side == -1) fb *= 0.5;
      side = -1;
    } else {
      b = c, fb = fc;
      if (side == 1) fa *= 0.5;
      side = 1;
    }
  }
  return (a * fb - b * fa) / (fb - fa);
}

int mergeSlivers(Front2& front, double minLength) {
  if (!(minLength > 0)) return 0;
  int removed = 0;
  bool again = true;
  while (again) {
    again = false;
    const auto incident = pointSegments(front);
    for (int s = 0; s < front.elementCount(); ++s) {
      const auto e = front.elements[s];
      if ((front.points[e[1]] - front.points[e[0]]).norm() >= minLength) continue;
      const int before = incident[e[0]][0], after = incident[e[1]][1];
      // Deleting e[0] joins (before's start) -> e[1]; deleting e[1] joins e[0] -> (after's end).
      const double lengthDrop0 = before >= 0 ? (front.points[e[1]] - front.points[front.elements[before][0]]).norm() : 1e300;
      const double lengthDrop1 = after >= 0 ? (front.points[front.elements[after][1]] - front.points[e[0]]).norm() : 1e300;
      if (before < 0 && after < 0) continue;  // an isolated segment: leave it
      // A merged segment whose two ends lie on one grid line would lie on that line (a cap over the
      // line whose tip is deleted), and the inside of that line's faces would be undecided; such a
      // merge is taken only when the other one has the same fault.
      auto onOneLine = [&](int a, int b) {
        return front.points[a].x() == front.points[b].x() || front.points[a].y() == front.points[b].y();
      };
      const bool bad0 = before >= 0 && onOneLine(front.elements[before][0], e[1]);
      const bool bad1 = after >= 0 && onOneLine(e[0], front.elements[after][1]);
      std::vector<std::array<int, 2>> elements;
      if (bad0 != bad1 ? bad1 : lengthDrop0 <= lengthDrop1) {
        for (int q = 0; q < front.elementCount(); ++q)
          if (q == before) elements.push_back({front.elements[before][0], e[1]});
          else if (q != s) elements.push_back(front.elements[q]);
      } else {
        for (int q = 0; q < front.elementCount(); ++q)
          if (q == after) elements.push_back({e[0], front.elements[after][1]});
          else if (q != s) elements.push_back(front.elements[q]);
      }
      front.elements = std::move(elements);
      ++removed;
      again = true;
      break;
    }
  }
  // Drop unreferenced points.
  std::vector<int> map(front.points.size(), -1);
  std::vector<Eigen::Vector2d> points;
  for (auto& e : front.elements)
    for (int& k : e) {
      if (map[k] < 0) map[k] = static_cast<int>(points.size()), points.push_back(front.points[k]);
      k = map[k];
    }
  front.points = std::move(points);
  return removed;
}

Front2 frontFromLevelSet(const MacLayout<2>& layout, const std::vector<double>& phi, CrossingOrder order,
                         double sliverFraction, double nodeSnap) {
  const int nx = layout.cells[0], ny = layout.cells[1];
  if (static_cast<int>(phi.size()) != nx * ny) throw std::invalid_argument("frontFromLevelSet: phi has the wrong size");
  const double dx = layout.dx;
  auto cell = [&](int i, int j) {
    i = std::clamp(i, 0, nx - 1);
    j = std::clamp(j, 0, ny - 1);
    return phi[static_cast<std::size_t>(j) * nx + i];
  };
  // Node (i, j) is the lower-left corner of cell (i, j).
  auto node = [&](int i, int j) {
    const double outer = cell(i - 2, j - 1) + cell(i + 1, j - 1) + cell(i - 2, j) + cell(i + 1, j) + cell(i - 1, j - 2) +
                         cell(i, j - 2) + cell(i - 1, j + 1) + cell(i, j + 1);
    const double inner = cell(i - 1, j - 1) + cell(i, j - 1) + cell(i - 1, j) + cell(i, j);
    return -outer / 32 + 5 * inner / 16;
  };
  // Value on the vertical grid line x = i dx at the height of cell row j (between cells i-1 and i).
  auto xFace = [&](int i, int j) {
    return -(cell(i - 2, j) + cell(i + 1, j)) / 16 + 9 * (cell(i - 1, j) + cell(i, j)) / 16;
  };
  auto yFace = [&](int i, int j) {
    return -(cell(i, j - 2) + cell(i, j + 1)) / 16 + 9 * (cell(i, j - 1) + cell(i, j)) / 16;
  };
  std::vector<double> nodes(static_cast<std::size_t>(nx + 1) * (ny + 1));
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) nodes[static_cast<std::size_t>(j) * (nx + 1) + i] = node(i, j);
  auto nodeAt = [&](int i, int j) { return nodes[static_cast<std::size_t>(j) * (nx + 1) + i]; };
  auto origin = [&](int i, int j) { return Eigen::Vector2d(layout.origin + dx * Eigen::Vector2d(i, j)); };

  Front2 front;
  // A crossing next to a node whose value is within nodeSnap dx of zero is the node itself: one point
  // shared by every edge that meets there.
  std::map<long, int> nodePoint;
  auto nodeId = [&](int i, int j) -> int {
    const long key = static_cast<long>(j) * (nx + 1) + i;
    const auto found = nodePoint.find(key);
    if (found != nodePoint.end()) return found->second;
    front.points.push_back(origin(i, j));
    return nodePoint[key] = front.pointCount() - 1;
  };
  // Edge ids: vertical edge (i, j) from node (i, j) to (i, j+1); horizontal from (i, j) to (i+1, j).
  std::map<long, int> crossingOf;
  auto edgeCrossing = [&](bool vertical, int i, int j) -> int {
    const long key = (static_cast<long>(vertical) * (nx + 2) + i) * (ny + 2) + j;
    const auto found = crossingOf.find(key);
    if (found != crossingOf.end()) return found->second;
    double a, b;
    std::vector<double> t, v;
    if (vertical) {
      a = nodeAt(i, j), b = nodeAt(i, j + 1);
      if (order == CrossingOrder::Third) t = {0, 0.5, 1}, v = {a, xFace(i, j), b};
      else t = {-0.5, 0, 1, 1.5}, v = {xFace(i, j - 1), a, b, xFace(i, j + 1)};
    } else {
      a = nodeAt(i, j), b = nodeAt(i + 1, j);
      if (order == CrossingOrder::Third) t = {0, 0.5, 1}, v = {a, yFace(i, j), b};
      else t = {-0.5, 0, 1, 1.5}, v = {yFace(i - 1, j), a, b, yFace(i + 1, j)};
    }
    if (std::abs(a) < nodeSnap * dx) return crossingOf[key] = nodeId(i, j);
    if (std::abs(b) < nodeSnap * dx) return crossingOf[key] = vertical ? nodeId(i, j + 1) : nodeId(i + 1, j);
    const double theta = crossingParameter(t, v);
    const Eigen::Vector2d x = origin(i, j) + theta * dx * (vertical ? Eigen::Vector2d(0, 1) : Eigen::Vector2d(1, 0));
    front.points.push_back(x);
    const int id = front.pointCount() - 1;
    crossingOf[key] = id;
    return id;
  };
  auto crosses = [](double a, double b) { return (a < 0) != (b < 0); };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const double c00 = nodeAt(i, j), c10 = nodeAt(i + 1, j), c01 = nodeAt(i, j + 1), c11 = nodeAt(i + 1, j + 1);
      // Edges in counter-clockwise order: bottom, right, top, left.
      std::vector<int> ids;
      if (crosses(c00, c10)) ids.push_back(edgeCrossing(false, i, j));
      if (crosses(c10, c11)) ids.push_back(edgeCrossing(true, i + 1, j));
      if (crosses(c01, c11)) ids.push_back(edgeCrossing(false, i, j + 1));
      if (crosses(c00, c01)) ids.push_back(edgeCrossing(true, i, j));
      if (ids.empty()) continue;
      std::vector<std::array<int, 2>> pairs;
      if (ids.size() == 2) pairs.push_back({ids[0], ids[1]});
      else if (ids.size() == 4) {
        // Saddle: the cell-centre value decides which corners connect.
        const bool centreInside = cell(i, j) < 0, c00Inside = c00 < 0;
        const int first = centreInside == c00Inside ? 0 : 3;  // pairs (0,1),(2,3) or (3,0),(1,2)
        pairs.push_back({ids[first], ids[(first + 1) % 4]});
        pairs.push_back({ids[(first + 2) % 4], ids[(first + 3) % 4]});
      } else continue;
      // Orient: the outward normal R t = (t_y, -t_x) points up the bilinear gradient.
      const Eigen::Vector2d gradient((c10 - c00 + c11 - c01) / 2, (c01 - c00 + c11 - c10) / 2);
      for (auto p : pairs) {
        if (p[0] == p[1]) continue;  // both ends on one snapped node
        const Eigen::Vector2d t = front.points[p[1]] - front.points[p[0]];
        if (Eigen::Vector2d(t.y(), -t.x()).dot(gradient) < 0) std::swap(p[0], p[1]);
        front.elements.push_back(p);
      }
    }
  mergeSlivers(front, sliverFraction * dx);
  return front;
}

}  // namespace monolith::solvers
