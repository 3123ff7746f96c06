// Sleeping (world.sleep; engine/src/world/islands.hpp): still
// islands fall asleep and then cost nothing and move not a bit; a touch, an
// edit, a setter or the mouse spring wakes the island concerned and only
// it; a sleeping run looks like an awake one; resume and step back stay
// exact with islands asleep.

#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world.hpp"
#include "world/world_internals.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

using namespace stepwise;
namespace fs = std::filesystem;

namespace {

Entity named(Scene& s, const std::string& name, Vec2 p) {
    const Entity e = s.registry.create();
    s.registry.emplace<Name>(e, Name{name});
    s.registry.emplace<Position>(e, Position{p});
    return e;
}

/// `stacks` columns of `height` unit boxes resting exactly on a floor, 10 m
/// apart: one island per column (the floor joins none).
Scene boxStacks(int stacks, int height, bool sleep = true) {
    Scene s;
    s.world.sleep = sleep;
    s.world.substeps = 4;
    s.world.solverIterations = 2;
    const Entity floor = named(s, "floor", {0.0, -0.5});
    s.registry.emplace<Static>(floor, Static{true});
    s.registry.emplace<Box>(floor, Box{60.0, 1.0});
    for (int c = 0; c < stacks; ++c)
        for (int k = 0; k < height; ++k) {
            const Entity e = named(s, "s" + std::to_string(c) + "_" + std::to_string(k), {10.0 * c, 0.5 + k});
            s.registry.emplace<Box>(e, Box{1.0, 1.0});
            s.registry.emplace<Friction>(e, Friction{0.6});
        }
    return s;
}

World build(const Scene& s) {
    Result<World> w = World::build(s);
    if (!w) throw std::runtime_error(w.error());
    w->setProfiling(false);
    return std::move(*w);
}

Entity entityNamed(const Scene& s, const std::string& name) {
    for (const Entity e : s.registry.entities())
        if (const Name* n = s.registry.tryGet<Name>(e); n && n->value == name) return e;
    return {};
}

/// Whether every body whose name starts with `prefix` sleeps.
bool allAsleep(const World& w, const Scene& s, const std::string& prefix) {
    int seen = 0;
    for (std::size_t b = 0; b < w.bodyCount(); ++b) {
        const Name* n = s.registry.tryGet<Name>(w.bodyEntity(b));
        if (!n || n->value.rfind(prefix, 0) != 0) continue;
        ++seen;
        if (!w.asleep(b)) return false;
    }
    return seen > 0;
}
bool noneAsleep(const World& w, const Scene& s, const std::string& prefix) {
    for (std::size_t b = 0; b < w.bodyCount(); ++b) {
        const Name* n = s.registry.tryGet<Name>(w.bodyEntity(b));
        if (n && n->value.rfind(prefix, 0) == 0 && w.asleep(b)) return false;
    }
    return true;
}

/// Steps until every body sleeps; the step count, or -1 after `limit`.
int stepsUntilAllAsleep(World& w, int limit) {
    for (int k = 1; k <= limit; ++k) {
        EXPECT_TRUE(w.step().ok());
        if (w.sleepingBodyCount() == w.bodyCount()) return k;
    }
    return -1;
}

std::vector<double> positionsOf(const World& w) {
    std::vector<double> out;
    for (std::size_t b = 0; b < w.bodyCount(); ++b) {
        out.push_back(w.bodyPosition(b).x);
        out.push_back(w.bodyPosition(b).y);
    }
    return out;
}

/// A circle of radius 0.3 m named "ball" at `p`.
Entity addBall(Scene& s, Vec2 p) {
    const Entity e = named(s, "ball", p);
    s.registry.emplace<Radius>(e, Radius{0.3});
    s.registry.emplace<Friction>(e, Friction{0.6});
    return e;
}

std::string saved(const World& w, Scene scene) {
    w.writeBack(scene);
    scene.solverState = w.solverState();
    return sceneToJsonText(scene);
}

/// The first line where two texts differ, both versions ("" when equal).
std::string firstDifference(const std::string& a, const std::string& b) {
    std::size_t line = 0, i = 0;
    while (i < a.size() && i < b.size() && a[i] == b[i]) {
        if (a[i] == '\n') line = i + 1;
        ++i;
    }
    if (i == a.size() && i == b.size()) return "";
    return "\n  " + a.substr(line, a.find('\n', line) - line) + "\n  " + b.substr(line, b.find('\n', line) - line);
}

} // namespace

