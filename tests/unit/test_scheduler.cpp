// Scheduler: graph edges from stages and read/write conflicts, instrumented non-overlap of
// conflicting systems, real overlap of independent ones, skipping of unneeded systems.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "ecs/scheduler.h"

using namespace monolith;

namespace {

// A system with declared access that records how many conflicting systems were running when it
// ran (through per-resource activity counters shared by all probes of a test).
struct Activity {
  std::map<std::string, std::atomic<int>> writers, readers;
  std::atomic<int> violations{0};
  std::atomic<int> runs{0};
};

class Probe final : public System<3> {
 public:
  Probe(std::string name, Stage stage, std::vector<std::string> reads, std::vector<std::string> writes,
        Activity* activity, bool needed = true, int sleepMicros = 200)
      : name_(std::move(name)), stage_(stage), reads_(std::move(reads)), writes_(std::move(writes)),
        activity_(activity), needed_(needed), sleepMicros_(sleepMicros) {}
  std::string name() const override { return name_; }
  Stage stage() const override { return stage_; }
  std::vector<std::string> reads() const override { return reads_; }
  std::vector<std::string> writes() const override { return writes_; }
  bool needed(const World<3>&) const override { return needed_; }
  void run(World<3>&, StepContext&) override {
    auto& a = *activity_;
    for (const auto& w : writes_) {
      if (a.writers[w]++ > 0 || a.readers[w] > 0) ++a.violations;
    }
    for (const auto& r : reads_) {
      if (a.writers[r] > 0) ++a.violations;
      ++a.readers[r];
    }
    std::this_thread::sleep_for(std::chrono::microseconds(sleepMicros_));
    for (const auto& w : writes_) --a.writers[w];
    for (const auto& r : reads_) --a.readers[r];
    ++a.runs;
  }

 private:
  std::string name_;
  Stage stage_;
  std::vector<std::string> reads_, writes_;
  Activity* activity_;
  bool needed_;
  int sleepMicros_;
};

// Two of these meet only if they run at the same time: each waits (bounded) for the other.
class Rendezvous final : public System<3> {
 public:
  Rendezvous(std::string name, std::string resource, std::atomic<int>* arrived, std::atomic<bool>* met,
             int timeoutMillis)
      : name_(std::move(name)), resource_(std::move(resource)), arrived_(arrived), met_(met),
        timeoutMillis_(timeoutMillis) {}
  std::string name() const override { return name_; }
  Stage stage() const override { return Stage::Collisions; }
  std::vector<std::string> reads() const override { return {}; }
  std::vector<std::string> writes() const override { return {resource_}; }
  bool needed(const World<3>&) const override { return true; }
  void run(World<3>&, StepContext&) override {
    ++*arrived_;  // "active": running right now
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeoutMillis_);
    while (std::chrono::steady_clock::now() < deadline) {
      if (arrived_->load() >= 2 || met_->load()) {  // the other may already have left
        *met_ = true;
        break;
      }
      std::this_thread::yield();
    }
    --*arrived_;
  }

 private:
  std::string name_, resource_;
  std::atomic<int>* arrived_;
  std::atomic<bool>* met_;
  int timeoutMillis_;
};

}  // namespace

TEST(SystemsConflict, ReadAfterWriteWriteAfterReadWriteAfterWrite) {
  EXPECT_TRUE(systemsConflict({}, {"x"}, {"x"}, {}));   // RAW
  EXPECT_TRUE(systemsConflict({"x"}, {}, {}, {"x"}));   // WAR
  EXPECT_TRUE(systemsConflict({}, {"x"}, {}, {"x"}));   // WAW
  EXPECT_FALSE(systemsConflict({"x"}, {}, {"x"}, {}));  // readers share
  EXPECT_FALSE(systemsConflict({"x"}, {"y"}, {"z"}, {"w"}));
}

