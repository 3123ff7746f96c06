// The editor's one live World:
// step back N then step N replays the same bytes with contacts; an edit
// while paused keeps the warm start; the step-back history holds states,
// not scenes; "Save simulation state" resumes exactly.

#include "editor_fixture.hpp"

#include <malloc.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>

using namespace stepwise;
using namespace stepwise::editor;
namespace fs = std::filesystem;

namespace {

using editor_test::kLevels;
using editor_test::TempDir;

/// An editor with the level open (no viewport: these tests step and save).
struct Fixture : editor_test::LevelOpen {
    using LevelOpen::LevelOpen;
    void step(int n) {
        for (int i = 0; i < n; ++i) ed.stepForward();
    }
    void back(int n) {
        for (int i = 0; i < n; ++i) ed.stepBack();
    }
    /// The scene and the solver's warm start, as "Save simulation state" writes them.
    std::string stateText() {
        Scene s = ed.doc.scene;
        s.solverState.reset();
        if (ed.sim.ensureWorld(ed.doc.scene))
            if (SolverState solver = ed.sim.world()->solverState(); !solver.empty()) s.solverState = solver;
        return sceneToJsonText(s);
    }
};

/// `level` stepped `steps` times by a World of its own, as the file it would save.
std::string straightRun(const std::string& level, int steps) {
    Result<Scene> scene = loadSceneFile(kLevels / level);
    EXPECT_TRUE(scene) << scene.error();
    Result<World> w = World::build(*scene);
    EXPECT_TRUE(w) << w.error();
    EXPECT_TRUE(advance(*w, std::uint64_t(steps)).ok());
    w->writeBack(*scene);
    SolverState solver = w->solverState();
    if (!solver.empty()) scene->solverState = solver;
    return sceneToJsonText(*scene);
}

} // namespace

// In default.json, step 60, step 30, step back 30, step 30 replays the
// first pass bit for bit: step back restores the warm start too (a World
// rebuilt from the scene, warm start dropped, ends up to 0.1 mm off).
TEST(EditorState, StepBackThenStepReplaysTheFirstPassBitForBitWithContacts) {
    // bridge and car: joints too (their impulses are part of the state).
    for (const char* level : {"default.json", "pile.json", "ramp_friction.json", "pyramid.json", "bridge.json", "car.json"}) {
        Fixture f(level);
        f.step(60);
        ASSERT_GT(f.ed.sim.world()->contacts().size(), 0u) << level;
        f.step(30);
        const std::string first = f.stateText();
        f.back(30);
        EXPECT_EQ(f.ed.sim.steps(), 60u);
        f.step(30);
        EXPECT_TRUE(f.stateText() == first) << level << ": step back 30 + step 30 differs from the first pass";
        // And it is the run a World of its own takes.
        EXPECT_TRUE(first == straightRun(level, 90)) << level;
    }
}

TEST(EditorState, StepBackRestoresTheExactEarlierBytes) {
    Fixture f("pile.json");
    f.step(40);
    const std::string at40 = f.stateText();
    f.step(25);
    f.back(25);
    EXPECT_TRUE(f.stateText() == at40);
}

// An edit while paused recompiles the live World in place and keeps the
// warm start, so an edit that changes nothing physical (a colour) does not
// change the run (a rebuilt World, warm start dropped, would).
TEST(EditorState, AnEditWhilePausedKeepsTheWarmStart) {
    Fixture f("default.json");
    f.step(60);
    const Entity crate = f.ed.sim.world()->contacts().front().a;
    ASSERT_TRUE(f.ed.applyEdit("colour", [&](Scene& s) {
        s.registry.emplace<Color>(crate, Color{Rgb{0.1, 0.2, 0.3}});
        return true;
    }));
    f.step(30);
    Result<Scene> expected = parseScene(straightRun("default.json", 90), "straight.json");
    ASSERT_TRUE(expected);
    expected->registry.emplace<Color>(crate, Color{Rgb{0.1, 0.2, 0.3}});
    EXPECT_TRUE(f.stateText() == sceneToJsonText(*expected));
}