// A stack placed at rest is still from its first step: it sleeps once every
// box has been still for sleep_time = 0.5 s, i.e. at step 30 of 1/60 s
// (timers add dt from the first still step), plus the steps the soft
// contacts need to take up the load (the stack sinks by its overlap, micro-
// metres here, at under 0.05 m/s): bound 0.5 s + 0.25 s = 45 steps
// (measured 32). A heap of 60 circles in columns collapses and rolls for a
// while: rolling costs no energy (there is no rolling resistance), so the
// last circles come to rest against the walls and each other only; measured
// asleep after 252 steps; bound 360 (6 s).
TEST(Sleep, ASettledPileSleepsWithinItsBoundAndThenStaysBitIdentical) {
    Scene stacks = boxStacks(2, 4);
    World w = build(stacks);
    const int steps = stepsUntilAllAsleep(w, 45);
    EXPECT_GE(steps, 30) << "slept before sleep_time had passed";
    EXPECT_GT(steps, 0) << "the stacks did not sleep within 45 steps (0.75 s)";
    const WorldState frozen = w.saveState();
    for (int k = 0; k < 120; ++k) ASSERT_TRUE(w.step().ok());
    const WorldState later = w.saveState();
    ASSERT_EQ(frozen.x.size(), later.x.size());
    EXPECT_EQ(std::memcmp(frozen.x.data(), later.x.data(), frozen.x.size() * sizeof(double)), 0)
        << "a sleeping body moved";
    // Its (tiny) velocity and spin are frozen with it, for the wake.
    EXPECT_TRUE(frozen.v == later.v && frozen.colliderAngle == later.colliderAngle &&
                frozen.colliderSpin == later.colliderSpin);
    double fastest = 0.0;
    for (std::size_t b = 0; b < w.bodyCount(); ++b) fastest = std::max(fastest, length(w.bodyVelocity(b)));
    EXPECT_LE(fastest, 0.05);
    // The sleeping stacks' contacts are still listed (the contacts view).
    EXPECT_GE(w.contacts().size(), 8u);

    // A heap of 60 circles falling a few centimetres into a box.
    Scene heap;
    heap.world.substeps = 4;
    heap.world.solverIterations = 2;
    const Entity floor = named(heap, "floor", {0.0, -0.5});
    heap.registry.emplace<Static>(floor, Static{true});
    heap.registry.emplace<Box>(floor, Box{20.0, 1.0});
    for (int side : {-1, 1}) {
        const Entity wall = named(heap, side < 0 ? "left" : "right", {2.85 * side, 2.0});
        heap.registry.emplace<Static>(wall, Static{true});
        heap.registry.emplace<Box>(wall, Box{0.5, 4.0});
    }
    for (int i = 0; i < 60; ++i) {
        const Entity e = named(heap, "c" + std::to_string(i), {-2.2 + 0.5 * (i % 10) + 0.01 * (i / 10 % 2), 0.26 + 0.52 * (i / 10)});
        heap.registry.emplace<Radius>(e, Radius{0.25});
        heap.registry.emplace<Friction>(e, Friction{0.6});
    }
    World h = build(heap);
    const int heapSteps = stepsUntilAllAsleep(h, 360);
    EXPECT_GT(heapSteps, 30);
    EXPECT_GT(heapSteps, 0) << "the heap did not sleep within 6 s";
    std::printf("box stacks asleep after %d steps, circle heap after %d steps\n", steps, heapSteps);
    const std::vector<double> heapFrozen = positionsOf(h);
    for (int k = 0; k < 60; ++k) ASSERT_TRUE(h.step().ok());
    EXPECT_TRUE(heapFrozen == positionsOf(h));
    // Asleep, the heap costs the collision stages nothing: no manifold is computed.
    EXPECT_EQ(internals(h).collision->manifoldCount(), 0u);
    EXPECT_EQ(internals(h).collision->candidatePairCount(), 0u);
}

