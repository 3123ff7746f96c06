// The engine's own choice of substeps and solver iterations (a level that
// leaves them out): decided from the scene's structure, recorded in a saved
// run's solver_state, and said by `stepwise validate`. Every test sweeps a
// parameter and asserts a rule, a measured bound or an exact line.

#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world.hpp"

#include "../test_support.hpp"
#include "bridge_level.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

namespace fs = std::filesystem;
using namespace stepwise;

namespace {

constexpr auto num = &test::exactNumber;

constexpr auto parse = &test::parseLevel;

constexpr auto build = &test::buildWorld;

using test::shippedLevels;

constexpr auto savedText = &test::savedRunText;

/// n + m straight steps against n steps, save as text, parse, m steps: the
/// two saved texts (every number round-trips to its double) must be equal.
void expectResumeExact(const Scene& scene, std::uint64_t n, std::uint64_t m, const std::string& label) {
    World straight = build(scene);
    ASSERT_TRUE(advance(straight, n + m).ok()) << label;
    World first = build(scene);
    ASSERT_TRUE(advance(first, n).ok()) << label;
    Scene reloaded = parse(savedText(first, scene));
    World second = build(reloaded);
    EXPECT_EQ(second.settings().substeps, straight.settings().substeps) << label;
    EXPECT_EQ(second.settings().solverIterations, straight.settings().solverIterations) << label;
    ASSERT_TRUE(advance(second, m).ok()) << label;
    EXPECT_EQ(savedText(second, reloaded), savedText(straight, scene)) << label << ": resumed run differs";
}

/// `links` boxes 0.5 m long, hinged end to end, the first to the world, laid
/// out level (released horizontally). Settings left to the engine.
std::string chainLevel(int links, double gravity = 9.81, double lastMass = 1.0) {
    std::ostringstream s;
    s << R"({"world": {"gravity": {"x": 0, "y": )" << num(-gravity) << R"(}}, "entities": [)";
    for (int i = 0; i < links; ++i)
        s << (i ? ",\n" : "") << R"({"name": "link)" << i << R"(", "position": {"x": )" << num((i + 0.5) * 0.5)
          << R"(, "y": 0}, "mass": )" << num(i == links - 1 ? lastMass : 1.0)
          << R"(, "box": {"width": 0.5, "height": 0.05}})";
    for (int i = 0; i < links; ++i) {
        s << R"(, {"name": "pin)" << i << R"(", "joint": {"type": "hinge", "a": "link)" << i << "\"";
        if (i > 0) s << R"(, "b": "link)" << (i - 1) << "\"";
        s << R"(, "anchor": {"x": )" << num(i * 0.5) << R"(, "y": 0}}})";
    }
    s << "]}";
    return s.str();
}

/// A ball (1 m) resting on a static box `thickness` thick, under `gravity`.
std::string ballOnShelf(double gravity, double thickness) {
    return R"({"world": {"gravity": {"x": 0, "y": )" + num(-gravity) + R"(}}, "entities": [
        {"name": "shelf", "position": {"x": 0, "y": )" + num(-0.5 * thickness) + R"(}, "static": true,
         "box": {"width": 4, "height": )" + num(thickness) + R"(}},
        {"name": "ball", "position": {"x": 0, "y": 0.5}, "radius": 0.5, "mass": 1}]})";
}

/// `n` unit boxes stacked on a plane under `gravity`. Settings left to the
/// engine.
std::string stackLevel(int n, double gravity) {
    std::ostringstream s;
    s << R"({"world": {"gravity": {"x": 0, "y": )" << num(-gravity) << R"(}}, "entities": [
        {"name": "floor", "plane": {"normal": {"x": 0, "y": 1}, "offset": 0}, "friction": 0.6})";
    for (int k = 0; k < n; ++k)
        s << R"(, {"name": "box)" << k << R"(", "position": {"x": 0, "y": )" << num(0.5 + k)
          << R"(}, "mass": 1, "friction": 0.6, "box": {"width": 1, "height": 1}})";
    s << "]}";
    return s.str();
}

/// The start of a level: ten 1 kg unit boxes standing on a 2 cm static box
/// under `gravity`, for a test to add what presses them and close.
std::string tenBoxesOnAThinFloor(double gravity) {
    std::ostringstream out;
    out << R"({"world": {"gravity": {"x": 0, "y": )" << num(-gravity) << R"(}}, "entities": [)"
        << R"({"name": "floor", "position": {"x": 0, "y": -0.01}, "static": true,)"
        << R"( "box": {"width": 20, "height": 0.02}, "friction": 0.6})";
    for (int k = 0; k < 10; ++k)
        out << R"(, {"name": "b)" << k << R"(", "position": {"x": 0, "y": )" << num(0.5 + k)
            << R"(}, "mass": 1, "box": {"width": 1, "height": 1}, "friction": 0.6})";
    return out.str();
}

/// Ten boxes on a thin floor under gravity 10 and a 10 m bar, 0.2 m thick,
/// `gap` m above them, hinged to the world at (pivotX, its height) with a
/// motor of `torque` N*m at speed `side` rad/s.
std::string hingedBarLevel(double torque, double gap, double side, double pivotX) {
    std::ostringstream out;
    out << tenBoxesOnAThinFloor(10.0);
    const double y = 10.1 + gap;
    out << R"(, {"name": "bar", "position": {"x": 0, "y": )" << num(y)
        << R"(}, "mass": 1, "box": {"width": 10, "height": 0.2}, "friction": 0.6},)"
        << R"( {"name": "arm", "joint": {"type": "hinge", "a": "bar", "anchor": {"x": )" << num(pivotX)
        << R"(, "y": )" << num(y) << R"(}, "motor_speed": )" << num(side)
        << R"(, "max_motor_torque": )" << num(torque) << "}}]}";
    return out.str();
}

/// Ten 1 m boxes on a floor, under `gravity` and, when `field` > 0, the pull
/// of a static attractor 100 m away, `side` m to the side of straight
/// below, whose pull at the floor is `field` m/s^2 (a planet under the
/// level).
std::string planetStackLevel(Vec2 gravity, double field, double side) {
    const double r = 100.0;
    std::ostringstream s;
    s << R"({"world": {"gravity": {"x": )" << num(gravity.x) << R"(, "y": )" << num(gravity.y)
      << R"(}, "G": 1}, "entities": [)";
    if (field > 0.0)
        s << R"({"name": "planet", "position": {"x": )" << num(side) << R"(, "y": )"
          << num(-std::sqrt(r * r - side * side)) << R"(}, "static": true, "mass": )" << num(field * r * r)
          << R"(, "attractor": {"softening": 0}}, )";
    s << R"({"name": "floor", "plane": {"normal": {"x": 0, "y": 1}, "offset": 0}, "friction": 0.6})";
    for (int k = 0; k < 10; ++k)
        s << R"(, {"name": "box)" << k << R"(", "position": {"x": 0, "y": )" << num(0.5 + k)
          << R"(}, "mass": 1, "friction": 0.6, "box": {"width": 1, "height": 1}})";
    s << "]}";
    return s.str();
}

/// `rows` rows of 10 circles (0.5 m) in a container 5.2 m wide (the
/// tall-pile test's box), scattered over x by `scatter` m: where they are
/// must not change the choice.
std::string pileLevel(int rows, double scatter, double gravity = 10.0) {
    std::ostringstream s;
    s << R"({"world": {"gravity": {"x": 0, "y": )" << num(-gravity) << R"(}}, "entities": [
        {"position": {"x": 0, "y": -0.5}, "static": true, "box": {"width": 8, "height": 1}},
        {"position": {"x": -3.1, "y": 10}, "static": true, "box": {"width": 1, "height": 22}},
        {"position": {"x": 3.1, "y": 10}, "static": true, "box": {"width": 1, "height": 22}})";
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < 10; ++c) {
            const double x = -2.3 + 0.51 * c + scatter * std::sin(1.7 * (r * 10 + c));
            s << R"(, {"position": {"x": )" << num(x) << R"(, "y": )" << num(0.3 + 0.52 * r)
              << R"(}, "radius": 0.25, "friction": 0.6})";
        }
    s << "]}";
    return s.str();
}

/// The deepest contact overlap over steps 420 to 480 of `w` (8 s in, when a
/// pile has settled); infinity if a step fails.
double deepestOverlapSettling(World& w) {
    double deepest = 0.0;
    for (int i = 0; i < 480; ++i) {
        if (!w.step()) return std::numeric_limits<double>::infinity();
        if (i >= 420)
            for (const ContactRecord& c : w.contacts()) deepest = std::max(deepest, c.depth);
    }
    return deepest;
}

int fewestHolding(const std::function<bool(int)>& holds) {
    for (int s = 1; s < 16; s *= 2)
        if (holds(s)) return s;
    return 16;
}


test::CommandResult runCli(const std::string& args) {
    return test::runCommand(std::string(STEPWISE_BINARY) + " " + args + " 2>/dev/null");
}

constexpr auto readText = &test::readFile;

fs::path tempFile(const std::string& name) {
    return fs::path(::testing::TempDir()) / ("hard_settings_" + std::to_string(::getpid()) + "_" + name);
}

} // namespace

// ---- resume: what the engine chose is what a resumed run runs --------------

