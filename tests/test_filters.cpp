// Collision filters: Box2D's category, mask and group rule, through the
// loader, the world's contacts, sleeping and the shipped level.
#include "test_support.hpp"

#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>

using namespace stepwise;
using namespace stepwise::test;

namespace {

/// "filter": {...} text for an entity, or nothing for the default.
std::string filterJson(std::uint32_t category, std::uint32_t mask, int group) {
    return R"(, "filter": {"category": )" + std::to_string(category) + R"(, "mask": )" + std::to_string(mask) +
           R"(, "group": )" + std::to_string(group) + "}";
}

/// Two balls (radius r) dropped from rest on one vertical line over a floor
/// plane, the upper one `gap` metres above the lower; each with its filter
/// text. Returns the scene text.
std::string droppedPair(const std::string& lowerFilter, const std::string& upperFilter, double r, double mass,
                        const std::string& floorFilter = "") {
    const std::string ball = R"(, "radius": )" + exactNumber(r) + R"(, "mass": )" + exactNumber(mass);
    return R"({"world": {"gravity": {"x": 0, "y": -9.81}, "dt": 0.016666666666666666},
      "entities": [
        {"name": "floor", "plane": {"normal": {"x": 0, "y": 1}, "offset": 0})" + floorFilter + R"(},
        {"name": "lower", "position": {"x": 0, "y": )" + exactNumber(r) + "}" + ball + lowerFilter + R"(},
        {"name": "upper", "position": {"x": 0, "y": )" + exactNumber(4.0 * r) + "}" + ball + upperFilter + R"(}]})";
}

/// Heights of `lower` and `upper` after `steps` steps.
std::pair<double, double> heightsAfter(const std::string& level, int steps) {
    Scene scene = parseLevel(level);
    World world = buildWorld(scene);
    for (int i = 0; i < steps; ++i) {
        Result<void> stepped = world.step();
        if (!stepped) throw std::runtime_error(stepped.error());
    }
    world.writeBack(scene);
    double lower = 0.0, upper = 0.0;
    for (const Entity e : scene.registry.entities()) {
        const Name* name = scene.registry.tryGet<Name>(e);
        if (name && name->value == "lower") lower = scene.registry.tryGet<Position>(e)->value.y;
        if (name && name->value == "upper") upper = scene.registry.tryGet<Position>(e)->value.y;
    }
    return {lower, upper};
}

} // namespace

TEST(Filters, BoxTwoDsRuleOnGroupsCategoriesAndMasks) {
    const Filter none;
    EXPECT_TRUE(shouldCollide(none, none));
    // The same negative group never collides, whatever the bits say.
    EXPECT_FALSE(shouldCollide(Filter{1, 0xFFFFFFFFu, -3}, Filter{1, 0xFFFFFFFFu, -3}));
    // The same positive group always collides, even with masks that exclude.
    EXPECT_TRUE(shouldCollide(Filter{2, 0, 4}, Filter{4, 0, 4}));
    // Different groups fall back to the bits.
    EXPECT_TRUE(shouldCollide(Filter{1, 0xFFFFFFFFu, -1}, Filter{1, 0xFFFFFFFFu, -2}));
    EXPECT_FALSE(shouldCollide(Filter{2, 0xFFFFFFFFu, -1}, Filter{1, 0xFFFFFFFDu, -2}));
    // Box2D's joint grid: category 2, mask ~2 against each other: no; against
    // the default ground: yes.
    const Filter grid{2, ~2u, 0};
    EXPECT_FALSE(shouldCollide(grid, grid));
    EXPECT_TRUE(shouldCollide(grid, none));
    // Both directions must agree: a's mask takes b's category and b's mask a's.
    for (int bit = 0; bit < 32; ++bit) {
        const std::uint32_t c = 1u << bit;
        EXPECT_TRUE(shouldCollide(Filter{c, c, 0}, Filter{c, c, 0})) << bit;
        EXPECT_FALSE(shouldCollide(Filter{c, ~c, 0}, Filter{c, 0xFFFFFFFFu, 0})) << bit;
        EXPECT_FALSE(shouldCollide(Filter{c, 0xFFFFFFFFu, 0}, Filter{c, ~c, 0})) << bit;
    }
}