// Two stacks asleep; a ball dropped on stack 0 wakes stack 0 and leaves
// stack 1 asleep. The result is then compared with the same drop and sleep
// off: the stacks were exactly at rest when they fell asleep (residual
// speeds under 1e-3 m/s, measured), so the only difference is that
// residual motion: within 1 mm.
TEST(Sleep, ABodyDroppedOnOneOfTwoSleepingPilesWakesThatPileOnly) {
    const auto run = [](bool sleep, std::vector<double>* positions, bool* otherSlept, bool* hitWoke) {
        Scene scene = boxStacks(2, 4, sleep);
        World w = build(scene);
        for (int k = 0; k < 60; ++k) ASSERT_TRUE(w.step().ok());
        if (sleep) {
            ASSERT_EQ(w.sleepingBodyCount(), 8u);
        }
        w.writeBack(scene);
        addBall(scene, {0.0, 5.5});
        ASSERT_TRUE(w.reload(scene).ok());
        if (sleep) {
            ASSERT_EQ(w.sleepingBodyCount(), 8u) << "adding a body far from the piles woke them";
        }
        bool stayed = true, woke = false;
        for (int k = 0; k < 90; ++k) {
            ASSERT_TRUE(w.step().ok());
            stayed = stayed && allAsleep(w, scene, "s1_");
            woke = woke || noneAsleep(w, scene, "s0_");
        }
        if (otherSlept) *otherSlept = stayed;
        if (hitWoke) *hitWoke = woke;
        *positions = positionsOf(w);
    };
    std::vector<double> on, off;
    bool otherSlept = false, hitWoke = false;
    run(true, &on, &otherSlept, &hitWoke);
    run(false, &off, nullptr, nullptr);
    EXPECT_TRUE(hitWoke) << "the ball landed on stack 0 and it stayed asleep";
    EXPECT_TRUE(otherSlept) << "stack 1 woke, but nothing touched it";
    ASSERT_EQ(on.size(), off.size());
    double gap = 0.0;
    for (std::size_t i = 0; i < on.size(); ++i) gap = std::max(gap, std::abs(on[i] - off[i]));
    std::printf("sleep on vs off after the drop: %.3g m apart\n", gap);
    EXPECT_LT(gap, 1e-3);
}

