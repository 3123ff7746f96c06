// Exact resume: N steps, save, load, N steps equals 2N straight steps, bit
// for bit, on every shipped level. The bodies' state goes to the
// file through writeBack; the solver's warm start through `solver_state`.
// Also the in-memory forms the editor uses: saveState/restoreState and
// reload (an edit of the live World that keeps the warm start).

#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world.hpp"

#include "test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

namespace fs = std::filesystem;
using namespace stepwise;

namespace {

constexpr std::uint64_t kSteps = 100;

using test::shippedLevels;

Scene load(const fs::path& p) {
    Result<Scene> s = loadSceneFile(p);
    if (!s) throw std::runtime_error(s.error());
    return std::move(*s);
}

constexpr auto build = &test::buildWorld;

/// The scene as `stepwise run --out` writes it: state and solver state.
std::string savedText(const World& world, Scene scene, bool withSolverState = true) {
    world.writeBack(scene);
    scene.solverState.reset();
    if (withSolverState) {
        SolverState solver = world.solverState();
        if (!solver.empty()) scene.solverState = std::move(solver);
    }
    return sceneToJsonText(scene);
}

std::string straight(const fs::path& level, std::uint64_t steps) {
    const Scene scene = load(level);
    World w = build(scene);
    const AdvanceResult r = advance(w, steps);
    EXPECT_TRUE(r.ok()) << level << ": " << (r.divergence ? r.divergence->message : "");
    return savedText(w, scene);
}

/// N steps, save to text, parse, N more steps.
std::string resumed(const fs::path& level, std::uint64_t steps, bool withSolverState) {
    const Scene scene = load(level);
    World first = build(scene);
    EXPECT_TRUE(advance(first, steps).ok());
    const std::string middle = savedText(first, scene, withSolverState);
    Result<Scene> reloaded = parseScene(middle, "middle.json");
    EXPECT_TRUE(reloaded) << reloaded.error();
    World second = build(*reloaded);
    EXPECT_TRUE(advance(second, steps).ok());
    return savedText(second, *reloaded);
}

/// Where a level is saved and resumed: kSteps, except rain.json. At step
/// 100 only two of its drops have landed, each alone on the floor and
/// sliding at the friction limit; one iteration solves a lone contact to the
/// same impulses from any start, so a cold restart there is exact as well
/// (measured: no body differs in any bit over the next 100 steps) and the
/// save would test nothing. By step 150 the drops pile up, and a cold
/// restart is 6 cm away within 5 steps.
std::uint64_t splitFor(const fs::path& level) { return level.filename() == "rain.json" ? 2 * kSteps : kSteps; }

/// True when the warm start at step `split` holds a non-zero impulse (a
/// contact's or a joint's): then a cold restart there starts the solve from
/// elsewhere. (Newton's cradle and the pool break have contacts but no load
/// on them at that step.)
bool carriesImpulses(const fs::path& level, std::uint64_t split) {
    const Scene scene = load(level);
    World w = build(scene);
    advance(w, split);
    const SolverState state = w.solverState();
    for (const ContactImpulse& c : state.contacts)
        if (c.normalImpulse != 0.0 || c.tangentImpulse != 0.0) return true;
    return !state.joints.empty();  // only joints that carry something are listed
}

/// Largest distance between the same entity's positions in two saved texts.
double largestPositionGap(const std::string& a, const std::string& b) {
    Result<Scene> sa = parseScene(a, "a.json"), sb = parseScene(b, "b.json");
    if (!sa || !sb) return -1.0;
    double gap = 0.0;
    const auto& ea = sa->registry.entities();
    const auto& eb = sb->registry.entities();
    for (std::size_t i = 0; i < ea.size() && i < eb.size(); ++i) {
        const Position* pa = sa->registry.tryGet<Position>(ea[i]);
        const Position* pb = sb->registry.tryGet<Position>(eb[i]);
        if (pa && pb) gap = std::max(gap, length(pa->value - pb->value));
    }
    return gap;
}

} // namespace

