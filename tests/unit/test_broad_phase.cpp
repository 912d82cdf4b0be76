// Broad phase: both methods must return exactly the brute-force list of overlapping
// closed boxes, sorted, without pairs of two flagged (infinite or static) boxes, in 2-D and 3-D,
// with unbounded half-space boxes in the mix, over calls whose boxes move or change in number.
#include "solvers/collision/broad_phase.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

namespace {

using monolith::solvers::collision::BroadPhase;
using monolith::solvers::collision::BroadPhaseMethod;
using Pairs = std::vector<std::pair<int, int>>;

template <int d>
using Box = Eigen::AlignedBox<double, d>;

template <int d>
Pairs bruteForce(const std::vector<Box<d>>& boxes, const std::vector<char>& flags) {
  Pairs pairs;
  for (int i = 0; i < static_cast<int>(boxes.size()); ++i)
    for (int j = i + 1; j < static_cast<int>(boxes.size()); ++j) {
      if (!flags.empty() && flags[i] && flags[j]) continue;
      bool overlap = true;
      for (int k = 0; k < d; ++k)
        overlap = overlap && boxes[i].min()[k] <= boxes[j].max()[k] && boxes[j].min()[k] <= boxes[i].max()[k];
      if (overlap) pairs.push_back({i, j});
    }
  return pairs;
}

// n random boxes in a cube of side `side`, a few of them unbounded (half-spaces), about a third
// flagged (static bodies and the half-spaces).
template <int d>
void randomScene(int n, double side, std::mt19937& rng, std::vector<Box<d>>& boxes, std::vector<char>& flags) {
  std::uniform_real_distribution<double> where(0, side), size(0.1, 1.0), coin(0, 1);
  boxes.clear();
  flags.clear();
  for (int i = 0; i < n; ++i) {
    if (i % 97 == 5) {  // a half-space's box
      boxes.push_back(Box<d>(Eigen::Matrix<double, d, 1>::Constant(-1e30), Eigen::Matrix<double, d, 1>::Constant(1e30)));
      flags.push_back(1);
      continue;
    }
    Eigen::Matrix<double, d, 1> c, h;
    for (int k = 0; k < d; ++k) {
      c[k] = where(rng);
      h[k] = size(rng);
    }
    // Some boxes exactly touching the previous one along axis 0: closed boxes must pair.
    if (i > 0 && i % 13 == 0 && boxes.back().max()[0] < 1e29) c[0] = boxes.back().max()[0] + h[0];
    boxes.push_back(Box<d>(c - h, c + h));
    flags.push_back(coin(rng) < 0.3);
  }
}

template <int d>
void expectBothMethodsMatchBruteForce(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<Box<d>> boxes;
  std::vector<char> flags;
  randomScene<d>(n, 2 * std::pow(n, 1.0 / d), rng, boxes, flags);
  const Pairs expected = bruteForce<d>(boxes, flags);
  ASSERT_GT(expected.size(), static_cast<std::size_t>(n));  // a meaningful test: many pairs
  BroadPhase<d> sap(BroadPhaseMethod::SweepAndPrune), tree(BroadPhaseMethod::FclDynamicTree);
  EXPECT_EQ(sap.findPairs(boxes, flags), expected);
  EXPECT_EQ(tree.findPairs(boxes, flags), expected);
  // Without flags nothing is filtered.
  const Pairs unfiltered = bruteForce<d>(boxes, {});
  EXPECT_EQ(sap.findPairs(boxes, {}), unfiltered);
  EXPECT_EQ(tree.findPairs(boxes, {}), unfiltered);
}

TEST(BroadPhase, BothMethodsMatchBruteForceIn3D) { expectBothMethodsMatchBruteForce<3>(500, 1); }
TEST(BroadPhase, BothMethodsMatchBruteForceIn2D) { expectBothMethodsMatchBruteForce<2>(500, 2); }

// findPairsTouching: the brute-force pairs with at least one box of the subset, after the tree
// has seen the boxes before some of them grew (as ContactWorkspace::growPairs uses it), with
// unbounded boxes in and out of the subset.
template <int d>
void expectTouchingPairsMatchBruteForce(unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<Box<d>> boxes;
  std::vector<char> flags;
  randomScene<d>(600, 2 * std::pow(600, 1.0 / d), rng, boxes, flags);
  BroadPhase<d> sap(BroadPhaseMethod::SweepAndPrune), tree(BroadPhaseMethod::FclDynamicTree);
  sap.findPairs(boxes, flags);
  tree.findPairs(boxes, flags);
  std::uniform_real_distribution<double> coin(0, 1), grow(0, 1.5);
  std::vector<char> subset(boxes.size(), 0);
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    if (coin(rng) > 0.1 && i % 97 != 5) continue;
    subset[i] = 1;
    if (boxes[i].max()[0] < 1e29) boxes[i].max()[0] += grow(rng);  // grown along +x
  }
  Pairs expected;
  for (const auto& p : bruteForce<d>(boxes, flags))
    if (subset[p.first] || subset[p.second]) expected.push_back(p);
  ASSERT_GT(expected.size(), 100u);
  EXPECT_EQ(sap.findPairsTouching(boxes, flags, subset), expected);
  EXPECT_EQ(tree.findPairsTouching(boxes, flags, subset), expected);
  EXPECT_THROW(tree.findPairsTouching(boxes, flags, std::vector<char>(3, 1)), std::invalid_argument);
}

