// The contact stages carry a polytope pair's manifold with its bodies instead of running the
// narrow phase at every update (ContactWorkspace::pairContacts). What the tests hold it to: a
// box lying tilted on a static box, its candidate pose then moved as the impulses of a step move
// it (millimetres, a fraction of a milliradian), gets the points a fresh narrow phase gives there,
// with depths equal to within push-out's tolerance (1e-5 m); a move beyond the reach queries
// afresh; a sphere is always queried afresh.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "scenarios/simulation.h"
#include "support/scenes.h"
#include "systems/contact_workspace.h"

using namespace monolith;
namespace col = monolith::solvers::collision;

namespace {

constexpr double kPushOutTolerance = 1e-5;

std::string boxOnBox(const std::string& upperShape) {
  // A 1 m box (or the given shape) 50 micrometres into a static 4 m slab, turned by 0.02 rad
  // about the vertical: a face contact at the upper box's four corners.
  return R"({"dimension": 3, "time": {"dt": 0.03333333333333333, "end": 1.0}, "gravity": [0, -9.81, 0],
      "entities": [
        {"name": "slab", "shape": {"type": "box", "half_extents": [2, 0.5, 2]},
         "rigid_body": {"static": true, "position": [0, 0, 0]}, "collider": {"friction": 0.5}},
        {"name": "upper", "shape": )" +
         upperShape + R"(,
         "rigid_body": {"mass": 1, "position": [0.3, 0.99995, 0.1], "orientation": [0.99995, 0, 0.0099998, 0]},
         "collider": {"friction": 0.5}}]})";
}

// The scene packed as Step II packs it, with its one pair; the pair's manifold asked as the
// contact stages ask it (margin: the contact thickness) and as a fresh narrow phase gives it.
struct PackedPair {
  Registry registry = test::builtins();
  Simulation<3> sim;
  ContactWorkspace<3> ws;
  col::ContactQuery query;
  explicit PackedPair(const std::string& scene) : sim(parseScene(scene, "carried.json", {}), registry) {
    ws.pack(sim.world(), 1.0 / 30, true);
    ws.findPairs();
    EXPECT_EQ(ws.pairs.size(), 1u);
    query.margin = 1e-4;
  }
  ContactPairState& pair() { return ws.pairs.at(0); }
  ContactBody<3>& a() { return ws.bodies[pair().a]; }
  ContactBody<3>& b() { return ws.bodies[pair().b]; }
  ContactBody<3>& upper() { return a().isStatic ? b() : a(); }
  std::vector<col::ContactPoint<3>> carried(bool firstIsB = false) {
    std::vector<col::ContactPoint<3>> out;
    if (firstIsB) ws.pairContacts(pair(), true, b(), a(), query, out);
    else ws.pairContacts(pair(), false, a(), b(), query, out);
    return out;
  }
  std::vector<col::ContactPoint<3>> fresh() {
    std::vector<col::ContactPoint<3>> out;
    col::findContacts(*a().geometry, a().candidate, *b().geometry, b().candidate, query, out);
    return out;
  }
};

// The pose of `b` moved by dx and turned by `angle` about `axis` (through its centre).
void move(ContactBody<3>& b, const Eigen::Vector3d& dx, double angle, const Eigen::Vector3d& axis) {
  b.candidate.x += dx;
  b.candidate.R = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix() * b.candidate.R;
}

TEST(CarriedManifold, MatchesAFreshQueryAfterASmallMove) {
  PackedPair s(boxOnBox(R"({"type": "box", "half_extents": [0.5, 0.5, 0.5]})"));
  ASSERT_EQ(s.carried().size(), 4u);
  // What a step's impulses do to a resting box's candidate between two contact stages
  // (pyramid_20: 2-9 mm, up to 6e-4 rad).
  move(s.upper(), Eigen::Vector3d(6e-4, -5e-3, 3e-4), 4e-4, Eigen::Vector3d(1, 0.3, 0.2));
  const auto carried = s.carried(), fresh = s.fresh();
  ASSERT_EQ(carried.size(), fresh.size());
  for (const auto& c : carried) {
    // The fresh point nearest to it.
    const auto near = std::min_element(fresh.begin(), fresh.end(), [&](const auto& x, const auto& y) {
      return (x.point - c.point).norm() < (y.point - c.point).norm();
    });
    EXPECT_LT((near->point - c.point).norm(), 5e-3);
    EXPECT_NEAR(near->depth, c.depth, kPushOutTolerance);
    EXPECT_GT(near->normal.dot(c.normal), 1 - 1e-6);
  }
  // The joint solve asks with the pair's b first: the same points, normals reversed.
  const auto flipped = s.carried(true);
  ASSERT_EQ(flipped.size(), carried.size());
  for (std::size_t k = 0; k < carried.size(); ++k) {
    EXPECT_EQ(flipped[k].depth, carried[k].depth);
    EXPECT_EQ(flipped[k].normal, (-carried[k].normal).eval());
  }
}

// The carried points against a fresh query where they must be the fresh ones.
void expectFresh(PackedPair& s, std::size_t expected) {
  const auto again = s.carried(), fresh = s.fresh();
  ASSERT_EQ(fresh.size(), expected);
  ASSERT_EQ(again.size(), fresh.size());
  for (std::size_t k = 0; k < fresh.size(); ++k) {
    EXPECT_NEAR((again[k].point - fresh[k].point).norm(), 0, 1e-12);
    EXPECT_NEAR(again[k].depth, fresh[k].depth, 1e-12);
  }
}

TEST(CarriedManifold, AMoveBeyondTheReachQueriesAfresh) {
  PackedPair s(boxOnBox(R"({"type": "box", "half_extents": [0.5, 0.5, 0.5]})"));
  s.carried();
  // 0.1 rad: far beyond 2 % of the box's radius at its corners; the box now stands on one edge,
  // 7 mm deep.
  move(s.upper(), Eigen::Vector3d(0, 0.04, 0), 0.1, Eigen::Vector3d(1, 0, 0));
  expectFresh(s, 2);
}

TEST(CarriedManifold, ASphereIsAlwaysQueriedAfresh) {
  PackedPair s(boxOnBox(R"({"type": "sphere", "radius": 0.5})"));
  s.carried();
  move(s.upper(), Eigen::Vector3d(1e-3, 0, 0), 0, Eigen::Vector3d(1, 0, 0));
  expectFresh(s, 1);
}

}  // namespace
