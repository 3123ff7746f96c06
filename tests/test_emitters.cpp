// Templates and emitters: copies of a prefab added and removed while a World
// runs, in place (no World is built for them), on exact times, with their
// joints and springs, a seeded spread, and a save that resumes bit for bit.
#include "test_support.hpp"

#include "world/world_internals.hpp"

#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world.hpp"

#include <gtest/gtest.h>

#include <deque>
#include <map>
#include <tuple>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <span>
#include <unordered_map>
#include <unordered_set>
#include <sstream>
#include <string>
#include <vector>

using namespace stepwise;
using namespace stepwise::test;

namespace {

std::string refusal(const std::string& text) {
    Result<Scene> scene = parseScene(text, "t.json");
    return scene ? std::string("(loaded)") : scene.error();
}

/// A level with one ball template `drop` and an emitter at (0, 5). `emitter`
/// is the emitter's JSON fields after "template"; `world` the world's.
std::string ballLevel(const std::string& emitter, const std::string& world = R"("gravity": {"x": 0, "y": 0})") {
    return R"({"world": {)" + world + R"(},
      "entities": [
        {"name": "proto", "template": "drop", "position": {"x": 40, "y": 40}, "radius": 0.1, "mass": 2},
        {"name": "spout", "position": {"x": 0, "y": 5}, "emitter": {"template": "drop", )" + emitter + R"(}}
      ]})";
}

/// Names of the emitted copies alive, in scene order, as a save writes them.
std::vector<std::string> copiesAlive(const World& world, Scene scene) {
    world.writeBack(scene);
    std::vector<std::string> out;
    for (const Entity e : scene.registry.entities())
        if (const Name* n = scene.registry.tryGet<Name>(e); n && n->value.find('#') != std::string::npos)
            out.push_back(n->value);
    return out;
}

std::string ragdollLevel(int substeps, int count, const std::string& lifetime = "", int seed = 0) {
    std::ostringstream s;
    s << R"({"world": {"gravity": {"x": 0, "y": -9.81}, "dt": 0.016666666666666666)";
    if (substeps > 0) s << R"(, "substeps": )" << substeps;
    if (seed != 0) s << R"(, "seed": )" << seed;
    s << R"(},
      "entities": [
        {"name": "ground", "position": {"x": 0, "y": -0.5}, "static": true, "box": {"width": 12, "height": 1},
         "friction": 0.6},
        {"name": "wall_l", "position": {"x": -6, "y": 3}, "static": true, "box": {"width": 0.4, "height": 8}},
        {"name": "wall_r", "position": {"x": 6, "y": 3}, "static": true, "box": {"width": 0.4, "height": 8}},
        {"name": "torso", "template": "doll", "position": {"x": 20, "y": 20}, "capsule": {"a": {"x": 0, "y": -0.3},
         "b": {"x": 0, "y": 0.3}, "radius": 0.15}, "mass": 2},
        {"name": "head", "template": "doll", "position": {"x": 20, "y": 20.65}, "radius": 0.15, "mass": 0.5,
         "filter": {"category": 1, "mask": 4294967295, "group": -1}},
        {"name": "leg", "template": "doll", "position": {"x": 20, "y": 19.3}, "capsule": {"a": {"x": 0, "y": -0.25},
         "b": {"x": 0, "y": 0.25}, "radius": 0.1}, "mass": 1, "filter": {"category": 1, "mask": 4294967295, "group": -1}},
        {"name": "neck", "joint": {"type": "hinge", "a": "torso", "b": "head", "anchor": {"x": 20, "y": 20.45},
         "spring_hz": 2, "spring_damping_ratio": 0.7}},
        {"name": "hip", "joint": {"type": "hinge", "a": "torso", "b": "leg", "anchor": {"x": 20, "y": 19.6},
         "lower": -1, "upper": 1}},
        {"name": "tie", "spring": {"a": "head", "b": "leg", "k": 5, "damping": 0.5}},
        {"name": "hatch", "position": {"x": 0, "y": 6}, "emitter": {"template": "doll", "interval": 0.5, "count": )"
      << count << R"(, "velocity": {"x": 1, "y": 0}, "spread": 0.8)" << lifetime << R"(}}
      ]})";
    return s.str();
}

/// What a run of `total` steps saves when it is saved after `split` steps,
/// loaded and continued: a straight run's text when resume is exact. Empty
/// when a step fails (with the failure reported). The saved file must also
/// write back byte for byte.
std::string savedAfterResumeAt(const Scene& scene, int split, int total) {
    Scene first = scene;
    World world = buildWorld(first);
    for (int s = 0; s < split; ++s)
        if (!world.step()) {
            ADD_FAILURE() << "step " << s << " failed";
            return {};
        }
    const std::string saved = savedRunText(world, first);
    Scene resumed = parseLevel(saved);
    EXPECT_EQ(sceneToJsonText(resumed).size(), saved.size());
    World again = buildWorld(resumed);
    for (int s = split; s < total; ++s)
        if (!again.step()) {
            ADD_FAILURE() << "step " << s << " failed after the resume";
            return {};
        }
    return savedRunText(again, resumed);
}

} // namespace

TEST(Emitters, ACopyAppearsEveryIntervalUpToCountAndTheOldestGoesFirst) {
    // Intervals of 1, 3 and 30 steps and counts 1, 2 and 4: copy k (from 1)
    // appears at the start of step (k - 1) * interval + 1; while `count` are
    // alive the oldest leaves as the next one comes; names count on.
    const double dt = 1.0 / 60.0;
    for (const int every : {1, 3, 30})
        for (const int count : {1, 2, 4}) {
            SCOPED_TRACE("every " + std::to_string(every) + " steps, count " + std::to_string(count));
            const Scene scene = parseLevel(ballLevel(R"("interval": )" + exactNumber(every * dt) + R"(, "count": )" +
                                                     std::to_string(count) + R"(, "velocity": {"x": 3, "y": 0})"));
            World world = buildWorld(scene);
            EXPECT_EQ(world.bodyCount(), 0u);
            for (int step = 1; step <= 4 * every * count + 5; ++step) {
                ASSERT_TRUE(world.step());
                const int emitted = (step - 1) / every + 1;
                const int alive = std::min(emitted, count);
                ASSERT_EQ(world.bodyCount(), std::size_t(alive)) << "step " << step;
                if (step % every == 0 || step < 3) {
                    std::vector<std::string> expected;
                    for (int k = emitted - alive + 1; k <= emitted; ++k) expected.push_back("drop#" + std::to_string(k));
                    ASSERT_EQ(copiesAlive(world, scene), expected) << "step " << step;
                }
            }
        }
}

TEST(Emitters, AnIntervalThatIsNoWholeNumberOfStepsEmitsAtTheFirstStepWithinHalfAStep) {
    // dt 0.125 s, interval 0.31 s: copy k (from 0) is due at 0.31 k and
    // appears at the first step that starts at or after 0.31 k - dt / 2.
    const Scene scene = parseLevel(
        ballLevel(R"("interval": 0.31, "count": 100, "velocity": {"x": 3, "y": 0})", R"("gravity": {"x": 0, "y": 0}, "dt": 0.125)"));
    World world = buildWorld(scene);
    std::vector<int> appeared;
    std::size_t before = 0;
    for (int step = 1; step <= 20; ++step) {
        ASSERT_TRUE(world.step());
        for (std::size_t k = before; k < world.bodyCount(); ++k) appeared.push_back(step);
        before = world.bodyCount();
    }
    // (s - 1) * 0.125 >= 0.31 k - 0.0625: s = ceil(2.48 k - 0.5) + 1.
    EXPECT_EQ(appeared, (std::vector<int>{1, 3, 6, 8, 11, 13, 16, 18}));
}