TEST(Scheduler, EdgesFollowStagesAndConflicts) {
  Activity activity;
  std::vector<std::unique_ptr<System<3>>> systems;
  systems.push_back(std::make_unique<Probe>("late", Stage::Diagnostics, std::vector<std::string>{"x"},
                                            std::vector<std::string>{}, &activity));
  systems.push_back(std::make_unique<Probe>("writer", Stage::Contact, std::vector<std::string>{},
                                            std::vector<std::string>{"x"}, &activity));
  systems.push_back(std::make_unique<Probe>("reader", Stage::Contact, std::vector<std::string>{"x"},
                                            std::vector<std::string>{}, &activity));
  systems.push_back(std::make_unique<Probe>("other", Stage::Contact, std::vector<std::string>{"y"},
                                            std::vector<std::string>{"z"}, &activity));
  systems.push_back(std::make_unique<Probe>("unneeded", Stage::Contact, std::vector<std::string>{},
                                            std::vector<std::string>{"x"}, &activity, false));
  World<3> world;
  Scheduler<3> s(std::move(systems), world, 2);
  ASSERT_EQ(s.systems().size(), 4u);
  EXPECT_EQ(s.skipped(), std::vector<std::string>{"unneeded"});
  // Serial order: stage first, registration order inside a stage.
  EXPECT_EQ(s.systems()[0]->name(), "writer");
  EXPECT_EQ(s.systems()[3]->name(), "late");
  const int writer = s.indexOf("writer"), reader = s.indexOf("reader"), other = s.indexOf("other"),
            late = s.indexOf("late");
  const std::vector<std::pair<int, int>> expected = {{writer, reader}, {writer, late}, {reader, late}, {other, late}};
  EXPECT_EQ(s.edges(), expected);
  EXPECT_TRUE(s.ordered(writer, reader));
  EXPECT_FALSE(s.ordered(writer, other));
  EXPECT_FALSE(s.ordered(reader, other));
  EXPECT_FALSE(s.ordered(other, reader));
  EXPECT_NE(s.dot().find("\"writer\\n(contact)\""), std::string::npos);
}

TEST(Scheduler, ConflictingSystemsNeverOverlap) {
  Activity activity;
  std::vector<std::unique_ptr<System<3>>> systems;
  // Six systems in one stage over three resources, with every kind of conflict among them.
  const std::vector<std::pair<std::vector<std::string>, std::vector<std::string>>> access = {
      {{"a"}, {"b"}}, {{"b"}, {"c"}}, {{}, {"a"}}, {{"c"}, {}}, {{"a", "c"}, {}}, {{}, {"b", "c"}}};
  for (std::size_t i = 0; i < access.size(); ++i)
    systems.push_back(std::make_unique<Probe>("p" + std::to_string(i), Stage::Contact, access[i].first,
                                              access[i].second, &activity));
  World<3> world;
  Scheduler<3> s(std::move(systems), world, 2);
  StepContext ctx;
  for (int step = 0; step < 200; ++step) s.step(world, ctx);
  EXPECT_EQ(activity.runs.load(), 1200);
  EXPECT_EQ(activity.violations.load(), 0) << "a system ran while a conflicting one was running";
}

TEST(Scheduler, IndependentSystemsRunConcurrentlyWithTwoThreads) {
  std::atomic<int> arrived{0};
  std::atomic<bool> met{false};
  std::vector<std::unique_ptr<System<3>>> systems;
  // Generous timeout: it returns as soon as both run; a loaded machine may be slow to wake a worker.
  systems.push_back(std::make_unique<Rendezvous>("left", "x", &arrived, &met, 5000));
  systems.push_back(std::make_unique<Rendezvous>("right", "y", &arrived, &met, 5000));
  World<3> world;
  Scheduler<3> s(std::move(systems), world, 2);
  EXPECT_TRUE(s.edges().empty());
  StepContext ctx;
  s.step(world, ctx);
  EXPECT_TRUE(met.load()) << "two independent systems did not overlap on 2 threads";
}

TEST(Scheduler, OneThreadRunsSerially) {
  std::atomic<int> arrived{0};
  std::atomic<bool> met{false};
  std::vector<std::unique_ptr<System<3>>> systems;
  systems.push_back(std::make_unique<Rendezvous>("left", "x", &arrived, &met, 200));
  systems.push_back(std::make_unique<Rendezvous>("right", "y", &arrived, &met, 200));
  World<3> world;
  Scheduler<3> s(std::move(systems), world, 1);
  StepContext ctx;
  s.step(world, ctx);
  EXPECT_FALSE(met.load()) << "with one thread no two systems may run at the same time";
  EXPECT_EQ(arrived.load(), 0);
}

TEST(Scheduler, ExceptionInASystemIsRethrownAndGraphIsReusable) {
  struct Thrower final : System<3> {
    bool fail = true;
    std::string name() const override { return "thrower"; }
    Stage stage() const override { return Stage::Contact; }
    std::vector<std::string> reads() const override { return {}; }
    std::vector<std::string> writes() const override { return {"x"}; }
    bool needed(const World<3>&) const override { return true; }
    void run(World<3>&, StepContext&) override {
      if (fail) throw std::runtime_error("boom");
    }
  };
  auto thrower = std::make_unique<Thrower>();
  Thrower* raw = thrower.get();
  std::vector<std::unique_ptr<System<3>>> systems;
  systems.push_back(std::move(thrower));
  World<3> world;
  Scheduler<3> s(std::move(systems), world, 2);
  StepContext ctx;
  EXPECT_THROW(s.step(world, ctx), std::runtime_error);
  raw->fail = false;
  EXPECT_NO_THROW(s.step(world, ctx));
}
