#include "solvers/deformable/bvh.h"

#include <algorithm>
#include <numeric>

namespace monolith::solvers::deformable {

namespace {
constexpr int kLeafSize = 4;
}

template <int d>
void Bvh<d>::build(const std::vector<Box<d>>& boxes) {
  nodes_.clear();
  leafBoxes_ = boxes;
  order_.resize(boxes.size());
  std::iota(order_.begin(), order_.end(), 0);
  if (!boxes.empty()) buildNode(boxes, 0, static_cast<int>(boxes.size()));
}

template <int d>
int Bvh<d>::buildNode(const std::vector<Box<d>>& boxes, int begin, int end) {
  const int id = static_cast<int>(nodes_.size());
  nodes_.push_back(Node{});
  Box<d> box = boxes[order_[begin]];
  for (int k = begin + 1; k < end; ++k) {
    box.lo = box.lo.cwiseMin(boxes[order_[k]].lo);
    box.hi = box.hi.cwiseMax(boxes[order_[k]].hi);
  }
  nodes_[id].box = box;
  if (end - begin <= kLeafSize) {
    nodes_[id].begin = begin;
    nodes_[id].end = end;
    return id;
  }
  int axis = 0;
  (box.hi - box.lo).maxCoeff(&axis);
  const int mid = (begin + end) / 2;
  // Ties broken by index, so the split does not depend on the standard library's nth_element.
  std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end, [&](int a, int b) {
    const double ca = boxes[a].lo(axis) + boxes[a].hi(axis), cb = boxes[b].lo(axis) + boxes[b].hi(axis);
    return ca < cb || (ca == cb && a < b);
  });
  const int left = buildNode(boxes, begin, mid);
  const int right = buildNode(boxes, mid, end);
  nodes_[id].left = left;
  nodes_[id].right = right;
  return id;
}

template <int d>
void Bvh<d>::refit(const std::vector<Box<d>>& boxes) {
  if (boxes.size() != order_.size()) {
    build(boxes);
    return;
  }
  leafBoxes_ = boxes;
  // Children are created after their parent: a reverse sweep sees them first.
  for (int id = static_cast<int>(nodes_.size()) - 1; id >= 0; --id) {
    Node& n = nodes_[id];
    if (n.left < 0) {
      n.box = boxes[order_[n.begin]];
      for (int k = n.begin + 1; k < n.end; ++k) {
        n.box.lo = n.box.lo.cwiseMin(boxes[order_[k]].lo);
        n.box.hi = n.box.hi.cwiseMax(boxes[order_[k]].hi);
      }
    } else {
      n.box.lo = nodes_[n.left].box.lo.cwiseMin(nodes_[n.right].box.lo);
      n.box.hi = nodes_[n.left].box.hi.cwiseMax(nodes_[n.right].box.hi);
    }
  }
}

template <int d>
void Bvh<d>::query(const Box<d>& q, std::vector<int>& out) const {
  if (nodes_.empty()) return;
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    if (!n.box.overlaps(q)) continue;
    if (n.left < 0) {
      for (int k = n.begin; k < n.end; ++k)
        if (leafBoxes_[order_[k]].overlaps(q)) out.push_back(order_[k]);
      continue;
    }
    stack[top++] = n.right;
    stack[top++] = n.left;
  }
}

template class Bvh<2>;
template class Bvh<3>;

}  // namespace monolith::solvers::deformable