TEST(Resume, EveryShippedLevelResumesBitForBitFromItsSavedFile) {
    const std::vector<fs::path> levels = shippedLevels();
    ASSERT_GE(levels.size(), 15u);
    for (const fs::path& level : levels) {
        const std::uint64_t split = splitFor(level);
        const std::string once = straight(level, 2 * split);
        const std::string twice = resumed(level, split, true);
        EXPECT_TRUE(once == twice) << level.filename() << ": " << split << " + save + load + " << split
                                   << " steps differs from " << 2 * split << " steps, by up to "
                                   << largestPositionGap(once, twice) << " m";
    }
}

// The same, swept: saved after 1, 2 and 7 steps (bodies still falling or
// just landed, where the file may hold a velocity the long run ends
// without), at the level's dt and at 0.01 s, then 24 more steps. A
// polygon that landed and stopped dead (v exactly 0) was written without a
// velocity by the long run and with one by the resumed run.
TEST(Resume, EveryShippedLevelResumesBitForBitAtAnyStepAndStepSize) {
    for (const fs::path& level : shippedLevels()) {
        for (const double dt : {0.0, 0.01}) {
            Scene scene = load(level);
            if (dt > 0.0) scene.world.dt = dt;
            for (const std::uint64_t split : {1u, 2u, 7u}) {
                World whole = build(scene);
                ASSERT_TRUE(advance(whole, split + 24).ok()) << level.filename();
                World first = build(scene);
                ASSERT_TRUE(advance(first, split).ok());
                Result<Scene> middle = parseScene(savedText(first, scene), "middle.json");
                ASSERT_TRUE(middle) << middle.error();
                World second = build(*middle);
                ASSERT_TRUE(advance(second, 24).ok());
                EXPECT_TRUE(savedText(whole, scene) == savedText(second, *middle))
                    << level.filename() << " at dt " << scene.world.dt << ": " << split << " + save + load + 24 steps differs from "
                    << split + 24 << " steps";
            }
        }
    }
}

// The test above needs `solver_state`: without the warm start the resumed
// run leaves the straight one on every level whose contacts carry load at
// the save (measured: rain 3.3 m saved at step 200, pile 0.36 m,
// ramp_friction 7.3 mm, default 3.7 mm), without the joints' impulses on the joint levels (bridge
// 0.19 m, chain 8.2 cm, car 2.2 mm, ragdoll 1.9 um), and without contacts
// of polygons on polygons.json (0.35 mm). This keeps the check honest:
// dropping the section must show, on every level that carries something.
TEST(Resume, WithoutTheSolverStateLoadedContactsDoNotResumeExactly) {
    int carrying = 0;
    for (const fs::path& level : shippedLevels()) {
        const std::uint64_t split = splitFor(level);
        if (!carriesImpulses(level, split)) continue;
        ++carrying;
        const std::string once = straight(level, 2 * split), cold = resumed(level, split, false);
        EXPECT_TRUE(once != cold) << level.filename();
        std::cout << level.filename().string() << ": a resume without solver_state ends up to "
                  << largestPositionGap(once, cold) << " m away after " << split << " + " << split << " steps\n";
    }
    EXPECT_GE(carrying, 11);
}

// The shipped levels use hinges and a weld only: the slider, distance and
// rope rows (and a spring weld) resume exactly too, from the file and from
// a snapshot.
TEST(Resume, EveryJointTypeResumesExactly) {
    const fs::path level = fs::path(STEPWISE_SOURCE_DIR) / "tests" / "data" / "joints_every_type.json";
    const std::string once = straight(level, 2 * kSteps);
    EXPECT_TRUE(once == resumed(level, kSteps, true)) << "100 + save + load + 100 steps differs from 200 steps";
    EXPECT_TRUE(once != resumed(level, kSteps, false)) << "without solver_state it should not be exact";
    const Scene scene = load(level);
    World w = build(scene);
    ASSERT_TRUE(advance(w, kSteps).ok());
    const WorldState middle = w.saveState();
    ASSERT_EQ(middle.joints.size(), 5u);
    ASSERT_TRUE(advance(w, kSteps).ok());
    ASSERT_TRUE(w.restoreState(middle).ok());
    ASSERT_TRUE(advance(w, kSteps).ok());
    EXPECT_TRUE(once == savedText(w, scene)) << "step back 100 + step 100 differs";
}

