// ECS core: entity generations, sparse-set pools, multi-component iteration, World<d>.
#include <gtest/gtest.h>

#include "ecs/binary_io.h"
#include "ecs/world.h"

using namespace monolith;

namespace {
struct Mass {
  static constexpr const char* kName = "test_mass";
  double value = 0;
  template <class V>
  void visitFields(V& v) {
    v("value", value);
  }
};
struct Tag {
  static constexpr const char* kName = "test_tag";
  int id = 0;
  template <class V>
  void visitFields(V& v) {
    v("id", id);
  }
};
struct Position3 {
  static constexpr const char* kName = "test_position";
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  template <class V>
  void visitFields(V& v) {
    v("x", x);
  }
};
}  // namespace

TEST(EntityRegistry, DestroyInvalidatesHandleAndSlotReuseBumpsGeneration) {
  EntityRegistry r;
  const Entity a = r.create(), b = r.create();
  EXPECT_EQ(a.index, 0u);
  EXPECT_EQ(b.index, 1u);
  r.destroy(a);
  EXPECT_FALSE(r.alive(a));
  EXPECT_TRUE(r.alive(b));
  const Entity c = r.create();  // reuses slot 0 with a new generation
  EXPECT_EQ(c.index, 0u);
  EXPECT_EQ(c.generation, 1u);
  EXPECT_FALSE(r.alive(a)) << "a stale handle must not alias the recreated entity";
  EXPECT_TRUE(r.alive(c));
  r.destroy(a);  // destroying through a stale handle is a no-op
  EXPECT_TRUE(r.alive(c));
  EXPECT_EQ(r.aliveCount(), 2u);
}

TEST(Pool, AddGetRemoveKeepsDenseArrayConsistent) {
  Pool<Mass> pool("test_mass");
  std::vector<Entity> es;
  for (std::uint32_t i = 0; i < 5; ++i) {
    es.push_back(Entity{i, 0});
    pool.add(es.back(), Mass{double(i)});
  }
  pool.remove(es[1]);  // last element (4) moves into slot 1
  EXPECT_EQ(pool.size(), 4u);
  EXPECT_FALSE(pool.contains(es[1]));
  EXPECT_EQ(pool.get(es[4])->value, 4.0);
  EXPECT_EQ(pool.entities()[1], es[4]);
  for (std::size_t i = 0; i < pool.size(); ++i)
    EXPECT_EQ(pool.get(pool.entities()[i]), &pool.components()[i]) << "sparse and dense views disagree at " << i;
  EXPECT_EQ(pool.get(Entity{0, 1}), nullptr) << "other generation of a slot must not match";
  pool.add(es[0], Mass{42});  // re-adding replaces
  EXPECT_EQ(pool.size(), 4u);
  EXPECT_EQ(pool.get(es[0])->value, 42.0);
}

TEST(Pool, SerializeRoundTripIsBitwise) {
  Pool<Position3> pool("test_position");
  pool.add(Entity{3, 2}, Position3{Eigen::Vector3d(0.1, -1e-300, 3e10)});
  pool.add(Entity{7, 0}, Position3{Eigen::Vector3d(1.0 / 3, 2, 3)});
  BinaryWriter out;
  pool.serialize(out);
  Pool<Position3> back("test_position");
  BinaryReader in(out.bytes().data(), out.bytes().size(), "test");
  back.deserialize(in, 8);
  EXPECT_TRUE(in.atEnd());
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back.entities()[0], (Entity{3, 2}));
  EXPECT_EQ(back.components()[1].x, pool.components()[1].x);
  BinaryWriter again;
  back.serialize(again);
  EXPECT_EQ(again.bytes(), out.bytes());
}

TEST(Pool, TruncatedDataIsAnErrorNotACrash) {
  Pool<Position3> pool("test_position");
  pool.add(Entity{0, 0}, Position3{});
  BinaryWriter out;
  pool.serialize(out);
  BinaryReader in(out.bytes().data(), out.bytes().size() - 3, "truncated");
  Pool<Position3> back("test_position");
  EXPECT_THROW(back.deserialize(in, 1), std::runtime_error);
}

