// The engine's impact rule (ContactSettingsChoice::impactSubsteps): a fast
// body striking a block of smaller ones, at the settings the engine chooses,
// keeps the bodies out of each other; the choice is recorded so a resumed
// run steps as the long run; a level that gives too few substeps is warned.

#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world.hpp"

#include "test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <optional>
#include <utility>
#include <sstream>
#include <string>
#include <vector>

using namespace stepwise;

namespace {

constexpr auto num = &test::exactNumber;

/// Zero gravity: a square striker `strikerSize` m wide, `massRatio` times a
/// brick's mass (1 kg), at `speed` m/s along x, 0.5 m short of a block of
/// `cols` x `rows` touching bricks `brick` m wide (Box2D's smash, smaller).
/// `substeps` 0 leaves the step settings to the engine.
std::string impactLevel(double speed, double massRatio, double strikerSize, double brick = 0.4, int cols = 12,
                        int rows = 12, int substeps = 0, double restitution = 0.0) {
    std::ostringstream s;
    s << R"({"world": {"gravity": {"x": 0, "y": 0}, "sleep": false)";
    if (substeps > 0) s << R"(, "substeps": )" << substeps << R"(, "solver_iterations": 1)";
    s << R"(}, "entities": [)";
    const double blockHeight = rows * brick;
    s << R"({"name": "striker", "position": {"x": )" << num(-0.5 - 0.5 * strikerSize) << R"(, "y": )"
      << num(0.5 * blockHeight) << R"(}, "velocity": {"x": )" << num(speed) << R"(, "y": 0}, "mass": )"
      << num(massRatio) << R"(, "box": {"width": )" << num(strikerSize) << R"(, "height": )" << num(strikerSize)
      << R"(}, "friction": 0.6, "restitution": )" << num(restitution) << "}";
    for (int c = 0; c < cols; ++c)
        for (int r = 0; r < rows; ++r)
            s << R"(, {"position": {"x": )" << num((c + 0.5) * brick) << R"(, "y": )" << num((r + 0.5) * brick)
              << R"(}, "mass": 1, "box": {"width": )" << num(brick) << R"(, "height": )" << num(brick)
              << R"(}, "friction": 0.6})";
    s << "]}";
    return s.str();
}

/// The deepest contact overlap (m) after `steps` steps (the engine's own
/// contacts of the last step, as bench/hard_cases.cpp measures it).
double endOverlap(const Scene& scene, int steps) {
    World world = test::buildWorld(scene);
    for (int i = 0; i < steps; ++i)
        if (!world.step()) return std::numeric_limits<double>::infinity();
    double deepest = 0.0;
    for (const ContactRecord& c : world.contacts()) deepest = std::max(deepest, c.depth);
    return deepest;
}

/// The deepest contact overlap over `steps` steps (m): what an impact
/// drives into the bricks before the push-out separates them.
double peakOverlap(const Scene& scene, int steps) {
    World world = test::buildWorld(scene);
    double deepest = 0.0;
    for (int i = 0; i < steps; ++i) {
        if (!world.step()) return std::numeric_limits<double>::infinity();
        for (const ContactRecord& c : world.contacts()) deepest = std::max(deepest, c.depth);
    }
    return deepest;
}

/// What the rule asks for a striker `massRatio` times a brick's mass at
/// `speed` on bricks `brick` m wide (restitution 0): the fewest of 1, 2, 4,
/// 8 substeps with the driven brick moving under kImpactTravel of itself.
int expectedSubsteps(double speed, double massRatio, double brick, double dt = 1.0 / 60.0) {
    const double driven = massRatio / (massRatio + 1.0) * speed;
    int s = 1;
    while (s < kImpactMaxSubsteps && driven * dt / s > kImpactTravel * brick) s *= 2;
    return s;
}

/// A level file's scene with its step settings removed (left to the engine).
Scene withoutSettings(const std::string& path) {
    Scene scene = test::parseLevel(test::readFile(path));
    scene.world.substeps = 0;
    scene.world.solverIterations = 0;
    return scene;
}

constexpr int kCols = 30, kRows = 20;  // 600 bricks: the smallest block measured to pack under a ram
constexpr int kSteps = 240;            // 4 s: the ram through the block and the bricks apart

} // namespace