TEST(HardSettings, EveryShippedLevelResumesBitForBitAsGivenAndWithoutSettings) {
    for (const fs::path& level : shippedLevels()) {
        Result<Scene> given = loadSceneFile(level);
        ASSERT_TRUE(given) << given.error();
        expectResumeExact(*given, 20, 40, level.filename().string() + " (its own settings)");
        // The same level leaving substeps and iterations to the engine.
        Scene chosen = std::move(*given);
        chosen.world.substeps = 0;
        chosen.world.solverIterations = 0;
        expectResumeExact(chosen, 20, 40, level.filename().string() + " (settings left to the engine)");
    }
}

TEST(HardSettings, GeneratedLevelsWithoutSettingsResumeBitForBit) {
    for (const int links : {3, 20}) expectResumeExact(parse(chainLevel(links)), 30, 45, "chain " + std::to_string(links));
    for (const double g : {9.81, 1000.0}) expectResumeExact(parse(ballOnShelf(g, 0.1)), 30, 45, "shelf g " + num(g));
    for (const int rows : {2, 12}) expectResumeExact(parse(pileLevel(rows, 0.0)), 25, 50, "pile " + std::to_string(rows));
    // The load of a static attractor is read where the bodies stand, which
    // a run changes: the recorded choice keeps it.
    expectResumeExact(parse(planetStackLevel({}, 1000.0, 3.0)), 25, 50, "stack on a planet");
    // So is a hinge motor's, read from where its bar stands against the
    // stack.
    expectResumeExact(parse(hingedBarLevel(1e4, 0.5, 1.0, -5.0)), 25, 50, "stack under a hinged bar");
    // Stiffened contacts (contactHertz above the default) are recorded too.
    for (const double g : {100.0, 1000.0}) {
        const Scene stack = parse(stackLevel(10, g));
        ASSERT_GT(chooseContactSettings(stack).contactHertz, kContactHertz);
        World w = build(stack);
        ASSERT_TRUE(advance(w, 5).ok());
        EXPECT_NE(savedText(w, stack).find("\"contact_hertz\": " + num(chooseContactSettings(stack).contactHertz)),
                  std::string::npos);
        expectResumeExact(stack, 25, 50, "stack of 10 at g " + num(g));
    }
}

// A column's contacts compress in series, so its top sinks by n (n - 1) / 2
// times one layer's load overlap. Past what 60 Hz contacts hold (the column
// rule at 1% of a box) under a load stronger than 10 m/s^2, the engine
// stiffens them, by up to loadSpeedup(g), takes the substeps that carry the
// stiffness (up to kMaxContactSubsteps), and lets them push out as much
// faster. A stack under g is then the stack at 10 m/s^2 sped up: swept
// over the height (2 to 20 boxes) and the load (9.81 to 10^6 m/s^2) at the
// engine's choice, every stack stands (its top within 1 cm of upright), and
// wherever the chosen substeps carry the chosen stiffness its top sinks no
// more than the rules' 1% of a box between the boxes plus the floor's slop
// (1.5 cm), or than the same stack sinks at 10 m/s^2 (a 20-box column's
// rule does not hold even there: 27 mm), 10% allowed. Where they do not,
// `contactStiffnessHint` says so, and no layer sinks more than 5% of a box.
// Before: with the stiffness held at 60 Hz, ten boxes under 100 m/s^2 sank
// 97 mm and slid 0.68 m sideways, and toppled at 300 m/s^2; with up to 16
// substeps and the push held at 3 m/s, ten flew apart from 7000 m/s^2,
// twenty from 3000 and five at 10^6.
TEST(HardSettings, StacksUnderStrongLoadsGetTheStiffnessThatHoldsThem) {
    const auto sinkAfter = [](World& w, int n, const std::string& label) {
        for (int i = 0; i < 120; ++i) EXPECT_TRUE(w.step().ok()) << label;
        const Vec2 top = w.bodyPosition(std::size_t(n - 1));
        EXPECT_LT(std::abs(top.x), 0.01) << label;
        return (double(n) - 0.5) - top.y;
    };
    for (const int n : {2, 5, 10, 20}) {
        World reference = build(parse(stackLevel(n, kReferenceGravity)));
        const double referenceSink = sinkAfter(reference, n, std::to_string(n) + " boxes at the reference gravity");
        for (const double g : {9.81, 30.0, 100.0, 300.0, 1000.0, 1e4, 1e5, 1e6}) {
            const Scene scene = parse(stackLevel(n, g));
            const ContactSettingsChoice choice = chooseContactSettings(scene);
            const std::string label = std::to_string(n) + " boxes at g " + num(g) + " (" + choice.reason() + ")";
            // The default stiffness where it holds the column (or at up to
            // kReferenceGravity, where it was measured), more where not.
            const double n1 = double(n);
            const bool holdsAtDefault =
                0.5 * n1 * (n1 - 1.0) * expectedPileOverlap(2, g, 1e-12, 1.0, choice.hertzFraction) <= 0.01 &&
                expectedSupportOverlap(choice.stackDepth, g, 1e-12, 1.0, choice.hertzFraction) <= 0.01;
            if (holdsAtDefault || g <= kReferenceGravity) EXPECT_EQ(choice.contactHertz, kContactHertz) << label;
            else EXPECT_GT(choice.contactHertz, kContactHertz) << label;
            World w = build(scene);
            // The hint is about stiffened contacts only (at the default
            // stiffness the pile's hint speaks).
            const bool carried = choice.contactHertz == kContactHertz ||
                                 choice.contactHertz <=
                                     choice.hertzFraction * w.settings().substeps / scene.world.dt * (1.0 + 1e-12);
            EXPECT_EQ(w.contactStiffnessHint().has_value(), !carried) << label;
            const double sink = sinkAfter(w, n, label);
            if (carried)
                EXPECT_LT(sink, std::max(0.015, 1.1 * referenceSink))
                    << label << ", " << w.settings().substeps << " substeps";
            else
                EXPECT_LT(sink, 0.05 * n1) << label << ", " << w.settings().substeps << " substeps";
        }
    }
}

// A steady load need not be gravity: a static attractor (a planet under
// the level) loads a stack as gravity does, and the choice reads its field
// where it is strongest on a body. Ten boxes on a floor 100 m above a
// planet, no gravity, swept over the field at the floor from 10 to 10^4
// m/s^2, with the planet straight below and 3 m to the side (the field
// 1.7 degrees off -y, which the boxes' friction holds): the choice's load
// is the bottom box's field, and after 2 s the top box is within 1.5 cm
// of where it is under uniform gravity equal to that field, and no more
// than 1.5 cm lower than it started. Read as no load (the choice saw
// gravity only), ten boxes got 1 substep and collapsed from 1000 m/s^2.
TEST(HardSettings, AStaticAttractorLoadsAStackAsGravityDoes) {
    const auto topAfter = [](const Scene& scene, const std::string& label) {
        World w = build(scene);
        for (int i = 0; i < 120; ++i) EXPECT_TRUE(w.step().ok()) << label;
        return w.bodyPosition(9);
    };
    for (const double field : {10.0, 1000.0, 1e4}) {
        for (const double side : {0.0, 3.0}) {
            const Scene pulled = parse(planetStackLevel({}, field, side));
            const ContactSettingsChoice choice = chooseContactSettings(pulled);
            const std::string label = "field " + num(field) + ", planet at x " + num(side) + " (" + choice.reason() + ")";
            // The bottom box, 0.5 m nearer the planet than the floor.
            const double r = 100.0;
            const Vec2 toPlanet = Vec2{side, -std::sqrt(r * r - side * side)} - Vec2{0.0, 0.5};
            const Vec2 bottomField = (field * r * r / std::pow(length(toPlanet), 3.0)) * toPlanet;
            EXPECT_NEAR(choice.gravity, length(bottomField), 1e-9 * field) << label;
            EXPECT_EQ(choice.stackHeight, 10) << label;
            const Vec2 top = topAfter(pulled, label);
            const Vec2 uniform = topAfter(parse(planetStackLevel(bottomField, 0.0, 0.0)), label + ", as gravity");
            EXPECT_LT(length(top - uniform), 0.015) << label << ": top at " << top.x << ", " << top.y
                                                    << "; under gravity " << uniform.x << ", " << uniform.y;
            EXPECT_LT(9.5 - top.y, 0.015) << label;
        }
    }
}

/// Ten 1 m boxes in a column on (or, with `gap` > 0, dropped from 1 m
/// above, `gap` metres apart) a planet of radius 100 m pulling `field`
/// m/s^2 at its surface, static unless `dynamicPlanet`, under `gravity`
/// m/s^2 (down). The planet's mass is field r^2 at G = 1, or
/// `planetMass` with G to match.
std::string onPlanetLevel(double field, double gap = 0.0, int boxes = 10, bool dynamicPlanet = false,
                          double gravity = 0.0, double planetMass = 0.0) {
    const double r = 100.0;
    const double mass = planetMass > 0.0 ? planetMass : field * r * r;
    std::ostringstream level;
    level << R"({"world": {"gravity": {"x": 0, "y": )" << num(-gravity) << R"(}, "G": )"
          << num(field * r * r / mass) << R"(}, "entities": [)"
          << R"({"name": "planet", "position": {"x": 0, "y": )" << num(-r) << "}"
          << (dynamicPlanet ? "" : R"(, "static": true)") << R"(, "mass": )" << num(mass)
          << R"(, "radius": )" << num(r) << R"(, "friction": 0.6, "attractor": {"softening": 0}})";
    const double bottom = gap > 0.0 ? 1.5 : 0.5;
    for (int k = 0; k < boxes; ++k)
        level << R"(, {"name": "box)" << k << R"(", "position": {"x": 0, "y": )" << num(bottom + k * (1.0 + gap))
              << R"(}, "mass": 1, "friction": 0.6, "box": {"width": 1, "height": 1}})";
    level << "]}";
    return level.str();
}