// Step back across an edit and a switched-off system: the history entry's
// scene and warm start come back together, so the replay is exact.
TEST(EditorState, StepBackAcrossAnEditAndASystemSwitchReplaysExactly) {
    for (const char* level : {"default.json", "bridge.json"}) {
        SCOPED_TRACE(level);
        Fixture f(level);
        f.step(40);
        const std::string at40 = f.stateText();
        f.step(10);
        const std::string at50 = f.stateText();
        f.ed.sim.disabledSystems.insert("gravity");
        f.ed.sim.sceneChanged();
        f.step(5);
        f.back(5);
        f.ed.sim.disabledSystems.clear();
        f.ed.sim.sceneChanged();
        EXPECT_TRUE(f.stateText() == at50);
        f.back(10);
        EXPECT_TRUE(f.stateText() == at40);
        f.step(10);
        EXPECT_TRUE(f.stateText() == at50);
    }
}

// The history holds states (positions, velocities, angles, impulses) and
// one shared scene per change, not a scene per step: its bytes are the
// states' bytes plus a few scenes.
TEST(EditorState, TheStepBackHistoryHoldsStatesNotScenes) {
    Fixture f("pile.json");
    const std::size_t entities = f.ed.doc.scene.registry.size();
    std::size_t oneState = 0;  // the largest state of the run
    for (int i = 0; i < 100; ++i) {
        f.step(1);
        oneState = std::max(oneState, f.ed.sim.world()->saveState().bytes());
    }
    ASSERT_EQ(f.ed.sim.historySize(), 100u);
    const std::size_t bytes = f.ed.sim.historyBytes();
    const std::size_t sceneEstimate = 256 + 256 * entities;
    EXPECT_LT(bytes, 100 * (oneState + 1024) + 3 * sceneEstimate) << bytes;
    std::cout << "pile.json (" << entities << " entities, " << f.ed.sim.world()->solverState().contacts.size()
              << " cached contact points): largest state " << oneState / 1024 << " KiB; history of 100 steps "
              << bytes / 1024 << " KiB; a scene per step (estimated) " << 100 * sceneEstimate / 1024
              << " KiB\n";
}

TEST(EditorState, TheHistoryStaysInsideItsByteBudget) {
    Fixture f("pile.json");
    f.ed.sim.historyBudgetBytes = 2u << 20;
    f.step(200);
    EXPECT_LT(f.ed.sim.historySize(), 200u);
    EXPECT_GE(f.ed.sim.historySize(), 8u);
    // The states alone stay inside the budget (plus one entry).
    EXPECT_LT(f.ed.sim.historyBytes(), (2u << 20) + (1u << 20));
}

// "Save simulation state" writes the warm start: the saved file, played on
// by a World of its own, gives the bits the editor's session gives.
TEST(EditorState, SavedSimulationStateResumesExactly) {
    Fixture f("ramp_friction.json");
    Fixture g("ramp_friction.json");  // before saving: a fixture clears the test's folder
    f.step(50);
    const fs::path saved = f.tmp.path / "state.json";
    ASSERT_TRUE(f.ed.saveStateAs(saved)) << f.ed.errorModal;
    EXPECT_NE(test::readFile(saved).find("\"solver_state\""), std::string::npos);
    f.step(50);
    const std::string inEditor = f.stateText();

    Result<Scene> resumed = loadSceneFile(saved);
    ASSERT_TRUE(resumed) << resumed.error();
    Result<World> w = World::build(*resumed);
    ASSERT_TRUE(w);
    ASSERT_TRUE(advance(*w, 50).ok());
    w->writeBack(*resumed);
    resumed->solverState = w->solverState();
    EXPECT_TRUE(sceneToJsonText(*resumed) == inEditor);

    // Opened in the editor and played on, the same.
    ASSERT_TRUE(g.ed.open(saved)) << g.ed.errorModal;
    g.step(50);
    EXPECT_TRUE(g.stateText() == inEditor);
}

// Through the scripted editor, as a user would: `stepback` and `savestate`.
TEST(EditorState, ScriptedStepBackAndReplaySaveTheSameBytes) {
    TempDir tmp;
    const fs::path script = fs::path(STEPWISE_SOURCE_DIR) / "tests" / "editor_scripts" / "step_back_replay.txt";
    const std::string cmd = "cd " + tmp.path.string() + " && " + STEPWISE_BINARY + " edit " +
                            (kLevels / "default.json").string() + " --builtin-font --size 640x400 --config " +
                            (tmp.path / "cfg").string() + " --script " + script.string() + " > out.txt 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << test::readFile(tmp.path / "out.txt");
    const std::string first = test::readFile(tmp.path / "first_pass.json");
    const std::string replay = test::readFile(tmp.path / "replay.json");
    ASSERT_FALSE(first.empty());
    EXPECT_NE(first.find("\"solver_state\""), std::string::npos);
    EXPECT_TRUE(first == replay) << "step back 30 + step 30 saved other bytes than the first pass";
    EXPECT_TRUE(first == straightRun("default.json", 90));
}