TEST(BroadPhase, PairsTouchingASubsetMatchBruteForceIn3D) { expectTouchingPairsMatchBruteForce<3>(5); }
TEST(BroadPhase, PairsTouchingASubsetMatchBruteForceIn2D) { expectTouchingPairsMatchBruteForce<2>(6); }

TEST(BroadPhase, MovingAndChangingScenesStayExact) {
  // The tree refits when only bounds move and rebuilds when boxes come and go.
  std::mt19937 rng(3);
  std::vector<Box<3>> boxes;
  std::vector<char> flags;
  randomScene<3>(300, 12, rng, boxes, flags);
  BroadPhase<3> sap(BroadPhaseMethod::SweepAndPrune), tree(BroadPhaseMethod::FclDynamicTree);
  std::normal_distribution<double> step(0, 0.2);
  for (int call = 0; call < 12; ++call) {
    for (auto& b : boxes) {
      if (b.max()[0] > 1e29) continue;
      const Eigen::Vector3d move(step(rng), step(rng), step(rng));
      b = Box<3>(b.min() + move, b.max() + move);
    }
    if (call == 5) {  // boxes removed and added
      boxes.resize(250);
      flags.resize(250);
      for (int i = 0; i < 40; ++i) {
        const Eigen::Vector3d c(i % 7, i % 5, i % 3);
        boxes.push_back(Box<3>(c, c + Eigen::Vector3d::Constant(0.8)));
        flags.push_back(0);
      }
    }
    const Pairs expected = bruteForce<3>(boxes, flags);
    EXPECT_EQ(sap.findPairs(boxes, flags), expected) << "call " << call;
    EXPECT_EQ(tree.findPairs(boxes, flags), expected) << "call " << call;
  }
}

TEST(BroadPhase, InfiniteBoxesPairWithEverythingButEachOther) {
  const double big = 1e30;
  std::vector<Box<2>> boxes = {Box<2>(Eigen::Vector2d(-big, -big), Eigen::Vector2d(big, 0)),  // ground
                               Box<2>(Eigen::Vector2d(0, -0.1), Eigen::Vector2d(1, 0.9)),
                               Box<2>(Eigen::Vector2d(-big, -big), Eigen::Vector2d(big, big)),  // wall
                               Box<2>(Eigen::Vector2d(5, 5), Eigen::Vector2d(6, 6)),
                               Box<2>(Eigen::Vector2d(6, 6), Eigen::Vector2d(7, 7))};  // touches box 3 at a corner
  const std::vector<char> flags = {1, 0, 1, 0, 0};
  for (auto method : {BroadPhaseMethod::SweepAndPrune, BroadPhaseMethod::FclDynamicTree}) {
    BroadPhase<2> broad(method);
    const Pairs expected = {{0, 1}, {1, 2}, {2, 3}, {2, 4}, {3, 4}};
    EXPECT_EQ(broad.findPairs(boxes, flags), expected);
    // Unflagged, the two unbounded boxes pair too (the narrow phase then finds nothing).
    const Pairs all = {{0, 1}, {0, 2}, {1, 2}, {2, 3}, {2, 4}, {3, 4}};
    EXPECT_EQ(broad.findPairs(boxes, {}), all);
  }
}

TEST(BroadPhase, EdgeCasesAndErrors) {
  for (auto method : {BroadPhaseMethod::SweepAndPrune, BroadPhaseMethod::FclDynamicTree}) {
    BroadPhase<3> broad(method);
    EXPECT_EQ(broad.method(), method);
    EXPECT_TRUE(broad.findPairs({}, {}).empty());
    const std::vector<Box<3>> one = {Box<3>(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones())};
    EXPECT_TRUE(broad.findPairs(one, {0}).empty());
    std::vector<Box<3>> two = {one[0], one[0]};
    EXPECT_EQ(broad.findPairs(two, {}), (Pairs{{0, 1}}));
    EXPECT_THROW(broad.findPairs(two, {0}), std::invalid_argument);
    two[1].min()[1] = std::nan("");
    EXPECT_THROW(broad.findPairs(two, {}), std::invalid_argument);
  }
}

TEST(BroadPhase, RepeatedCallsGiveTheSameList) {
  std::mt19937 rng(9);
  std::vector<Box<3>> boxes;
  std::vector<char> flags;
  randomScene<3>(400, 14, rng, boxes, flags);
  BroadPhase<3> tree(BroadPhaseMethod::FclDynamicTree);
  const Pairs first = tree.findPairs(boxes, flags);
  for (int rep = 0; rep < 3; ++rep) EXPECT_EQ(tree.findPairs(boxes, flags), first);
  BroadPhase<3> other(BroadPhaseMethod::FclDynamicTree);
  EXPECT_EQ(other.findPairs(boxes, flags), first);
}

}  // namespace