// Only bodies that rest on or under another bear a load the contact rules
// need: a body in orbit rests on nothing, and a lone body on static ground
// holds at any load (its contacts turn rigid before the slop).
// - The stack above a planet (10 m/s^2 at its floor), plus a moon (a 0.2 m
//   ball) 2 m from a sun 1.4 km away that pulls it at 10^4 m/s^2 and
//   touches nothing: the choice is the stack's alone. Read where strongest
//   on any body, the level was taken as under 10^4 m/s^2.
// - render_showcase.json: its planet lands alone on the sun within a
//   second and rests there under 233 m/s^2; the level is read under
//   gravity, as before. Read on every body that lands, it was warned that
//   10 substeps would carry a load its one pile does not bear.
// - A stack standing on the planet's own surface (no floor) bears its
//   field: after 2 s at 10 and 1000 m/s^2 its top is within 1.5 cm of
//   where it started.
// - The same boxes dropped from 1 m above it, half a metre apart, land
//   where the stack stands: the choice reads the field there and chooses
//   the stack's substeps. Read as placed (apart, in the air), they got 1
//   substep and fell through the planet at 1000 m/s^2.
// - Two boxes placed touching in orbit fall together and never land: no
//   load. (Read as placed, touching each other, they were 694 m/s^2.)
// - One box resting on the planet at 10^4 m/s^2 is no load, and rests
//   within the slop.
TEST(HardSettings, OnlyBodiesThatRestOnSomethingBearASteadyLoad) {
    const std::string alone = planetStackLevel({}, 10.0, 0.0);
    std::string withMoon = alone;
    withMoon.insert(withMoon.rfind("]}"),
                    R"(, {"name": "sun", "position": {"x": 1000, "y": 1000}, "static": true, "mass": 40000,)"
                    R"( "attractor": {"softening": 0}}, {"name": "moon", "position": {"x": 1002, "y": 1000},)"
                    R"( "velocity": {"x": 0, "y": 141.4}, "mass": 0.1, "radius": 0.2})");
    const ContactSettingsChoice expected = chooseContactSettings(parse(alone));
    const ContactSettingsChoice got = chooseContactSettings(parse(withMoon));
    // The sun, 1.4 km away, pulls the stack at 0.02 m/s^2.
    EXPECT_NEAR(got.gravity, expected.gravity, 0.05) << got.reason();
    EXPECT_EQ(got.substeps, expected.substeps) << got.reason();
    EXPECT_EQ(got.contactHertz, expected.contactHertz) << got.reason();
    EXPECT_EQ(got.columnHeight, 10) << got.reason();

    Result<Scene> showcase = loadSceneFile(std::string(STEPWISE_SOURCE_DIR) + "/levels/render_showcase.json");
    ASSERT_TRUE(showcase) << showcase.error();
    const ContactSettingsChoice showcaseChoice = chooseContactSettings(*showcase);
    EXPECT_EQ(showcaseChoice.gravity, 9.81) << showcaseChoice.reason();
    EXPECT_FALSE(showcaseChoice.attractorLoad) << showcaseChoice.reason();
    EXPECT_FALSE(build(*showcase).contactStiffnessHint());

    const double r = 100.0;
    for (const double field : {10.0, 1000.0}) {
        const Scene onPlanet = parse(onPlanetLevel(field));
        const ContactSettingsChoice choice = chooseContactSettings(onPlanet);
        const std::string label = "field " + num(field) + " (" + choice.reason() + ")";
        EXPECT_NEAR(choice.gravity, field * r * r / ((r + 0.5) * (r + 0.5)), 1e-9 * field) << label;
        EXPECT_NE(label.find("attractors load resting bodies at up to " + std::string(field == 10.0 ? "9.901" : "990.1") +
                             " m/s^2"),
                  std::string::npos)
            << label;
        World w = build(onPlanet);
        for (int i = 0; i < 120; ++i) ASSERT_TRUE(w.step().ok()) << label;
        EXPECT_LT(9.5 - w.bodyPosition(9).y, 0.015) << label;
        EXPECT_LT(std::abs(w.bodyPosition(9).x), 0.01) << label;

        const Scene dropped = parse(onPlanetLevel(field, 0.5));
        const ContactSettingsChoice landed = chooseContactSettings(dropped);
        const std::string droppedLabel = "dropped, field " + num(field) + " (" + landed.reason() + ")";
        // Where the path first comes within a quarter box of the planet.
        EXPECT_NEAR(landed.gravity, field, 0.02 * field) << droppedLabel;
        EXPECT_EQ(landed.substeps, choice.substeps) << droppedLabel;
        World fell = build(dropped);
        for (int i = 0; i < 300; ++i) ASSERT_TRUE(fell.step().ok()) << droppedLabel;
        EXPECT_LT(std::abs(9.5 - fell.bodyPosition(9).y), 0.015) << droppedLabel;
    }

    // Two boxes placed touching in a circular orbit 120 m from the planet's
    // centre, at 45 degrees (inside the corner of the planet's bounding
    // box): they fall together and never land, so they bear nothing.
    std::string orbiting = onPlanetLevel(1000.0, 0.0, 0);
    const double v = std::sqrt(1000.0 * r * r / 120.0);
    for (const double at : {120.0, 121.0}) {
        const double c = std::sqrt(0.5);
        orbiting.insert(orbiting.rfind("]}"), R"(, {"name": "r)" + num(at) + R"(", "position": {"x": )" +
                                                  num(at * c) + R"(, "y": )" + num(-r + at * c) +
                                                  R"(}, "velocity": {"x": )" + num(-v * c) + R"(, "y": )" +
                                                  num(v * c) + R"(}, "mass": 1, "box": {"width": 1, "height": 1}})");
    }
    const ContactSettingsChoice inOrbit = chooseContactSettings(parse(orbiting));
    EXPECT_EQ(inOrbit.gravity, 0.0) << inOrbit.reason();
    EXPECT_FALSE(inOrbit.attractorLoad) << inOrbit.reason();

    const Scene lone = parse(onPlanetLevel(1e4, 0.0, 1));
    const ContactSettingsChoice loneChoice = chooseContactSettings(lone);
    EXPECT_EQ(loneChoice.gravity, 0.0) << loneChoice.reason();
    World w = build(lone);
    for (int i = 0; i < 120; ++i) ASSERT_TRUE(w.step().ok());
    EXPECT_LT(0.5 - w.bodyPosition(0).y, 0.005);
}