// The joints' part of the section on its own: with the contacts' warm start
// kept and the joints' dropped, the joint levels do not resume exactly.
TEST(Resume, JointImpulsesAreWhatTheJointLevelsNeedToResume) {
    for (const char* name : {"bridge.json", "car.json", "chain.json", "ragdoll.json"}) {
        const fs::path level = fs::path(STEPWISE_SOURCE_DIR) / "levels" / name;
        const Scene scene = load(level);
        World first = build(scene);
        ASSERT_TRUE(advance(first, kSteps).ok());
        Scene middle = scene;
        first.writeBack(middle);
        middle.solverState = first.solverState();
        ASSERT_FALSE(middle.solverState->joints.empty()) << name;
        middle.solverState->joints.clear();
        Result<Scene> reloaded = parseScene(sceneToJsonText(middle), name);
        ASSERT_TRUE(reloaded) << reloaded.error();
        World second = build(*reloaded);
        ASSERT_TRUE(advance(second, kSteps).ok());
        const std::string once = straight(level, 2 * kSteps), withoutJoints = savedText(second, *reloaded);
        EXPECT_TRUE(once != withoutJoints) << name;
        std::cout << name << ": without the joints' impulses, " << largestPositionGap(once, withoutJoints)
                  << " m away after 100 + 100 steps\n";
    }
}

TEST(Resume, SnapshotRestoreThenStepGivesTheSameBytesAsTheFirstPass) {
    for (const fs::path& level : shippedLevels()) {
        const std::string name = level.filename().string();
        const Scene scene = load(level);
        World w = build(scene);
        ASSERT_TRUE(advance(w, 60).ok());
        const WorldState at60 = w.saveState();
        ASSERT_TRUE(advance(w, 30).ok());
        const std::string firstPass = savedText(w, scene);
        const WorldState at90 = w.saveState();
        ASSERT_TRUE(w.restoreState(at60).ok());
        EXPECT_EQ(w.time(), at60.time);
        ASSERT_TRUE(advance(w, 30).ok());
        EXPECT_TRUE(firstPass == savedText(w, scene)) << name << ": step back 30 + step 30 differs";
        const WorldState again = w.saveState();
        EXPECT_EQ(again.x, at90.x) << name;
        EXPECT_EQ(again.v, at90.v) << name;
        EXPECT_EQ(again.contacts, at90.contacts) << name;
        EXPECT_EQ(again.joints, at90.joints) << name;
        EXPECT_EQ(again.steps, 90u) << name;
    }
}

TEST(Resume, ASnapshotFromADifferentLayoutIsRefusedAndChangesNothing) {
    const Scene pile = load(fs::path(STEPWISE_SOURCE_DIR) / "levels" / "pile.json");
    const Scene def = load(fs::path(STEPWISE_SOURCE_DIR) / "levels" / "default.json");
    World a = build(pile), b = build(def);
    ASSERT_TRUE(advance(b, 5).ok());
    const std::string before = savedText(b, def);
    Result<void> r = b.restoreState(a.saveState());
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), "the snapshot was taken from a world with other bodies or shapes");
    EXPECT_EQ(before, savedText(b, def));
}

// The editor edits its one World with reload(): the warm start survives, so
// an edit that changes nothing the step reads leaves the run exact.
TEST(Resume, ReloadKeepsTheWarmStartSoANoOpEditLeavesTheRunExact) {
    for (const char* name : {"default.json", "pile.json", "ramp_friction.json", "bridge.json"}) {
        const Scene scene = load(fs::path(STEPWISE_SOURCE_DIR) / "levels" / name);
        const std::string once = straight(fs::path(STEPWISE_SOURCE_DIR) / "levels" / name, 2 * kSteps);
        World w = build(scene);
        ASSERT_TRUE(advance(w, kSteps).ok());
        Scene edited = scene;
        w.writeBack(edited);
        edited.solverState.reset();
        ASSERT_TRUE(w.reload(edited).ok());
        EXPECT_EQ(w.lastStats().step, kSteps);
        ASSERT_TRUE(advance(w, kSteps).ok());
        EXPECT_TRUE(once == savedText(w, scene)) << name;
    }
}