TEST(Emitters, ALifetimeRemovesEachCopyThatLongAfterItAppeared) {
    // Interval 10 steps; lifetimes of 5, 25 and 40 steps (40 > count *
    // interval: then count removes them first). Copy k appears at step
    // 10 (k - 1) + 1 and leaves at the first step that starts at or after
    // its time plus the lifetime.
    const double dt = 1.0 / 60.0;
    for (const int life : {5, 25, 40}) {
        SCOPED_TRACE("lifetime " + std::to_string(life) + " steps");
        const Scene scene = parseLevel(ballLevel(R"("interval": )" + exactNumber(10 * dt) + R"(, "count": 3, "lifetime": )" +
                                                 exactNumber(life * dt) + R"(, "velocity": {"x": 3, "y": 0})"));
        World world = buildWorld(scene);
        for (int step = 1; step <= 200; ++step) {
            ASSERT_TRUE(world.step());
            int alive = 0;
            for (int k = 1; 10 * (k - 1) + 1 <= step; ++k) {
                const int born = 10 * (k - 1) + 1, gone = born + life;
                const int pushedOut = 10 * (k + 3 - 1) + 1;  // when copy k + 3 arrives with 3 alive
                if (step < gone && step < pushedOut) ++alive;
            }
            ASSERT_EQ(world.bodyCount(), std::size_t(alive)) << "step " << step;
        }
    }
}

TEST(Emitters, CopiesCarryTheTemplatesJointsAndSprings) {
    // The doll: three bodies, two hinges (one with a spring, one with
    // limits) and a spring. Every copy alive holds its own joints and
    // spring, its hinges stay closed, and what is removed takes its
    // joints and spring along.
    const Scene scene = parseLevel(ragdollLevel(4, 3));
    World world = buildWorld(scene);
    const WorldImpl& w = internals(world);
    for (int step = 1; step <= 360; ++step) {
        ASSERT_TRUE(world.step());
        const std::size_t copies = world.bodyCount() / 3;
        ASSERT_EQ(world.bodyCount(), 3 * copies);
        ASSERT_EQ(world.joints().size(), 2 * copies) << "step " << step;
        ASSERT_EQ(w.model.springs.size(), copies) << "step " << step;
        for (const JointRecord& j : world.joints()) ASSERT_LT(j.separation, 5e-3) << "step " << step;
        for (const detail::SpringData& s : w.model.springs) {
            // Both ends of each spring in the same copy: adjacent bodies.
            ASSERT_NE(s.b, detail::kNoBody);
            ASSERT_EQ(s.a / 3, s.b / 3);
        }
    }
    EXPECT_EQ(world.bodyCount(), 9u);
    // The copies' names: the first body is the copy's own name.
    const std::vector<std::string> names = copiesAlive(world, scene);
    const std::string newest = "doll#" + std::to_string(12);  // the twelfth copy
    EXPECT_NE(std::find(names.begin(), names.end(), newest), names.end());
    EXPECT_NE(std::find(names.begin(), names.end(), newest + "/head"), names.end());
    EXPECT_NE(std::find(names.begin(), names.end(), newest + "/neck"), names.end());
    EXPECT_EQ(std::find(names.begin(), names.end(), "doll#9"), names.end());
}

TEST(Emitters, EachCopysVelocityIsTurnedWithinTheSpreadBySeed) {
    // Zero gravity, nothing to hit: each copy keeps the velocity it got.
    // Its direction is within +- spread of the emitter's, spread over the
    // range; the same seed gives the same turns, another seed others.
    const auto turns = [](int seed, double spread) {
        const Scene scene = parseLevel(ballLevel(R"("interval": 0.1, "count": 50, "velocity": {"x": 4, "y": 0}, "spread": )" +
                                                     exactNumber(spread),
                                                 R"("gravity": {"x": 0, "y": 0}, "seed": )" + std::to_string(seed)));
        World world = buildWorld(scene);
        for (int step = 0; step < 240; ++step) EXPECT_TRUE(world.step());
        std::vector<double> out;
        for (std::size_t b = 0; b < world.bodyCount(); ++b) {
            const Vec2 v = world.bodyVelocity(b);
            EXPECT_NEAR(length(v), 4.0, 1e-12);
            out.push_back(std::atan2(v.y, v.x));
        }
        return out;
    };
    for (const double spread : {0.05, 0.5, 3.0}) {
        SCOPED_TRACE("spread " + std::to_string(spread));
        const std::vector<double> a = turns(7, spread);
        ASSERT_EQ(a.size(), 40u);
        double lo = 1e9, hi = -1e9;
        for (const double t : a) {
            EXPECT_LE(std::abs(t), spread + 1e-12);
            lo = std::min(lo, t);
            hi = std::max(hi, t);
        }
        EXPECT_GT(hi - lo, 1.2 * spread);  // 40 uniform draws cover most of the 2 spread range
        EXPECT_EQ(turns(7, spread), a);
        const std::vector<double> b = turns(8, spread);
        int same = 0;
        for (std::size_t k = 0; k < a.size(); ++k) same += a[k] == b[k];
        EXPECT_EQ(same, 0);
    }
    // No spread: every copy goes straight.
    for (const double t : turns(3, 0.0)) EXPECT_EQ(t, 0.0);
}

TEST(Emitters, SaveLoadAndContinueIsBitIdenticalToRunningOn) {
    // 600 steps straight against a save after `split` steps, a load and the
    // rest, over split points on and around emissions (every 30 steps) and
    // removals, at 1, 2 and 4 substeps and the engine's own choice, with
    // and without a lifetime.
    struct Case {
        int substeps;
        std::string lifetime, integrator;
    };
    std::vector<Case> cases;
    for (const int substeps : {1, 2, 4, 0})
        for (const std::string lifetime : {std::string(), std::string(R"(, "lifetime": 2.1)")})
            cases.push_back({substeps, lifetime, "semi_implicit_euler"});
    // The integrators whose scratch is sized by the bodies, or that carry a step.
    for (const char* integrator : {"rk4", "velocity_verlet", "implicit_euler", "dopri5"})
        cases.push_back({2, R"(, "lifetime": 2.1)", integrator});
    for (const Case& c : cases) {
        {
            const int substeps = c.substeps;
            const std::string& lifetime = c.lifetime;
            SCOPED_TRACE("substeps " + std::to_string(substeps) + (lifetime.empty() ? "" : ", lifetime 2.1 s") + ", " +
                         c.integrator);
            Scene scene = parseLevel(ragdollLevel(substeps, 4, lifetime));
            scene.world.integrator = c.integrator;
            World straight = buildWorld(scene);
            for (int s = 0; s < 600; ++s) ASSERT_TRUE(straight.step());
            const std::string expected = savedRunText(straight, scene);
            for (const int split : {1, 29, 30, 31, 121, 200, 451}) {
                SCOPED_TRACE("split " + std::to_string(split));
                ASSERT_EQ(savedAfterResumeAt(scene, split, 600), expected);
            }
        }
    }
}