TEST(Pool, EntityIndexBeyondTheTableIsRejected) {
  Pool<Position3> pool("test_position");
  pool.add(Entity{5, 0}, Position3{});
  BinaryWriter out;
  pool.serialize(out);
  BinaryReader in(out.bytes().data(), out.bytes().size(), "test");
  Pool<Position3> back("test_position");
  EXPECT_THROW(back.deserialize(in, 5), std::runtime_error) << "slot 5 does not exist in a 5-slot table";
}

TEST(Pool, SanityCheckNamesFieldAndIndex) {
  Pool<Position3> pool("test_position");
  pool.add(Entity{0, 0}, Position3{Eigen::Vector3d(1, 2, 3)});
  pool.add(Entity{1, 0}, Position3{Eigen::Vector3d(1, std::nan(""), 3)});
  auto v = pool.firstViolation(1e9);
  ASSERT_TRUE(v.has_value());
  EXPECT_EQ(v->entity, (Entity{1, 0}));
  EXPECT_EQ(v->field.field, "x");
  EXPECT_EQ(v->field.index, 1);
  pool.get(Entity{1, 0})->x = Eigen::Vector3d(1, 2, 2e9);  // finite but absurd
  v = pool.firstViolation(1e9);
  ASSERT_TRUE(v.has_value());
  EXPECT_EQ(v->field.index, 2);
  EXPECT_EQ(v->field.value, 2e9);
}

TEST(World, ViewsVisitExactlyEntitiesWithAllComponents) {
  World<3> w;
  std::vector<Entity> es;
  for (int i = 0; i < 10; ++i) {
    es.push_back(w.create("e" + std::to_string(i)));
    w.add(es.back(), Mass{double(i)});
    if (i % 3 == 0) w.add(es.back(), Tag{i});
  }
  std::vector<int> seen;
  w.each<Mass, Tag>([&](Entity e, Mass& m, Tag& t) {
    EXPECT_EQ(m.value, double(t.id));
    EXPECT_EQ(w.name(e), "e" + std::to_string(t.id));
    seen.push_back(t.id);
  });
  EXPECT_EQ(seen, (std::vector<int>{0, 3, 6, 9}));
  // The view order is the first pool's dense order, whichever pool is smaller.
  seen.clear();
  w.each<Tag, Mass>([&](Entity, Tag& t, Mass&) { seen.push_back(t.id); });
  EXPECT_EQ(seen, (std::vector<int>{0, 3, 6, 9}));
}

TEST(World, DestroyRemovesAllComponentsAndNames) {
  World<2> w;
  const Entity a = w.create("a");
  w.add(a, Mass{1});
  w.add(a, Tag{1});
  w.destroy(a);
  EXPECT_FALSE(w.alive(a));
  EXPECT_EQ(w.count<Mass>(), 0u);
  EXPECT_EQ(w.count<Tag>(), 0u);
  EXPECT_FALSE(w.find("a").has_value());
  const Entity b = w.create("a");  // the name is free again, the slot is reused
  EXPECT_EQ(b.index, a.index);
  EXPECT_NE(b.generation, a.generation);
  EXPECT_EQ(w.get<Mass>(a), nullptr);
  EXPECT_EQ(w.find("a").value(), b);
  EXPECT_THROW(w.add(a, Mass{2}), std::logic_error) << "adding to a dead handle is an internal error";
}

TEST(World, FindPoolIsNullUntilTypeIsUsed) {
  World<3> w;
  EXPECT_EQ(w.findPool<Mass>(), nullptr);
  EXPECT_EQ(w.count<Mass>(), 0u);
  w.add(w.create(), Mass{});
  ASSERT_NE(w.findPool<Mass>(), nullptr);
  EXPECT_EQ(w.count<Mass>(), 1u);
  EXPECT_TRUE(w.hasComponentNamed("test_mass"));
}

TEST(BinaryIo, Fnv1aKnownValues) {
  // Published FNV-1a 64-bit test vectors.
  EXPECT_EQ(fnv1a(nullptr, 0), 0xcbf29ce484222325ull);
  const std::uint8_t a[] = {'a'};
  EXPECT_EQ(fnv1a(a, 1), 0xaf63dc4c8601ec8cull);
}
