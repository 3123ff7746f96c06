// The shared scene builders (engine/scenes/generated_scenes.hpp). The
// benchmarks, the editor's --bench-bodies level and the tests share one
// CircleGrid, each with its own parameters. The hashes below are of each
// scene's saved JSON text (every position, radius, velocity, name and
// colour, to the last bit): the figures in docs/performance.md and
// docs/collisions.md and the tests' bounds were measured on exactly these
// scenes. A change that moves a scene must fail here: re-measure what
// depends on it and re-record.

#include "app/scene_edit.hpp"
#include "generated_scenes.hpp"
#include "test_support.hpp"

#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

using namespace stepwise;

namespace {

using test::fnv1a;
using test::hex;

void expectBytes(const Scene& scene, std::uint64_t recorded, std::size_t size, const char* what) {
    // Recorded without the world's sleep lines (the entities' bytes are
    // what matter here).
    const std::string text = test::withoutSleepLines(sceneToJsonText(scene));
    EXPECT_EQ(text.size(), size) << what;
    EXPECT_EQ(hex(fnv1a(text)), hex(recorded)) << what;
}

} // namespace

TEST(Scenes, CollisionBenchmarkScenesAreTheBytesTheyWereMeasuredOn) {
    expectBytes(scenes::circlesInBox(), 0xce840b26f7b5c054ull, 382752, "pile, 2,000 circles");
    expectBytes(scenes::circlesInBox(300), 0xcebacc6603617e1dull, 58419, "pile, 300 circles");
    expectBytes(scenes::boxPyramid(), 0x09fed35452e78defull, 42840, "pyramid, 20 rows");
    expectBytes(scenes::circleRain(), 0x0ea5978aaee42532ull, 289034, "rain, 1,000 drops");
}

TEST(Scenes, EditorBenchLevelIsTheBytesItWasMeasuredOn) {
    expectBytes(editor::benchScene(2000), 0x0eb2395ed98b3c61ull, 511317, "--bench-bodies 2000");
    expectBytes(editor::benchScene(37), 0x0b25afb7fe9e5256ull, 9766, "--bench-bodies 37");
    expectBytes(editor::benchScene(1), 0x9023dee617bcb616ull, 1068, "--bench-bodies 1");
}

TEST(Scenes, TallPileIsTheBytesItsTestsWereBoundedOn) {
    expectBytes(scenes::tallPile(), 0x183d34f1dcdecad2ull, 53042, "tall pile");
}

TEST(Scenes, CircleGridPlacesRowByRowWithTheGivenPitchAndOnlyTheComponentsAsked) {
    Scene s;
    scenes::CircleGrid grid;
    grid.count = 5;
    grid.columns = 2;
    grid.first = {1.0, 2.0};
    grid.pitch = {0.5, 0.75};
    grid.radius = 0.125;
    scenes::addCircleGrid(s, grid);
    ASSERT_EQ(s.registry.size(), 5u);
    const Vec2 expected[] = {{1.0, 2.0}, {1.5, 2.0}, {1.0, 2.75}, {1.5, 2.75}, {1.0, 3.5}};
    int i = 0;
    for (Entity e : s.registry.entities()) {
        EXPECT_EQ(s.registry.tryGet<Position>(e)->value.x, expected[i].x) << i;
        EXPECT_EQ(s.registry.tryGet<Position>(e)->value.y, expected[i].y) << i;
        EXPECT_EQ(s.registry.tryGet<Radius>(e)->value, 0.125);
        EXPECT_FALSE(s.registry.has<Name>(e));
        EXPECT_FALSE(s.registry.has<Velocity>(e));
        EXPECT_FALSE(s.registry.has<Mass>(e));
        EXPECT_FALSE(s.registry.has<Friction>(e));
        EXPECT_FALSE(s.registry.has<Color>(e));
        ++i;
    }
}

TEST(Scenes, EveryJitterStaysWithinItsAmplitudeAndAZeroVelocityFactorGivesPositiveZero) {
    for (scenes::Jitter jitter : {scenes::Jitter::Hash, scenes::Jitter::Lcg, scenes::Jitter::Mod11}) {
        Scene s;
        scenes::CircleGrid grid;
        grid.count = 500;
        grid.columns = 1;
        grid.pitch = {0.0, 1.0};
        grid.jitter = jitter;
        grid.jitterAmplitude = 0.02;
        grid.velocityPerJitter = 0.0;
        scenes::addCircleGrid(s, grid);
        double smallest = 1.0, largest = -1.0;
        for (Entity e : s.registry.entities()) {
            const double x = s.registry.tryGet<Position>(e)->value.x;
            smallest = std::min(smallest, x);
            largest = std::max(largest, x);
            const double vx = s.registry.tryGet<Velocity>(e)->value.x;
            EXPECT_EQ(vx, 0.0);
            EXPECT_FALSE(std::signbit(vx)) << "a circle at x = " << x << " starts at -0";
        }
        EXPECT_GE(smallest, -0.02) << int(jitter);
        EXPECT_LE(largest, 0.02) << int(jitter);
        // Spread over most of the range, both sides.
        EXPECT_LT(smallest, -0.015) << int(jitter);
        EXPECT_GT(largest, 0.015) << int(jitter);
    }
}