// A planet left dynamic is ground to what rests on it: the stack bears
// its pull less its own acceleration (under gravity both fall, and the
// stack bears the pull alone), scaled by 1 + m / M for a planet of mass M
// under boxes of mass m, which pushes it away. Swept over the pull (10,
// 1000 and 10^4 m/s^2) and gravity (0, and 10 with the planet falling),
// with the planet 10^4 to 10^7 times a box: ten boxes standing on it bear
// the field at the bottom box, and after 2 s the top is within 1.5 cm of
// 9.5 m above the planet's surface and 1 cm of upright; dropped half a
// metre apart (up to 1000 m/s^2; at 10^4 they strike at 100 m/s and
// more, which the impact rule reads), they get the standing stack's
// substeps and stand. Read as no load (static attractors only), the stack
// got 1 substep and fell through the planet at 1000 m/s^2; under gravity
// it got 4, and its top sank 16 cm at 1000 and fell through at 10^4.
// - Swept over the planet's mass at 1000 m/s^2, from 1 to 1000 times the
//   stack's: the load is the bottom box's field times 1 + m / M, and the
//   stack stands. Read only for planets 100 times the median body, the
//   stack on a 99 kg planet of radius 5 m sank 333 mm.
// - The same planet resting on a static floor under gravity does not
//   fall: the stack bears the pull and gravity together.
// - A cluster of attracting discs, each ground to the others, with
//   nothing else resting on them, bears nothing.
TEST(HardSettings, ADynamicAttractorIsGroundToWhatRestsOnIt) {
    const double r = 100.0;
    const auto topAbovePlanet = [&](World& w, int steps, const std::string& label) {
        for (int i = 0; i < steps; ++i) EXPECT_TRUE(w.step().ok()) << label;
        return w.bodyPosition(10) - w.bodyPosition(0) - Vec2{0.0, r};
    };
    for (const double field : {10.0, 1000.0, 1e4}) {
        for (const double gravity : {0.0, 10.0}) {
            const Scene standing = parse(onPlanetLevel(field, 0.0, 10, true, gravity));
            const ContactSettingsChoice choice = chooseContactSettings(standing);
            const std::string label =
                "field " + num(field) + ", gravity " + num(gravity) + " (" + choice.reason() + ")";
            // The planet (field r^2 kg) under ten 1 kg boxes.
            const double bottomField = field * r * r / ((r + 0.5) * (r + 0.5)) * (1.0 + 10.0 / (field * r * r));
            // Under gravity the baseline is gravity itself, which the
            // weakest pull does not exceed.
            EXPECT_NEAR(choice.gravity, std::max(bottomField, gravity), 1e-9 * field) << label;
            EXPECT_TRUE(choice.attractorLoad || bottomField < gravity) << label;
            EXPECT_EQ(choice.stackHeight, 10) << label;
            World w = build(standing);
            const Vec2 top = topAbovePlanet(w, 120, label);
            EXPECT_LT(std::abs(9.5 - top.y), 0.015) << label << ": top " << top.y;
            EXPECT_LT(std::abs(top.x), 0.01) << label;

            if (field > 1000.0) continue;
            const Scene dropped = parse(onPlanetLevel(field, 0.5, 10, true, gravity));
            const ContactSettingsChoice landed = chooseContactSettings(dropped);
            const std::string droppedLabel = "dropped, " + label + " (" + landed.reason() + ")";
            EXPECT_NEAR(landed.gravity, std::max(field, gravity), 0.02 * field) << droppedLabel;
            EXPECT_EQ(landed.substeps, choice.substeps) << droppedLabel;
            World fell = build(dropped);
            const Vec2 fellTop = topAbovePlanet(fell, 300, droppedLabel);
            EXPECT_LT(std::abs(9.5 - fellTop.y), 0.015) << droppedLabel << ": top " << fellTop.y;
        }
    }

    for (const double planetMass : {10.0, 99.0, 100.0, 1000.0, 1e4}) {
        const Scene light = parse(onPlanetLevel(1000.0, 0.0, 10, true, 0.0, planetMass));
        const ContactSettingsChoice choice = chooseContactSettings(light);
        const std::string label = "planet " + num(planetMass) + " kg (" + choice.reason() + ")";
        const double bottomField = 1000.0 * r * r / ((r + 0.5) * (r + 0.5));
        EXPECT_NEAR(choice.gravity, bottomField * (1.0 + 10.0 / planetMass), 1e-9 * bottomField) << label;
        World w = build(light);
        const Vec2 top = topAbovePlanet(w, 120, label);
        EXPECT_LT(std::abs(9.5 - top.y), 0.015) << label << ": top " << top.y;
        EXPECT_LT(std::abs(top.x), 0.01) << label;
    }

    std::string held = onPlanetLevel(1000.0, 0.0, 10, true, 10.0);
    held.insert(held.rfind("]}"), R"(, {"name": "floor", "position": {"x": 0, "y": -200.5}, "static": true,)"
                                  R"( "box": {"width": 400, "height": 1}})");
    const Scene onFloor = parse(held);
    const ContactSettingsChoice heldChoice = chooseContactSettings(onFloor);
    EXPECT_NEAR(heldChoice.gravity, 1000.0 * r * r / ((r + 0.5) * (r + 0.5)) + 10.0, 1e-9) << heldChoice.reason();
    World w = build(onFloor);
    for (int i = 0; i < 120; ++i) ASSERT_TRUE(w.step().ok());
    EXPECT_LT(std::abs(9.5 - (w.bodyPosition(10).y - w.bodyPosition(0).y - r)), 0.015);

    // With attractors switched off the planet is a body like the boxes,
    // and the row on it floats with it, spring and all: no load.
    std::string switchedOff = onPlanetLevel(1000.0, 0.0, 10, true);
    switchedOff.insert(switchedOff.rfind("]}"), R"(, {"name": "pull", "spring": {"a": "box9", "anchor": {"x": 0, "y": -300},)"
                                                R"( "k": 1, "rest_length": 0}})");
    SystemSwitches noAttractors;
    noAttractors.attractors = false;
    const ContactSettingsChoice off = chooseContactSettings(parse(switchedOff), noAttractors);
    EXPECT_EQ(off.gravity, 0.0) << off.reason();
    EXPECT_FALSE(off.attractorLoad) << off.reason();
    EXPECT_GT(chooseContactSettings(parse(switchedOff)).gravity, 990.0);

    std::ostringstream cluster;
    cluster << R"({"world": {"gravity": {"x": 0, "y": 0}, "G": 1}, "entities": [)";
    for (int k = 0; k < 20; ++k)
        cluster << (k ? ", " : "") << R"({"name": "disc)" << k << R"(", "position": {"x": )" << num(k % 5) << R"(, "y": )"
                << num(k / 5) << R"(}, "mass": 1e6, "radius": 0.5, "attractor": {"softening": 0}})";
    cluster << "]}";
    const ContactSettingsChoice clusterChoice = chooseContactSettings(parse(cluster.str()));
    EXPECT_EQ(clusterChoice.gravity, 0.0) << clusterChoice.reason();
    EXPECT_FALSE(clusterChoice.attractorLoad) << clusterChoice.reason();
}

// A spring is a steady force too. A row of n 1 kg boxes resting on a
// 2 cm static box (or against a 2 cm wall), no gravity, its far box
// pulled toward the support by a spring anchored 100 m beyond it with a
// force F as placed: the group bears F over its mass, read as a load of
// F / n along the spring, and named. Swept over F (10, 1000 and 10^5 N),
// n (3 and 10) and the direction (down onto a floor, sideways into a
// wall): after 3 s the pulled box has moved less than 1 cm and the near
// box is no more than the slop into the support. Read as no load (the
// rules saw no gravity), ten boxes got 1 substep: the far box moved
// 368 mm at 1000 N, and at 10^5 N the row went through the support.
TEST(HardSettings, ASpringPressingARowOntoItsSupportIsALoad) {
    for (const bool sideways : {false, true}) {
        for (const int n : {3, 10}) {
            for (const double force : {10.0, 1000.0, 1e5}) {
                // Along the row, away from the support.
                const Vec2 out = sideways ? Vec2{1.0, 0.0} : Vec2{0.0, 1.0};
                const auto at = [&](double along) { return out * along; };
                const auto vec = [](Vec2 v) { return R"({"x": )" + num(v.x) + R"(, "y": )" + num(v.y) + "}"; };
                std::ostringstream level;
                level << R"({"world": {"gravity": {"x": 0, "y": 0}}, "entities": [)"
                      << R"({"name": "support", "position": )" << vec(at(-0.01)) << R"(, "static": true, "box": )"
                      << (sideways ? R"({"width": 0.02, "height": 20})" : R"({"width": 20, "height": 0.02})")
                      << R"(, "friction": 0.6})";
                for (int k = 0; k < n; ++k)
                    level << R"(, {"name": "b)" << k << R"(", "position": )" << vec(at(0.5 + k))
                          << R"(, "mass": 1, "box": {"width": 1, "height": 1}, "friction": 0.6})";
                const double far = n - 0.5, anchorAt = -100.0;
                level << R"(, {"name": "pull", "spring": {"a": "b)" << n - 1 << R"(", "anchor": )" << vec(at(anchorAt))
                      << R"(, "k": )" << num(force / (far - anchorAt)) << R"(, "rest_length": 0}}]})";
                const Scene scene = parse(level.str());
                const ContactSettingsChoice choice = chooseContactSettings(scene);
                const std::string label = std::string(sideways ? "sideways" : "down") + ", " + std::to_string(n) +
                                          " boxes, " + num(force) + " N (" + choice.reason() + ")";
                EXPECT_NEAR(choice.gravity, force / n, 1e-9 * force) << label;
                EXPECT_TRUE(choice.springLoad) << label;
                EXPECT_FALSE(choice.attractorLoad) << label;
                EXPECT_NE(label.find("springs load resting bodies at up to"), std::string::npos) << label;
                World w = build(scene);
                for (int i = 0; i < 180; ++i) ASSERT_TRUE(w.step().ok()) << label;
                EXPECT_LT(far - dot(w.bodyPosition(std::size_t(n - 1)), out), 0.01) << label;
                EXPECT_LT(0.5 - dot(w.bodyPosition(0), out), 0.005) << label;
            }
        }
    }
}