TEST(Filters, ExcludedBallsPassThroughEachOtherAndRestOnTheFloorAtEveryMassAndSize) {
    // Excluded by a negative group, or by a mask: the upper ball falls
    // through the lower one and both rest on the floor, centres at r. Not
    // excluded: it stacks, centre at 3r. Swept over size and mass.
    const std::string group = filterJson(1, 0xFFFFFFFFu, -7);
    const std::string maskA = filterJson(2, 0xFFFFFFFDu, 0), maskB = filterJson(2, 0xFFFFFFFFu, 0);
    for (const double r : {0.05, 0.5, 2.0})
        for (const double mass : {0.1, 1.0, 50.0}) {
            const int steps = int(60.0 * (1.0 + 2.0 * std::sqrt(r)));
            // Soft contacts rest within the linear slop (5 mm, Box2D's):
            // a fifth of it per contact, or 2% of a large ball.
            const double tolerance = 0.001 + 0.02 * r;
            for (const auto& [lowerF, upperF] : {std::pair{group, group}, std::pair{maskA, maskB}}) {
                const auto [lower, upper] = heightsAfter(droppedPair(lowerF, upperF, r, mass), steps);
                EXPECT_NEAR(lower, r, tolerance) << "r " << r << " mass " << mass;
                EXPECT_NEAR(upper, r, tolerance) << "r " << r << " mass " << mass;
            }
            const auto [lower, upper] = heightsAfter(droppedPair("", "", r, mass), steps);
            EXPECT_NEAR(lower, r, tolerance) << "r " << r << " mass " << mass;
            EXPECT_NEAR(upper, 3.0 * r, tolerance) << "r " << r << " mass " << mass;
        }
}

TEST(Filters, APlaneOutsideABodysMaskLetsItFall) {
    // The floor is category 4; a ball whose mask leaves out 4 falls through
    // it at g t^2 / 2, the other rests on it.
    const std::string level = droppedPair(filterJson(1, ~4u, 0), "", 0.5, 1.0, filterJson(4, 0xFFFFFFFFu, 0));
    const auto [lower, upper] = heightsAfter(level, 60);
    EXPECT_NEAR(lower, 0.5 - 0.5 * 9.81 * 1.0 * 1.0, 0.1);
    EXPECT_NEAR(upper, 0.5, 0.01);  // it was on the lower ball, which fell away
}

/// Scene text of two "ragdolls": a small hub with two bars crossing at it,
/// each bar welded to the hub and not to the other, so the bars overlap
/// from the start and only a filter keeps them from pushing apart. The
/// second falls onto the first. `groupOf(i)` is ragdoll i's group.
std::string crossedRagdolls(int firstGroup, int secondGroup) {
    const auto ragdoll = [](const std::string& name, double y, int group) {
        const std::string f = filterJson(1, 0xFFFFFFFFu, group);
        const std::string at = R"("position": {"x": 0, "y": )" + exactNumber(y) + "}";
        const auto weld = [&](const std::string& bar) {
            return R"({"name": ")" + name + " weld " + bar + R"(", "joint": {"type": "weld", "a": ")" + name +
                   R"( hub", "b": ")" + name + " " + bar + R"(", "anchor": {"x": 0, "y": )" + exactNumber(y) + "}}}";
        };
        return R"({"name": ")" + name + R"( hub", )" + at + R"(, "radius": 0.05, "mass": 1)" + f + R"(},
                {"name": ")" + name + R"( x", )" + at + R"(, "box": {"width": 2, "height": 0.2}, "mass": 2)" + f + R"(},
                {"name": ")" + name + R"( y", )" + at + R"(, "box": {"width": 0.2, "height": 2}, "mass": 2)" + f + "},\n" +
               weld("x") + ",\n" + weld("y");
    };
    return R"({"world": {"gravity": {"x": 0, "y": -9.81}},
      "entities": [
        {"name": "floor", "plane": {"normal": {"x": 0, "y": 1}, "offset": 0}, "friction": 0.8},
        )" + ragdoll("first", 1.0, firstGroup) + ",\n" + ragdoll("second", 3.5, secondGroup) + "]}";
}

TEST(Filters, ARagdollsBonesPassThroughEachOtherButStackOnAnotherRagdoll) {
    // One negative group per ragdoll: its crossed bars never touch, so each
    // cross stays whole; the first stands on the floor on its upright bar
    // (centre 1 m up) and the second stands on the first (centre 3 m up).
    Scene scene = parseLevel(crossedRagdolls(-1, -2));
    World world = buildWorld(scene);
    const auto nameOf = [&](Entity e) { return scene.registry.tryGet<Name>(e)->value; };
    for (int i = 0; i < 180; ++i) {
        ASSERT_TRUE(world.step());
        for (const ContactRecord& c : world.contacts())
            ASSERT_NE(nameOf(c.a).substr(0, 5), nameOf(c.b).substr(0, 5))
                << nameOf(c.a) << " touches " << nameOf(c.b) << " at step " << i;
    }
    world.writeBack(scene);
    std::map<std::string, Vec2> at;
    for (const Entity e : scene.registry.entities())
        if (scene.registry.has<Position>(e)) at[nameOf(e)] = scene.registry.tryGet<Position>(e)->value;
    // The welds' own give under load is about a millimetre; bars that
    // touched each other would be 0.38 m apart by now.
    EXPECT_LT(length(at["first x"] - at["first y"]), 5e-3);
    EXPECT_LT(length(at["second x"] - at["second y"]), 5e-3);
    EXPECT_NEAR(at["first y"].y, 1.0, 0.02);
    EXPECT_NEAR(at["second y"].y, 3.0, 0.05);
    EXPECT_NEAR(at["second y"].x, 0.0, 0.05);
}

