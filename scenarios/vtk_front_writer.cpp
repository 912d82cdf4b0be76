#include "scenarios/vtk_front_writer.h"

#include "components/two_phase_flow.h"
#include "scenarios/vtk_writer.h"
#include "solvers/mac_layout.h"
#include "solvers/surface_tension/front.h"
#include "solvers/surface_tension/two_phase_flow.h"

namespace monolith {

namespace {

// The loops (or open polylines) of a front as point-id lists in segment order, starting at an open
// end where there is one.
std::vector<std::vector<int>> frontLines(const solvers::Front2& front) {
  const auto segmentsAt = solvers::pointSegments(front);
  std::vector<char> visited(front.elements.size(), 0);
  std::vector<std::vector<int>> lines;
  for (int s0 = 0; s0 < front.elementCount(); ++s0) {
    if (visited[s0]) continue;
    int s = s0;  // walk back to an open end; a closed loop starts at s0
    for (int prev = segmentsAt[front.elements[s][0]][0]; prev >= 0 && !visited[prev];
         prev = segmentsAt[front.elements[s][0]][0]) {
      if (prev == s0) {
        s = s0;
        break;
      }
      s = prev;
    }
    std::vector<int> line{front.elements[s][0]};
    for (; s >= 0 && !visited[s]; s = segmentsAt[front.elements[s][1]][1]) {
      visited[s] = 1;
      line.push_back(front.elements[s][1]);
    }
    lines.push_back(std::move(line));
  }
  return lines;
}

}  // namespace

void writeFrontFrame(const World<2>& world, const std::string& path) {
  std::vector<double> coords;
  VtkArray velocity{"velocity", 3, {}}, normal{"normal", 3, {}}, curvature{"curvature", 1, {}}, entity{"entity", 1, {}};
  VtkArray lineEntity{"entity", 1, {}}, lineLength{"length", 1, {}};
  std::vector<std::vector<int>> lines;
  const auto* pool = world.findPool<TwoPhaseFlow<2>>();
  for (std::size_t g = 0; pool && g < pool->size(); ++g) {
    const TwoPhaseFlow<2>& flow = pool->components()[g];
    const double id = pool->entities()[g].index;
    solvers::Front2 front;
    for (std::size_t k = 0; k + 1 < flow.frontPoints.size(); k += 2)
      front.points.emplace_back(flow.frontPoints[k], flow.frontPoints[k + 1]);
    for (std::size_t k = 0; k + 1 < flow.frontElements.size(); k += 2)
      front.elements.push_back({flow.frontElements[k], flow.frontElements[k + 1]});
    const solvers::MacLayout<2> layout(flow.cells, flow.dx, flow.origin);
    const Eigen::VectorXd u = Eigen::Map<const Eigen::VectorXd>(flow.u.data(), static_cast<Eigen::Index>(flow.u.size()));
    const auto kappaN = solvers::curvatureNormals(front);
    const auto segmentsAt = solvers::pointSegments(front);
    const int base = static_cast<int>(coords.size() / 3);
    for (int k = 0; k < front.pointCount(); ++k) {
      const Eigen::Vector2d& x = front.points[k];
      coords.insert(coords.end(), {x.x(), x.y(), 0.0});
      velocity.values.insert(velocity.values.end(), {solvers::sampleFaceVelocity(layout, u, 0, x),
                                                     solvers::sampleFaceVelocity(layout, u, 1, x), 0.0});
      Eigen::Vector2d n = Eigen::Vector2d::Zero();
      for (const int s : segmentsAt[k]) {
        if (s < 0) continue;
        const Eigen::Vector2d t = (front.points[front.elements[s][1]] - front.points[front.elements[s][0]]).normalized();
        n += Eigen::Vector2d(t.y(), -t.x());  // R t, outward for counter-clockwise loops
      }
      if (n.norm() > 0) n.normalize();
      normal.values.insert(normal.values.end(), {n.x(), n.y(), 0.0});
      curvature.values.push_back(-kappaN[k].dot(n));
      entity.values.push_back(id);
    }
    for (std::vector<int> line : frontLines(front)) {
      double length = 0;
      for (std::size_t i = 0; i + 1 < line.size(); ++i) length += (front.points[line[i + 1]] - front.points[line[i]]).norm();
      for (int& p : line) p += base;
      lines.push_back(std::move(line));
      lineEntity.values.push_back(id);
      lineLength.values.push_back(length);
    }
  }
  writeFileAtomically(path, polyLineFile(coords, lines, {velocity, normal, curvature, entity}, {lineEntity, lineLength}));
}

}  // namespace monolith