TEST(Emitters, CopiesComeAndGoWithoutBuildingAWorld) {
    const Scene scene = parseLevel(ragdollLevel(4, 3, R"(, "lifetime": 1.2)"));
    World world = buildWorld(scene);
    const std::uint64_t builds = worldBuildCount();
    std::set<std::size_t> counts;
    for (int s = 0; s < 600; ++s) {
        ASSERT_TRUE(world.step());
        counts.insert(world.bodyCount());
    }
    EXPECT_EQ(worldBuildCount(), builds);
    EXPECT_EQ(counts, (std::set<std::size_t>{3, 6, 9}));
}

TEST(Emitters, TemplatesNeverMoveCollideOrCount) {
    // The template doll sits inside the ground: were it simulated it would
    // be pushed out. It is no body, has no contacts and no energy, and a
    // save writes it as it was.
    std::string level = ragdollLevel(4, 3);
    for (const char* y : {"\"y\": 20}", "\"y\": 20.65}", "\"y\": 19.3}"}) {
        const std::size_t at = level.find(std::string("\"x\": 20, ") + y);
        ASSERT_NE(at, std::string::npos);
        level.replace(at, std::string("\"x\": 20, ").size() + std::string(y).size(), "\"x\": 0, \"y\": -0.5}");
    }
    const Scene scene = parseLevel(level);
    World world = buildWorld(scene);
    EXPECT_EQ(world.bodyCount(), 0u);
    EXPECT_EQ(world.energy().total(), 0.0);
    std::unordered_set<Entity> templates;
    for (const Entity e : scene.registry.entities())
        if (scene.registry.has<Template>(e)) templates.insert(e);
    ASSERT_EQ(templates.size(), 3u);
    for (int s = 0; s < 300; ++s) {
        ASSERT_TRUE(world.step());
        for (const ContactRecord& c : world.contacts()) {
            ASSERT_EQ(templates.count(c.a), 0u);
            ASSERT_EQ(templates.count(c.b), 0u);
        }
        for (std::size_t b = 0; b < world.bodyCount(); ++b) ASSERT_EQ(templates.count(world.bodyEntity(b)), 0u);
    }
    Scene after = scene;
    world.writeBack(after);
    for (const Entity e : templates) {
        EXPECT_EQ(after.registry.tryGet<Position>(e)->value, scene.registry.tryGet<Position>(e)->value);
        EXPECT_FALSE(after.registry.has<Velocity>(e));
    }
}

TEST(Emitters, TheArraysAStepWalksHoldTheCopiesAliveAndNothingElse) {
    // What a step costs follows the copies alive: the state vector, the
    // colliders, the joints and the springs hold exactly theirs (plus the
    // three static walls), growing as copies come and shrinking as they
    // go, never the copies made so far.
    const Scene scene = parseLevel(ragdollLevel(2, 5, R"(, "lifetime": 1.6)"));
    World world = buildWorld(scene);
    const WorldImpl& w = internals(world);
    std::size_t most = 0;
    bool shrank = false;
    std::size_t last = 0;
    for (int s = 0; s < 900; ++s) {
        ASSERT_TRUE(world.step());
        const std::size_t copies = world.bodyCount() / 3;
        ASSERT_EQ(w.model.n, 3 * copies);
        ASSERT_EQ(w.xs() ? w.x[w.current].size() : 0, 6 * copies);
        ASSERT_EQ(w.collision->colliderCount(), 3 + 3 * copies);
        ASSERT_EQ(w.collision->jointConstraints().size(), 2 * copies);
        ASSERT_EQ(w.model.springs.size(), copies);
        ASSERT_LE(w.collision->warmStartCache().size(), 8 * (3 + 3 * copies));
        most = std::max(most, copies);
        shrank = shrank || copies < last;
        last = copies;
    }
    EXPECT_EQ(most, 4u);  // a lifetime of 1.6 s keeps 4 of a copy every 0.5 s
    EXPECT_TRUE(shrank);
}

TEST(Emitters, PolygonCopiesThatComeAndGoHoldFewOutlinesAndResumeExactly) {
    // A copy's outline stays where it is while its neighbours come and go
    // (the contact system points at it); the outlines of copies gone are
    // freed once they are half of those held. 100 triangles come and 95 go:
    // the outlines held stay within twice those alive plus 16 (and one new
    // copy's), and a save after the frees resumes as the long run goes on.
    const std::string level = R"({"world": {"gravity": {"x": 0, "y": -9.81}, "substeps": 2},
      "entities": [
        {"name": "ground", "position": {"x": 0, "y": -0.5}, "static": true, "box": {"width": 30, "height": 1}},
        {"name": "shard", "template": "bit", "position": {"x": 40, "y": 40}, "mass": 0.5,
         "polygon": {"vertices": [{"x": -0.2, "y": -0.1}, {"x": 0.2, "y": -0.1}, {"x": 0, "y": 0.25}]}},
        {"name": "spout", "position": {"x": -5, "y": 2}, "emitter": {"template": "bit", "interval": 0.1,
         "count": 5, "lifetime": 0.45, "velocity": {"x": 4, "y": 1}}}
      ]})";
    const Scene scene = parseLevel(level);
    World world = buildWorld(scene);
    const WorldImpl& w = internals(world);
    std::size_t most = 0;
    bool freed = false;
    for (int s = 0; s < 600; ++s) {
        const std::size_t before = w.collision->outlinesHeld();
        ASSERT_TRUE(world.step());
        const std::size_t alive = world.copiesAlive(), held = w.collision->outlinesHeld();
        ASSERT_LE(held, 2 * alive + 16 + 1) << "step " << s;
        freed = freed || held < before;
        most = std::max(most, held);
    }
    EXPECT_TRUE(freed);
    EXPECT_GT(most, 2u * 5u);  // outlines of copies gone were held a while
    const std::string expected = savedRunText(world, scene);
    for (const int split : {95, 302, 541}) {
        SCOPED_TRACE("split " + std::to_string(split));
        EXPECT_EQ(savedAfterResumeAt(scene, split, 600), expected);
    }
}

TEST(Emitters, SnapshotsAcrossEmissionsRestoreExactlyWithOneBuildEach) {
    // Step back across emissions and removals: a snapshot from before the
    // copies changed is restored by building the World from the snapshot's
    // own scene (one build, only then); one with the same copies in place.
    // Either way the World steps on exactly as the one that took it.
    const Scene scene = parseLevel(ragdollLevel(2, 2, R"(, "lifetime": 0.7)"));
    for (const int at : {10, 25, 30, 31, 45, 61}) {
        SCOPED_TRACE("snapshot at step " + std::to_string(at));
        World world = buildWorld(scene);
        for (int s = 0; s < at; ++s) ASSERT_TRUE(world.step());
        const WorldState before = world.saveState();
        World reference = buildWorld(scene);
        for (int s = 0; s < at; ++s) ASSERT_TRUE(reference.step());
        for (int s = 0; s < 40; ++s) ASSERT_TRUE(world.step());
        const std::size_t copiesThen = reference.bodyCount(), copiesNow = world.bodyCount();
        const std::uint64_t builds = worldBuildCount();
        ASSERT_TRUE(world.restoreState(before));
        EXPECT_EQ(world.bodyCount(), copiesThen);
        // Another layout since: the one build; the same bodies: none. (The
        // copies in place can be the same bodies with other copies between.)
        EXPECT_LE(worldBuildCount() - builds, 1u);
        if (copiesThen != copiesNow) EXPECT_EQ(worldBuildCount() - builds, 1u);
        for (int s = 0; s < 100; ++s) {
            ASSERT_TRUE(world.step());
            ASSERT_TRUE(reference.step());
        }
        EXPECT_EQ(savedRunText(world, scene), savedRunText(reference, scene));
    }
    // A snapshot of another level is still refused.
    World other = buildWorld(parseLevel(ragdollLevel(2, 3)));
    World world = buildWorld(scene);
    ASSERT_TRUE(other.step());
    EXPECT_FALSE(world.restoreState(other.saveState()));
}