// A slider motor held still pushes with its largest force: a ram on a
// slider to the world, driven down onto ten 1 kg boxes standing on a 2 cm
// static box (no gravity), presses the group of eleven with max_motor_force
// F, read as a load of F / 11 kg and named. Placed 0.5 m above the stack,
// the ram meets it where it drives and presses the ten: F / 10 kg. Swept
// over F (1000 and 10^5 N), the gap and the slider's axis (up with the
// motor driving at +1 m/s, down at -1 m/s: the same push): after 3 s the
// ram has stalled within 3 cm of where it met the stack, the bottom box is
// within the slop of the floor and the top box within 1 cm of upright.
// Read as no load, the boxes got 1 substep and the ram drove through the
// stack (the top box 3.9 m down, the boxes spilled; placed apart, 2.7 m
// down with the sixth box thrown 4 m aside). Driven away from the stack,
// the motor runs free and is no load: the ram leaves.
TEST(HardSettings, ASliderMotorPressingAStackIsALoad) {
    const auto level = [](double force, double axisY, double speed, double gap = 0.0) {
        std::ostringstream out;
        out << tenBoxesOnAThinFloor(0.0);
        out << R"(, {"name": "ram", "position": {"x": 0, "y": )" << num(10.5 + gap)
            << R"(}, "mass": 1, "box": {"width": 1, "height": 1},)"
            << R"( "friction": 0.6}, {"name": "press", "joint": {"type": "slider", "a": "ram", "axis": {"x": 0, "y": )"
            << num(axisY) << R"(}, "anchor": {"x": 0, "y": )" << num(10.5 + gap) << R"(}, "motor_speed": )" << num(speed)
            << R"(, "max_motor_force": )" << num(force) << "}}]}";
        return out.str();
    };
    for (const double force : {1000.0, 1e5}) {
        for (const double gap : {0.0, 0.5}) {
            for (const double axisY : {1.0, -1.0}) {
                const Scene scene = parse(level(force, axisY, axisY, gap));
                const ContactSettingsChoice choice = chooseContactSettings(scene);
                const std::string label =
                    num(force) + " N, gap " + num(gap) + ", axis " + num(axisY) + " (" + choice.reason() + ")";
                EXPECT_NEAR(choice.gravity, force / (gap > 0.0 ? 10.0 : 11.0), 1e-9 * force) << label;
                EXPECT_TRUE(choice.motorLoad) << label;
                EXPECT_NE(label.find("motors load resting bodies at up to"), std::string::npos) << label;
                World w = build(scene);
                for (int i = 0; i < 180; ++i) ASSERT_TRUE(w.step().ok()) << label;
                EXPECT_LT(10.5 - w.bodyPosition(10).y, 0.03) << label;
                EXPECT_LT(0.5 - w.bodyPosition(0).y, 0.005) << label;
                EXPECT_LT(std::abs(w.bodyPosition(9).x), 0.01) << label;
            }
        }
    }
    const Scene away = parse(level(1000.0, 1.0, -1.0));
    const ContactSettingsChoice free = chooseContactSettings(away);
    EXPECT_EQ(free.gravity, 0.0) << free.reason();
    EXPECT_FALSE(free.motorLoad) << free.reason();
    World w = build(away);
    for (int i = 0; i < 180; ++i) ASSERT_TRUE(w.step().ok());
    EXPECT_GT(w.bodyPosition(10).y, 12.0);
}

// A hinge motor held still gives its largest torque: a 10 m bar hinged
// to the world at one end, turned down onto ten 1 kg boxes on a 2 cm
// static box under gravity 10, presses the top box with torque / lever,
// the lever being the pivot's distance to it (4.5 to 5.6 m), read as a
// load and named. Swept over the torque (10^3, 10^4 and 10^5 N*m), the bar
// placed on the stack or 0.5 m above it, and the side the pivot is on
// (left, turning clockwise; right, counter-clockwise): after 3 s every box
// is within 0.2 m of its column, the top within 0.1 m of its height and
// the bottom within the slop of the floor. Read as no load (4 substeps),
// at 10^4 the stack bowed 0.57 m and its top sank 0.29 m; at 10^5 it burst,
// a box ending 35 m below the floor. A bar turning about its own centre
// (a rotor, Box2D's spinner) presses nothing: no load.
TEST(HardSettings, AHingeMotorPressingAStackIsALoad) {
    for (const double torque : {1e3, 1e4, 1e5}) {
        for (const double gap : {0.0, 0.5}) {
            for (const double side : {1.0, -1.0}) {
                const Scene scene = parse(hingedBarLevel(torque, gap, side, -5.0 * side));
                const ContactSettingsChoice choice = chooseContactSettings(scene);
                const std::string label = num(torque) + " N*m, gap " + num(gap) + ", pivot " +
                                          (side > 0.0 ? "left" : "right") + " (" + choice.reason() + ")";
                EXPECT_TRUE(choice.motorLoad) << label;
                EXPECT_NE(label.find("motors load resting bodies at up to"), std::string::npos) << label;
                EXPECT_GT(choice.gravity, torque / 5.6 / 11.0) << label;
                EXPECT_LT(choice.gravity, torque / 4.5 / 10.0 + 10.0) << label;
                World w = build(scene);
                for (int i = 0; i < 180; ++i) ASSERT_TRUE(w.step().ok()) << label;
                for (std::size_t k = 0; k < 10; ++k)
                    EXPECT_LT(std::abs(w.bodyPosition(k).x), 0.2) << label << ", box " << k;
                EXPECT_LT(9.5 - w.bodyPosition(9).y, 0.1) << label;
                EXPECT_LT(0.5 - w.bodyPosition(0).y, 0.005) << label;
            }
        }
    }
    // The same bar hinged at its centre, on the stack and within reach of it.
    const ContactSettingsChoice rotor = chooseContactSettings(parse(hingedBarLevel(1e5, 0.0, 1.0, 0.0)));
    EXPECT_FALSE(rotor.motorLoad) << rotor.reason();
    EXPECT_EQ(rotor.gravity, 10.0) << rotor.reason();
}

// The warning names the substeps that would carry the stiffness a load
// needs, for a level's own substeps and for the engine's past its cap.
TEST(HardSettings, ContactStiffnessHintNamesTheSubstepsThatCarryIt) {
    Scene given = parse(stackLevel(10, 7000.0));
    given.world.substeps = 16;
    const std::optional<ContactStiffnessHint> hint = build(given).contactStiffnessHint();
    ASSERT_TRUE(hint);
    EXPECT_EQ(hint->message(),
              "a load of 7e+03 m/s^2 needs contacts of 1263 Hz, and 16 substeps carry 240 Hz: stacks and piles sink "
              "into themselves and a tall one can collapse; substeps 85 would carry them");
    // 85 carry it: no warning, and the stack stands within the rules' 1%.
    given.world.substeps = 85;
    World carried = build(given);
    EXPECT_FALSE(carried.contactStiffnessHint());
    for (int i = 0; i < 120; ++i) ASSERT_TRUE(carried.step().ok());
    EXPECT_LT(9.5 - carried.bodyPosition(9).y, 0.015);
    // Past what a level can give (kMaxLevelSubsteps), it says so.
    const std::optional<ContactStiffnessHint> most = build(parse(stackLevel(20, 1e6))).contactStiffnessHint();
    ASSERT_TRUE(most);
    EXPECT_EQ(most->substeps, kMaxContactSubsteps);
    EXPECT_EQ(most->substepsNeeded, 0);
    EXPECT_NE(most->message().find("no substep count up to 1000 carries them: lower the load"), std::string::npos)
        << most->message();
    // A lone body rests only on static ground, whose contacts turn rigid
    // before the slop: it holds at any substeps (the ball on a 2 cm box,
    // HardContacts), and nothing is said.
    Scene lone = parse(stackLevel(1, 1e5));
    lone.world.substeps = 1;
    ASSERT_GT(chooseContactSettings(lone).contactHertz, kContactHertz);
    World loneWorld = build(lone);
    EXPECT_FALSE(loneWorld.contactStiffnessHint());
    for (int i = 0; i < 120; ++i) ASSERT_TRUE(loneWorld.step().ok());
    EXPECT_LT(0.5 - loneWorld.bodyPosition(0).y, 0.005);
    // At the reference gravity nothing is stiffened, and nothing is said
    // even at 1 substep (the pile's own hint covers that).
    Scene light = parse(stackLevel(10, 9.81));
    light.world.substeps = 1;
    EXPECT_FALSE(build(light).contactStiffnessHint());
}

TEST(HardSettings, RunOutThenRunEqualsOneLongRunThroughTheCli) {
    // The reported case: `run A --steps 20 --out B; run B --steps 40` against
    // `run A --steps 60`, on a pile whose engine choice would differ if made
    // again from where the bodies lie after 20 steps.
    for (const int rows : {6, 12}) {
        const fs::path a = tempFile("a" + std::to_string(rows) + ".json"), b = tempFile("b.json"),
                       c = tempFile("c.json"), d = tempFile("d.json");
        std::ofstream(a) << pileLevel(rows, 0.0);
        ASSERT_EQ(runCli("run " + a.string() + " --steps 60 --out " + c.string()).exitCode, 0);
        ASSERT_EQ(runCli("run " + a.string() + " --steps 20 --out " + b.string()).exitCode, 0);
        ASSERT_EQ(runCli("run " + b.string() + " --steps 40 --out " + d.string()).exitCode, 0);
        const std::string straight = readText(c), resumed = readText(d);
        EXPECT_EQ(resumed, straight) << rows << " rows";
        // The file leaves substeps to the engine and records what it chose.
        EXPECT_EQ(straight.find("\"substeps\": "), straight.find("\"chosen\": {\"substeps\": ") + 11) << straight.substr(0, 400);
        for (const fs::path& p : {a, b, c, d}) fs::remove(p);
    }
}

