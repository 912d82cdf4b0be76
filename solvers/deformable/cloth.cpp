#include "solvers/deformable/cloth.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>

namespace monolith::solvers::deformable {

ClothMeshData sheetMesh(double halfX, double halfZ, double h) {
  if (!(halfX > 0) || !(halfZ > 0) || !(h > 0)) throw std::invalid_argument("sheet mesh: sizes must be positive");
  const int nx = std::max(1, static_cast<int>(std::lround(2 * halfX / h)));
  const int nz = std::max(1, static_cast<int>(std::lround(2 * halfZ / h)));
  ClothMeshData m;
  for (int j = 0; j <= nz; ++j)
    for (int i = 0; i <= nx; ++i) m.x.push_back(VecD<3>(-halfX + 2 * halfX * i / nx, 0, -halfZ + 2 * halfZ * j / nz));
  auto id = [&](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nx; ++i) {
      const int a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), e = id(i, j + 1);
      // Counter-clockwise seen from +y: (a, e, c) has normal (e - a) x (c - a) along +y.
      if ((i + j) % 2 == 0) m.triangles.insert(m.triangles.end(), {a, e, c, a, c, b});
      else m.triangles.insert(m.triangles.end(), {a, e, b, b, e, c});
    }
  return m;
}

std::string clothProblem(const ClothMeshData& m) {
  std::ostringstream out;
  const int n = static_cast<int>(m.x.size());
  if (m.triangles.empty()) return "no triangles";
  std::vector<char> used(n, 0);
  std::map<std::pair<int, int>, int> edges;
  for (int t = 0; t < m.triangleCount(); ++t) {
    const int* v = &m.triangles[3 * t];
    for (int k = 0; k < 3; ++k)
      if (v[k] < 0 || v[k] >= n) {
        out << "triangle " << t << ": vertex index " << v[k] << " out of range [0, " << n << ")";
        return out.str();
      }
    if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) {
      out << "triangle " << t << ": repeated vertex";
      return out.str();
    }
    const double area = 0.5 * (m.x[v[1]] - m.x[v[0]]).cross(m.x[v[2]] - m.x[v[0]]).norm();
    const double edge = std::max({(m.x[v[1]] - m.x[v[0]]).norm(), (m.x[v[2]] - m.x[v[1]]).norm(),
                                  (m.x[v[0]] - m.x[v[2]]).norm()});
    if (!(area > 1e-10 * edge * edge)) {
      out << "triangle " << t << ": degenerate (area " << area << ")";
      return out.str();
    }
    for (int k = 0; k < 3; ++k) {
      used[v[k]] = 1;
      const int a = v[k], b = v[(k + 1) % 3];
      if (++edges[{std::min(a, b), std::max(a, b)}] > 2) {
        out << "triangle " << t << ": edge (" << a << ", " << b << ") shared by more than two triangles";
        return out.str();
      }
    }
  }
  for (int i = 0; i < n; ++i)
    if (!used[i]) {
      out << "vertex " << i << ": used by no triangle";
      return out.str();
    }
  return "";
}

std::vector<double> clothMasses(const std::vector<double>& restX, const std::vector<int>& triangles, double density) {
  std::vector<double> m(restX.size() / 3, 0.0);
  auto X = [&](int i) { return Eigen::Vector3d(restX[3 * i], restX[3 * i + 1], restX[3 * i + 2]); };
  for (std::size_t t = 0; t + 2 < triangles.size(); t += 3) {
    const int a = triangles[t], b = triangles[t + 1], c = triangles[t + 2];
    const double area = 0.5 * (X(b) - X(a)).cross(X(c) - X(a)).norm();
    for (int v : {a, b, c}) m[v] += density * area / 3;
  }
  return m;
}

std::vector<int> bendingPairs(const std::vector<int>& triangles) {
  // Per edge, the opposite vertices of the triangles around it.
  std::map<std::pair<int, int>, std::vector<int>> opposite;
  for (std::size_t t = 0; t + 2 < triangles.size(); t += 3)
    for (int k = 0; k < 3; ++k) {
      const int a = triangles[t + k], b = triangles[t + (k + 1) % 3], c = triangles[t + (k + 2) % 3];
      opposite[{std::min(a, b), std::max(a, b)}].push_back(c);
    }
  std::vector<int> out;
  for (const auto& [edge, far] : opposite)
    if (far.size() == 2) {
      out.push_back(far[0]);
      out.push_back(far[1]);
    }
  return out;
}

ForceModel<3> clothForceModel(const std::vector<double>& restX, const std::vector<int>& triangles,
                              const ClothParameters& p, const std::vector<double>& masses) {
  ForceModel<3> fm;
  fm.model = Model::Springs;
  fm.rayleighAlpha = p.rayleighAlpha;
  fm.mass = masses;
  auto X = [&](int i) { return Eigen::Vector3d(restX[3 * i], restX[3 * i + 1], restX[3 * i + 2]); };
  auto addSpring = [&](int i, int j, double k) {
    const double mEff = masses[i] * masses[j] / (masses[i] + masses[j]);
    fm.springs.push_back(i);
    fm.springs.push_back(j);
    fm.springRest.push_back((X(j) - X(i)).norm());
    fm.springK.push_back(k);
    fm.springC.push_back(p.overdamping * 2 * std::sqrt(k * mEff));
  };
  std::vector<std::pair<int, int>> edges;
  for (std::size_t t = 0; t + 2 < triangles.size(); t += 3)
    for (int k = 0; k < 3; ++k) {
      const int a = triangles[t + k], b = triangles[t + (k + 1) % 3];
      edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  for (auto [i, j] : edges) addSpring(i, j, p.stretchStiffness);
  if (p.bendStiffness > 0) {
    const std::vector<int> pairs = bendingPairs(triangles);
    for (std::size_t k = 0; k + 1 < pairs.size(); k += 2) addSpring(pairs[k], pairs[k + 1], p.bendStiffness);
  }
  return fm;
}

}  // namespace monolith::solvers::deformable