// Speed x mass ratio x striker size at the engine's choice: the deepest
// overlap at the end stays under 2% of a brick at every point, and the
// choice is the rule's. The control: the same block at 1 substep, struck at
// 40 m/s by a ram 1000 times a brick, is driven into itself by more than a
// quarter of a brick while the ram strikes, over twice as deep as at the
// engine's choice.
TEST(ImpactSettings, FastStrikersAtTheDefaultsKeepTheBricksApart) {
    const double brick = 0.4;
    double worst = 0.0;
    for (double size : {2.0, 8.0})
        for (double ratio : {1.0, 30.0, 1000.0})
            for (double speed : {5.0, 10.0, 20.0, 40.0, 80.0, 160.0}) {
                const Scene scene = test::parseLevel(impactLevel(speed, ratio, size, brick, kCols, kRows));
                const ContactSettingsChoice c = chooseContactSettings(scene);
                const std::string label = "striker " + num(size) + " m, " + num(ratio) + ":1, " + num(speed) +
                                          " m/s: " + c.reason();
                EXPECT_EQ(c.impactSubsteps, expectedSubsteps(speed, ratio, brick)) << label;
                EXPECT_EQ(c.substeps, c.impactSubsteps) << label;
                const double overlap = endOverlap(scene, kSteps);
                EXPECT_LT(overlap, 0.02 * brick) << label << ": overlap " << overlap;
                worst = std::max(worst, overlap);
            }
    RecordProperty("deepest_overlap_mm", std::to_string(1e3 * worst));
    const Scene oneSubstep = test::parseLevel(impactLevel(40.0, 1000.0, 8.0, brick, kCols, kRows, 1));
    const Scene chosen = test::parseLevel(impactLevel(40.0, 1000.0, 8.0, brick, kCols, kRows));
    const double oneSubstepPeak = peakOverlap(oneSubstep, kSteps);
    EXPECT_GT(oneSubstepPeak, 0.25 * brick) << "the control no longer packs the bricks";
    EXPECT_GT(oneSubstepPeak, 2.0 * peakOverlap(chosen, kSteps)) << "the choice no longer helps";
}

// Box2D's smash at the defaults: the impact sets the choice, and says so.
TEST(ImpactSettings, SmashChoosesFourSubstepsAndSaysWhy) {
    const Scene smash = withoutSettings(std::string(STEPWISE_SOURCE_DIR) + "/bench/levels/box2d_smash.json");
    const ContactSettingsChoice c = chooseContactSettings(smash);
    EXPECT_EQ(c.impactSubsteps, 4);
    EXPECT_EQ(c.substeps, 4);
    EXPECT_EQ(c.iterations, 2);
    EXPECT_DOUBLE_EQ(c.impactSpeed, 40.0);
    EXPECT_DOUBLE_EQ(c.impactSize, 0.4);
    EXPECT_NE(c.reason().find("impact 40 m/s on 0.4 m bodies, mass ratio 3200:1"), std::string::npos) << c.reason();
}

// Slow scenes choose what they chose without the rule: a ball rolling at
// 1 to 5 m/s into a row of balls, a box dropped 10 m onto a block under
// gravity (a fall is not an impact the rule counts), and bodies that move
// fast but touch nothing (bullet_wall.json: lone bodies just move).
TEST(ImpactSettings, SlowOrLoneBodiesKeepOneSubstep) {
    for (double speed : {1.0, 2.0, 5.0}) {
        std::ostringstream s;
        s << R"({"world": {"gravity": {"x": 0, "y": 0}}, "entities": [{"position": {"x": -2, "y": 0}, "velocity": {"x": )"
          << num(speed) << R"(, "y": 0}, "radius": 0.5})";
        for (int i = 0; i < 5; ++i) s << R"(, {"position": {"x": )" << i << R"(, "y": 0}, "radius": 0.5})";
        s << "]}";
        const ContactSettingsChoice c = chooseContactSettings(test::parseLevel(s.str()));
        EXPECT_EQ(c.substeps, 1) << speed << " m/s: " << c.reason();
        EXPECT_EQ(c.impactSubsteps, 1) << speed;
        EXPECT_EQ(c.reason(), "nothing in the scene needs more") << speed;
    }
    for (double height : {1.0, 10.0, 100.0}) {
        Scene scene = test::parseLevel(impactLevel(0.0, 1000.0, 2.0, 0.4, 4, 4));
        scene.world.gravity = {0.0, -9.81};
        // The striker above the block, falling from rest.
        const Entity striker = test::named(scene, "striker");
        scene.registry.tryGet<Position>(striker)->value = {0.8, 1.6 + height};
        EXPECT_EQ(chooseContactSettings(scene).impactSubsteps, 1) << height << " m";
    }
    const Scene bullets = withoutSettings(std::string(STEPWISE_SOURCE_DIR) + "/levels/bullet_wall.json");
    EXPECT_EQ(chooseContactSettings(bullets).impactSubsteps, 1);
}