// Every way of changing something wakes the islands it touches, and only them.
TEST(Sleep, EditsSettersAndTheMouseSpringWakeTheIslandsTheyTouch) {
    const auto asleepScene = [](Scene& scene, World& w) {
        for (int k = 0; k < 60; ++k) ASSERT_TRUE(w.step().ok());
        ASSERT_EQ(w.sleepingBodyCount(), w.bodyCount());
        w.writeBack(scene);
    };
    {   // an edit of one body (the inspector moves it): its island only
        Scene scene = boxStacks(2, 3);
        World w = build(scene);
        asleepScene(scene, w);
        scene.registry.tryGet<Position>(entityNamed(scene, "s0_2"))->value.x += 0.01;
        ASSERT_TRUE(w.reload(scene).ok());
        EXPECT_TRUE(noneAsleep(w, scene, "s0_"));
        EXPECT_TRUE(allAsleep(w, scene, "s1_"));
    }
    {   // an unchanged reload wakes nothing
        Scene scene = boxStacks(2, 3);
        World w = build(scene);
        asleepScene(scene, w);
        ASSERT_TRUE(w.reload(scene).ok());
        EXPECT_EQ(w.sleepingBodyCount(), 6u);
    }
    {   // removing a body wakes what touched it
        Scene scene = boxStacks(2, 3);
        World w = build(scene);
        asleepScene(scene, w);
        scene.registry.destroy(entityNamed(scene, "s1_2"));
        ASSERT_TRUE(w.reload(scene).ok());
        EXPECT_TRUE(noneAsleep(w, scene, "s1_"));
        EXPECT_TRUE(allAsleep(w, scene, "s0_"));
    }
    {   // moving the floor wakes everything it may hold up
        Scene scene = boxStacks(2, 3);
        World w = build(scene);
        asleepScene(scene, w);
        scene.registry.tryGet<Position>(entityNamed(scene, "floor"))->value.y -= 0.1;
        ASSERT_TRUE(w.reload(scene).ok());
        EXPECT_EQ(w.sleepingBodyCount(), 0u);
    }
    {   // a world setting wakes everything at the next step (an edit undone
        // before a step wakes nothing); so does another integrator
        Scene scene = boxStacks(2, 3);
        World w = build(scene);
        asleepScene(scene, w);
        scene.world.gravity.y = -5.0;
        ASSERT_TRUE(w.reload(scene).ok());
        EXPECT_EQ(w.sleepingBodyCount(), 6u);
        ASSERT_TRUE(w.step().ok());
        EXPECT_EQ(w.sleepingBodyCount(), 0u);
        asleepScene(scene, w);
        ASSERT_TRUE(w.setIntegrator("velocity_verlet").ok());
        EXPECT_TRUE(w.wakeIfSettingsChanged());
        EXPECT_EQ(w.sleepingBodyCount(), 0u);
        scene.world.integrator = "velocity_verlet";  // the reloads below keep it
        asleepScene(scene, w);
        scene.world.gravity.y = -2.0;
        ASSERT_TRUE(w.reload(scene).ok());
        scene.world.gravity.y = -5.0;
        ASSERT_TRUE(w.reload(scene).ok());
        ASSERT_TRUE(w.step().ok());
        EXPECT_EQ(w.sleepingBodyCount(), 6u) << "gravity changed and changed back before a step";
    }
    {   // the API: wake(entity) wakes that island only
        Scene scene = boxStacks(2, 3);
        World w = build(scene);
        asleepScene(scene, w);
        EXPECT_TRUE(w.wake(entityNamed(scene, "s1_0")));
        EXPECT_TRUE(noneAsleep(w, scene, "s1_"));
        EXPECT_TRUE(allAsleep(w, scene, "s0_"));
        EXPECT_FALSE(w.wake(entityNamed(scene, "s1_0"))) << "already awake";
    }
    {   // a spring between the two stacks' tops makes one island; changing
        // its stiffness wakes both ends (and with them both stacks)
        Scene scene = boxStacks(3, 2);
        const Entity spring = scene.registry.create();
        Spring sp;
        sp.a = entityNamed(scene, "s0_1");
        sp.b = entityNamed(scene, "s1_1");
        sp.k = 1.0;
        sp.damping = 0.5;
        scene.registry.emplace<Name>(spring, Name{"link"});
        scene.registry.emplace(spring, sp);
        World w = build(scene);
        asleepScene(scene, w);
        scene.registry.tryGet<Spring>(spring)->k = 2.0;
        ASSERT_TRUE(w.reload(scene).ok());
        EXPECT_TRUE(noneAsleep(w, scene, "s0_"));
        EXPECT_TRUE(noneAsleep(w, scene, "s1_"));
        EXPECT_TRUE(allAsleep(w, scene, "s2_"));
    }
    {   // a hinge joining two stacks: a changed limit wakes both ends
        Scene scene = boxStacks(3, 2);
        const Entity hinge = scene.registry.create();
        Joint j;
        j.type = "hinge";
        j.a = entityNamed(scene, "s1_1");
        j.b = entityNamed(scene, "s2_1");
        j.localA = {5.0, 0.0};
        j.localB = {-5.0, 0.0};
        scene.registry.emplace<Name>(hinge, Name{"pin"});
        scene.registry.emplace(hinge, j);
        World w = build(scene);
        asleepScene(scene, w);
        scene.registry.tryGet<Joint>(hinge)->upper = 0.5;
        ASSERT_TRUE(w.reload(scene).ok());
        EXPECT_TRUE(allAsleep(w, scene, "s0_"));
        EXPECT_TRUE(noneAsleep(w, scene, "s1_"));
        EXPECT_TRUE(noneAsleep(w, scene, "s2_"));
    }
    {   // the mouse spring: a new drag (a new spring to the cursor) wakes its
        // body's island; moving the cursor (setSpringAnchor) wakes it again
        Scene scene = boxStacks(2, 3);
        World w = build(scene);
        asleepScene(scene, w);
        Scene dragged = scene;
        const Entity mouse = dragged.registry.create();
        Spring sp;
        sp.a = entityNamed(dragged, "s1_2");
        sp.anchor = Vec2{10.0, 2.5};
        sp.k = 144.0;
        sp.damping = 24.0;
        sp.restLength = 0.0;
        dragged.registry.emplace(mouse, sp);
        ASSERT_TRUE(w.reload(dragged).ok());
        EXPECT_TRUE(noneAsleep(w, dragged, "s1_"));
        EXPECT_TRUE(allAsleep(w, dragged, "s0_"));
        for (int k = 0; k < 60; ++k) ASSERT_TRUE(w.step().ok());
        ASSERT_TRUE(allAsleep(w, dragged, "s1_")) << "held still by the cursor, the stack sleeps again";
        ASSERT_TRUE(w.setSpringAnchor(mouse, {10.0, 3.5}).ok());
        EXPECT_TRUE(noneAsleep(w, dragged, "s1_"));
        EXPECT_TRUE(allAsleep(w, dragged, "s0_"));
    }
}