TEST(Resume, ReloadDropsTheWarmStartOfRemovedShapesAndKeepsTheRest) {
    const Scene scene = load(fs::path(STEPWISE_SOURCE_DIR) / "levels" / "default.json");
    World w = build(scene);
    ASSERT_TRUE(advance(w, 60).ok());
    const SolverState before = w.solverState();
    ASSERT_FALSE(before.empty());
    const Entity removed = before.contacts.front().a;
    Scene edited = scene;
    w.writeBack(edited);
    edited.registry.remove<Radius>(removed);
    edited.registry.remove<Box>(removed);
    edited.registry.remove<Plane>(removed);
    ASSERT_TRUE(w.reload(edited).ok());
    const SolverState after = w.solverState();
    std::size_t kept = 0;
    for (const ContactImpulse& c : before.contacts) kept += c.a != removed && c.b != removed;
    EXPECT_EQ(after.contacts.size(), kept);
    EXPECT_GT(kept, 0u);
    for (const ContactImpulse& c : after.contacts) {
        EXPECT_NE(c.a, removed);
        EXPECT_NE(c.b, removed);
    }
}

TEST(Resume, ReloadOfASceneTheEngineRefusesLeavesTheWorldAsItWas) {
    const Scene scene = load(fs::path(STEPWISE_SOURCE_DIR) / "levels" / "default.json");
    World w = build(scene);
    ASSERT_TRUE(advance(w, 10).ok());
    const std::string before = savedText(w, scene);
    Scene bad = scene;
    bad.world.dt = -1.0;
    Result<void> r = w.reload(bad);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().find("world.dt"), std::string::npos) << r.error();
    EXPECT_EQ(before, savedText(w, scene));
}

TEST(Resume, SolverStateRoundTripsThroughTheFileExactly) {
    const Scene scene = load(fs::path(STEPWISE_SOURCE_DIR) / "levels" / "pile.json");
    World w = build(scene);
    ASSERT_TRUE(advance(w, 50).ok());
    const std::string text = savedText(w, scene);
    ASSERT_NE(text.find("\"solver_state\""), std::string::npos);
    Result<Scene> again = parseScene(text, "pile_resume.json");
    ASSERT_TRUE(again) << again.error();
    ASSERT_TRUE(again->solverState);
    EXPECT_EQ(again->solverState->contacts.size(), w.solverState().contacts.size());
    EXPECT_EQ(sceneToJsonText(*again), text) << "load -> save gives the same bytes";
    // Built from it, the world holds the same cache (same keys and bits).
    World resumedWorld = build(*again);
    EXPECT_EQ(resumedWorld.saveState().contacts, w.saveState().contacts);
}

TEST(Resume, JointImpulsesRoundTripThroughTheFileExactly) {
    // ragdoll: hinges with limits; car: motors; chain and bridge: plain hinges.
    for (const char* name : {"ragdoll.json", "car.json", "chain.json"}) {
        const Scene scene = load(fs::path(STEPWISE_SOURCE_DIR) / "levels" / name);
        World w = build(scene);
        ASSERT_TRUE(advance(w, 50).ok());
        const std::string text = savedText(w, scene);
        ASSERT_NE(text.find("\"joints\": ["), std::string::npos) << name;
        Result<Scene> again = parseScene(text, name);
        ASSERT_TRUE(again) << again.error();
        EXPECT_EQ(again->solverState->joints, w.solverState().joints) << name;
        EXPECT_EQ(sceneToJsonText(*again), text) << name << ": load -> save gives the same bytes";
        World resumedWorld = build(*again);
        EXPECT_EQ(resumedWorld.saveState().joints, w.saveState().joints) << name;
    }
    // The rows each level exercises are in the file.
    const Scene car = load(fs::path(STEPWISE_SOURCE_DIR) / "levels" / "car.json");
    World w = build(car);
    ASSERT_TRUE(advance(w, 50).ok());
    EXPECT_NE(savedText(w, car).find("\"motor_impulse\": "), std::string::npos);
}