TEST(HardSettings, SavedRunRecordsTheChoiceAndAFreshLevelDoesNot) {
    const Scene level = parse(pileLevel(12, 0.0));
    EXPECT_EQ(sceneToJsonText(level).find("substeps"), std::string::npos) << "an authored level stays without them";
    World w = build(level);
    ASSERT_TRUE(advance(w, 5).ok());
    const std::string saved = savedText(w, level);
    EXPECT_NE(saved.find("\"chosen\": {\"substeps\": 4, \"solver_iterations\": 2, \"contact_hertz_fraction\": 0.25}"),
              std::string::npos)
        << saved.substr(0, 300);
    const Scene back = parse(saved);
    EXPECT_EQ(back.world.substeps, 0) << "recorded in solver_state, not as the level's own setting";
    ASSERT_TRUE(back.solverState && back.solverState->chosen);
    EXPECT_EQ(back.solverState->chosen->substeps, 4);
    // The recorded choice wins over a fresh one: a level edited to need
    // fewer substeps still resumes with what the run ran.
    Scene edited = back;
    edited.solverState->chosen->substeps = 2;
    EXPECT_EQ(build(edited).settings().substeps, 2);
    EXPECT_EQ(build(edited).settingsSource(), World::SettingsSource::Recorded);
    // A level's own setting wins over a record.
    edited.world.substeps = 3;
    EXPECT_EQ(build(edited).settings().substeps, 3);
    // A level that gives both records only the contacts' stiffness cap,
    // which the engine chooses whatever the level gives, and only once it
    // has run.
    Scene given = level;
    given.world.substeps = 8;
    given.world.solverIterations = 4;
    World g = build(given);
    EXPECT_FALSE(g.solverState().chosen) << "nothing run yet: a fresh load chooses the same";
    ASSERT_TRUE(advance(g, 5).ok());
    ASSERT_TRUE(g.solverState().chosen);
    EXPECT_EQ(g.solverState().chosen->contactHertzFraction, std::optional<double>(0.25));
}

TEST(HardSettings, ChoiceDependsOnStructureNotOnWhereBodiesAre) {
    for (const int rows : {2, 6, 12, 30}) {
        const Scene neat = parse(pileLevel(rows, 0.0));
        const Scene scattered = parse(pileLevel(rows, 0.2));
        const ContactSettingsChoice a = chooseContactSettings(neat), b = chooseContactSettings(scattered);
        EXPECT_EQ(a.substeps, b.substeps) << rows;
        EXPECT_EQ(a.stackDepth, b.stackDepth) << rows;
        // And after the pile has fallen and settled for a while.
        World w = build(neat);
        ASSERT_TRUE(advance(w, 120).ok());
        Scene after = neat;
        w.writeBack(after);
        EXPECT_EQ(chooseContactSettings(after).substeps, a.substeps) << rows;
        EXPECT_EQ(chooseContactSettings(after).stackDepth, a.stackDepth) << rows;
    }
}

// ---- the rule: pile, load, joints ------------------------------------------

TEST(HardSettings, PileDepthIsRowsOfTheContainerAndSubstepsHoldItUnderOnePercent) {
    for (const int rows : {1, 2, 4, 8, 12, 20, 30}) {
        const ContactSettingsChoice c = chooseContactSettings(parse(pileLevel(rows, 0.0)));
        // 10 circles fit across the 5.2 m bay; a heap of 10 n bodies on open
        // ground would be k deep with k (k + 1) / 2 >= 10 n, and in the bay
        // no wider than 10.
        int heap = 1;
        while (heap * (heap + 1) / 2 < 10 * rows) ++heap;
        EXPECT_EQ(c.stackDepth, std::max(rows, std::min(heap, 10))) << rows;
        EXPECT_DOUBLE_EQ(c.diameter, 0.5);
        const int expected = fewestHolding([&](int s) {
            return expectedPileOverlap(c.stackDepth, 10.0, (1.0 / 60.0) / s) <= 0.005 &&
                   expectedSupportOverlap(c.stackDepth, 10.0, (1.0 / 60.0) / s) <= 0.005;
        });
        // Past 4 substeps at 60 Hz the contacts stop stiffening: the choice
        // stops there.
        EXPECT_EQ(c.substeps, std::min(expected, 4)) << rows << " rows: " << c.reason();
    }
    // Measured: the 20-row pile settles with its deepest overlap under 2% of
    // a diameter at the engine's choice.
    World w = build(parse(pileLevel(20, 0.0)));
    EXPECT_LT(deepestOverlapSettling(w), 0.02 * 0.5) << "substeps " << w.settings().substeps;
}

// Under strong gravity a pile is the reference pile sped up (loadSpeedup):
// the engine stiffens its contacts, takes the substeps that carry them and
// lets them push overlaps out as much faster. Swept from 100 to 10^5 m/s^2,
// the 12-row pile of 120 circles settles with its deepest contact under 1%
// of a diameter (the pile rule's goal; 10% allowed) and every circle within
// the slop of the floor. With at most 16 substeps and the push held at
// 3 m/s, the 30-row pile overlapped by 25 mm at 1000 m/s^2, 445 mm at 10^4
// and 500 mm, one circle on another, at 10^5.
TEST(HardSettings, PilesUnderStrongLoadsSettleUnderOnePercentOfADiameter) {
    for (const double g : {100.0, 1000.0, 1e4, 1e5}) {
        World w = build(parse(pileLevel(12, 0.0, g)));
        const std::string label = "g " + num(g) + ", " + std::to_string(w.settings().substeps) + " substeps";
        EXPECT_FALSE(w.contactStiffnessHint()) << label;
        EXPECT_LT(deepestOverlapSettling(w), 1.1 * 0.01 * 0.5) << label;
        double lowest = std::numeric_limits<double>::infinity();
        for (std::size_t b = 0; b < w.bodyCount(); ++b) lowest = std::min(lowest, w.bodyPosition(b).y);
        EXPECT_GT(lowest, 0.25 - 0.005) << label;
    }
}

// A container drawn as a chain (the format's way to draw terrain and
// containers) holds the same pile as one built of boxes: the same depth and
// substeps for every row count, and the 20-row pile settles as deep.
TEST(HardSettings, AChainContainerHoldsThePileABoxContainerDoes) {
    const auto inChain = [](int rows) {
        std::string text = pileLevel(rows, 0.0);
        // The floor and the two walls of pileLevel, as one chain with the
        // same inner faces: down the right wall, right to left along the
        // floor, up the left wall (bodies on the right of each segment).
        const std::string boxes = R"({"position": {"x": 0, "y": -0.5}, "static": true, "box": {"width": 8, "height": 1}},
        {"position": {"x": -3.1, "y": 10}, "static": true, "box": {"width": 1, "height": 22}},
        {"position": {"x": 3.1, "y": 10}, "static": true, "box": {"width": 1, "height": 22}})";
        const std::size_t at = text.find(boxes);
        EXPECT_NE(at, std::string::npos);
        text.replace(at, boxes.size(),
                     R"({"position": {"x": 0, "y": 0}, "static": true, "chain": {"points": [{"x": 2.6, "y": 21},
                        {"x": 2.6, "y": 0}, {"x": -2.6, "y": 0}, {"x": -2.6, "y": 21}]}})");
        return text;
    };
    for (const int rows : {1, 2, 4, 8, 12, 20, 30}) {
        const ContactSettingsChoice boxes = chooseContactSettings(parse(pileLevel(rows, 0.0)));
        const ContactSettingsChoice chain = chooseContactSettings(parse(inChain(rows)));
        EXPECT_EQ(chain.stackDepth, boxes.stackDepth) << rows << " rows";
        EXPECT_EQ(chain.substeps, boxes.substeps) << rows << " rows: " << chain.reason();
        EXPECT_EQ(chain.iterations, boxes.iterations) << rows << " rows";
    }
    World w = build(parse(inChain(20)));
    EXPECT_LT(deepestOverlapSettling(w), 0.02 * 0.5) << "substeps " << w.settings().substeps;
}

// A floor laid as tiles is the floor it makes: 100 circles (0.5 m) above
// open ground 8 m wide give the same choice whether the ground is one box
// or tiles of any width, touching or with gaps no body fits through, and
// with tops level within a quarter body. Gaps a body fits through, or steps
// higher than that, leave separate floors, and each body heaps on the
// highest one under it (or, over none, on the widest).
TEST(HardSettings, ATiledFloorCountsAsTheFloorItMakes) {
    const auto level = [](double tile, double gap, double step) {
        std::ostringstream s;
        s << R"({"entities": [)";
        int k = 0;
        for (double x = -4.0; x + tile <= 4.0 + 1e-9; x += tile + gap, ++k)
            s << (k ? ", " : "") << R"({"position": {"x": )" << num(x + 0.5 * tile) << R"(, "y": )"
              << num(-0.5 + (k % 2) * step) << R"(}, "static": true, "box": {"width": )" << num(tile)
              << R"(, "height": 1}})";
        for (int r = 0; r < 10; ++r)
            for (int c = 0; c < 10; ++c)
                s << R"(, {"position": {"x": )" << num(-2.3 + 0.51 * c) << R"(, "y": )" << num(0.3 + 0.52 * r)
                  << R"(}, "radius": 0.25})";
        s << "]}";
        return s.str();
    };
    const ContactSettingsChoice whole = chooseContactSettings(parse(level(8.0, 0.0, 0.0)));
    // 16 bodies a row on 8 m; a heap of 100 is 14 deep and no wider than 16.
    EXPECT_EQ(whole.stackDepth, 14);
    for (const double tile : {0.1, 0.25, 0.5, 1.0, 2.0, 4.0})
        for (const double gap : {0.0, 0.01, 0.2})
            for (const double step : {0.0, 0.1}) {
                // Gaps shrink the ground a little: 8 m less the gaps.
                const ContactSettingsChoice c = chooseContactSettings(parse(level(tile, gap, step)));
                const int tiles = int(std::floor((8.0 + gap + 1e-9) / (tile + gap)));
                const double width = tiles * tile + (tiles - 1) * gap;
                const int perRow = int(std::floor(width / 0.5));
                EXPECT_EQ(c.stackDepth, std::max((100 + perRow - 1) / perRow, std::min(14, perRow)))
                    << "tiles " << tile << " m, gaps " << gap << " m, steps " << step << " m";
                if (width == 8.0) {
                    EXPECT_EQ(c.substeps, whole.substeps) << tile << " " << gap << " " << step;
                }
            }
    // A body fits through 0.6 m gaps, and 0.2 m steps are not level: 1 m
    // tiles are then floors of their own, 2 bodies a row. The ten columns
    // of circles (x = -2.3 + 0.51 c) put at most three columns, 30 bodies,
    // over one tile (within half a body of its ends): 15 deep.
    EXPECT_EQ(chooseContactSettings(parse(level(1.0, 0.6, 0.0))).stackDepth, 15);
    EXPECT_EQ(chooseContactSettings(parse(level(1.0, 0.0, 0.2))).stackDepth, 15);
    // Shelves: the same 100 circles over a 2 m shelf 3 m above an 8 m
    // floor. The 40 over the shelf heap on it (4 a row: 10 deep), the other
    // 60 on the floor (16 a row; a heap of 60 is 11 deep): 11.
    std::ostringstream shelf;
    shelf << R"({"entities": [
        {"position": {"x": 0, "y": -0.5}, "static": true, "box": {"width": 8, "height": 1}},
        {"position": {"x": 0, "y": 2.75}, "static": true, "box": {"width": 2, "height": 0.5}})";
    for (int r = 0; r < 10; ++r)
        for (int c = 0; c < 10; ++c)
            shelf << R"(, {"position": {"x": )" << num(-2.3 + 0.51 * c) << R"(, "y": )" << num(3.3 + 0.52 * r)
                  << R"(}, "radius": 0.25})";
    shelf << "]}";
    EXPECT_EQ(chooseContactSettings(parse(shelf.str())).stackDepth, 11);
}