TEST(Emitters, RefusalsNameTheEmitterOrTemplate) {
    const std::string ground = R"({"name": "ground", "position": {"x": 0, "y": 0}, "static": true, "box": {"width": 4, "height": 1}})";
    const std::string proto = R"({"name": "proto", "template": "drop", "position": {"x": 9, "y": 9}, "radius": 0.1})";
    const auto level = [&](const std::string& emitter, const std::string& extra = "") {
        return R"({"entities": [)" + ground + "," + proto + extra +
               R"(, {"name": "spout", "position": {"x": 0, "y": 5}, "emitter": )" + emitter + "}]}";
    };
    EXPECT_EQ(refusal(level(R"({"template": "rain", "interval": 1, "count": 3})")),
              "t.json: error: /entities/2/emitter/template: emitter on entity 2 (\"spout\"): no entity has "
              "\"template\": \"rain\"");
    EXPECT_EQ(refusal(level(R"({"template": "drop", "interval": 0, "count": 3})")),
              "t.json: error: /entities/2/emitter/interval: expected a number in (0, 1e+30], got 0");
    EXPECT_EQ(refusal(level(R"({"template": "drop", "interval": 1, "count": 0})")),
              "t.json: error: /entities/2/emitter/count: expected an integer in [1, 100000], got 0");
    EXPECT_EQ(refusal(level(R"({"template": "drop", "interval": 1, "count": 2, "spread": -0.1})")),
              "t.json: error: /entities/2/emitter/spread: expected a number in [0, 3.14159], got -0.1");
    EXPECT_EQ(refusal(level(R"({"template": "drop", "interval": 1, "count": 2, "lifetime": -1})")),
              "t.json: error: /entities/2/emitter/lifetime: expected a number in (0, 1e+30], got -1");
    // Two emitters of one template share its copy numbers; each says which
    // of them it has alive when they are not its newest.
    const std::string spout2 =
        R"(, {"name": "drop#3", "position": {"x": 0, "y": 5}, "radius": 0.1}, {"name": "drop#1", "position": {"x": 1, "y": 5},
           "radius": 0.1}, {"name": "spout2", "position": {"x": 0, "y": 5}, "emitter": {"template": "drop", "emitted": 2,
           "alive": 2, "next": 5, "oldest": 3, )";
    EXPECT_EQ(refusal(level(R"({"template": "drop", "interval": 1, "count": 2})", spout2 + R"("copies": [1]}})")),
              "t.json: error: /entities/4/emitter/copies: emitter on entity 4 (\"spout2\"): 1 copy numbers for 2 "
              "copies alive");
    EXPECT_EQ(refusal(level(R"({"template": "drop", "interval": 1, "count": 2})", spout2 + R"("copies": [3, 1]}})")),
              "t.json: error: /entities/4/emitter/copies/1: emitter on entity 4 (\"spout2\"): copy numbers go up, "
              "oldest first; 1 follows 3");
    EXPECT_EQ(refusal(level(R"({"template": "drop", "interval": 1, "count": 2})", spout2 + R"("copies": [0, 3]}})")),
              "t.json: error: /entities/4/emitter/copies/0: expected an integer in [1, 2147483647], got 0");
    EXPECT_EQ(refusal(level(R"({"template": "drop", "interval": 1, "count": 2, "emitted": 1, "alive": 1, "next": 5,
                                "oldest": 4, "copies": [3]})",
                            spout2 + R"("copies": [1, 3]}})")),
              "t.json: error: /entities/5/emitter/copies: emitter on entity 5 (\"spout\"): copy \"drop#3\" is alive in "
              "the run state of entity 4 (\"spout2\") already");
    EXPECT_EQ(refusal(level(R"({"template": "drop", "interval": 1, "count": 2})", spout2 + R"("copies": [1, 3]}})")),
              "(loaded)");
    EXPECT_EQ(refusal(level(R"({"template": "drop", "interval": 1, "count": 2, "emitted": 4, "alive": 1, "next": 5, "oldest": 4})")),
              "t.json: error: /entities/2/emitter/alive: emitter on entity 2 (\"spout\"): copy \"drop#4\" is alive in "
              "its run state but not in the scene");
    EXPECT_EQ(refusal(level(R"({"template": "drop", "interval": 1, "count": 2})",
                            R"(, {"name": "drop#3", "position": {"x": 0, "y": 5}})")),
              "t.json: error: /entities/2/name: \"drop#3\" is a name the emitter on entity 3 (\"spout\") gives its "
              "copies, and that copy is not alive in its run state (0 alive of 0 emitted)");
    EXPECT_EQ(refusal(R"({"entities": [{"name": "p", "template": "t", "position": {"x": 0, "y": 0}, "static": true,
                          "radius": 1}]})"),
              "t.json: error: /entities/0/template: entity 0 (\"p\"): a template entity is a dynamic body with a "
              "shape; remove \"static\"");
    EXPECT_EQ(refusal(R"({"entities": [{"name": "p", "template": "t", "position": {"x": 0, "y": 0}}]})"),
              "t.json: error: /entities/0/template: entity 0 (\"p\"): a template body needs a shape (radius, box, "
              "polygon, capsule or shapes): its copies are added to the contact solver as they appear");
    EXPECT_EQ(refusal(R"({"entities": [)" + ground + "," + proto +
                      R"(, {"name": "j", "joint": {"type": "hinge", "a": "proto", "b": "ground"}}]})"),
              "t.json: error: /entities/2/joint: joint on entity 2 (\"j\"): joins \"ground\" to template \"drop\"; a "
              "template's joints and springs stay within it");
}

TEST(Emitters, ASavedRunWithCopiesRoundTripsByteForByte) {
    const Scene scene = parseLevel(ragdollLevel(4, 3, R"(, "lifetime": 1.2)"));
    World world = buildWorld(scene);
    for (int s = 0; s < 100; ++s) ASSERT_TRUE(world.step());
    const std::string saved = savedRunText(world, scene);
    EXPECT_NE(saved.find("\"doll#4\""), std::string::npos);
    EXPECT_NE(saved.find("\"alive\": 3"), std::string::npos);
    const std::string again = sceneToJsonText(parseLevel(saved));
    EXPECT_EQ(again, saved);
}