// A hinge without a motor or limits has no such rows: impulses given for
// them (a hand-edited file, a joint edited since the save) are dropped, or
// the warm start would apply them every substep with nothing to undo them.
TEST(Resume, ImpulsesForRowsAJointDoesNotHaveAreDropped) {
    const std::string text = R"({"world": {"gravity": {"x": 0, "y": 0}},
        "entities": [{"name": "bob", "position": {"x": 1, "y": 0}, "radius": 0.1},
                     {"name": "pin", "joint": {"type": "hinge", "a": "bob", "anchor": {"x": 0, "y": 0}}}],
        "solver_state": {"joints": [{"joint": "pin", "linear_impulse": {"x": 0.5, "y": -0.0}, "motor_impulse": 5,
                                     "lower_impulse": 1, "upper_impulse": 2, "axial_impulse": 3}]}})";
    Result<Scene> scene = parseScene(text, "pin.json");
    ASSERT_TRUE(scene) << scene.error();
    ASSERT_EQ(scene->solverState->joints.size(), 1u);
    EXPECT_EQ(scene->solverState->joints[0].motor, 5.0);
    World w = build(*scene);
    const SolverState state = w.solverState();
    ASSERT_EQ(state.joints.size(), 1u);
    EXPECT_EQ(state.joints[0].linear.x, 0.5);
    EXPECT_TRUE(std::signbit(state.joints[0].linear.y));
    EXPECT_EQ(state.joints[0].motor, 0.0);
    EXPECT_EQ(state.joints[0].lower, 0.0);
    EXPECT_EQ(state.joints[0].upper, 0.0);
    EXPECT_EQ(state.joints[0].axial, 0.0);
    // Without gravity, the bob at rest stays at rest: no phantom torque.
    ASSERT_TRUE(advance(w, 120).ok());
    EXPECT_LT(std::abs(w.saveState().colliderSpin.at(0)), 1e-12);
}

TEST(Resume, ALevelWithoutSolverStateLoadsAsBefore) {
    const Scene scene = load(fs::path(STEPWISE_SOURCE_DIR) / "levels" / "default.json");
    EXPECT_FALSE(scene.solverState);
    World w = build(scene);
    EXPECT_TRUE(w.solverState().empty());
    EXPECT_EQ(sceneToJsonText(scene).find("solver_state"), std::string::npos);
}