// Undo stores what changed, not two whole scenes per edit. A
// thousand edits (each moves one body) of a 2,000-body level; heap in use
// measured with mallinfo2 (two copies of this scene per command would be
// over half a MiB an edit).
TEST(EditorState, AThousandEditsOfA2000BodyLevelHoldWhatChangedOnly) {
#ifdef STEPWISE_UNDER_ASAN
    GTEST_SKIP() << "AddressSanitizer replaces malloc, so mallinfo2 reports nothing; the release stage measures it";
#endif
    Fixture f("pile.json");
    const std::vector<Entity> bodies = [&] {
        std::vector<Entity> out;
        for (Entity e : f.ed.doc.scene.registry.entities())
            if (f.ed.doc.scene.registry.has<Radius>(e)) out.push_back(e);
        return out;
    }();
    ASSERT_GE(bodies.size(), 2000u);
    const std::string original = sceneToJsonText(f.ed.doc.scene);
    f.ed.commands.clear();

    const std::size_t heap0 = ::mallinfo2().uordblks;
    for (int i = 0; i < 1000; ++i)
        ASSERT_TRUE(f.ed.applyEdit("move", [&](Scene& s) {
            s.registry.tryGet<Position>(bodies[std::size_t(i) * 7 % bodies.size()])->value.x += 0.01;
            return true;
        }));
    const std::size_t held = ::mallinfo2().uordblks - heap0;
    ASSERT_EQ(f.ed.commands.size(), 1000u);

    const std::size_t heap1 = ::mallinfo2().uordblks;
    std::size_t perScene = 0;
    {
        const Scene copy = f.ed.doc.scene;
        perScene = ::mallinfo2().uordblks - heap1;
    }
    std::cout << "1,000 edits of pile.json (" << f.ed.doc.scene.registry.size() << " entities): undo holds "
              << held / 1024 << " KiB (stack's own count " << f.ed.commands.bytes() / 1024
              << " KiB); one scene copy is " << perScene / 1024 << " KiB, so two per command would hold "
              << 2 * 1000 * perScene / (1024 * 1024) << " MiB for 1,000\n";
    EXPECT_LT(held, std::size_t(1) << 20) << "1,000 one-body edits should hold well under 1 MiB";
    EXPECT_LT(held * 100, 2 * 256 * perScene);

    while (f.ed.commands.canUndo()) ASSERT_FALSE(f.ed.commands.undo(f.ed.doc.scene).empty());
    EXPECT_TRUE(sceneToJsonText(f.ed.doc.scene) == original);
}

// Undo of a delete brings back the very same handle (springs, selection).
TEST(EditorState, UndoOfADeleteRevivesTheSameHandleAndBytes) {
    Fixture f("spring_chain.json");
    const std::string original = sceneToJsonText(f.ed.doc.scene);
    const Entity victim = f.ed.doc.scene.registry.entities()[3];
    ASSERT_TRUE(f.ed.applyEdit("delete", [&](Scene& s) { return s.registry.destroy(victim); }));
    ASSERT_TRUE(f.ed.applyEdit("add", [&](Scene& s) {
        const Entity e = s.registry.create();
        s.registry.emplace<Position>(e, Position{{1.0, 2.0}});
        return true;
    }));
    const std::string afterAdd = sceneToJsonText(f.ed.doc.scene);
    ASSERT_TRUE(f.ed.undo());
    ASSERT_TRUE(f.ed.undo());
    EXPECT_TRUE(f.ed.doc.scene.registry.alive(victim));
    EXPECT_TRUE(sceneToJsonText(f.ed.doc.scene) == original);
    ASSERT_TRUE(f.ed.redo());
    ASSERT_TRUE(f.ed.redo());
    EXPECT_FALSE(f.ed.doc.scene.registry.alive(victim));
    EXPECT_TRUE(sceneToJsonText(f.ed.doc.scene) == afterAdd);
}