// pool_break.json ships with 8 substeps; without them the rule gives the
// same for its 9 m/s cue ball on 57 mm balls (restitution 0.95).
TEST(ImpactSettings, PoolBreakWithoutSettingsGetsTheEightItShipsWith) {
    const ContactSettingsChoice c =
        chooseContactSettings(withoutSettings(std::string(STEPWISE_SOURCE_DIR) + "/levels/pool_break.json"));
    EXPECT_EQ(c.substeps, 8) << c.reason();
    EXPECT_EQ(c.impactSubsteps, 8);
    EXPECT_EQ(c.reason(), "impact 9 m/s on 0.0572 m bodies");
}

// A run of n steps, saved and loaded, then m more equals n + m in one go,
// bit for bit, on impact levels the rule sets (the choice is recorded, so
// the resumed run does not choose again from the bodies' new speeds).
TEST(ImpactSettings, ResumeMidImpactIsBitForBit) {
    for (double speed : {20.0, 40.0, 80.0}) {
        const Scene scene = test::parseLevel(impactLevel(speed, 1000.0, 8.0, 0.4, 12, 10));
        ASSERT_GT(chooseContactSettings(scene).impactSubsteps, 1) << speed;
        for (const auto& [n, m] : {std::pair{10, 30}, std::pair{25, 15}}) {
            World straight = test::buildWorld(scene);
            ASSERT_TRUE(advance(straight, std::uint64_t(n + m)).ok());
            World first = test::buildWorld(scene);
            ASSERT_TRUE(advance(first, std::uint64_t(n)).ok());
            const Scene reloaded = test::parseLevel(test::savedRunText(first, scene));
            World second = test::buildWorld(reloaded);
            EXPECT_EQ(second.settings().substeps, straight.settings().substeps) << speed;
            ASSERT_TRUE(advance(second, std::uint64_t(m)).ok());
            EXPECT_EQ(test::savedRunText(second, reloaded), test::savedRunText(straight, scene))
                << speed << " m/s, " << n << " + " << m << ": resumed run differs";
        }
    }
}

// A level that gives too few substeps for its impact is warned, naming the
// substeps that would hold it; one that gives enough, or leaves the choice
// to the engine, is not.
TEST(ImpactSettings, GivenSubstepsTooFewAreWarnedWithTheNumberThatHolds) {
    for (int given : {1, 2, 3, 4, 8}) {
        const Scene scene = test::parseLevel(impactLevel(40.0, 1000.0, 8.0, 0.4, 4, 4, given));
        const World world = test::buildWorld(scene);
        const std::optional<ImpactHint> hint = world.impactHint();
        // 40 m/s x 1000/1001 over 60 Hz is 0.666 m a step; under 0.2 m needs 4.
        if (given < 4) {
            ASSERT_TRUE(hint.has_value()) << given;
            EXPECT_EQ(hint->substepsNeeded, 4) << given;
            EXPECT_NE(hint->message().find("substeps 4 would keep it under 50%"), std::string::npos)
                << hint->message();
        } else {
            EXPECT_FALSE(hint.has_value()) << given;
        }
    }
    EXPECT_FALSE(test::buildWorld(test::parseLevel(impactLevel(40.0, 1000.0, 8.0, 0.4, 4, 4))).impactHint());
}

// validate and run say it on stderr.
TEST(ImpactSettings, ValidateAndRunWarn) {
    const test::TempDir dir("impact");
    const std::string level = (dir.path / "smash.json").string();
    {
        std::ofstream out(level);
        out << impactLevel(40.0, 1000.0, 8.0, 0.4, 4, 4, 1);
    }
    for (const std::string& command : {std::string("validate ") + level, std::string("run ") + level + " --steps 1"}) {
        const test::CommandResult r =
            test::runCommand(std::string(STEPWISE_BINARY) + " " + command + " 2>&1 >/dev/null");
        EXPECT_EQ(r.exitCode, 0) << command;
        EXPECT_NE(r.out.find(level + ": warning: a body at 40 m/s strikes 0.4 m bodies and drives them 666 mm per "
                                     "substep"),
                  std::string::npos)
            << command << ":\n" << r.out;
        EXPECT_NE(r.out.find("at 1 substep; substeps 4 would keep it under 50%"), std::string::npos)
            << command << ":\n" << r.out;
    }
}
