#pragma once
// A bounding volume hierarchy of axis-aligned boxes, entity-free: built top-down by splitting
// at the median centroid of the longest axis, queried with a box for every leaf it overlaps.
// The build is serial and depends only on the boxes (same tree on any thread count); queries are
// read-only and may run in parallel.
#include <Eigen/Core>
#include <vector>

namespace monolith::solvers::deformable {

template <int d>
struct Box {
  Eigen::Matrix<double, d, 1> lo = Eigen::Matrix<double, d, 1>::Zero(), hi = Eigen::Matrix<double, d, 1>::Zero();
  bool overlaps(const Box& o) const { return (lo.array() <= o.hi.array()).all() && (o.lo.array() <= hi.array()).all(); }
};

template <int d>
class Bvh {
 public:
  void build(const std::vector<Box<d>>& boxes);
  // New boxes for the same primitives: the tree keeps its structure, its boxes are recomputed
  // bottom-up (cheaper than a build; looser as the primitives move, never wrong).
  void refit(const std::vector<Box<d>>& boxes);
  std::size_t size() const { return order_.size(); }
  // Appends to `out` every primitive index whose box overlaps `query`, in tree order (fixed for a
  // given build).
  void query(const Box<d>& query, std::vector<int>& out) const;

 private:
  struct Node {
    Box<d> box;
    int left = -1, right = -1;  // children, or -1 for a leaf
    int begin = 0, end = 0;     // a leaf's primitives: order_[begin, end)
  };
  int buildNode(const std::vector<Box<d>>& boxes, int begin, int end);
  std::vector<Node> nodes_;
  std::vector<int> order_;
  std::vector<Box<d>> leafBoxes_;
};

}  // namespace monolith::solvers::deformable