// A ball rolling at 1 cm/s toward a settled stack, 15 mm from it: rolling
// costs no energy and the ball moves faster than the drift limit (5 mm/s),
// so it never sleeps. The stack must sleep all the same (a speculative
// point across the gap joins no island: joined, a rolling trio would keep
// pile.json's 2,000 bodies awake), and wake before the ball touches it:
// within reach of this step: the gap the two can close in dt (relative
// speed at either end of the step, forces included: a sleeping box is
// integrated and put back, so its end speed carries one step of gravity,
// g dt = 0.16 m/s), the ball's spin and the 5 mm slop: at a gap between 0
// and 5 + (0.01 + 0.16) / 60 + 0.17 = 8.06 mm (measured 7.67).
TEST(Sleep, ARollingBallNearASettledStackLetsItSleepAndWakesItBeforeTheTouch) {
    Scene scene = boxStacks(1, 3);
    const double radius = 0.3, speed = 0.01;  // m, m/s
    const Entity ball = addBall(scene, {0.5 + radius + 0.015, radius});
    scene.registry.emplace<Velocity>(ball, Velocity{{-speed, 0.0}});
    scene.registry.emplace<AngularVelocity>(ball, AngularVelocity{speed / radius});  // rolling: no slip at the floor
    World w = build(scene);
    std::size_t ballBody = 0, stackBody = 0;
    for (std::size_t b = 0; b < w.bodyCount(); ++b) {
        if (w.bodyEntity(b) == ball) ballBody = b;
        if (w.bodyEntity(b) == entityNamed(scene, "s0_0")) stackBody = b;
    }
    int asleepAt = -1, wokenAt = -1;
    double gapAtWake = -1.0;
    for (int k = 1; k <= 150 && wokenAt < 0; ++k) {
        ASSERT_TRUE(w.step().ok());
        const double gap = (w.bodyPosition(ballBody).x - radius) - (w.bodyPosition(stackBody).x + 0.5);
        ASSERT_GT(gap, -1e-3) << "step " << k << ": the ball went into the stack";
        EXPECT_FALSE(w.asleep(ballBody)) << "step " << k << ": the rolling ball slept";
        if (asleepAt < 0 && allAsleep(w, scene, "s0_")) asleepAt = k;
        if (asleepAt >= 0 && wokenAt < 0 && noneAsleep(w, scene, "s0_")) {
            wokenAt = k;
            gapAtWake = gap;
        }
    }
    // Still from the start: asleep by 45 steps (the bound of the stack test).
    ASSERT_GT(asleepAt, 0) << "the stack never slept beside the rolling ball";
    EXPECT_LE(asleepAt, 45);
    ASSERT_GT(wokenAt, asleepAt) << "the ball reached the stack without waking it";
    EXPECT_GT(gapAtWake, 0.0);
    EXPECT_LT(gapAtWake, 8.06e-3);
    std::printf("stack asleep at step %d, woken at step %d with the ball %.2f mm away\n", asleepAt, wokenAt,
                1e3 * gapAtWake);
}

