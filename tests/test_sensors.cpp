// Sensors: shapes that report bodies entering and leaving them and never
// change anyone's motion.
#include "test_support.hpp"

#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

using namespace stepwise;
using namespace stepwise::test;

namespace {

/// A ball of radius r dropped from rest at height `drop` through a static
/// sensor box of height `thickness` centred at y = 0, onto nothing; with
/// `sensor` false the box is absent (an entity with only a name).
std::string dropThrough(double r, double drop, double thickness, bool sensor, const std::string& ballExtra = "") {
    const std::string zone = sensor ? R"({"name": "zone", "position": {"x": 0, "y": 0}, "static": true, "sensor": true,
           "box": {"width": 4, "height": )" + exactNumber(thickness) + "}}"
                                    : R"({"name": "zone"})";
    return R"({"world": {"gravity": {"x": 0, "y": -9.81}},
      "entities": [)" + zone + R"(,
        {"name": "ball", "position": {"x": 0.25, "y": )" + exactNumber(drop) + R"(}, "radius": )" + exactNumber(r) +
           ballExtra + "}]}";
}

struct Logged {
    std::vector<std::pair<int, bool>> events;  ///< step, begin
    std::vector<double> y;                     ///< the ball's height after each step
};

Logged run(const std::string& level, int steps) {
    Scene scene = parseLevel(level);
    World world = buildWorld(scene);
    Logged out;
    for (int s = 1; s <= steps; ++s) {
        Result<void> stepped = world.step();
        if (!stepped) throw std::runtime_error(stepped.error());
        for (const SensorEvent& e : world.sensorEvents()) out.events.emplace_back(s, e.begin);
        out.y.push_back(world.bodyPosition(0).y);
    }
    return out;
}

} // namespace

TEST(Sensors, ABallFallingThroughASensorBeginsAndEndsAtTheStepsItsShapeCrossesAndKeepsItsPath) {
    // Swept over ball size, drop height and zone thickness. The sensor
    // changes nothing: the path is bit for bit the path without it. The
    // events fall exactly on the steps where the ball's disc starts and
    // stops overlapping the zone (|y| < r + thickness / 2).
    for (const double r : {0.1, 0.5})
        for (const double drop : {2.0, 3.0, 10.0})
            for (const double thickness : {0.5, 2.0}) {
                const int steps = 150;
                const Logged with = run(dropThrough(r, drop, thickness, true), steps);
                const Logged without = run(dropThrough(r, drop, thickness, false), steps);
                const std::string where = "r " + exactNumber(r) + " drop " + exactNumber(drop) + " thickness " +
                                          exactNumber(thickness);
                ASSERT_EQ(with.y, without.y) << where;
                std::vector<std::pair<int, bool>> expected;
                bool inside = std::abs(drop) < r + 0.5 * thickness;  // no begin for a start inside
                for (int s = 1; s <= steps; ++s) {
                    const bool now = std::abs(with.y[std::size_t(s - 1)]) < r + 0.5 * thickness;
                    if (now != inside) expected.emplace_back(s, now);
                    inside = now;
                }
                ASSERT_EQ(expected.size(), 2u) << where;  // the sweep keeps every case a full pass
                EXPECT_EQ(with.events, expected) << where;
            }
}

TEST(Sensors, ABodyThatStartsInsideIsInsideFromTheStartAndSleepingKeepsItThere) {
    // A ball resting on a floor inside a goal zone: listed as inside from
    // the build on, no begin event; it falls asleep there and stays listed,
    // with no end event.
    Scene scene = parseLevel(R"({"world": {"gravity": {"x": 0, "y": -9.81}},
      "entities": [
        {"name": "floor", "plane": {"normal": {"x": 0, "y": 1}, "offset": 0}},
        {"name": "goal", "position": {"x": 0, "y": 1}, "static": true, "sensor": true, "box": {"width": 2, "height": 2}},
        {"name": "ball", "position": {"x": 0, "y": 0.5}, "radius": 0.5}]})");
    World world = buildWorld(scene);
    ASSERT_EQ(world.sensorOverlaps().size(), 1u);
    bool slept = false;
    for (int s = 0; s < 300; ++s) {
        ASSERT_TRUE(world.step());
        EXPECT_TRUE(world.sensorEvents().empty()) << "step " << s + 1;
        ASSERT_EQ(world.sensorOverlaps().size(), 1u) << "step " << s + 1;
        slept = slept || world.asleep(0);
    }
    EXPECT_TRUE(slept);
}

TEST(Sensors, AFilterKeepsABodyOutOfASensor) {
    const Logged seen = run(dropThrough(0.25, 2.0, 1.0, true), 90);
    EXPECT_EQ(seen.events.size(), 2u);
    const Logged unseen =
        run(dropThrough(0.25, 2.0, 1.0, true, R"(, "filter": {"category": 2, "mask": 4294967294, "group": 0})"), 90);
    EXPECT_TRUE(unseen.events.empty());
}