TEST(Emitters, RunLogsEachEmissionAndRemovalAndCountsTheCopiesAlive) {
    // Interval 10 steps, count 2: copies at steps 1, 11, 21, 31; from step
    // 21 on each new copy pushes the oldest out in the same step.
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "stepwise_emitters_cli";
    std::filesystem::create_directories(dir);
    const std::filesystem::path level = dir / "drops.json", log = dir / "contacts.jsonl";
    {
        std::ofstream out(level);
        out << ballLevel(R"("interval": )" + exactNumber(10.0 / 60.0) + R"(, "count": 2, "velocity": {"x": 3, "y": 0})");
    }
    const CommandResult run = runCommand(std::string(STEPWISE_BINARY) + " run " + level.string() +
                                         " --steps 35 --contacts " + log.string() + " 2>&1");
    ASSERT_EQ(run.exitCode, 0) << run.out;
    EXPECT_NE(run.out.find("; 2 emitted copies alive;"), std::string::npos) << run.out;
    std::vector<std::string> events;
    std::istringstream lines(readFile(log));
    for (std::string line; std::getline(lines, line);)
        if (line.rfind("{\"event\"", 0) == 0) events.push_back(line.substr(0, line.find(", \"time\"")) + line.substr(line.find(", \"emitter\"")));
    EXPECT_EQ(events, (std::vector<std::string>{
                          R"({"event": "emit", "step": 1, "emitter": "spout", "copy": "drop#1"})",
                          R"({"event": "emit", "step": 11, "emitter": "spout", "copy": "drop#2"})",
                          R"({"event": "remove", "step": 21, "emitter": "spout", "copy": "drop#1"})",
                          R"({"event": "emit", "step": 21, "emitter": "spout", "copy": "drop#3"})",
                          R"({"event": "remove", "step": 31, "emitter": "spout", "copy": "drop#2"})",
                          R"({"event": "emit", "step": 31, "emitter": "spout", "copy": "drop#4"})"}));
    std::filesystem::remove_all(dir);
}

TEST(Emitters, ACopyRemovedWhileItsIslandSleepsWakesItAndResumeStaysExact) {
    // A doll every 5 s, one alive: each lands, settles and sleeps before
    // the next arrives and pushes it, asleep, out. Saving around those
    // steps resumes bit for bit.
    std::string text = ragdollLevel(4, 1);
    const std::string every = R"("interval": 0.5)";
    text.replace(text.find(every), every.size(), R"("interval": 5)");
    const Scene scene = parseLevel(text);
    World straight = buildWorld(scene);
    std::size_t asleepAtRemoval = 0;
    for (int s = 1; s <= 800; ++s) {
        const std::size_t asleep = straight.sleepingBodyCount();
        if (s == 301 || s == 601) EXPECT_EQ(asleep, 3u) << "step " << s;
        ASSERT_TRUE(straight.step());
        for (const EmitterEvent& e : straight.emitterEvents())
            if (!e.added) asleepAtRemoval = std::max(asleepAtRemoval, asleep);
    }
    EXPECT_GE(asleepAtRemoval, 3u);  // a whole doll asleep when one was removed
    const std::string expected = savedRunText(straight, scene);
    for (const int split : {250, 300, 301, 302, 600, 601}) {
        SCOPED_TRACE("split " + std::to_string(split));
        ASSERT_EQ(savedAfterResumeAt(scene, split, 800), expected);
    }
}

TEST(Emitters, ValidateNotesWhatATemplateIgnores) {
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "stepwise_emitters_validate";
    std::filesystem::create_directories(dir);
    const std::filesystem::path level = dir / "t.json";
    {
        std::ofstream out(level);
        out << R"({"entities": [
          {"name": "a", "template": "lonely", "position": {"x": 0, "y": 0}, "radius": 1},
          {"name": "b", "template": "lonely", "position": {"x": 3, "y": 0}, "radius": 1},
          {"name": "c", "template": "used", "position": {"x": 0, "y": 5}, "velocity": {"x": 1, "y": 0}, "radius": 1},
          {"name": "e", "position": {"x": 0, "y": 9}, "emitter": {"template": "used"}}]})";
    }
    const CommandResult r = runCommand(std::string(STEPWISE_BINARY) + " validate " + level.string() + " 2>&1");
    EXPECT_EQ(r.exitCode, 0) << r.out;
    EXPECT_NE(r.out.find("warning: entity 0 (\"a\"): template \"lonely\" has no emitter, so it is never copied (and "
                         "never simulated)"),
              std::string::npos)
        << r.out;
    EXPECT_EQ(r.out.find("entity 1 (\"b\"): template"), std::string::npos) << r.out;  // said once per template
    EXPECT_NE(r.out.find("warning: entity 2 (\"c\"): \"velocity\" on a template body has no effect (each copy takes "
                         "its emitter's velocity)"),
              std::string::npos)
        << r.out;
    std::filesystem::remove_all(dir);
}

TEST(Emitters, ABuildRefusesATemplateBodyWithoutAShapeMadeInCode) {
    // The loader refuses it; a scene made in code reaches World::build.
    Scene scene = parseLevel(ballLevel(R"("interval": 1, "count": 2)"));
    Registry& reg = scene.registry;
    const Entity proto = reg.entities()[0];
    reg.remove<Radius>(proto);
    Result<World> w = World::build(scene);
    ASSERT_FALSE(w);
    EXPECT_EQ(w.error(), "entity 0 (\"proto\"): template \"drop\": a template entity is a dynamic body with a shape "
                         "(radius, box, polygon, capsule or shapes)");
}

TEST(Emitters, AnEmitterWithAShapeIsABodyAndCopiesAppearWhereItIsNow) {
    // A kinematic box moving at 2 m/s drops a resting ball every half
    // second, no gravity, the two never colliding (one negative group):
    // copy k appears where the box is at the start of step 30 (k - 1) + 1,
    // x = k - 1, and stays there.
    const Scene scene = parseLevel(R"({"world": {"gravity": {"x": 0, "y": 0}},
      "entities": [
        {"name": "proto", "template": "drop", "position": {"x": 40, "y": 40}, "radius": 0.1,
         "filter": {"category": 1, "mask": 4294967295, "group": -5}},
        {"name": "cart", "position": {"x": 0, "y": 0}, "kinematic": true, "velocity": {"x": 2, "y": 0},
         "box": {"width": 1, "height": 0.5}, "filter": {"category": 1, "mask": 4294967295, "group": -5},
         "emitter": {"template": "drop", "interval": 0.5, "count": 10}}]})");
    World world = buildWorld(scene);
    EXPECT_EQ(world.bodyCount(), 1u);  // the cart
    EXPECT_EQ(world.kinematicCount(), 1u);
    for (int s = 0; s < 150; ++s) ASSERT_TRUE(world.step());
    ASSERT_EQ(world.bodyCount(), 6u);
    for (std::size_t k = 1; k <= 5; ++k) {
        EXPECT_NEAR(world.bodyPosition(k).x, double(k - 1), 1e-9) << "copy " << k;
        EXPECT_EQ(world.bodyPosition(k).y, 0.0);
    }
}