// Sleeping changes nothing you can see of the bodies that slept: a
// shipped level run with sleep on and off for 15 s (the pile's heap
// settles in 10 to 14 s, by how its edge comes to rest) ends with every
// body that fell asleep within millimetres. Asleep, a body stops where it
// was when its island had been still for 0.5 s; awake, it creeps on at its
// residual speed (under 0.05 m/s, in practice under 2 mm/s) - the pyramid
// differs by that creep: under 5 mm. pile.json likewise: circles at the
// heap's foot keep rolling along its floor at a few mm/s (rolling costs no
// energy), under the drift limit of 5 mm/s, so they sleep in one run and
// roll on in the other, bounded by one pixel at the level's zoom (22 px/m:
// 4.5 cm). That is the known limit of the drift rule (docs/collisions.md,
// sleeping).
// default.json's crates sleep from 0.5 s until the wrecking ball wakes them
// and end within a pixel at the level's zoom (55 px/m: 1.8 cm). Its balls
// never sleep: they bounce (restitution 0.6) off crates that paused instead
// of creeping a micrometre, then off each other, and roll on for ever; ball
// on ball collisions amplify a micrometre into metres within seconds (the
// balls' difference grows from 5e-4 m at 3 s to 1 m at 10 s, the crates'
// stays under 1e-5 m), as billiards do. Their end positions measure that
// chaos, not sleeping, so only bodies that slept are compared.
TEST(Sleep, ALevelRunWithSleepOnMatchesSleepOffWithinMillimetres) {
    const std::pair<const char*, double> levels[] = {
        {"pyramid.json", 5e-3}, {"pile.json", 1.0 / 22.0}, {"default.json", 1.0 / 55.0}};
    for (const auto& [name, bound] : levels) {
        Result<Scene> loaded = loadSceneFile(fs::path(STEPWISE_SOURCE_DIR) / "levels" / name);
        ASSERT_TRUE(loaded) << loaded.error();
        Scene on = *loaded, off = *loaded;
        on.world.sleep = true;
        off.world.sleep = false;
        World a = build(on), b = build(off);
        std::size_t mostAsleep = 0;
        std::vector<bool> slept(a.bodyCount(), false);
        for (int k = 0; k < 900; ++k) {
            ASSERT_TRUE(a.step().ok());
            ASSERT_TRUE(b.step().ok());
            mostAsleep = std::max(mostAsleep, a.sleepingBodyCount());
            for (std::size_t i = 0; i < a.bodyCount(); ++i) slept[i] = slept[i] || a.asleep(i);
        }
        double gap = 0.0;
        for (std::size_t i = 0; i < a.bodyCount(); ++i)
            if (slept[i]) gap = std::max(gap, length(a.bodyPosition(i) - b.bodyPosition(i)));
        std::printf("%s: %zu of %zu bodies asleep at most; sleep on vs off %.3g m apart after 15 s\n", name,
                    mostAsleep, a.bodyCount(), gap);
        EXPECT_GT(mostAsleep, 0u) << name << ": nothing slept, so nothing was compared";
        EXPECT_LT(gap, bound) << name;
    }
}