TEST(Sensors, AMovingSensorMeetsStaticShapesAndOtherSensorsNever) {
    // A dynamic sensor falls through a static box and past a static sensor:
    // it reports the box (begin, end), never the other sensor, and falls
    // freely (y = y0 - g t^2 / 2 under semi-implicit Euler's rounding).
    Scene scene = parseLevel(R"({"world": {"gravity": {"x": 0, "y": -9.81}, "substeps": 1},
      "entities": [
        {"name": "shelf", "position": {"x": 0, "y": 0}, "static": true, "box": {"width": 2, "height": 0.2}},
        {"name": "beam", "position": {"x": 0, "y": -1}, "static": true, "sensor": true, "box": {"width": 2, "height": 0.2}},
        {"name": "probe", "position": {"x": 0, "y": 1}, "sensor": true, "radius": 0.2}]})");
    World world = buildWorld(scene);
    std::vector<SensorEvent> events;
    for (int s = 0; s < 60; ++s) {
        ASSERT_TRUE(world.step());
        for (const SensorEvent& e : world.sensorEvents()) events.push_back(e);
    }
    ASSERT_EQ(events.size(), 2u);
    world.writeBack(scene);
    const auto nameOf = [&](Entity e) { return scene.registry.tryGet<Name>(e)->value; };
    EXPECT_EQ(nameOf(events[0].sensor), "probe");
    EXPECT_EQ(nameOf(events[0].body), "shelf");
    EXPECT_TRUE(events[0].begin);
    EXPECT_FALSE(events[1].begin);
    // Semi-implicit Euler from rest: y_n = y0 - g h^2 n (n + 1) / 2.
    const double h = 1.0 / 60.0;
    EXPECT_NEAR(world.bodyPosition(0).y, 1.0 - 9.81 * h * h * 60.0 * 61.0 / 2.0, 1e-9);
}

TEST(Sensors, EventsAfterASaveAndLoadAreTheEventsOfTheRunOn) {
    // Three balls dropped at different heights through a zone; the run is
    // split in the middle of the first one's pass.
    const std::string level = R"({"world": {"gravity": {"x": 0, "y": -9.81}},
      "entities": [
        {"name": "zone", "position": {"x": 0, "y": 0}, "static": true, "sensor": true, "box": {"width": 6, "height": 1}},
        {"name": "a", "position": {"x": -2, "y": 1}, "radius": 0.2},
        {"name": "b", "position": {"x": 0, "y": 3}, "radius": 0.2},
        {"name": "c", "position": {"x": 2, "y": 6}, "radius": 0.2}]})";
    const auto eventsOf = [](World& world, const Scene& scene, int steps) {
        std::vector<std::string> out;
        for (int s = 0; s < steps; ++s) {
            if (!world.step()) return out;
            for (const SensorEvent& e : world.sensorEvents())
                out.push_back(std::to_string(std::lround(world.time() * 60.0)) + " " +
                              scene.registry.tryGet<Name>(e.body)->value + (e.begin ? " begin" : " end"));
        }
        return out;
    };
    Scene straightScene = parseLevel(level);
    World straight = buildWorld(straightScene);
    const std::vector<std::string> all = eventsOf(straight, straightScene, 120);
    ASSERT_EQ(all.size(), 6u);

    Scene first = parseLevel(level);
    World world = buildWorld(first);
    std::vector<std::string> split = eventsOf(world, first, 25);
    Scene resumed = parseLevel(savedRunText(world, first));
    World again = buildWorld(resumed);
    const std::vector<std::string> rest = eventsOf(again, resumed, 95);
    split.insert(split.end(), rest.begin(), rest.end());
    EXPECT_EQ(split, all);
}

TEST(Sensors, RunContactsWritesABeginAndAnEndLine) {
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "stepwise_sensor_cli";
    std::filesystem::create_directories(dir);
    {
        std::ofstream(dir / "drop.json") << dropThrough(0.5, 2.0, 1.0, true);
    }
    const CommandResult r = runCommand(std::string(STEPWISE_BINARY) + " run " + (dir / "drop.json").string() +
                                       " --steps 60 --contacts " + (dir / "c.jsonl").string() + " 2>&1");
    ASSERT_EQ(r.exitCode, 0) << r.out;
    std::vector<std::string> eventLines;
    std::istringstream lines(readFile(dir / "c.jsonl"));
    for (std::string line; std::getline(lines, line);)
        if (line.find("\"event\"") != std::string::npos) eventLines.push_back(line);
    ASSERT_EQ(eventLines.size(), 2u);
    const Logged logged = run(dropThrough(0.5, 2.0, 1.0, true), 60);
    // {"event": ..., "step": N, "time": T, "sensor": "zone", "body": "ball"}, at the steps the engine reports.
    const char* kinds[2] = {"begin", "end"};
    for (int k = 0; k < 2; ++k) {
        const std::string& line = eventLines[std::size_t(k)];
        const std::string head = "{\"event\": \"" + std::string(kinds[k]) + "\", \"step\": " +
                                 std::to_string(logged.events[std::size_t(k)].first) + ", \"time\": ";
        EXPECT_EQ(line.substr(0, head.size()), head) << line;
        EXPECT_EQ(line.substr(line.find("\"sensor\"")), "\"sensor\": \"zone\", \"body\": \"ball\"}") << line;
    }
    std::filesystem::remove_all(dir);
}