TEST(HardSettings, HeavyLoadOnAThinShelfGetsTheSubstepsThatHoldIt) {
    struct Case {
        double gravity;
        int substeps;
    };
    // g / omega^2 at 1 substep (15 Hz) is 1.1 mm per 9.81 m/s^2; the limit
    // is 1% of the ball (10 mm) and 10% of a 0.1 m shelf (10 mm).
    for (const Case k : {Case{9.81, 1}, Case{50.0, 1}, Case{100.0, 2}, Case{400.0, 4}, Case{1000.0, 4}}) {
        const Scene scene = parse(ballOnShelf(k.gravity, 0.1));
        const ContactSettingsChoice c = chooseContactSettings(scene);
        EXPECT_EQ(c.substeps, k.substeps) << "g " << k.gravity << ": " << c.reason();
        // Measured: the ball rests on the shelf, never through it, sinking
        // less than the rule's limit.
        World w = build(scene);
        EXPECT_EQ(w.settings().substeps, k.substeps);
        double lowest = 1e9, deepest = 0.0;
        for (int i = 0; i < 240; ++i) {
            ASSERT_TRUE(w.step());
            Scene now = scene;
            w.writeBack(now);
            for (const Entity e : now.registry.entities())
                if (const Radius* r = now.registry.tryGet<Radius>(e); r)
                    lowest = std::min(lowest, now.registry.tryGet<Position>(e)->value.y);
            for (const ContactRecord& cr : w.contacts()) deepest = std::max(deepest, cr.depth);
        }
        EXPECT_GT(lowest, 0.5 - 0.01) << "g " << k.gravity << ": the ball sank to " << lowest;
        EXPECT_LT(deepest, 0.01) << "g " << k.gravity;
    }
}

namespace {
/// The widest joint opening over a 2 s swing from level, metres.
double widestOpening(Scene scene, int substeps) {
    scene.world.substeps = substeps;
    scene.world.solverIterations = substeps == 1 ? 8 : 2;
    World w = build(scene);
    double widest = 0.0;
    for (int i = 0; i < 120; ++i) {
        if (!w.step()) return 1e9;
        for (const JointRecord& j : w.joints()) widest = std::max(widest, j.separation);
    }
    return widest;
}
} // namespace

// Joints add no substeps: the joint solver holds a chain (a tree of
// joints) exactly, so at the engine's choice, one substep, a chain of
// hinged boxes of any length and a heavy last link keeps its joints within
// 1% of a link, as it does at more substeps.
TEST(HardSettings, ChainOfHingedBoxesNeedsNoExtraSubsteps) {
    struct Case {
        int links;
        double lastMass;
    };
    for (const Case k : {Case{1, 1.0}, Case{2, 1.0}, Case{3, 1.0}, Case{5, 1.0}, Case{10, 1.0}, Case{20, 1.0},
                         Case{40, 1.0}, Case{10, 50.0}}) {
        const Scene scene = parse(chainLevel(k.links, 9.81, k.lastMass));
        const ContactSettingsChoice c = chooseContactSettings(scene);
        const std::string label = std::to_string(k.links) + " links, last " + num(k.lastMass) + " kg";
        EXPECT_EQ(c.substeps, 1) << label << ": " << c.reason();
        EXPECT_EQ(build(scene).settings().substeps, 1) << label;
        for (const int substeps : {1, 2, 4, 8})
            EXPECT_LT(widestOpening(scene, substeps), 0.01 * 0.5) << label << " at " << substeps << " substeps";
    }
}

namespace {
/// The bridge with a crate of `crateMass` kg dropped onto the middle from
/// 2.6 m; no settings.
std::string bridgeLevel(double crateMass) { return test::bridgeJson({.crateMass = crateMass}); }
} // namespace

// A crate on a bridge presses one light plank the joints hold up; at one
// substep a 20 kg crate on 2 kg planks bounced on it and fell through
// within 5 s, while the choice said "nothing needs more". Swept over the
// crate's mass ratio to a plank, at the engine's choice: the crate's centre
// never passes within 0.2 m of the lowest plank's (resting in the sag it
// is 0.27 m above it at the closest; fallen through, 3.1 m below). Measured
// at fixed settings, the crate fell through from 25:1 at 1 and 2
// substeps and from 50:1 at 4.
TEST(HardSettings, ACrateOnABridgeGetsTheSubstepsThatHoldIt) {
    struct Case {
        double ratio;
        int substeps;
    };
    for (const Case k : {Case{1.0, 1}, Case{2.5, 1}, Case{5.0, 2}, Case{10.0, 2}, Case{25.0, 4}, Case{50.0, 8},
                         Case{100.0, 8}, Case{250.0, 16}}) {
        const Scene scene = parse(bridgeLevel(2.0 * k.ratio));
        const ContactSettingsChoice c = chooseContactSettings(scene);
        const std::string label = "crate " + num(k.ratio) + " times a plank";
        EXPECT_EQ(c.substeps, k.substeps) << label << ": " << c.reason();
        World w = build(scene);
        double closest = 1e9;
        for (int i = 0; i < 600; ++i) {
            ASSERT_TRUE(w.step()) << label;
            Scene now = scene;
            w.writeBack(now);
            double crateY = 0.0, lowestPlank = 1e9;
            for (const Entity e : now.registry.entities()) {
                const Name* n = now.registry.tryGet<Name>(e);
                if (!n || !now.registry.has<Position>(e)) continue;
                const double y = now.registry.tryGet<Position>(e)->value.y;
                if (n->value == "crate") crateY = y;
                if (n->value.rfind("plank", 0) == 0) lowestPlank = std::min(lowestPlank, y);
            }
            closest = std::min(closest, crateY - lowestPlank);
        }
        EXPECT_GT(closest, 0.2) << label << ": the crate's centre came this close to the lowest plank's";
    }
}

// A level that gives fewer substeps than the crate needs is warned, with
// the number that holds it; one that gives enough is not.
TEST(HardSettings, TooFewSubstepsForALoadOnJointsAreNamed) {
    Scene scene = parse(bridgeLevel(20.0));
    scene.world.substeps = 1;
    const std::optional<JointSupportHint> one = build(scene).jointSupportHint();
    ASSERT_TRUE(one);
    EXPECT_EQ(one->message(),
              "bodies 10 times as heavy as jointed bodies they can rest on: at 1 substep a load over 3 times can "
              "spring on the joints and fall through them; substeps 2 would hold it");
    scene.world.substeps = 2;
    EXPECT_FALSE(build(scene).jointSupportHint());
    scene = parse(bridgeLevel(500.0));
    scene.world.substeps = 4;
    ASSERT_TRUE(build(scene).jointSupportHint());
    EXPECT_EQ(build(scene).jointSupportHint()->message(),
              "bodies 250 times as heavy as jointed bodies they can rest on: at 4 substeps a load over 48 times can "
              "spring on the joints and fall through them; substeps 10 would hold it");
    scene.world.substeps = 0;  // the engine's choice warns of nothing
    EXPECT_FALSE(build(scene).jointSupportHint());
}