TEST(Resume, BadSolverStateIsRefusedWithWhereAndWhat) {
    const std::string head = R"({"entities": [{"name": "ball", "position": {"x": 0, "y": 0}, "radius": 0.5},
                                  {"name": "wall", "plane": {"normal": {"x": 0, "y": 1}, "offset": -1}},
                                  {"name": "dot", "position": {"x": 3, "y": 0}},
                                  {"name": "pin", "joint": {"type": "hinge", "a": "ball", "anchor": {"x": 0, "y": 1}}}],
                                 "solver_state": )";
    struct Case {
        std::string state, message;
    };
    const std::vector<Case> cases = {
        {R"({"contacts": [{"a": "wall", "b": "nobody", "feature": 0, "normal_impulse": 1, "tangent_impulse": 0}]})",
         "t.json: error: /solver_state/contacts/0/b: no entity is named \"nobody\""},
        {R"({"contacts": [{"a": "wall", "b": "dot", "feature": 0, "normal_impulse": 1, "tangent_impulse": 0}]})",
         "t.json: error: /solver_state/contacts/0/b: entity \"dot\" has no shape (radius, box, polygon, capsule, chain or plane), so it "
         "has no contacts"},
        {R"({"contacts": [{"a": 1, "b": 7, "feature": 0, "normal_impulse": 1, "tangent_impulse": 0}]})",
         "t.json: error: /solver_state/contacts/0/b: expected an integer in [0, 3], got 7"},
        {R"({"contacts": [{"a": 1, "b": 0, "feature": 70000, "normal_impulse": 1, "tangent_impulse": 0}]})",
         "t.json: error: /solver_state/contacts/0/feature: expected an integer in [0, 65535], got 70000"},
        {R"({"contacts": [{"a": 1, "b": 0, "feature": 0, "normal_impulse": "big", "tangent_impulse": 0}]})",
         "t.json: error: /solver_state/contacts/0/normal_impulse: expected a finite number, got \"big\""},
        {R"({"contacts": [{"a": 1, "b": 0, "feature": 0, "normal_impulse": 1}]})",
         "t.json: error: /solver_state/contacts/0: missing \"tangent_impulse\""},
        {R"({"impulses": []})",
         "t.json: error: /solver_state/impulses: unknown key \"impulses\" in solver_state. Known keys: contacts, joints, "
         "bodies, chosen"},
        {R"({"chosen": {"substeps": 0, "solver_iterations": 2}})",
         "t.json: error: /solver_state/chosen/substeps: expected an integer in [1, 1000], got 0"},
        {R"({"chosen": {"substeps": 4}})", "t.json: error: /solver_state/chosen: missing \"solver_iterations\""},
        {R"([])",
         "t.json: error: /solver_state: expected an object {\"contacts\": [...], \"joints\": [...], \"bodies\": "
         "[...]}, got an empty array"},
        {R"({"bodies": [{"body": "wall", "sleep_time": 1}]})",
         "t.json: error: /solver_state/bodies/0/body: entity \"wall\" is not a dynamic body (it needs a position and no "
         "static)"},
        {R"({"bodies": [{"body": "ball", "sleep_time": -1}]})",
         "t.json: error: /solver_state/bodies/0/sleep_time: expected a number in [0, 1e+300], got -1"},
        {R"({"bodies": [{"body": "dot"}, {"body": 2}]})",
         "t.json: error: /solver_state/bodies/1/body: body 2 has an entry already"},
        {R"({"joints": [{"joint": "ball", "linear_impulse": {"x": 1, "y": 0}}]})",
         "t.json: error: /solver_state/joints/0/joint: entity \"ball\" is not a joint"},
        {R"({"joints": [{"joint": "pin"}, {"joint": 3}]})",
         "t.json: error: /solver_state/joints/1/joint: joint 3 has an entry already"},
        {R"({"joints": [{"linear_impulse": {"x": 1, "y": 0}}]})", "t.json: error: /solver_state/joints/0: missing \"joint\""},
        {R"({"joints": [{"joint": "pin", "upper_impulse": -1}]})",
         "t.json: error: /solver_state/joints/0/upper_impulse: expected a number >= 0, got -1"},
        {R"({"joints": [{"joint": "pin", "spin": 1}]})",
         "t.json: error: /solver_state/joints/0/spin: unknown key \"spin\" in a joint. Known keys: joint, "
         "linear_impulse, angular_impulse, axial_impulse, motor_impulse, lower_impulse, upper_impulse"},
        {R"({"joints": {}})", "t.json: error: /solver_state/joints: expected an array of joints, got an empty object"},
    };
    for (const Case& c : cases) {
        Result<Scene> r = parseScene(head + c.state + "}", "t.json");
        ASSERT_FALSE(r) << c.state;
        EXPECT_EQ(r.error(), c.message) << c.state;
    }
    // Names and indices both work; unnamed entities are written by index.
    Result<Scene> ok = parseScene(
        head + R"({"contacts": [{"a": 1, "b": "ball", "feature": 3, "normal_impulse": 0.1, "tangent_impulse": -0.0}]})" +
            "}",
        "t.json");
    ASSERT_TRUE(ok) << ok.error();
    ASSERT_EQ(ok->solverState->contacts.size(), 1u);
    EXPECT_EQ(ok->solverState->contacts[0].feature, 3u);
    EXPECT_EQ(ok->solverState->contacts[0].normalImpulse, 0.1);
    EXPECT_TRUE(std::signbit(ok->solverState->contacts[0].tangentImpulse));
    EXPECT_NE(sceneToJsonText(*ok).find(
                  R"({"a": "wall", "b": "ball", "feature": 3, "normal_impulse": 0.1, "tangent_impulse": -0.0})"),
              std::string::npos)
        << sceneToJsonText(*ok);
}