// Copies of a compound template (a dumbbell of two discs on a capsule bar,
// hinged to a rounded block) poured onto a chain floor beside a standing
// compound L: every emission rebuilds the collision arrays in place with
// hubs, shapes and chain segments among them, and those arrays must be the
// ones a build of the saved file makes. So a run saved at any step and
// continued equals the straight run bit for bit, no emission builds a
// World, and every copy lands on the chain.
TEST(Emitters, CompoundCopiesOnAChainResumeExactlyWithoutBuilds) {
    const auto level = [](int substeps) {
        std::ostringstream s;
        s << R"({"world": {"gravity": {"x": 0, "y": -9.81})";
        if (substeps > 0) s << R"(, "substeps": )" << substeps;
        s << R"(},
          "entities": [
            {"name": "floor", "position": {"x": 0, "y": 0}, "static": true, "friction": 0.6,
             "chain": {"points": [{"x": 8, "y": 3}, {"x": 4, "y": 0.5}, {"x": 0, "y": 0}, {"x": -4, "y": 0.4},
                                  {"x": -8, "y": 3}]}},
            {"name": "L", "position": {"x": 3, "y": 0.9},
             "shapes": [{"box": {"center": {"x": 0, "y": 0}, "width": 1.5, "height": 0.3, "angle": 0}},
                        {"box": {"center": {"x": -0.6, "y": 0.6}, "width": 0.3, "height": 0.9, "angle": 0}}]},
            {"name": "bell", "template": "drop", "position": {"x": 30, "y": 30},
             "shapes": [{"circle": {"center": {"x": -0.4, "y": 0}, "radius": 0.2}},
                        {"circle": {"center": {"x": 0.4, "y": 0}, "radius": 0.2}, "density": 3},
                        {"capsule": {"a": {"x": -0.4, "y": 0}, "b": {"x": 0.4, "y": 0}, "radius": 0.05}}]},
            {"name": "block", "template": "drop", "position": {"x": 30, "y": 29.3}, "mass": 0.5,
             "polygon": {"vertices": [{"x": -0.2, "y": -0.15}, {"x": 0.2, "y": -0.15}, {"x": 0.2, "y": 0.15},
                                      {"x": -0.2, "y": 0.15}], "radius": 0.05}},
            {"name": "link", "joint": {"type": "hinge", "a": "bell", "b": "block", "anchor": {"x": 30, "y": 29.6}}},
            {"name": "hatch", "position": {"x": -1, "y": 4},
             "emitter": {"template": "drop", "interval": 0.5, "count": 3, "velocity": {"x": 1, "y": 0}, "spread": 0.5}}
          ]})";
        return s.str();
    };
    for (const int substeps : {1, 4, 0}) {
        SCOPED_TRACE("substeps " + std::to_string(substeps));
        const Scene scene = parseLevel(level(substeps));
        World straight = buildWorld(scene);
        const std::uint64_t builds = worldBuildCount();
        for (int s = 0; s < 300; ++s) ASSERT_TRUE(straight.step());
        EXPECT_EQ(worldBuildCount(), builds) << "an emission built a World";
        const std::string expected = savedRunText(straight, scene);
        // Every copy alive rests on the chain (its lowest point is 0 m
        // there), none fell through it.
        Scene after = parseLevel(expected);
        int copies = 0;
        for (const Entity e : after.registry.entities()) {
            const Name* n = after.registry.tryGet<Name>(e);
            const Position* p = after.registry.tryGet<Position>(e);
            if (!n || !p || n->value.find('#') == std::string::npos) continue;  // not a copied body
            ++copies;
            EXPECT_GT(p->value.y, 0.0) << n->value;
            // A copy carries the template's shapes, not the component's default.
            if (const Shapes* shapes = after.registry.tryGet<Shapes>(e)) {
                ASSERT_EQ(shapes->items.size(), 3u) << n->value;
                EXPECT_EQ(shapes->items[1].density, std::optional<double>(3.0)) << n->value;
            } else {
                ASSERT_TRUE(after.registry.has<Polygon>(e)) << n->value;
                EXPECT_EQ(after.registry.tryGet<Polygon>(e)->radius, std::optional<double>(0.05)) << n->value;
            }
        }
        EXPECT_EQ(copies, 6) << "three copies of two bodies";
        for (const int split : {1, 29, 30, 31, 151, 240}) {
            SCOPED_TRACE("split " + std::to_string(split));
            ASSERT_EQ(savedAfterResumeAt(scene, split, 300), expected);
        }
    }
}

namespace {

/// A cut-down Box2D rain (bench/box2d_scenes.cpp, rain()): `rows` floors
/// 10 m apart, and `columns` columns, each a template holding a group of two
/// two-bone dolls above every floor (hip and torso capsules hinged within
/// limits, the k-th doll of a group in collision group -k), with an emitter
/// on the template's first body: one copy alive, a new one every
/// `columns * delay` steps, the first at step `delay * j` (counted from 0),
/// as Box2D's StepRain makes and remakes its columns.
std::string rainLevel(int rows, int columns, int delay) {
    const double dt = 1.0 / 60.0;
    std::ostringstream s;
    s << R"({"world": {"gravity": {"x": 0, "y": -10}, "dt": )" << exactNumber(dt)
      << R"(, "substeps": 4, "solver_iterations": 1, "sleep": false}, "entities": [)";
    for (int row = 0; row < rows; ++row)
        s << R"({"name": "floor )" << row << R"(", "position": )" << vectorJson(0.0, 10.0 * row)
          << R"(, "static": true, "box": {"width": 40, "height": 0.5}},)";
    for (int j = 0; j < columns; ++j) {
        const std::string column = "column " + std::to_string(j);
        Vec2 first;
        for (int row = 0; row < rows; ++row)
            for (int k = 0; k < 2; ++k) {
                const std::string doll =
                    "doll " + std::to_string(j) + "." + std::to_string(row) + "." + std::to_string(k) + " ";
                const Vec2 at{-15.0 + 10.0 * j + 0.5 * k, 10.0 * row + 3.0};
                if (row == 0 && k == 0) first = at;
                const std::string filter =
                    R"(, "filter": {"category": 2, "mask": 3, "group": )" + std::to_string(-(k + 1)) + "}";
                s << R"({"name": ")" << doll << R"(hip", "template": ")" << column << R"(", "position": )"
                  << vectorJson(at.x, at.y)
                  << R"(, "capsule": {"a": {"x": 0, "y": -0.2}, "b": {"x": 0, "y": 0.2}, "radius": 0.1}, "mass": 1)"
                  << filter << "},";
                s << R"({"name": ")" << doll << R"(torso", "template": ")" << column << R"(", "position": )"
                  << vectorJson(at.x, at.y + 0.6)
                  << R"(, "capsule": {"a": {"x": 0, "y": -0.2}, "b": {"x": 0, "y": 0.2}, "radius": 0.1}, "mass": 1)"
                  << filter << "},";
                s << R"({"name": ")" << doll << R"(waist", "joint": {"type": "hinge", "a": ")" << doll
                  << R"(hip", "b": ")" << doll << R"(torso", "anchor": )" << vectorJson(at.x, at.y + 0.3)
                  << R"(, "lower": -0.5, "upper": 0.5}},)";
            }
        s << R"({"name": ")" << column << R"( emitter", "position": )" << vectorJson(first.x, first.y)
          << R"(, "emitter": {"template": ")" << column << R"(", "interval": )" << exactNumber(columns * delay * dt)
          << R"(, "count": 1, "next": )" << exactNumber(j * delay * dt) << "}}"
          << (j + 1 < columns ? "," : "");
    }
    s << "]}";
    return s.str();
}