// Resume and step back with islands falling asleep and waking inside the
// window: stacks settle (asleep at step ~31), a ball falls on stack 0 and
// wakes it at step ~55, the stack sleeps again later.
TEST(Sleep, ResumeAndStepBackAreExactWithSleepingIslands) {
    Scene scene = boxStacks(2, 4);
    addBall(scene, {0.0, 8.0});
    const int kHalf = 100;
    World straight = build(scene);
    bool sleptInWindow = false, wokeInWindow = false;
    std::size_t before = 0;
    for (int k = 0; k < 2 * kHalf; ++k) {
        ASSERT_TRUE(straight.step().ok());
        const std::size_t now = straight.sleepingBodyCount();
        if (k >= 20 && now > before) sleptInWindow = true;
        if (now < before) wokeInWindow = true;
        before = now;
    }
    EXPECT_TRUE(sleptInWindow);
    EXPECT_TRUE(wokeInWindow);
    const std::string once = saved(straight, scene);

    for (int split : {20, 40, 60, kHalf}) {
        World first = build(scene);
        for (int k = 0; k < split; ++k) ASSERT_TRUE(first.step().ok());
        Result<Scene> middle = parseScene(saved(first, scene), "middle.json");
        ASSERT_TRUE(middle) << middle.error();
        World second = build(*middle);
        EXPECT_EQ(second.sleepingBodyCount(), first.sleepingBodyCount());
        for (int k = split; k < 2 * kHalf; ++k) ASSERT_TRUE(second.step().ok());
        const std::string resumedText = saved(second, *middle);
        EXPECT_TRUE(once == resumedText) << split << " + save + load differs from straight: " << firstDifference(once, resumedText);

        // Step back: restore a snapshot taken at `split`, step again.
        World live = build(scene);
        for (int k = 0; k < split; ++k) ASSERT_TRUE(live.step().ok());
        const WorldState snapshot = live.saveState();
        for (int k = 0; k < 30; ++k) ASSERT_TRUE(live.step().ok());
        ASSERT_TRUE(live.restoreState(snapshot).ok());
        EXPECT_EQ(live.sleepingBodyCount(), first.sleepingBodyCount());
        for (int k = split; k < 2 * kHalf; ++k) ASSERT_TRUE(live.step().ok());
        EXPECT_TRUE(once == saved(live, scene)) << "restore at " << split << " + step differs from straight";
    }
}

// The file: world fields and the solver_state "bodies" section round-trip,
// and bad entries are refused naming where.
TEST(Sleep, TheFileCarriesTheSettingsAndTheSleepState) {
    Scene scene = boxStacks(1, 2);
    scene.world.sleepVelocity = 0.02;
    scene.world.sleepTime = 0.25;
    World w = build(scene);
    for (int k = 0; k < 40; ++k) ASSERT_TRUE(w.step().ok());
    ASSERT_EQ(w.sleepingBodyCount(), 2u);
    const std::string text = saved(w, scene);
    EXPECT_NE(text.find("\"sleep_velocity\": 0.02"), std::string::npos);
    EXPECT_NE(text.find("\"bodies\": ["), std::string::npos);
    EXPECT_NE(text.find("{\"body\": \"s0_1\", \"sleep_time\": "), std::string::npos);
    EXPECT_NE(text.find("\"island\": \"s0_0\"}"), std::string::npos);
    Result<Scene> back = parseScene(text, "s.json");
    ASSERT_TRUE(back) << back.error();
    EXPECT_EQ(sceneToJsonText(*back), text);
    EXPECT_EQ(back->world.sleepTime, 0.25);

    const std::string bad = R"({"entities": [{"name": "g", "position": {"x": 0, "y": 0}, "static": true},
        {"name": "b", "position": {"x": 0, "y": 1}}],
        "solver_state": {"contacts": [], "bodies": [{"body": "b", "island": "g"}]}})";
    Result<Scene> refused = parseScene(bad, "bad.json");
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error(), "bad.json: error: /solver_state/bodies/0/island: entity \"g\" is not a dynamic body "
                               "(it needs a position and no static)");
    Result<Scene> negative = parseScene(R"({"world": {"sleep_time": -1}, "entities": []})", "n.json");
    ASSERT_FALSE(negative);
    EXPECT_NE(negative.error().find("/world/sleep_time"), std::string::npos) << negative.error();

    // Sleep off: a file's sleeping entries are ignored (everything awake).
    Result<Scene> off = parseScene(text, "s.json");
    off->world.sleep = false;
    World awake = build(*off);
    EXPECT_EQ(awake.sleepingBodyCount(), 0u);
}

