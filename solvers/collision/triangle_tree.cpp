// Bounding-box tree over a mesh's triangles, built once per PreparedGeometry: the mesh
// narrow phase asks it for the triangles near a shape before running FCL on each of them. Also
// finds each triangle's neighbours across its edges.
// Median splits along the longest axis of the triangle centroids, ties broken by index, so the
// tree (and the candidate order) only depends on the mesh.
#include <algorithm>
#include <numeric>

#include "solvers/collision/collision_impl.h"

namespace monolith::solvers::collision {

namespace {

constexpr int kLeafSize = 4;

struct Builder {
  PreparedGeometry<3>::Impl& impl;
  std::vector<Eigen::AlignedBox3d> boxes;
  std::vector<Eigen::Vector3d> centroids;

  int build(int first, int count) {
    using Node = PreparedGeometry<3>::Impl::TreeNode;
    const int id = static_cast<int>(impl.triangleTree.size());
    impl.triangleTree.push_back(Node{});
    Eigen::AlignedBox3d box, centres;
    for (int k = first; k < first + count; ++k) {
      box.extend(boxes[impl.triangleOrder[k]]);
      centres.extend(centroids[impl.triangleOrder[k]]);
    }
    impl.triangleTree[id].box = box;
    if (count <= kLeafSize) {
      impl.triangleTree[id].first = first;
      impl.triangleTree[id].count = count;
      return id;
    }
    int axis;
    centres.sizes().maxCoeff(&axis);
    const int half = count / 2;
    auto begin = impl.triangleOrder.begin() + first;
    std::nth_element(begin, begin + half, begin + count, [&](int i, int j) {
      const double ci = centroids[i][axis], cj = centroids[j][axis];
      return ci != cj ? ci < cj : i < j;
    });
    const int left = build(first, half);
    const int right = build(first + half, count - half);
    impl.triangleTree[id].left = left;
    impl.triangleTree[id].right = right;
    return id;
  }
};

}  // namespace

void buildTriangleTree(PreparedGeometry<3>::Impl& impl, const Geometry<3>& mesh) {
  Builder builder{impl, {}, {}};
  for (const auto& t : mesh.triangles) {
    Eigen::AlignedBox3d box;
    for (int v : t) box.extend(mesh.vertices[v]);
    builder.boxes.push_back(box);
    builder.centroids.push_back((mesh.vertices[t[0]] + mesh.vertices[t[1]] + mesh.vertices[t[2]]) / 3);
  }
  impl.triangleOrder.resize(mesh.triangles.size());
  std::iota(impl.triangleOrder.begin(), impl.triangleOrder.end(), 0);
  impl.triangleTree.clear();
  builder.build(0, static_cast<int>(mesh.triangles.size()));
  // Neighbours across each edge: the (undirected) edges sorted, a run of exactly two is shared.
  std::vector<std::pair<std::pair<int, int>, int>> edges;  // (edge, 3 * triangle + e)
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (int e = 0; e < 3; ++e) {
      const int a = mesh.triangles[t][e], b = mesh.triangles[t][(e + 1) % 3];
      edges.push_back({{std::min(a, b), std::max(a, b)}, static_cast<int>(3 * t + e)});
    }
  std::sort(edges.begin(), edges.end());
  impl.edgeNeighbours.assign(mesh.triangles.size(), {-1, -1, -1});
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j].first == edges[i].first) ++j;
    if (j - i == 2) {
      const int u = edges[i].second, v = edges[i + 1].second;
      impl.edgeNeighbours[u / 3][u % 3] = v / 3;
      impl.edgeNeighbours[v / 3][v % 3] = u / 3;
    }
    i = j;
  }
}

void trianglesNear(const PreparedGeometry<3>::Impl& impl, const Eigen::AlignedBox3d& box, std::vector<int>& out) {
  if (impl.triangleTree.empty()) return;
  // Depth-first, left before right: a fixed order. A median-split tree over n triangles is about
  // log2(n / 4) deep, so 64 slots cover any mesh that fits in memory.
  int stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const auto& node = impl.triangleTree[stack[--top]];
    if (!node.box.intersects(box)) continue;
    if (node.left < 0) {
      for (int k = node.first; k < node.first + node.count; ++k) out.push_back(impl.triangleOrder[k]);
    } else {
      stack[top++] = node.right;
      stack[top++] = node.left;
    }
  }
}

}  // namespace monolith::solvers::collision