/// A chain of `links` 1 kg beads on springs of stiffness k (1 m rest), the
/// first anchored, stretched 10% and released in zero gravity; no
/// damping, no substeps given.
std::string springChainLevel(const char* integrator, double k, int links = 6) {
    std::ostringstream s;
    s << R"({"world": {"gravity": {"x": 0, "y": 0}, "integrator": ")" << integrator << R"("}, "entities": [)";
    for (int i = 0; i < links; ++i)
        s << (i ? ", " : "") << R"({"name": "bead)" << i << R"(", "position": {"x": )" << num(1.1 * (i + 1))
          << R"(, "y": 0}, "mass": 1})";
    for (int i = 0; i < links; ++i) {
        s << R"(, {"name": "spring)" << i << R"(", "spring": {"a": "bead)" << i << "\"";
        if (i == 0) s << R"(, "anchor": {"x": 0, "y": 0})";
        else s << R"(, "b": "bead)" << (i - 1) << "\"";
        s << R"(, "k": )" << num(k) << R"(, "rest_length": 1}})";
    }
    s << "]}";
    return s.str();
}

// Springs set the substeps under an explicit integrator: the stiffest mode
// takes at most a radian a substep. Swept over six decades of stiffness, the
// chain's energy does not grow over 10 s at the engine's choice, where a
// single substep blows up from k = 1e4 on (so the rule is what holds it).
// Implicit integrators need no rule.
TEST(HardSettings, SpringsSetTheSubstepsSoTheStiffestModeTakesAtMostARadian) {
    for (const char* integrator : {"semi_implicit_euler", "velocity_verlet", "rk4"})
        for (double k = 10.0; k <= 1e6; k *= 10.0) {
            const std::string label = std::string(integrator) + " k " + num(k);
            const Scene scene = parse(springChainLevel(integrator, k));
            World w = build(scene);
            const ContactSettingsChoice c = chooseContactSettings(scene);
            const double h = scene.world.dt / w.settings().substeps;
            EXPECT_EQ(w.settings().substeps, c.springSubsteps) << label;
            EXPECT_LE(h * c.springRate, 1.0) << label;
            // Gershgorin's bound is above the chain's fastest mode,
            // 2 sqrt(k) for a long chain of unit masses.
            EXPECT_GE(c.springRate, 1.9 * std::sqrt(k)) << label;
            // Stable: the energy's peak over the last 2.5 s is within the
            // beat of the chain's modes (under 1% measured) of the first
            // 2.5 s's: semi-implicit Euler and Verlet oscillate about a
            // nearby conserved energy, RK4 loses a little; unstable, it
            // grows a hundredfold (below).
            const double start = w.energy().total();
            double firstPeak = 0.0, lastPeak = 0.0;
            for (int step = 0; step < 600; ++step) {
                ASSERT_TRUE(w.step().ok()) << label << " at step " << step;
                const double e = w.energy().total();
                if (step < 150) firstPeak = std::max(firstPeak, e);
                if (step >= 450) lastPeak = std::max(lastPeak, e);
            }
            EXPECT_LE(lastPeak, 1.05 * firstPeak) << label << " with " << w.settings().substeps << " substeps";
            EXPECT_LT(firstPeak, 1.5 * start) << label;
            if (k >= 1e4 && std::string(integrator) != "rk4") {
                Scene one = scene;
                one.world.substeps = 1;
                World single = build(one);
                bool blewUp = false;
                for (int step = 0; step < 600 && !blewUp; ++step)
                    blewUp = !single.step().ok() || std::abs(single.energy().total()) > 100.0 * start;
                EXPECT_TRUE(blewUp) << label << ": one substep holds too, so the test proves nothing";
            }
        }
    const Scene implicit = parse(springChainLevel("implicit_euler", 1e6));
    EXPECT_EQ(chooseContactSettings(implicit).springSubsteps, 1);
    EXPECT_EQ(build(implicit).settings().substeps, 1);
}

TEST(HardSettings, ASceneWithNothingHardStaysAtOneSubstepAndEightIterations) {
    for (const std::string& text :
         {std::string(R"({"entities": [{"position": {"x": 0, "y": 0}, "radius": 0.5}]})"),
          ballOnShelf(9.81, 1.0),
          std::string(R"({"world": {"gravity": {"x": 0, "y": 0}}, "entities": [
              {"position": {"x": 0, "y": 0}, "radius": 0.5}, {"position": {"x": 2, "y": 0}, "radius": 0.5}]})")}) {
        const Scene scene = parse(text);
        const World w = build(scene);
        EXPECT_EQ(w.settings().substeps, 1) << text;
        EXPECT_EQ(w.settings().solverIterations, 8) << text;
        EXPECT_FALSE(w.pileHint()) << text;
    }
}

// ---- what validate says ----------------------------------------------------

TEST(HardSettings, ValidateSaysWhatItChoseAndWhy) {
    const fs::path chain = tempFile("chain.json"), shelf = tempFile("shelf.json"), pile = tempFile("pile.json"),
                   given = tempFile("given.json"), resumed = tempFile("resumed.json");
    std::ofstream(chain) << chainLevel(20);
    std::ofstream(shelf) << ballOnShelf(1000.0, 0.1);
    std::ofstream(pile) << pileLevel(12, 0.0);
    {
        Scene g = parse(pileLevel(12, 0.0));
        g.world.substeps = 4;
        g.world.solverIterations = 2;
        std::ofstream(given) << sceneToJsonText(g);
    }
    const auto secondLine = [](const std::string& out) {
        const std::size_t nl = out.find('\n');
        return nl == std::string::npos ? std::string() : out.substr(nl + 1);
    };
    EXPECT_EQ(secondLine(runCli("validate " + chain.string()).out),
              chain.string() + ": substeps 1 (chosen: nothing in the scene needs more), solver_iterations 8\n");
    EXPECT_EQ(secondLine(runCli("validate " + shelf.string()).out),
              shelf.string() + ": substeps 4 (chosen: load 1000 m/s^2 on 1 m bodies, supports 0.1 m thick), "
                               "solver_iterations 2\n");
    EXPECT_EQ(secondLine(runCli("validate " + pile.string()).out),
              pile.string() + ": substeps 4 (chosen: pile 12 deep), solver_iterations 2\n");
    EXPECT_EQ(secondLine(runCli("validate " + given.string()).out),
              given.string() + ": substeps 4 (given by the level), solver_iterations 2 (given by the level)\n");
    ASSERT_EQ(runCli("run " + pile.string() + " --steps 10 --out " + resumed.string()).exitCode, 0);
    EXPECT_EQ(secondLine(runCli("validate " + resumed.string()).out),
              resumed.string() + ": substeps 4 (recorded by the run that saved this file; chosen afresh: 4, pile 12 "
                                 "deep), solver_iterations 2\n");
    for (const fs::path& p : {chain, shelf, pile, given, resumed}) fs::remove(p);
}

TEST(HardSettings, ARecordedChoiceRaisesNoWarning) {
    // The pile warning is about a level's own substeps; the engine's choice,
    // fresh or recorded, is what the rule allows.
    for (const int rows : {12, 30}) {
        const fs::path level = tempFile("warn.json"), out = tempFile("warn_out.json");
        std::ofstream(level) << pileLevel(rows, 0.0);
        ASSERT_EQ(runCli("run " + level.string() + " --steps 30 --out " + out.string()).exitCode, 0);
        for (const fs::path& p : {level, out}) {
            const std::string err =
                test::runCommand(std::string(STEPWISE_BINARY) + " validate " + p.string() + " 2>&1 >/dev/null").out;
            EXPECT_EQ(err, "") << rows << " rows, " << p;
        }
        fs::remove(level);
        fs::remove(out);
    }
}


// The contacts' stiffness cap is chosen from the structure a run starts
// from (a deep column standing gets the softer one), whatever settings the
// level gives. Boxes dropped with gaps between them are no column at the
// start and one once they have landed: a resume, loading that column, must
// still run the cap the run started with. Swept over the column's height
// and the step the run is saved at.
TEST(HardSettings, AResumeKeepsTheContactStiffnessTheRunStartedWith) {
    for (const int boxes : {14, 20}) {
        std::ostringstream s;
        s << R"({"world": {"gravity": {"x": 0, "y": -10}, "substeps": 4, "solver_iterations": 2}, "entities": [)"
          << R"({"name": "floor", "position": {"x": 0, "y": -0.5}, "box": {"width": 20, "height": 1}, "static": true})";
        for (int k = 0; k < boxes; ++k)
            s << R"(, {"name": "box )" << k << R"(", "position": {"x": 0, "y": )" << num(0.5 + 1.6 * k)
              << R"(}, "box": {"width": 1, "height": 1}, "mass": 1})";
        s << "]}";
        const Scene level = parse(s.str());
        EXPECT_EQ(build(level).settingsChoice().hertzFraction, 0.25) << boxes << " boxes apart: no column yet";
        World landed = build(level);
        ASSERT_TRUE(advance(landed, 120).ok());
        Scene column = parse(savedText(landed, level));
        ASSERT_TRUE(column.solverState && column.solverState->chosen);
        EXPECT_EQ(column.solverState->chosen->contactHertzFraction, std::optional<double>(0.25)) << boxes;
        column.solverState->chosen->contactHertzFraction.reset();
        EXPECT_EQ(build(column).settingsChoice().hertzFraction, 0.125)
            << boxes << " boxes landed: a fresh choice would see a deep column";
        for (const std::uint64_t split : {30u, 120u})
            expectResumeExact(level, split, 20, std::to_string(boxes) + " boxes, saved at step " + std::to_string(split));
    }
}