namespace {
std::string readFile(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}
} // namespace

// Through the command line, as a user would: run --out, then run the
// written file on.
TEST(Resume, RunOutThenRunOnEqualsOneLongRun) {
    const fs::path dir = fs::temp_directory_path() / ("stepwise_resume_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    for (const char* name : {"default.json", "ramp_friction.json", "pyramid.json", "bridge.json"}) {
        const std::string level = (fs::path(STEPWISE_SOURCE_DIR) / "levels" / name).string();
        auto run = [&](const std::string& in, int steps, const fs::path& out) {
            const std::string cmd = std::string(STEPWISE_BINARY) + " run " + in + " --steps " + std::to_string(steps) +
                                    " --out " + out.string() + " > /dev/null";
            ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
        };
        run(level, 100, dir / "half.json");
        run((dir / "half.json").string(), 100, dir / "resumed.json");
        run(level, 200, dir / "straight.json");
        const std::string resumedText = readFile(dir / "resumed.json"), straightText = readFile(dir / "straight.json");
        EXPECT_NE(readFile(dir / "half.json").find("\"solver_state\""), std::string::npos) << name;
        EXPECT_TRUE(resumedText == straightText) << name;
    }
    fs::remove_all(dir);
}

// The schema (levels/scene.schema.json) describes the section: a running
// state written by `run --out` validates, and a bad entry does not.
TEST(Resume, ASavedRunningStateValidatesAgainstTheSchema) {
    const fs::path dir = fs::temp_directory_path() / ("stepwise_resume_schema_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const fs::path state = dir / "pile_state.json";
    const std::string run = std::string(STEPWISE_BINARY) + " run " +
                            (fs::path(STEPWISE_SOURCE_DIR) / "levels" / "pile.json").string() +
                            " --steps 30 --out " + state.string() + " > /dev/null";
    ASSERT_EQ(std::system(run.c_str()), 0);
    const std::string text = readFile(state);
    ASSERT_NE(text.find("\"solver_state\""), std::string::npos);
    const std::string validator = "/usr/bin/python3 " +
                                  (fs::path(STEPWISE_SOURCE_DIR) / "tests" / "validate_levels_schema.py").string() +
                                  " " + (fs::path(STEPWISE_SOURCE_DIR) / "levels").string() + " ";
    EXPECT_EQ(std::system((validator + state.string() + " > /dev/null").c_str()), 0);
    std::string bad = text;
    bad.replace(bad.find("\"feature\": "), 11, "\"feature\": 7000000");  // past 65535
    {
        std::ofstream out(dir / "bad_state.json", std::ios::binary);
        out << bad;
    }
    EXPECT_NE(std::system((validator + (dir / "bad_state.json").string() + " > /dev/null").c_str()), 0);
    fs::remove_all(dir);
}

// A scene edited after it was saved from a run (a body lost its shape, one
// was deleted) still saves a file the loader accepts: entries of entities
// that are gone or have no shape are left out.
TEST(Resume, SavingDropsSolverStateEntriesOfEntitiesThatNoLongerCollide) {
    const Scene scene = load(fs::path(STEPWISE_SOURCE_DIR) / "levels" / "default.json");
    World w = build(scene);
    ASSERT_TRUE(advance(w, 60).ok());
    Scene edited = scene;
    w.writeBack(edited);
    edited.solverState = w.solverState();
    const Entity shapeless = edited.solverState->contacts.front().b;
    const Entity deleted = edited.solverState->contacts.back().b;
    ASSERT_NE(shapeless, deleted);
    edited.registry.remove<Radius>(shapeless);
    edited.registry.remove<Box>(shapeless);
    edited.registry.destroy(deleted);
    Result<Scene> again = parseScene(sceneToJsonText(edited), "edited.json");
    ASSERT_TRUE(again) << again.error();
    std::size_t expected = 0;
    for (const ContactImpulse& c : edited.solverState->contacts)
        expected += c.a != shapeless && c.b != shapeless && c.a != deleted && c.b != deleted;
    EXPECT_EQ(again->solverState->contacts.size(), expected);
    EXPECT_GT(expected, 0u);
}

namespace {
/// Two 1 kg balls stacked on a floor, saved after 20 steps (warm starts
/// between the floor and a, and a and b).
std::string stackedBallsSaved() {
    test::Sim first(R"({"entities": [
        {"name": "floor", "position": {"x": 0, "y": -0.5}, "static": true, "box": {"width": 10, "height": 1}},
        {"name": "a", "position": {"x": 0, "y": 0.5}, "radius": 0.5, "mass": 1},
        {"name": "b", "position": {"x": 0, "y": 1.5}, "radius": 0.5, "mass": 1}]})");
    EXPECT_TRUE(first.step(20));
    return sceneToJsonText(first.scene);
}
} // namespace