// A run keeps bodies joined by a joint, a spring or a touching contact in
// one island, so a file that splits such a group (one end asleep, the other
// awake or in another island) is not what a run writes: both islands wake
// when the World is built. Without the joint the same file keeps its crate
// asleep, so it is the joint that wakes it.
TEST(Sleep, AFileThatSplitsAJoinedGroupWakesBothIslands) {
    const auto level = [](const std::string& joint, const std::string& bobEntry) {
        return R"({"entities": [
            {"name": "floor", "position": {"x": 0, "y": -0.5}, "static": true, "box": {"width": 10, "height": 1}},
            {"name": "crate", "position": {"x": 0, "y": 0.5}, "box": {"width": 1, "height": 1}},
            {"name": "bob", "position": {"x": 3, "y": 0.5}, "radius": 0.2})" +
               joint + R"(],
            "solver_state": {"bodies": [
              {"body": "crate", "sleep_time": 1, "still_at": {"x": 0, "y": 0.5}, "still_angle": 0, "island": "crate"})" +
               bobEntry + "]}}";
    };
    const std::string hinge = R"(, {"name": "arm", "joint": {"type": "distance", "a": "crate", "b": "bob"}})";
    const std::string bobAsleepAlone =
        R"(, {"body": "bob", "sleep_time": 1, "still_at": {"x": 3, "y": 0.5}, "still_angle": 0, "island": "bob"})";
    const auto sleepingAfterLoad = [](const std::string& text) {
        Result<Scene> scene = parseScene(text, "split.json");
        EXPECT_TRUE(scene) << scene.error();
        return scene ? build(*scene).sleepingBodyCount() : std::size_t(99);
    };
    EXPECT_EQ(sleepingAfterLoad(level("", "")), 1u) << "the crate alone may sleep";
    EXPECT_EQ(sleepingAfterLoad(level("", bobAsleepAlone)), 2u) << "two islands that nothing joins";
    EXPECT_EQ(sleepingAfterLoad(level(hinge, "")), 0u) << "the awake bob is joined to the sleeping crate";
    EXPECT_EQ(sleepingAfterLoad(level(hinge, bobAsleepAlone)), 0u) << "two islands the joint makes one";
}

// A step's statistics count its contact points without making the records
// (the count is taken as the step ends): it must be the number of records
// contacts() then makes, while islands fall asleep, wake, and whether or not
// anyone asked for the records of the steps between.
TEST(Sleep, TheStepsContactCountIsTheNumberOfItsRecords) {
    Scene scene = boxStacks(2, 4, true);
    addBall(scene, {0.0, 9.5});                     // lands on stack 0 after it sleeps
    const Entity fast = addBall(scene, {4.0, 0.3});  // rolls into stack 1
    scene.registry.emplace<Velocity>(fast, Velocity{{6.0, 0.0}});
    World asked = build(scene), unasked = build(scene);
    std::size_t slept = 0, most = 0, before = 0;
    bool woke = false;
    for (int k = 0; k < 240; ++k) {
        ASSERT_TRUE(asked.step().ok());
        ASSERT_TRUE(unasked.step().ok());
        const std::size_t count = asked.lastStats().contactCount;
        const std::size_t records = asked.contacts().size();
        ASSERT_EQ(count, records) << "step " << k;
        ASSERT_EQ(unasked.lastStats().contactCount, records) << "step " << k;
        if (k % 7 == 0) ASSERT_EQ(unasked.contacts().size(), records) << "step " << k;
        slept = std::max(slept, asked.sleepingBodyCount());
        woke = woke || asked.sleepingBodyCount() < before;
        before = asked.sleepingBodyCount();
        most = std::max(most, records);
    }
    EXPECT_GE(slept, 4u) << "no island fell asleep";
    EXPECT_TRUE(woke) << "no island woke";
    EXPECT_GT(most, 10u);
}