/// What Box2D's StepRain does before step `step` (from 0) with `columns`
/// columns remade every `delay` steps: column (step / delay) % columns is
/// made for the (step / (columns * delay) + 1)-th time, its previous copy
/// destroyed first; nothing between.
std::vector<EmitterEvent> rainEventsAt(const Scene& scene, int step, int columns, int delay) {
    if (step % delay != 0) return {};
    const int j = (step / delay) % columns, made = step / (columns * delay);
    const std::string column = "column " + std::to_string(j);
    const Entity emitter = named(scene, column + " emitter");
    std::vector<EmitterEvent> out;
    if (made > 0) out.push_back({emitter, column + "#" + std::to_string(made), false});
    out.push_back({emitter, column + "#" + std::to_string(made + 1), true});
    return out;
}

} // namespace

TEST(Emitters, RainColumnsAppearAndAreRemadeAtBox2dsSteps) {
    // 3 columns remade every 4 steps over 3 rounds: column j is made before
    // steps 4j + 12k and nowhere else, each copy's bodies on its template's
    // places (a step's fall from rest is under 3 mm), one copy per column.
    const int rows = 2, columns = 3, delay = 4, bodiesPerColumn = rows * 2 * 2;
    const Scene scene = parseLevel(rainLevel(rows, columns, delay));
    World world = buildWorld(scene);
    ASSERT_EQ(world.emitterCount(), std::size_t(columns));
    EXPECT_EQ(world.bodyCount(), 0u);
    std::unordered_map<std::string, Vec2> templatePlace;  // "column J/NAME" -> where the template has it
    for (const Entity e : scene.registry.entities())
        if (const Template* t = scene.registry.tryGet<Template>(e))
            templatePlace[t->value + "/" + scene.registry.tryGet<Name>(e)->value] = scene.registry.tryGet<Position>(e)->value;
    for (int step = 0; step < 3 * columns * delay; ++step) {
        SCOPED_TRACE("step " + std::to_string(step));
        ASSERT_TRUE(world.step());
        const std::span<const EmitterEvent> events = world.emitterEvents();
        ASSERT_EQ(std::vector<EmitterEvent>(events.begin(), events.end()), rainEventsAt(scene, step, columns, delay));
        ASSERT_EQ(world.bodyCount(), std::size_t(std::min(step / delay + 1, columns) * bodiesPerColumn));
        if (events.empty()) continue;
        // The copy just made: its bodies where the template's are.
        const std::string made = events.back().copy;
        int found = 0;
        for (std::size_t b = 0; b < world.bodyCount(); ++b) {
            const std::string* name = world.copyName(world.bodyEntity(b));
            ASSERT_NE(name, nullptr);
            if (!name->starts_with(made + "/") && *name != made) continue;
            ++found;
            const std::string column = made.substr(0, made.find('#'));
            // The copy's first body is named after the copy alone: it is
            // the template's first, "doll J.0.0 hip".
            const std::string member =
                *name == made ? "doll " + column.substr(7) + ".0.0 hip" : name->substr(made.size() + 1);
            const Vec2 place = templatePlace.at(column + "/" + member);
            const Vec2 at = world.bodyPosition(b);
            EXPECT_EQ(at.x, place.x) << *name;
            EXPECT_LT(std::abs(at.y - place.y), 3e-3) << *name;
        }
        EXPECT_EQ(found, bodiesPerColumn);
    }
}

TEST(Emitters, RainScheduleHoldsOverManyRoundsAtSixtyHertz) {
    // Box2D's own numbers: 40 columns, one made every 8 steps of 1/60 s, so
    // each is remade every 320 steps; the times are sums of 1/60 and of
    // 320/60, which need not land exactly on one another. Over 40 rounds
    // (12,800 steps), every column is made exactly at steps 8j + 320k.
    const int rows = 1, columns = 40, delay = 8;
    const Scene scene = parseLevel(rainLevel(rows, columns, delay));
    World world = buildWorld(scene);
    for (int step = 0; step < 40 * columns * delay; ++step) {
        ASSERT_TRUE(world.step());
        const std::span<const EmitterEvent> events = world.emitterEvents();
        ASSERT_EQ(std::vector<EmitterEvent>(events.begin(), events.end()), rainEventsAt(scene, step, columns, delay))
            << "step " << step;
    }
}

TEST(Emitters, RainSavedAndResumedRunsOnAsOneRun) {
    // Saves before, on and after makings and remakings (steps 0, 4, 8 make,
    // 12 remakes column 0), loaded and continued to step 40: the same text
    // as 40 steps straight.
    const Scene scene = parseLevel(rainLevel(2, 3, 4));
    World straight = buildWorld(scene);
    for (int s = 0; s < 40; ++s) ASSERT_TRUE(straight.step());
    const std::string expected = savedRunText(straight, scene);
    for (const int split : {1, 3, 4, 5, 12, 13, 16, 27}) {
        SCOPED_TRACE("split " + std::to_string(split));
        ASSERT_EQ(savedAfterResumeAt(scene, split, 40), expected);
    }
}

// What the engine chooses from the scene's structure (substeps, iterations,
// the contacts' stiffness) counts a template as the bodies its copies will
// be: a level whose tower only appears through an emitter gets what the same
// tower standing in the level gets, not what an empty floor gets. Swept over
// the tower's height.
TEST(Emitters, TheEngineChoosesItsSettingsForWhatTheTemplatesWillMake) {
    for (const int height : {3, 8, 14, 20}) {
        const auto level = [&](bool asTemplate, bool withTower) {
            std::ostringstream s;
            s << R"({"world": {"gravity": {"x": 0, "y": -10}}, "entities": [)"
              << R"({"name": "floor", "position": {"x": 0, "y": -0.5}, "box": {"width": 60, "height": 1}, "static": true})";
            if (asTemplate && withTower)
                s << R"(, {"name": "spawn", "position": {"x": -20, "y": 30}, "emitter": {"template": "tower", "interval": 1, "count": 1}})";
            for (int k = 0; withTower && k < height; ++k)
                s << R"(, {"name": "block )" << k << R"(", "position": {"x": 10, "y": )" << 0.5 + k
                  << R"(}, "box": {"width": 1, "height": 1}, "mass": 1)" << (asTemplate ? R"(, "template": "tower"})" : "}");
            s << "]}";
            return parseLevel(s.str());
        };
        const ContactSettingsChoice templated = buildWorld(level(true, true)).settingsChoice();
        const ContactSettingsChoice standing = buildWorld(level(false, true)).settingsChoice();
        const ContactSettingsChoice empty = buildWorld(level(false, false)).settingsChoice();
        EXPECT_EQ(templated.substeps, standing.substeps) << height << " blocks";
        EXPECT_EQ(templated.iterations, standing.iterations) << height << " blocks";
        EXPECT_EQ(templated.hertzFraction, standing.hertzFraction) << height << " blocks";
        EXPECT_EQ(templated.stackHeight, height) << height << " blocks";
        EXPECT_EQ(empty.stackHeight, 0) << "a floor alone";
        if (height >= 8) EXPECT_GT(templated.substeps, empty.substeps) << height << " blocks";
    }
}