TEST(Filters, WithoutTheGroupTheSameRagdollsBarsPushApart) {
    // The contrast that shows the group is what holds the crosses: with no
    // filter the bars of one ragdoll touch from the first step.
    Scene scene = parseLevel(crossedRagdolls(0, 0));
    World world = buildWorld(scene);
    ASSERT_TRUE(world.step());
    bool sameRagdoll = false;
    for (const ContactRecord& c : world.contacts())
        sameRagdoll = sameRagdoll || scene.registry.tryGet<Name>(c.a)->value.substr(0, 5) ==
                                         scene.registry.tryGet<Name>(c.b)->value.substr(0, 5);
    EXPECT_TRUE(sameRagdoll);
}

TEST(Filters, AFilteredBodyFallingThroughASleepingOneDoesNotWakeIt) {
    // The lower ball sleeps on the floor; a ball that may not touch it falls
    // through it. Its island stays asleep: an excluded pair is not a contact.
    std::string level = droppedPair(filterJson(1, 0xFFFFFFFFu, -1), filterJson(1, 0xFFFFFFFFu, -1), 0.5, 1.0);
    level.replace(level.find(R"("y": 2})"), 7, R"("y": 40})");  // the upper ball starts high, falls later
    Scene scene = parseLevel(level);
    World world = buildWorld(scene);
    int firstAsleep = -1;
    for (int i = 0; i < 240; ++i) {
        ASSERT_TRUE(world.step());
        const bool lowerAsleep = world.asleep(0);
        if (lowerAsleep && firstAsleep < 0) firstAsleep = i;
        if (firstAsleep >= 0) EXPECT_TRUE(lowerAsleep) << "woken at step " << i;
    }
    EXPECT_GE(firstAsleep, 0) << "the lower ball never slept";
    EXPECT_NEAR(world.bodyPosition(1).y, 0.5, 0.01);  // the upper one passed it and rests on the floor
}

TEST(Filters, OutOfRangeBitsAndGroupsAreRefusedAtTheirPointer) {
    const auto refusal = [](const std::string& filter) {
        const std::string text = R"({"entities": [{"name": "ball", "position": {"x": 0, "y": 0}, "radius": 1,
            "filter": )" + filter + "}]}";
        Result<Scene> s = parseScene(text, "t.json");
        return s ? std::string("accepted") : s.error();
    };
    EXPECT_EQ(refusal(R"({"category": -1})"),
              "t.json: error: /entities/0/filter/category: expected an integer in [0, 4294967295], got -1");
    EXPECT_EQ(refusal(R"({"mask": 4294967296})"),
              "t.json: error: /entities/0/filter/mask: expected an integer in [0, 4294967295], got 4294967296");
    EXPECT_EQ(refusal(R"({"mask": 1.5})"),
              "t.json: error: /entities/0/filter/mask: expected an integer in [0, 4294967295], got 1.5");
    EXPECT_EQ(refusal(R"({"category": "2"})"),
              "t.json: error: /entities/0/filter/category: expected an integer in [0, 4294967295], got \"2\"");
    EXPECT_EQ(refusal(R"({"group": 2147483648})"),
              "t.json: error: /entities/0/filter/group: expected an integer in [-2147483647, 2147483647], got "
              "2147483648");
    EXPECT_EQ(refusal(R"({"group": 1, "layer": 2})").substr(0, 50), "t.json: error: /entities/0/filter/layer: unknown f");
    EXPECT_EQ(refusal(R"({"category": 4294967295, "mask": 0, "group": -2147483647})"), "accepted");
}

TEST(Filters, AFilterRoundTripsByteForByteWithEveryBitSet) {
    const std::string text = R"({"entities": [{"name": "ball", "position": {"x": 0, "y": 0}, "radius": 1,
        "filter": {"category": 4294967295, "mask": 2147483648, "group": -2147483647}}]})";
    const Scene first = parseLevel(text);
    const std::string saved = sceneToJsonText(first);
    EXPECT_NE(saved.find(R"("category": 4294967295)"), std::string::npos) << saved;
    EXPECT_NE(saved.find(R"("mask": 2147483648)"), std::string::npos) << saved;
    EXPECT_EQ(sceneToJsonText(parseLevel(saved)), saved);
}