// A hand-edited warm start cannot change the physics: at a step's start the
// engine bounds each contact point's warm start at what the step can need
// (docs/format.md, "The solver_state section"). Two 1 kg balls stacked on a
// floor, saved after 20 steps; the contact between them edited to 1e10 N*s
// (under the loader's bound for this scene, so it is kept) must not throw
// the top ball: without the bound it flew 2.8e8 m in a second.
TEST(Resume, AHandEditedWarmStartIsBoundedByWhatTheStepCanNeed) {
    const std::string saved = stackedBallsSaved();
    // The saved text with one entry's impulse replaced.
    const auto edited = [&](const std::string& pair, const std::string& field, const std::string& value) {
        std::string text = saved;
        const std::size_t entry = text.find(pair);
        EXPECT_NE(entry, std::string::npos) << text;
        const std::size_t at = text.find(field, entry) + field.size();
        text.replace(at, text.find_first_of(",}", at) - at, value);
        return text;
    };
    const std::string ab = R"("a": "a", "b": "b")", floorA = R"("a": "floor", "b": "a")";
    test::Sim plain(saved), wild(edited(ab, R"("normal_impulse": )", "1e10")),
        sideways(edited(floorA, R"("tangent_impulse": )", "1e10"));
    ASSERT_TRUE(wild.world && sideways.world);
    ASSERT_FALSE(wild.world->droppedImpulses()) << "the loader's bound keeps it";
    double highest = 0.0, widest = 0.0;
    for (int step = 0; step < 60; ++step) {
        ASSERT_TRUE(plain.step() && wild.step() && sideways.step());
        highest = std::max(highest, wild.position("b").y);
        widest = std::max(widest, std::abs(sideways.position("a").x));
    }
    // b rests at 1.5 m less the overlap; the bounded warm start lifts it by
    // centimetres at most, and the stack settles to the unedited run's energy.
    EXPECT_LT(highest, 1.55);
    const double energy = plain.world->energy().total();
    EXPECT_NEAR(wild.world->energy().total(), energy, 0.001 * energy);
    EXPECT_NEAR(sideways.world->energy().total(), energy, 0.001 * energy);
    // An edited friction impulse is taken back in the first pass (the
    // friction row clamps its accumulated impulse to the cone), and the
    // warm start keeps it within the cone as well: a stays put.
    EXPECT_LT(widest, 0.01);
}

// A normal impulse only pushes: a negative one given in code (the loader
// refuses it in a file) starts the contact at zero, as a run that left
// nothing there.
TEST(Resume, ANegativeWarmStartGivenInCodeCountsAsZero) {
    const std::string saved = stackedBallsSaved();
    Scene negative = test::parseLevel(saved);
    Scene zero = test::parseLevel(saved);
    ASSERT_TRUE(negative.solverState && negative.solverState->contacts.size() == 2);
    for (ContactImpulse& c : negative.solverState->contacts) c.normalImpulse = -100.0;
    for (ContactImpulse& c : zero.solverState->contacts) c.normalImpulse = 0.0;
    World w = build(negative), z = build(zero);
    ASSERT_TRUE(advance(w, 60).ok() && advance(z, 60).ok());
    EXPECT_EQ(savedText(w, negative), savedText(z, zero));
}