namespace {

/// `level` with a second emitter of its template `name` added last: `fields`
/// are its emitter's fields after "template".
std::string withSecondEmitter(std::string level, const std::string& name, const std::string& templateName,
                              const std::string& fields) {
    const std::string entity = R"(, {"name": ")" + name + R"(", "position": {"x": -2, "y": 6}, "emitter": {"template": ")" +
                               templateName + R"(", )" + fields + "}}";
    level.insert(level.rfind(']'), entity);
    return level;
}

} // namespace

// Two emitters of one template, at different intervals and counts (one with
// a lifetime): every copy has its own name, numbered in the order the
// copies appear (the emitters in scene order within a step), and each
// emitter removes only its own oldest copies.
TEST(Emitters, TwoEmittersOfOneTemplateNumberItsCopiesInTheOrderTheyAppear) {
    const double dt = 1.0 / 60.0;
    for (const auto& [every, count, lifetime] : {std::tuple{3, 2, std::string()}, std::tuple{5, 4, std::string()},
                                                 std::tuple{2, 3, std::string(R"(, "lifetime": 0.1)")}}) {
        SCOPED_TRACE("second emitter every " + std::to_string(every) + " steps, count " + std::to_string(count) +
                     lifetime);
        const Scene scene = parseLevel(withSecondEmitter(
            ballLevel(R"("interval": )" + exactNumber(3 * dt) + R"(, "count": 2, "velocity": {"x": 3, "y": 0})"),
            "spout2", "drop",
            R"("interval": )" + exactNumber(every * dt) + R"(, "count": )" + std::to_string(count) + lifetime));
        World world = buildWorld(scene);
        const Entity spout = named(scene, "spout"), spout2 = named(scene, "spout2");
        std::unordered_map<Entity, std::deque<std::string>> own;  // each emitter's copies alive, from its events
        int appeared = 0;
        for (int step = 1; step <= 90; ++step) {
            ASSERT_TRUE(world.step());
            for (const EmitterEvent& event : world.emitterEvents()) {
                std::deque<std::string>& mine = own[event.emitter];
                if (event.added) {
                    ASSERT_EQ(event.copy, "drop#" + std::to_string(++appeared)) << "step " << step;
                    mine.push_back(event.copy);
                } else {
                    ASSERT_FALSE(mine.empty()) << "step " << step;
                    ASSERT_EQ(event.copy, mine.front()) << "an emitter removes its own oldest copy, step " << step;
                    mine.pop_front();
                }
            }
            ASSERT_LE(own[spout].size(), 2u);
            ASSERT_LE(own[spout2].size(), std::size_t(count));
            std::vector<std::string> expected(own[spout].begin(), own[spout].end());
            expected.insert(expected.end(), own[spout2].begin(), own[spout2].end());
            std::sort(expected.begin(), expected.end());
            std::vector<std::string> alive = copiesAlive(world, scene);
            std::sort(alive.begin(), alive.end());
            ASSERT_EQ(alive, expected) << "step " << step;
            ASSERT_EQ(world.bodyCount(), alive.size()) << "step " << step;
        }
        EXPECT_EQ(appeared, 30 + 90 / every);
    }
}

// Save, load and continue equals running on with two emitters of one
// ragdoll template, whose copies alive are then not each emitter's newest
// numbers (the save lists them), over split points on and around both
// emitters' copies, at 1 and 4 substeps and the engine's choice.
TEST(Emitters, TwoEmittersOfOneTemplateResumeExactly) {
    for (const int substeps : {1, 4, 0}) {
        SCOPED_TRACE("substeps " + std::to_string(substeps));
        const Scene scene = parseLevel(withSecondEmitter(ragdollLevel(substeps, 3, R"(, "lifetime": 1.2)"), "chute",
                                                         "doll", R"("interval": 0.3, "count": 2, "spread": 0.4)"));
        World straight = buildWorld(scene);
        for (int s = 0; s < 240; ++s) ASSERT_TRUE(straight.step());
        const std::string expected = savedRunText(straight, scene);
        EXPECT_NE(expected.find("\"copies\""), std::string::npos) << "the interleaved numbers are listed";
        for (const int split : {1, 17, 18, 19, 30, 31, 72, 163}) {
            SCOPED_TRACE("split " + std::to_string(split));
            ASSERT_EQ(savedAfterResumeAt(scene, split, 240), expected);
        }
    }
}

// One of two emitters deleted while copies are alive, as the editor
// deletes it (its copies stay, renamed without the '#'): the other emitter
// numbers its copies past every copy alive, so no name is given twice, and
// a save of that scene resumes exactly. A body named like a copy that no
// emitter has alive is refused, naming the template's emitters.
TEST(Emitters, CopiesOfADeletedEmitterStayAndLaterCopiesNumberPastTheOthers) {
    const double dt = 1.0 / 60.0;
    const Scene scene = parseLevel(withSecondEmitter(
        ballLevel(R"("interval": )" + exactNumber(4 * dt) + R"(, "count": 1)"), "spout2", "drop",
        R"("interval": )" + exactNumber(2 * dt) + R"(, "count": 3)"));
    World world = buildWorld(scene);
    for (int s = 0; s < 20; ++s) ASSERT_TRUE(world.step());
    // Copies 1 to 15 came in turn (spout every 4 steps, spout2 every 2);
    // spout2's three newest stay, and spout's newest.
    EXPECT_EQ(copiesAlive(world, scene), (std::vector<std::string>{"drop#12", "drop#13", "drop#14", "drop#15"}));
    Scene edited = parseLevel(savedRunText(world, scene));
    Scene handNamed = edited;
    edited.registry.destroy(named(edited, "spout"));
    edited.registry.tryGet<Name>(named(edited, "drop#13"))->value = "drop 13";  // as the editor renames it
    const Scene reloaded = parseLevel(sceneToJsonText(edited));
    EXPECT_FALSE(named(reloaded, "drop 13").isNull()) << "the deleted emitter's copy stays, renamed";
    World after = buildWorld(reloaded);
    std::vector<std::string> added;
    for (int s = 0; s < 8; ++s) {
        ASSERT_TRUE(after.step());
        for (const EmitterEvent& event : after.emitterEvents())
            if (event.added) added.push_back(event.copy);
    }
    // spout2 alone has made 10: numbered past its newest alive, 15.
    EXPECT_EQ(added, (std::vector<std::string>{"drop#16", "drop#17", "drop#18", "drop#19"}));
    World straight = buildWorld(reloaded);
    for (int s = 0; s < 40; ++s) ASSERT_TRUE(straight.step());
    const std::string expected = savedRunText(straight, reloaded);
    for (const int split : {1, 2, 3, 13})
        EXPECT_EQ(savedAfterResumeAt(reloaded, split, 40), expected) << "split " << split;

    const Entity hand = handNamed.registry.create();
    handNamed.registry.emplace<Name>(hand, Name{"drop#40"});
    handNamed.registry.emplace<Position>(hand, Position{{3.0, 3.0}});
    handNamed.registry.emplace<Radius>(hand, Radius{0.1});
    const std::string text = sceneToJsonText(handNamed);
    EXPECT_EQ(refusal(text).substr(refusal(text).find("error:")),
              "error: /entities/" + std::to_string(handNamed.registry.entities().size() - 1) +
                  "/name: \"drop#40\" is a name the emitters of template \"drop\" give their copies, and no emitter "
                  "has that copy alive in its run state");
}
