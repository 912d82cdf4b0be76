// The contact schedules (solvers/contact/contact_settings.h, docs/rigid_contact.md "The
// schedule"): each row's values, the default, and their selection by the scene's
// "solvers": {"contact": {"schedule": ...}}.
#include <gtest/gtest.h>

#include <iterator>
#include <string>

#include "scenarios/simulation.h"
#include "solvers/contact/contact_settings.h"
#include "support/scenes.h"

namespace monolith {
namespace {

// A ball over the ground: enough for a scene that populates a world.
std::string sceneWithContact(const std::string& contact) {
  return R"({ "dimension": 3, "time": { "dt": 0.01, "steps": 1 }, "gravity": [0, -9.81, 0],
    "solvers": { "contact": )" +
         contact + R"( },
    "entities": [ { "name": "ball", "shape": { "type": "sphere", "radius": 0.5 }, "rigid_body": { "mass": 1 },
                    "collider": {} } ] })";
}

ContactSettings loaded(const std::string& contact) {
  World<3> world;
  populateWorld(parseScene(sceneWithContact(contact), "schedule.json"), test::builtins(), world);
  return world.resource<ContactSettings>();
}

// The values each schedule must have, written out here rather than read from the table.
// Short: one contact sweep of one level pass, one shock pass, exact finish, step clamp, gaps
// closed, jams from 2 % and regrown from 3 %.
constexpr ContactSchedule kShort{1, 1, 1, true, true, true, 0.02, 0.03};
// The thesis code's (notes 1.6: ten epsilon-ramped sweeps of two level passes, two
// shock-propagation passes; no exact finish, no step clamp, no gap closing; jams from 5 %).
constexpr ContactSchedule kThesis{10, 2, 2, false, false, false, 0.05, 0.05};

void expectSchedule(const ContactSchedule& s, const ContactSchedule& expected) {
  EXPECT_EQ(s.contactIterations, expected.contactIterations);
  EXPECT_EQ(s.contactLevelIterations, expected.contactLevelIterations);
  EXPECT_EQ(s.shockLevelIterations, expected.shockLevelIterations);
  EXPECT_EQ(s.exactManifoldFinish, expected.exactManifoldFinish);
  EXPECT_EQ(s.stepEnergyClamp, expected.stepEnergyClamp);
  EXPECT_EQ(s.closeGaps, expected.closeGaps);
  EXPECT_EQ(s.pushOutJointOverlap, expected.pushOutJointOverlap);
  EXPECT_EQ(s.pushOutJointRegrowOverlap, expected.pushOutJointRegrowOverlap);
}
void expectShort(const ContactSchedule& s) { expectSchedule(s, kShort); }
void expectThesis(const ContactSchedule& s) { expectSchedule(s, kThesis); }

TEST(ContactSchedule, TheTwoRowsHoldTheShortAndTheThesisSchedule) {
  ASSERT_EQ(std::size(kContactSchedules), 2u);
  EXPECT_STREQ(kContactSchedules[0].name, "short");
  EXPECT_STREQ(kContactSchedules[1].name, "thesis");
  ASSERT_NE(findContactSchedule("short"), nullptr);
  ASSERT_NE(findContactSchedule("thesis"), nullptr);
  EXPECT_EQ(findContactSchedule("fast"), nullptr);
  expectShort(*findContactSchedule("short"));
  expectThesis(*findContactSchedule("thesis"));
}

TEST(ContactSchedule, TheDefaultIsTheShortScheduleAndUseScheduleSetsOnlyItsFields) {
  ContactSettings s;
  expectShort(s);
  s.collisionIterations = 7;
  s.useSchedule(*findContactSchedule("thesis"));
  expectThesis(s);
  EXPECT_EQ(s.collisionIterations, 7);  // not a schedule field: left as it was
  s.useSchedule(*findContactSchedule("short"));
  expectShort(s);
}

TEST(ContactSchedule, TheSceneSelectsTheScheduleByName) {
  expectShort(loaded("{}"));
  expectShort(loaded(R"({ "schedule": "short" })"));
  expectThesis(loaded(R"({ "schedule": "thesis" })"));
  // The keys after the schedule adjust it, whatever their order in the file.
  const ContactSettings adjusted = loaded(R"({ "contact_iterations": 3, "schedule": "thesis" })");
  EXPECT_EQ(adjusted.contactIterations, 3);
  EXPECT_EQ(adjusted.contactLevelIterations, 2);
  // A world whose scene set nothing reads the defaults: the short schedule.
  const World<3> empty;
  expectShort(empty.resource<ContactSettings>());
}

TEST(ContactSchedule, AnUnknownScheduleIsRefusedWithTheFilePathAndTheNamesAllowed) {
  try {
    loaded(R"({ "schedule": "fast" })");
    ADD_FAILURE() << "accepted an unknown schedule";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.file(), "schedule.json");
    EXPECT_EQ(e.path(), "solvers.contact.schedule");
    const std::string m = e.what();
    EXPECT_NE(m.find("one of \"short\", \"thesis\""), std::string::npos) << m;
    EXPECT_NE(m.find("\"fast\""), std::string::npos) << m;
  }
}

}  // namespace
}  // namespace monolith
