// Unit tests of the editor model (editor/app): commands and the undo stack,
// tools driven by viewport events, the simulation controller, saving. No
// window and no GL: the same Editor the UI drives.

#include "app/editor.hpp"
#include "app/scene_edit.hpp"
#include "app/script.hpp"
#include "app/script_actions.hpp"
#include "app/tools/tools.hpp"

#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world.hpp"

#include "test_support.hpp"

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <random>
#include <set>
#include <thread>

#include <filesystem>
#include <fstream>
#include <sstream>

using namespace stepwise;
using namespace stepwise::editor;

namespace {

const std::filesystem::path kLevels = std::filesystem::path(STEPWISE_SOURCE_DIR) / "levels";

std::string textOf(const Scene& s) { return sceneToJsonText(s); }

using stepwise::test::readFile;

/// A fresh temporary folder per test, removed afterwards.
struct TempDir : stepwise::test::TempDir {
    TempDir() : stepwise::test::TempDir("stepwise-editor-test") {}
};

/// Editor with a level open, a 800x600 viewport, config in a temp folder.
struct Fixture {
    TempDir tmp;
    Editor ed;
    explicit Fixture(const std::string& level) {
        ed.configDir = tmp.path / "config";
        EXPECT_TRUE(ed.open(kLevels / level)) << ed.errorModal;
        ed.setViewportSize(800, 600);
        ed.fitView();
    }
    InputEvent mouse(InputEvent::Type t, Vec2 world, std::uint8_t mods = 0) const {
        InputEvent e;
        e.type = t;
        const Vec2 px = ed.view.toPixels(world);
        e.x = px.x;
        e.y = px.y;
        e.mods = mods;
        return e;
    }
    void click(Vec2 world, std::uint8_t mods = 0) {
        ed.handleViewportEvent(mouse(InputEvent::Type::MouseDown, world, mods));
        ed.handleViewportEvent(mouse(InputEvent::Type::MouseUp, world, mods));
    }
    void drag(Vec2 from, Vec2 to, int moves) {
        ed.handleViewportEvent(mouse(InputEvent::Type::MouseDown, from));
        for (int i = 1; i <= moves; ++i)
            ed.handleViewportEvent(mouse(InputEvent::Type::MouseMove, from + (to - from) * (double(i) / moves)));
        ed.handleViewportEvent(mouse(InputEvent::Type::MouseUp, to));
    }
    Entity named(const std::string& n) const { return findByName(ed.doc.scene.registry, n); }
    Vec2 positionOf(const std::string& n) const {
        return ed.doc.scene.registry.tryGet<Position>(named(n))->value;
    }
};

} // namespace

TEST(CommandStack, UndoRedoRestoreExactBytes) {
    Fixture f("course_notes.json");
    const std::string original = textOf(f.ed.doc.scene);
    ASSERT_TRUE(f.ed.applyEdit("add", [](Scene& s) {
        addCircle(s, {1.25, 2.5}, 0.75);
        return true;
    }));
    const std::string afterAdd = textOf(f.ed.doc.scene);
    ASSERT_NE(afterAdd, original);
    ASSERT_TRUE(f.ed.applyEdit("gravity", [](Scene& s) {
        s.world.gravity.y = -3.5;
        return true;
    }));
    const std::string afterGravity = textOf(f.ed.doc.scene);
    EXPECT_TRUE(f.ed.undo());
    EXPECT_EQ(textOf(f.ed.doc.scene), afterAdd);
    EXPECT_TRUE(f.ed.undo());
    EXPECT_EQ(textOf(f.ed.doc.scene), original);
    EXPECT_FALSE(f.ed.undo());
    EXPECT_FALSE(f.ed.dirty());
    EXPECT_TRUE(f.ed.redo());
    EXPECT_TRUE(f.ed.redo());
    EXPECT_EQ(textOf(f.ed.doc.scene), afterGravity);
    EXPECT_TRUE(f.ed.dirty());
    // A new edit after an undo forgets the redo branch.
    EXPECT_TRUE(f.ed.undo());
    ASSERT_TRUE(f.ed.applyEdit("G", [](Scene& s) {
        s.world.G = 2.0;
        return true;
    }));
    EXPECT_FALSE(f.ed.redo());
}

TEST(CommandStack, EditThatChangesNothingIsNotRecorded) {
    Scene s;
    CommandStack stack;
    EXPECT_FALSE(stack.apply(s, "nothing", [](Scene&) { return false; }));
    EXPECT_FALSE(stack.canUndo());
}

TEST(CommandStack, CapacityDropsOldest) {
    Scene s;
    CommandStack stack(3);
    for (int i = 0; i < 5; ++i)
        ASSERT_TRUE(stack.apply(s, std::to_string(i), [i](Scene& sc) {
            sc.world.G = double(i + 10);
            return true;
        }));
    EXPECT_EQ(stack.size(), 3u);
    while (stack.canUndo()) (void)stack.undo(s);
    EXPECT_EQ(s.world.G, 11.0);  // state before the oldest kept command ("g2")
}

TEST(Tools, OneDragIsOneUndoStep) {
    Fixture f("spring_chain.json");
    const std::string before = textOf(f.ed.doc.scene);
    const Vec2 start = f.positionOf("link2");
    const std::size_t undoDepth = f.ed.commands.size();
    f.drag(start, start + Vec2{1.0, 0.5}, 10);
    const Vec2 moved = f.positionOf("link2");
    EXPECT_NEAR(moved.x, start.x + 1.0, 1e-9);
    EXPECT_NEAR(moved.y, start.y + 0.5, 1e-9);
    EXPECT_EQ(f.ed.commands.size(), undoDepth + 1);  // ten moves, one command
    ASSERT_TRUE(f.ed.undo());
    EXPECT_EQ(textOf(f.ed.doc.scene), before);
    // A second drag is a second step.
    f.drag(start, start + Vec2{0.0, 1.0}, 3);
    f.drag(start + Vec2{0.0, 1.0}, start + Vec2{0.0, 2.0}, 3);
    EXPECT_EQ(f.ed.commands.size(), undoDepth + 2);
}

TEST(Tools, SnapPutsTheGrabbedBodyOnTheGrid) {
    Fixture f("spring_chain.json");
    f.ed.snap = true;
    f.ed.snapSpacing = 0.25;
    const Vec2 start = f.positionOf("link1");
    f.drag(start, start + Vec2{0.61, 0.37}, 4);
    const Vec2 p = f.positionOf("link1");
    EXPECT_NEAR(p.x / 0.25, std::round(p.x / 0.25), 1e-9);
    EXPECT_NEAR(p.y / 0.25, std::round(p.y / 0.25), 1e-9);
}

TEST(Tools, ClickSelectsShiftAddsBoxSelects) {
    Fixture f("spring_chain.json");
    f.click(f.positionOf("link0"));
    ASSERT_EQ(f.ed.selection.size(), 1u);
    EXPECT_EQ(f.ed.selection[0], f.named("link0"));
    f.click(f.positionOf("link3"), kModShift);
    EXPECT_EQ(f.ed.selection.size(), 2u);
    f.click(f.positionOf("link3"), kModShift);  // toggles off
    EXPECT_EQ(f.ed.selection.size(), 1u);
    // Box around link0..link2 only.
    const Vec2 a = f.positionOf("link0"), c = f.positionOf("link2");
    const Vec2 from{std::min(a.x, c.x) - 0.2, std::max(a.y, c.y) + 0.2};
    ASSERT_TRUE(pick(f.ed.doc.scene, from, 0.15).isNull()) << "the box must start on empty space";
    f.drag(from, Vec2{std::max(a.x, c.x) + 0.2, std::min(a.y, c.y) - 0.2}, 2);
    std::vector<std::string> names;
    for (Entity e : f.ed.selection) names.push_back(displayName(f.ed.doc.scene.registry, e));
    EXPECT_NE(std::find(names.begin(), names.end(), "link0"), names.end());
    EXPECT_NE(std::find(names.begin(), names.end(), "link2"), names.end());
    EXPECT_EQ(std::find(names.begin(), names.end(), "link5"), names.end());
}

TEST(Tools, PlaceCircleThenUndo) {
    Fixture f("orbit.json");
    const std::string before = textOf(f.ed.doc.scene);
    const std::size_t n = f.ed.doc.scene.registry.size();
    f.ed.tool = Tool::Circle;
    f.click({3.0, -2.0});
    ASSERT_EQ(f.ed.doc.scene.registry.size(), n + 1);
    const Entity e = f.ed.doc.scene.registry.entities().back();
    EXPECT_TRUE(f.ed.doc.scene.registry.has<Radius>(e));
    EXPECT_NEAR(f.ed.doc.scene.registry.tryGet<Position>(e)->value.x, 3.0, 1e-9);
    EXPECT_EQ(f.ed.selection, std::vector<Entity>{e});
    ASSERT_TRUE(f.ed.handleShortcut(Key::Z, kModCtrl));
    EXPECT_EQ(textOf(f.ed.doc.scene), before);
    EXPECT_TRUE(f.ed.selection.empty());
}

TEST(Tools, SpringBetweenTwoBodiesAndToAnAnchor) {
    Fixture f("orbit.json");
    f.ed.tool = Tool::Spring;
    f.click(f.positionOf("planet"));
    f.click(f.positionOf("comet"));
    const Registry& reg = f.ed.doc.scene.registry;
    const Spring* s = reg.tryGet<Spring>(reg.entities().back());
    ASSERT_NE(s, nullptr);
    EXPECT_EQ(s->a, f.named("planet"));
    EXPECT_EQ(s->b, f.named("comet"));
    ASSERT_TRUE(s->restLength);
    EXPECT_NEAR(*s->restLength, 6.5, 1e-9);
    f.click(f.positionOf("dust"));
    f.click({5.0, 5.0});
    const Spring* anchored = reg.tryGet<Spring>(reg.entities().back());
    ASSERT_NE(anchored, nullptr);
    EXPECT_EQ(anchored->a, f.named("dust"));
    ASSERT_TRUE(anchored->anchor);
    EXPECT_NEAR(anchored->anchor->x, 5.0, 1e-9);
    EXPECT_EQ(checkSceneRelations(f.ed.doc.scene), "");
}

TEST(Tools, JointBetweenTwoBodiesAndToTheWorldSavesAndSimulates) {
    Fixture f("orbit.json");
    f.ed.tool = Tool::Joint;
    f.ed.jointType = "hinge";
    f.click(f.positionOf("planet"));
    f.click(f.positionOf("comet"));
    const Registry& reg = f.ed.doc.scene.registry;
    const Joint* j = reg.tryGet<Joint>(reg.entities().back());
    ASSERT_NE(j, nullptr);
    EXPECT_EQ(j->type, "hinge");
    EXPECT_EQ(reg.tryGet<Name>(j->a)->value, "planet");
    EXPECT_EQ(reg.tryGet<Name>(j->b)->value, "comet");
    EXPECT_FALSE(j->anchor) << "the click point became the locals";
    ASSERT_TRUE(j->referenceAngle);
    // A rope to the world from "dust" to the point clicked in empty space.
    f.ed.jointType = "rope";
    f.click(f.positionOf("dust"));
    f.click({5.0, 5.0});
    const Joint* rope = reg.tryGet<Joint>(reg.entities().back());
    ASSERT_NE(rope, nullptr);
    EXPECT_TRUE(rope->b.isNull());
    EXPECT_NEAR(rope->localB.x, 5.0, 1e-9);  // a world point for the world end
    EXPECT_NEAR(rope->localB.y, 5.0, 1e-9);
    ASSERT_TRUE(rope->length);
    EXPECT_NEAR(*rope->length, length(rope->localB - f.positionOf("dust")), 1e-12);
    EXPECT_EQ(checkSceneRelations(f.ed.doc.scene), "");
    const std::string text = sceneToJsonText(f.ed.doc.scene);
    Result<Scene> again = parseScene(text, "joined.json");
    ASSERT_TRUE(again) << again.error();
    EXPECT_EQ(sceneToJsonText(*again), text);
    EXPECT_TRUE(World::build(f.ed.doc.scene));
    // Deleting a body takes its joints with it (they would name nothing).
    f.ed.selection = {reg.tryGet<Joint>(reg.entities().back())->a};
    ASSERT_TRUE(f.ed.deleteSelection());
    for (Entity e : reg.entities()) EXPECT_FALSE(reg.has<Joint>(e) && reg.tryGet<Joint>(e)->type == "rope");
    EXPECT_EQ(checkSceneRelations(f.ed.doc.scene), "");
}

TEST(Tools, PlaneBoidBrushAttractorAndRotate) {
    Fixture f("orbit.json");
    f.ed.tool = Tool::Plane;
    f.drag({0.0, -8.0}, {0.0, -6.0}, 2);  // normal points up from y = -8
    const Registry& reg = f.ed.doc.scene.registry;
    const Plane* pl = reg.tryGet<Plane>(reg.entities().back());
    ASSERT_NE(pl, nullptr);
    EXPECT_NEAR(pl->normal.y, 1.0, 1e-12);
    EXPECT_NEAR(pl->offset, -8.0, 1e-9);

    const std::size_t n = reg.size();
    const std::size_t depth = f.ed.commands.size();
    f.ed.tool = Tool::Boids;
    f.drag({-6.0, 6.0}, {0.0, 6.0}, 30);
    EXPECT_GE(reg.size(), n + 8);  // 6 m at 0.6 m spacing, plus the first
    EXPECT_EQ(f.ed.commands.size(), depth + 1);  // one stroke, one undo step

    f.ed.tool = Tool::Box;
    f.click({6.0, 6.0});
    const Entity box = reg.entities().back();
    f.ed.tool = Tool::Rotate;
    f.drag({7.0, 6.0}, {6.0, 7.0}, 5);  // a quarter turn counter-clockwise about the centre
    ASSERT_TRUE(reg.has<Angle>(box));
    EXPECT_NEAR(reg.tryGet<Angle>(box)->value, std::acos(-1.0) / 2, 1e-6);
}

TEST(Tools, DeleteTakesAttachedSpringsDuplicateAndPasteRenameAndRewire) {
    Fixture f("spring_chain.json");
    const Registry& reg = f.ed.doc.scene.registry;
    const std::size_t n = reg.size();
    f.ed.select({f.named("link1"), f.named("link2")});
    ASSERT_TRUE(f.ed.handleShortcut(Key::D, kModCtrl));
    ASSERT_EQ(f.ed.selection.size(), 2u);
    EXPECT_EQ(reg.size(), n + 2);
    EXPECT_EQ(checkSceneRelations(f.ed.doc.scene), "");
    // Copy the two links and the spring between them: the pasted spring
    // joins the pasted links, not the originals.
    std::vector<Entity> group{f.named("link1"), f.named("link2")};
    for (Entity s : springsAttachedTo(reg, f.named("link1")))
        for (Entity t : springsAttachedTo(reg, f.named("link2")))
            if (s == t) group.push_back(s);
    ASSERT_EQ(group.size(), 3u) << "spring_chain joins neighbouring links";
    f.ed.select(group);
    f.ed.copySelection();
    ASSERT_TRUE(f.ed.paste());
    const Spring* pasted = nullptr;
    for (Entity e : f.ed.selection)
        if (reg.has<Spring>(e)) pasted = reg.tryGet<Spring>(e);
    ASSERT_NE(pasted, nullptr);
    EXPECT_NE(pasted->a, f.named("link1"));
    EXPECT_NE(pasted->b, f.named("link2"));
    EXPECT_TRUE(reg.alive(pasted->a));
    EXPECT_TRUE(std::find(f.ed.selection.begin(), f.ed.selection.end(), pasted->a) != f.ed.selection.end());
    EXPECT_EQ(checkSceneRelations(f.ed.doc.scene), "");
    // Delete link3: the springs to link2 and link4 go with it.
    const std::size_t springs = springsAttachedTo(reg, f.named("link3")).size();
    ASSERT_GT(springs, 0u);
    const std::size_t before = reg.size();
    f.ed.select({f.named("link3")});
    ASSERT_TRUE(f.ed.handleShortcut(Key::Delete, 0));
    EXPECT_EQ(reg.size(), before - 1 - springs);
    EXPECT_EQ(checkSceneRelations(f.ed.doc.scene), "");
}

TEST(Inspector, MultiSelectionEditAppliesToAllAndIsOneUndoStep) {
    Fixture f("spring_chain.json");
    const ComponentInfo* mass = findComponent("mass");
    ASSERT_NE(mass, nullptr);
    const std::vector<Entity> sel{f.named("link0"), f.named("link1"), f.named("link4")};
    f.ed.select(sel);
    const std::string before = textOf(f.ed.doc.scene);
    const std::uint64_t key = f.ed.newMergeKey();
    // A slider drag: three values, one command.
    for (double v : {0.5, 0.7, 2.5})
        ASSERT_TRUE(f.ed.applyEdit("edit mass", [&](Scene& s) {
            return setFieldOnAll(s, *mass, mass->fields[0], v, f.ed.selection) > 0;
        }, key));
    f.ed.endEdit();
    for (Entity e : sel) EXPECT_EQ(f.ed.doc.scene.registry.tryGet<Mass>(e)->value, 2.5);
    EXPECT_NE(f.ed.doc.scene.registry.tryGet<Mass>(f.named("link2"))->value, 2.5);
    ASSERT_TRUE(f.ed.undo());
    EXPECT_EQ(textOf(f.ed.doc.scene), before);
    // Out of range: refused, nothing changes.
    std::string problem;
    EXPECT_EQ(setFieldOnAll(f.ed.doc.scene, *mass, mass->fields[0], -1.0, sel, &problem), 0u);
    EXPECT_NE(problem.find("mass"), std::string::npos) << problem;
    // Add and remove a component on the whole selection.
    const ComponentInfo* drag = findComponent("restitution");
    ASSERT_NE(drag, nullptr);
    ASSERT_TRUE(f.ed.applyEdit("add", [&](Scene& s) { return addComponentToAll(s, *drag, sel) > 0; }));
    for (Entity e : sel) EXPECT_TRUE(drag->has(f.ed.doc.scene.registry, e));
    ASSERT_TRUE(f.ed.applyEdit("remove", [&](Scene& s) { return removeComponentFromAll(s, *drag, sel) > 0; }));
    for (Entity e : sel) EXPECT_FALSE(drag->has(f.ed.doc.scene.registry, e));
}

TEST(Inspector, CopyEntityIsTableDrivenAndExact) {
    Result<Scene> s = loadSceneFile(kLevels / "render_showcase.json");
    ASSERT_TRUE(s) << s.error();
    // Copy every entity into a fresh scene with the same world: same bytes.
    Scene copy;
    copy.version = s->version;
    copy.world = s->world;
    copy.view = s->view;
    for (Entity e : s->registry.entities()) copyEntity(s->registry, e, copy.registry, copy.registry.create());
    EXPECT_EQ(textOf(copy), textOf(*s));
}

TEST(Simulation, ResetReturnsToTheEditedSceneAndStepBackIsExact) {
    Fixture f("spring_chain.json");
    // An edit before playing is part of the level.
    ASSERT_TRUE(f.ed.applyEdit("gravity", [](Scene& s) {
        s.world.gravity.y = -5.0;
        return true;
    }));
    const std::string edited = textOf(f.ed.doc.scene);
    f.ed.stepForward();
    ASSERT_EQ(f.ed.sim.state(), SimState::Paused) << f.ed.sim.message();
    const std::string afterOne = textOf(f.ed.doc.scene);
    EXPECT_NE(afterOne, edited);
    f.ed.stepForward();
    f.ed.stepForward();
    f.ed.stepBack();
    f.ed.stepBack();
    EXPECT_EQ(textOf(f.ed.doc.scene), afterOne);
    f.ed.stepBack();
    EXPECT_EQ(textOf(f.ed.doc.scene), edited);
    // Play, then edit while paused: the edit applies to the state ...
    f.ed.togglePlay();
    for (int i = 0; i < 10; ++i) f.ed.update(1.0 / 60.0);
    EXPECT_EQ(f.ed.sim.steps(), 10u);
    f.ed.togglePlay();
    ASSERT_TRUE(f.ed.applyEdit("mass", [&](Scene& s) {
        s.registry.tryGet<Mass>(f.named("link3"))->value = 9.0;
        return true;
    }));
    f.ed.stepForward();
    // ... and reset discards it with the simulated state.
    f.ed.resetSimulation();
    EXPECT_EQ(f.ed.sim.state(), SimState::Editing);
    EXPECT_EQ(textOf(f.ed.doc.scene), edited);
    // The edit from before Play is still undoable.
    ASSERT_TRUE(f.ed.undo());
    EXPECT_EQ(f.ed.doc.scene.world.gravity.y, -9.81);
}

TEST(Simulation, SteppingThroughTheEditorMatchesTheWorld) {
    Fixture f("orbit.json");
    Result<World> w = World::build(f.ed.doc.scene);
    ASSERT_TRUE(w) << w.error();
    for (int i = 0; i < 30; ++i) ASSERT_TRUE(w->step());
    Scene expected = f.ed.doc.scene;
    w->writeBack(expected);
    // A step back restores the World's saved state in place, so stepping
    // on gives the same bits (with contacts too: test_editor_state).
    for (int i = 0; i < 20; ++i) f.ed.stepForward();
    for (int i = 0; i < 5; ++i) f.ed.stepBack();
    for (int i = 0; i < 15; ++i) f.ed.stepForward();
    EXPECT_EQ(textOf(f.ed.doc.scene), textOf(expected));
}

TEST(Simulation, AMouseSpringDragBuildsTheWorldOnceAndPullsTheBody) {
    Fixture f("spring_chain.json");  // link11, the free end, starts at (6, 0)
    f.ed.tool = Tool::Select;
    f.ed.togglePlay();
    f.ed.update(1.0 / 60.0);
    const std::uint64_t buildsBefore = f.ed.sim.worldBuilds();
    const Entity link = findByName(f.ed.doc.scene.registry, "link11");
    const Vec2 grab = f.ed.doc.scene.registry.tryGet<Position>(link)->value;
    f.ed.handleViewportEvent(f.mouse(InputEvent::Type::MouseDown, grab));
    ASSERT_TRUE(f.ed.sim.mouseSpring);
    // The cursor moves every frame; the anchor follows without a rebuild.
    const Vec2 target{6.0, 3.0};
    for (int i = 1; i <= 60; ++i) {
        f.ed.handleViewportEvent(f.mouse(InputEvent::Type::MouseMove, grab + (target - grab) * std::min(1.0, i / 20.0)));
        f.ed.update(1.0 / 60.0);
    }
    EXPECT_EQ(f.ed.sim.worldBuilds(), buildsBefore + 1);  // once, when the drag began
    // Pulled up against gravity toward the cursor, from below y = 0.
    const Vec2 held = f.ed.doc.scene.registry.tryGet<Position>(link)->value;
    EXPECT_GT(held.y, 1.0) << held.x << ", " << held.y;
    f.ed.handleViewportEvent(f.mouse(InputEvent::Type::MouseUp, target));
    EXPECT_FALSE(f.ed.sim.mouseSpring);
    f.ed.update(1.0 / 60.0);
    EXPECT_EQ(f.ed.sim.worldBuilds(), buildsBefore + 2);  // released: rebuilt without it
}

TEST(Simulation, DisabledSystemIsLeftOutOfTheWorld) {
    Fixture f("spring_chain.json");
    f.ed.sim.disabledSystems.insert("springs");
    f.ed.stepForward();
    ASSERT_NE(f.ed.sim.world(), nullptr) << f.ed.sim.message();
    const auto active = f.ed.sim.world()->activeSystems();
    EXPECT_EQ(std::find(active.begin(), active.end(), "springs"), active.end());
    EXPECT_NE(std::find(active.begin(), active.end(), "gravity"), active.end());
    // The document keeps its springs.
    EXPECT_GT(f.ed.doc.scene.registry.count<Spring>(), 0u);
}

TEST(Simulation, DivergencePausesAndNamesEntityAndQuantity) {
    Fixture f("orbit.json");
    ASSERT_TRUE(f.ed.applyEdit("blow up", [&](Scene& s) {
        // G so large that the pull on the planet (first body) overflows to inf in the first step.
        s.world.G = 1e308;
        return true;
    }));
    f.ed.togglePlay();
    for (int i = 0; i < 5 && f.ed.sim.state() == SimState::Playing; ++i) f.ed.update(1.0 / 60.0);
    EXPECT_EQ(f.ed.sim.state(), SimState::Paused);
    EXPECT_TRUE(f.ed.sim.diverged());
    EXPECT_NE(f.ed.sim.message().find("planet"), std::string::npos) << f.ed.sim.message();
    EXPECT_NE(f.ed.sim.message().find("became"), std::string::npos) << f.ed.sim.message();
}

TEST(Simulation, TimeScaleSetsStepsPerFrame) {
    Fixture f("orbit.json");  // dt = 1/240
    f.ed.sim.timeScale = 0.5;
    f.ed.togglePlay();
    for (int i = 0; i < 10; ++i) f.ed.update(1.0 / 60.0);
    EXPECT_EQ(f.ed.sim.steps(), 20u);  // 10 frames * (1/60 * 0.5) / (1/240)
}

TEST(Simulation, ASlowFrameDropsTimeInsteadOfTakingMoreSteps) {
    Fixture f("orbit.json");  // dt = 1/240: a 1/60 s frame is due 4 steps
    f.ed.togglePlay();
    f.ed.update(1.0 / 60.0);
    EXPECT_EQ(f.ed.sim.steps(), 4u);
    EXPECT_FALSE(f.ed.sim.behind());
    // A budget already spent after the first step (as on a frame where one
    // step takes longer than the budget): one step per frame, the rest of
    // the frame's time dropped, and the editor says it is behind.
    f.ed.sim.physicsBudgetMs = -1.0;
    for (int i = 0; i < 5; ++i) f.ed.update(1.0 / 60.0);
    EXPECT_EQ(f.ed.sim.steps(), 9u);
    EXPECT_TRUE(f.ed.sim.behind());
    // The dropped time is not owed later: back on budget, 4 per frame again.
    f.ed.sim.physicsBudgetMs = 1e9;
    f.ed.update(1.0 / 60.0);
    EXPECT_EQ(f.ed.sim.steps(), 13u);
    EXPECT_FALSE(f.ed.sim.behind());
}

TEST(Files, SaveIsAtomicAndEqualsTheExpectedJson) {
    Fixture f("orbit.json");
    const std::filesystem::path out = f.tmp.path / "out.json";
    ASSERT_TRUE(f.ed.applyEdit("add", [](Scene& s) {
        addCircle(s, {1.0, 2.0}, 0.25);
        return true;
    }));
    Scene expected = f.ed.doc.scene;
    ASSERT_TRUE(f.ed.saveAs(out)) << f.ed.errorModal;
    EXPECT_EQ(readFile(out), sceneToJsonText(expected));
    EXPECT_FALSE(f.ed.dirty());
    // No temporaries left next to it.
    for (const auto& entry : std::filesystem::directory_iterator(f.tmp.path))
        EXPECT_TRUE(entry.path().filename() == "out.json" || entry.path().filename() == "config") << entry.path();
    // While playing, Save writes the edited level, not the state.
    f.ed.togglePlay();
    for (int i = 0; i < 10; ++i) f.ed.update(1.0 / 60.0);
    ASSERT_TRUE(f.ed.handleShortcut(Key::S, kModCtrl));
    EXPECT_EQ(readFile(out), sceneToJsonText(expected));
}

TEST(Files, UnwritableFolderAndBadLevelGiveMessagesNotCrashes) {
    Fixture f("orbit.json");
    const std::string before = textOf(f.ed.doc.scene);
    EXPECT_FALSE(f.ed.saveAs(f.tmp.path / "missing" / "folder" / "x.json"));
    EXPECT_FALSE(f.ed.errorModal.empty());
    f.ed.errorModal.clear();
    const std::filesystem::path bad = f.tmp.path / "bad.json";
    { std::ofstream(bad) << "{\"entities\": [ {\"mass\": -1} ]}"; }
    EXPECT_FALSE(f.ed.open(bad));
    EXPECT_NE(f.ed.errorModal.find("mass"), std::string::npos) << f.ed.errorModal;
    EXPECT_EQ(textOf(f.ed.doc.scene), before);  // the document is untouched
    f.ed.errorModal.clear();
    EXPECT_FALSE(f.ed.open(f.tmp.path / "no-such-level.json"));
    EXPECT_FALSE(f.ed.errorModal.empty());
    // An invalid scene (duplicate names) is refused before writing.
    ASSERT_TRUE(f.ed.applyEdit("dup", [](Scene& s) {
        const Entity e = s.registry.create();
        s.registry.emplace(e, Name{"sun"});
        s.registry.emplace(e, Position{});
        return true;
    }));
    EXPECT_FALSE(f.ed.saveAs(f.tmp.path / "dup.json"));
    EXPECT_FALSE(std::filesystem::exists(f.tmp.path / "dup.json"));
}

TEST(Files, AReadOnlyFolderGivesAMessageForSaveAndAutosave) {
    // /proc takes no new files, even from root (CI runs as root, where a
    // chmod'ed folder would still be writable).
    Fixture f("orbit.json");
    ASSERT_TRUE(f.ed.applyEdit("G", [](Scene& s) {
        s.world.G = 4.0;
        return true;
    }));
    const std::string edited = textOf(f.ed.doc.scene);
    EXPECT_FALSE(f.ed.saveAs("/proc/stepwise-level.json"));
    EXPECT_NE(f.ed.errorModal.find("Cannot save /proc/stepwise-level.json"), std::string::npos) << f.ed.errorModal;
    EXPECT_TRUE(f.ed.dirty());  // nothing was saved, and nothing is lost
    EXPECT_EQ(textOf(f.ed.doc.scene), edited);
    f.ed.configDir = "/proc/stepwise-config";
    EXPECT_FALSE(f.ed.tickAutosave(0.0));
    EXPECT_FALSE(f.ed.tickAutosave(31.0));
    EXPECT_EQ(f.ed.status.rfind("autosave failed: ", 0), 0u) << f.ed.status;
    EXPECT_EQ(textOf(f.ed.doc.scene), edited);
}

TEST(Files, UnsavedChangesAreAskedAbout) {
    Fixture f("orbit.json");
    f.ed.request(PendingAction::New);  // clean: happens at once
    EXPECT_EQ(f.ed.doc.title(), "untitled");
    ASSERT_TRUE(f.ed.open(kLevels / "orbit.json"));
    ASSERT_TRUE(f.ed.applyEdit("G", [](Scene& s) {
        s.world.G = 3.0;
        return true;
    }));
    f.ed.request(PendingAction::Open, kLevels / "spring_chain.json");
    EXPECT_EQ(f.ed.uiRequest, UiRequest::ConfirmDiscard);
    EXPECT_EQ(f.ed.doc.title(), "orbit.json");
    f.ed.resolvePending(Editor::Resolution::Cancel);
    EXPECT_EQ(f.ed.doc.title(), "orbit.json");
    f.ed.request(PendingAction::Open, kLevels / "spring_chain.json");
    f.ed.resolvePending(Editor::Resolution::Discard);
    EXPECT_EQ(f.ed.doc.title(), "spring_chain.json");
}

TEST(Files, AutosaveWritesRecoveryAndRecoverRestoresIt) {
    Fixture f("orbit.json");
    const std::filesystem::path level = f.tmp.path / "level.json";
    std::filesystem::copy_file(kLevels / "orbit.json", level);
    ASSERT_TRUE(f.ed.open(level));
    EXPECT_FALSE(f.ed.tickAutosave(0.0));
    ASSERT_TRUE(f.ed.applyEdit("G", [](Scene& s) {
        s.world.G = 7.0;
        return true;
    }));
    EXPECT_FALSE(f.ed.tickAutosave(10.0));  // not 30 s yet
    EXPECT_TRUE(f.ed.tickAutosave(31.0));
    const std::string edited = textOf(f.ed.doc.scene);
    // A "crash": a new editor on the same level finds the recovery file.
    Editor again;
    again.configDir = f.ed.configDir;
    ASSERT_TRUE(again.open(level));
    const auto recovery = again.recoveryAvailable();
    ASSERT_TRUE(recovery);
    ASSERT_TRUE(again.recover(*recovery));
    EXPECT_EQ(textOf(again.doc.scene), edited);
    EXPECT_TRUE(again.dirty());
    ASSERT_TRUE(again.save());
    EXPECT_FALSE(again.recoveryAvailable());  // saving removes it
}

TEST(Files, SaveAsRemovesTheOldPathsRecoveryCopy) {
    Fixture f("orbit.json");
    const std::filesystem::path a = f.tmp.path / "a.json", b = f.tmp.path / "b.json";
    std::filesystem::copy_file(kLevels / "orbit.json", a);
    ASSERT_TRUE(f.ed.open(a));
    ASSERT_TRUE(f.ed.applyEdit("G", [](Scene& s) {
        s.world.G = 5.0;
        return true;
    }));
    EXPECT_FALSE(f.ed.tickAutosave(0.0));
    ASSERT_TRUE(f.ed.tickAutosave(31.0));
    const std::filesystem::path recoveryOfA = f.ed.doc.recoveryPath(f.ed.configDir);
    ASSERT_TRUE(std::filesystem::exists(recoveryOfA));
    ASSERT_TRUE(f.ed.saveAs(b));
    // The work is in b.json now; a.json's copy would be offered, stale, the
    // next time a.json opens.
    EXPECT_FALSE(std::filesystem::exists(recoveryOfA));
    Editor again;
    again.configDir = f.ed.configDir;
    ASSERT_TRUE(again.open(a));
    EXPECT_FALSE(again.recoveryAvailable());
}

// Issue 7: "the same holds for the editor's autosave". A child process
// runs the editor's real autosave path (Editor::tickAutosave) in a loop,
// alternating between two edited versions of the level, and is killed with
// SIGKILL at random points of its later autosaves. After every kill the
// recovery file is exactly one of the two versions, never partial, and a
// fresh editor recovers it.
TEST(Files, AutosaveKilledAtRandomPointsLeavesAWholeRecoveryFile) {
    constexpr int kKills = 120;
    Fixture f("pile.json");  // ~2,000 bodies: an autosave long enough to be hit mid-write
    const std::filesystem::path level = f.tmp.path / "level.json";
    std::filesystem::copy_file(kLevels / "pile.json", level);
    ASSERT_TRUE(f.ed.open(level));
    const std::filesystem::path recovery = f.ed.doc.recoveryPath(f.ed.configDir);
    // The two versions the child alternates between: G = 2 and G = 3.
    std::string versions[2];
    for (int v = 0; v < 2; ++v) {
        Scene s = f.ed.levelToSave();
        s.world.G = 2.0 + v;
        versions[v] = sceneToJsonText(s);
    }
    ASSERT_NE(versions[0], versions[1]);
    const auto autosave = [&f](int k, double now) {
        f.ed.applyEdit("G", [k](Scene& s) {
            s.world.G = 2.0 + (k % 2);
            return true;
        });
        return f.ed.tickAutosave(now);
    };
    // How long one autosave takes here (sanitizers make it slower): the
    // kills are spread over two of them.
    ASSERT_FALSE(autosave(0, 0.0));  // the first tick starts the 30 s clock
    const auto t0 = std::chrono::steady_clock::now();
    ASSERT_TRUE(autosave(1, 31.0));
    const auto micros = std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now() - t0).count();
    std::filesystem::remove(recovery);

    std::mt19937 rng(20261201u);
    std::uniform_int_distribution<long long> delayMicros(0, 2 * micros);
    for (int kill = 0; kill < kKills; ++kill) {
        // One whole autosave first, then autosave forever (a new version
        // each time) until killed.
        double now = 100.0 + 31.0 * kill;
        int k = kill;
        const std::string killed = stepwise::test::killWhileWorking(
            [&] { return autosave(k, now); }, [&] { return autosave(++k, now += 31.0); },
            std::chrono::microseconds(delayMicros(rng)));
        ASSERT_EQ(killed, "") << "kill " << kill;
        const std::string onDisk = readFile(recovery);
        ASSERT_TRUE(onDisk == versions[0] || onDisk == versions[1])
            << "kill " << kill << ": the recovery file is neither version (" << onDisk.size() << " bytes)";
    }
    // A fresh editor on the level is offered the recovery copy and gets it whole.
    Editor again;
    again.configDir = f.ed.configDir;
    ASSERT_TRUE(again.open(level));
    const auto offered = again.recoveryAvailable();
    ASSERT_TRUE(offered);
    ASSERT_TRUE(again.recover(*offered));
    const double g = again.doc.scene.world.G;
    EXPECT_TRUE(g == 2.0 || g == 3.0) << g;
}

TEST(Camera, ZoomKeepsThePointUnderTheCursor) {
    ViewCamera v;
    v.width = 640;
    v.height = 480;
    v.camera.center = {1.0, 2.0};
    const Vec2 cursor{100.0, 400.0};
    const Vec2 before = v.toWorld(cursor);
    v.zoomAt(cursor, 3.0);
    const Vec2 after = v.toWorld(cursor);
    EXPECT_NEAR(before.x, after.x, 1e-9);
    EXPECT_NEAR(before.y, after.y, 1e-9);
    const Vec2 round = v.toWorld(v.toPixels({-3.0, 7.5}));
    EXPECT_NEAR(round.x, -3.0, 1e-9);
    EXPECT_NEAR(round.y, 7.5, 1e-9);
}

TEST(Script, ParsesEveryCommandAndRejectsBadLinesWithTheLineNumber) {
    const char* text = R"(# demo
key Space
key Ctrl+Shift+Z
click 100 200
click world 1.5 -2 right
drag world 0 0 3 4 12
wheel 2 400 300
text "mass 3"
wait 10
step 5
tool circle
overlay velocity on
saveas /tmp/x.json
)";
    Result<std::vector<ScriptCommand>> s = parseScript(text, "demo.txt");
    ASSERT_TRUE(s) << s.error();
    ASSERT_EQ(s->size(), 12u);
    EXPECT_EQ((*s)[1].key, Key::Z);
    EXPECT_EQ((*s)[1].mods, kModCtrl | kModShift);
    EXPECT_TRUE((*s)[3].a.world);
    EXPECT_EQ((*s)[3].button, MouseButton::Right);
    EXPECT_EQ((*s)[4].count, 12);
    EXPECT_EQ((*s)[6].text, "mass 3");
    EXPECT_EQ((*s)[8].count, 5);
    Result<std::vector<ScriptCommand>> bad = parseScript("wait 1\nclick 10\n", "b.txt");
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().find("b.txt:2:"), std::string::npos) << bad.error();
    Result<std::vector<ScriptCommand>> badKey = parseScript("key Hyper+Q\n", "c.txt");
    ASSERT_FALSE(badKey);
    EXPECT_NE(badKey.error().find("Hyper"), std::string::npos);
}

// ---- one table of tools, one of script actions ------------------------------

namespace {

/// The scripted runner's side, recorded: frames drawn, panels, tabs, shots.
struct RecordingHost final : ScriptHost {
    int frames = 0;
    std::vector<std::string> calls, errors;
    void frame() override { ++frames; }
    bool showWindow(const std::string& name, bool on) override {
        calls.push_back("window " + name + (on ? " on" : " off"));
        return name == "debug";
    }
    bool showDebugTab(const std::string& name) override {
        calls.push_back("tab " + name);
        return name == "plots";
    }
    Result<void> screenshot(const std::string& path) override {
        calls.push_back("screenshot " + path);
        return {};
    }
    void reportError(const std::string& message) override { errors.push_back(message); }
};

/// Parses one script line and runs it as the headless runner does.
bool runLine(Editor& ed, RecordingHost& host, const std::string& line) {
    Result<std::vector<ScriptCommand>> parsed = parseScript(line + "\n", "t.txt");
    EXPECT_TRUE(parsed) << parsed.error();
    if (!parsed) return false;
    EXPECT_EQ(parsed->size(), 1u);
    return runScriptAction(ed, host, parsed->front(), "t.txt");
}

} // namespace

TEST(ToolTable, EveryToolHasOneKeyOneScriptNameAndALeftClickHandler) {
    std::set<std::string_view> names;
    for (std::size_t i = 0; i < kToolCount; ++i) {
        const ToolInfo& info = toolTable()[i];
        EXPECT_EQ(info.tool, Tool(i));
        EXPECT_TRUE(names.insert(info.scriptName).second) << info.scriptName;
        EXPECT_EQ(toolFromScriptName(info.scriptName), info.tool);
        EXPECT_EQ(toolForKey(toolKey(info.tool)), info.tool);
        EXPECT_EQ(toolName(info.tool), info.label);
        EXPECT_NE(info.press, nullptr);
    }
    EXPECT_EQ(toolKey(Tool::Select), Key::Num1);
    EXPECT_EQ(toolKey(Tool::Polygon), Key::Num0);
    EXPECT_EQ(toolFromScriptName("wall"), std::nullopt) << "the script calls the Wall tool plane";
    EXPECT_EQ(toolScriptNames("|"), "select|rotate|circle|box|plane|spring|attractor|boids|joint|polygon");
    EXPECT_EQ(toolHelpNames(), "select, rotate, circle, box, wall, spring, attractor, boid brush, joint, polygon");
}

TEST(ToolTable, KeysAndTheScriptPickEveryTool) {
    Editor ed;
    RecordingHost host;
    for (const ToolInfo& info : toolTable()) {
        ed.tool = Tool::Select;
        EXPECT_TRUE(ed.handleShortcut(toolKey(info.tool), kModNone));
        EXPECT_EQ(ed.tool, info.tool) << info.scriptName;
        ed.tool = Tool::Select;
        EXPECT_TRUE(runLine(ed, host, "tool " + std::string(info.scriptName)));
        EXPECT_EQ(ed.tool, info.tool) << info.scriptName;
    }
    EXPECT_TRUE(host.errors.empty());
}

// The usage line listed eight of the ten tools (no joint, no polygon).
TEST(ScriptActions, UsageAndUnknownToolListEveryTool) {
    Result<std::vector<ScriptCommand>> bare = parseScript("tool\n", "u.txt");
    ASSERT_FALSE(bare);
    EXPECT_EQ(bare.error(), "u.txt:1: expected: tool select|rotate|circle|box|plane|spring|attractor|boids|joint|polygon");
    Editor ed;
    RecordingHost host;
    EXPECT_FALSE(runLine(ed, host, "tool wall"));
    ASSERT_EQ(host.errors.size(), 1u);
    EXPECT_EQ(host.errors[0], "t.txt:1: tool: unknown tool \"wall\" (select, rotate, circle, box, plane, spring, "
                              "attractor, boids, joint, polygon)");
}

TEST(ScriptActions, TheParserChecksArgumentsAgainstTheTable) {
    for (const ScriptAction& a : scriptActions()) {
        EXPECT_EQ(findScriptAction(a.name), &a);
        // One argument too many is refused with the action's usage.
        std::string line = a.name;
        for (std::size_t i = 0; i <= a.maxArgs && a.maxArgs < 1000; ++i) line += " x";
        if (a.maxArgs >= 1000) continue;
        Result<std::vector<ScriptCommand>> r = parseScript(line + "\n", "a.txt");
        ASSERT_FALSE(r) << line;
        EXPECT_EQ(r.error(), "a.txt:1: expected: " + a.usage) << line;
    }
    EXPECT_EQ(findScriptAction("teleport"), nullptr);
    Result<std::vector<ScriptCommand>> steps = parseScript("step 0\n", "s.txt");
    ASSERT_FALSE(steps);
    EXPECT_EQ(steps.error(), "s.txt:1: N must be 1..100000");
}

TEST(ScriptActions, PanelsTabsAndShotsGoToTheHostAndAFailureStopsWithTheLine) {
    Editor ed;
    RecordingHost host;
    EXPECT_TRUE(runLine(ed, host, "window debug off"));
    EXPECT_TRUE(runLine(ed, host, "tab plots"));
    const int framesBefore = host.frames;
    EXPECT_TRUE(runLine(ed, host, "screenshot /tmp/shot.png"));
    EXPECT_EQ(host.frames, framesBefore + 1) << "a screenshot draws its own frame, then none after it";
    EXPECT_EQ(host.calls, (std::vector<std::string>{"window debug off", "tab plots", "screenshot /tmp/shot.png"}));
    EXPECT_FALSE(runLine(ed, host, "window sidebar on"));
    EXPECT_FALSE(runLine(ed, host, "select nobody"));
    EXPECT_EQ(host.errors, (std::vector<std::string>{
                               "t.txt:1: window: expected inspector|world|tools|entities|debug|help on|off",
                               "t.txt:1: select: no entity named \"nobody\""}));
}

// ---- polygon tool (issue 15) ------------------------------------------------

TEST(PolygonTool, ClickedVerticesMakeTheirConvexHullAsOneUndoStep) {
    Fixture f("orbit.json");
    const std::string before = textOf(f.ed.doc.scene);
    const std::size_t n = f.ed.doc.scene.registry.size(), undoDepth = f.ed.commands.size();
    f.ed.tool = Tool::Polygon;
    // A square's corners with a point inside it: the hull drops the inner one.
    for (Vec2 p : {Vec2{4, -3}, Vec2{6, -3}, Vec2{5, -2.5}, Vec2{6, -1}, Vec2{4, -1}}) f.click(p);
    EXPECT_EQ(f.ed.polygonClicks().size(), 5u);
    EXPECT_EQ(f.ed.doc.scene.registry.size(), n) << "nothing is made before the outline is finished";
    // The preview is the hull, counter-clockwise, with the cursor (inside) adding nothing.
    const std::vector<Vec2> preview = f.ed.polygonPreview();
    ASSERT_EQ(preview.size(), 4u);
    EXPECT_EQ(polygonProblem(preview), "");
    ASSERT_TRUE(f.ed.handleShortcut(Key::Enter, 0));
    ASSERT_EQ(f.ed.doc.scene.registry.size(), n + 1);
    const Entity e = f.ed.doc.scene.registry.entities().back();
    const Polygon* poly = f.ed.doc.scene.registry.tryGet<Polygon>(e);
    ASSERT_NE(poly, nullptr);
    EXPECT_EQ(poly->vertices.size(), 4u);
    // Positioned at the centroid, vertices about it: the centre of mass is the position.
    const Vec2 p = f.ed.doc.scene.registry.tryGet<Position>(e)->value;
    EXPECT_NEAR(p.x, 5.0, 1e-9);
    EXPECT_NEAR(p.y, -2.0, 1e-9);
    const PolygonMassProperties props = polygonMassProperties(poly->vertices);
    EXPECT_NEAR(props.centroid.x, 0.0, 1e-12);
    EXPECT_NEAR(props.area, 4.0, 1e-9);
    EXPECT_EQ(f.ed.selection, std::vector<Entity>{e});
    EXPECT_TRUE(f.ed.polygonClicks().empty());
    EXPECT_EQ(f.ed.commands.size(), undoDepth + 1);
    ASSERT_TRUE(f.ed.undo());
    EXPECT_EQ(textOf(f.ed.doc.scene), before);
    // It saves and loads: the level stays valid.
    ASSERT_TRUE(f.ed.redo());
    Result<Scene> again = parseScene(textOf(f.ed.doc.scene), "edited.json");
    EXPECT_TRUE(again) << again.error();
}

TEST(PolygonTool, CollinearClicksAreRefusedAndEscapeCancels) {
    Fixture f("orbit.json");
    const std::string before = textOf(f.ed.doc.scene);
    f.ed.tool = Tool::Polygon;
    for (Vec2 p : {Vec2{4, -3}, Vec2{5, -3}, Vec2{6, -3}}) f.click(p);
    EXPECT_FALSE(f.ed.finishPolygon());
    EXPECT_EQ(f.ed.status, "polygon: needs 3 vertices that are not on one line");
    EXPECT_EQ(textOf(f.ed.doc.scene), before);
    f.click({4, -3});
    f.click({5, -2});
    ASSERT_TRUE(f.ed.handleShortcut(Key::Escape, 0));
    EXPECT_TRUE(f.ed.polygonClicks().empty());
    EXPECT_TRUE(f.ed.polygonPreview().empty());
    EXPECT_EQ(textOf(f.ed.doc.scene), before);
}

TEST(PolygonTool, ANinthHullVertexIsRefused) {
    Fixture f("orbit.json");
    f.ed.tool = Tool::Polygon;
    for (const Vec2 v : regularPolygon(9, 2.0, 0.0)) f.click(v + Vec2{4.0, -3.0});
    EXPECT_EQ(f.ed.polygonClicks().size(), 8u);
    EXPECT_EQ(f.ed.status, "polygon: at most 8 vertices; press Enter to make it");
    ASSERT_TRUE(f.ed.finishPolygon());
    const Entity e = f.ed.doc.scene.registry.entities().back();
    EXPECT_EQ(f.ed.doc.scene.registry.tryGet<Polygon>(e)->vertices.size(), 8u);
}

TEST(PolygonTool, RegularPolygonDraggedFromItsCentre) {
    Fixture f("orbit.json");
    const std::size_t n = f.ed.doc.scene.registry.size(), undoDepth = f.ed.commands.size();
    f.ed.tool = Tool::Polygon;
    f.ed.polygonSides = 6;
    const Vec2 centre{4.0, -3.0}, rim{5.5, -3.0};
    f.ed.handleViewportEvent(f.mouse(InputEvent::Type::MouseDown, centre));
    f.ed.handleViewportEvent(f.mouse(InputEvent::Type::MouseMove, rim));
    const std::vector<Vec2> preview = f.ed.polygonPreview();
    ASSERT_EQ(preview.size(), 6u) << "previewed while dragging";
    EXPECT_NEAR(preview[0].x, rim.x, 1e-6);
    EXPECT_NEAR(preview[0].y, rim.y, 1e-6);
    f.ed.handleViewportEvent(f.mouse(InputEvent::Type::MouseUp, rim));
    ASSERT_EQ(f.ed.doc.scene.registry.size(), n + 1);
    const Entity e = f.ed.doc.scene.registry.entities().back();
    const Polygon* poly = f.ed.doc.scene.registry.tryGet<Polygon>(e);
    ASSERT_NE(poly, nullptr);
    ASSERT_EQ(poly->vertices.size(), 6u);
    EXPECT_NEAR(f.ed.doc.scene.registry.tryGet<Position>(e)->value.x, centre.x, 1e-6);
    // Circumradius 1.5: area 3 sqrt(3)/2 r^2.
    EXPECT_NEAR(polygonMassProperties(poly->vertices).area, 1.5 * std::sqrt(3.0) * 1.5 * 1.5, 1e-4);
    EXPECT_EQ(f.ed.commands.size(), undoDepth + 1);
    // A click without a drag makes nothing.
    f.click({0.0, 5.0});
    EXPECT_EQ(f.ed.doc.scene.registry.size(), n + 1);
}

TEST(PolygonTool, TheInspectorRefusesADentAndKeepsTheOldOutline) {
    Fixture f("orbit.json");
    Entity e;
    ASSERT_TRUE(f.ed.applyEdit("add", [&](Scene& s) {
        e = addPolygon(s, {{0, 0}, {2, 0}, {2, 2}, {0, 2}});
        return !e.isNull();
    }));
    const ComponentInfo* info = findComponent("polygon");
    const std::vector<Vec2> before = f.ed.doc.scene.registry.tryGet<Polygon>(e)->vertices;
    std::string problem;
    const std::vector<Vec2> dent{{-1, -1}, {1, -1}, {-0.25, -0.25}, {-1, 1}};
    EXPECT_EQ(setFieldOnAll(f.ed.doc.scene, *info, info->fields[0], dent, {e}, &problem), 0u);
    EXPECT_EQ(problem, "\"polygon\" polygon.vertices/2: not convex: the outline turns clockwise at vertex 2 {\"x\": -0.25, \"y\": "
                       "-0.25}; "
                       "a polygon shape must be convex (split the shape into convex pieces)");
    EXPECT_EQ(f.ed.doc.scene.registry.tryGet<Polygon>(e)->vertices, before);
    const std::vector<Vec2> kite{{-1, -1}, {1, -1}, {1.5, 0.5}, {-1, 1}};
    EXPECT_EQ(setFieldOnAll(f.ed.doc.scene, *info, info->fields[0], kite, {e}, &problem), 1u);
    EXPECT_EQ(f.ed.doc.scene.registry.tryGet<Polygon>(e)->vertices, kite);
}

TEST(PolygonTool, ConvexHullIsCounterClockwiseWithoutCollinearPoints) {
    const std::vector<Vec2> hull = convexHull({{0, 0}, {1, 0}, {2, 0}, {2, 2}, {1, 1}, {0, 2}, {0, 0}, {1, 2}});
    ASSERT_EQ(hull.size(), 4u);
    EXPECT_EQ(polygonProblem(hull), "");
    EXPECT_EQ(convexHull({{0, 0}, {1, 1}, {2, 2}}).size(), 2u);
}

// ---- handles in memory, names in files ------------------------------------------------

namespace {

/// Renames `e` through the inspector's path (setFieldOnAll on "name").
bool rename(Fixture& f, Entity e, const std::string& to, std::string* problem = nullptr) {
    const ComponentInfo* name = findComponent("name");
    return f.ed.applyEdit("rename", [&](Scene& s) {
        return setFieldOnAll(s, *name, name->fields[0], std::string(to), {e}, problem) > 0;
    });
}

} // namespace

TEST(Springs, RenamingABodyKeepsItsSpringPlaysAndSavesTheNewName) {
    // default.json: "pendulum spring" holds "bob" 2.2 m below an anchor.
    Fixture f("default.json");
    const Entity bob = f.named("bob");
    ASSERT_FALSE(bob.isNull());
    ASSERT_EQ(springsAttachedTo(f.ed.doc.scene.registry, bob).size(), 1u);
    ASSERT_TRUE(rename(f, bob, "pendulum"));
    EXPECT_EQ(f.named("bob"), Entity{});
    EXPECT_EQ(springsAttachedTo(f.ed.doc.scene.registry, bob).size(), 1u) << "the spring follows the body, not its old name";
    EXPECT_EQ(checkSceneRelations(f.ed.doc.scene), "");

    // Play two seconds: without its spring bob would fall about 20 m; on it
    // it swings at about the rest length from the anchor (0, 7.5).
    f.ed.togglePlay();
    ASSERT_EQ(f.ed.sim.state(), SimState::Playing) << f.ed.sim.message();
    f.ed.togglePlay();
    for (int i = 0; i < 120; ++i) f.ed.stepForward();
    ASSERT_TRUE(f.ed.sim.message().empty() || f.ed.sim.message().find("no entity") == std::string::npos)
        << f.ed.sim.message();
    const Vec2 p = f.ed.doc.scene.registry.tryGet<Position>(bob)->value;
    EXPECT_LT(length(p - Vec2{0.0, 7.5}), 3.5) << "bob at " << p.x << ", " << p.y;
    f.ed.resetSimulation();

    // Saved with the new name, and it loads back attached.
    const std::filesystem::path out = f.tmp.path / "renamed.json";
    ASSERT_TRUE(f.ed.saveAs(out)) << f.ed.errorModal;
    const std::string text = readFile(out);
    EXPECT_NE(text.find("\"a\": \"pendulum\""), std::string::npos) << text;
    EXPECT_EQ(text.find("\"bob\""), std::string::npos) << text;
    Result<Scene> back = loadSceneFile(out);
    ASSERT_TRUE(back) << back.error();
    const Entity spring = findByName(back->registry, "pendulum spring");
    ASSERT_FALSE(spring.isNull());
    EXPECT_EQ(back->registry.tryGet<Spring>(spring)->a, findByName(back->registry, "pendulum"));
}

TEST(Springs, EndsArePickedInTheViewportOrTheEntityList) {
    Fixture f("default.json");
    const Entity spring = f.named("pendulum spring");
    const ComponentInfo* info = findComponent("spring");
    const FieldInfo* a = &info->fields[0];
    ASSERT_EQ(a->kind, FieldKind::EntityRef);
    f.ed.select({spring});
    // Viewport: arm the pick, click the wrecking ball; the Select tool does
    // not select it, the click answers the pick.
    f.ed.startReferencePick(*info, *a, {spring});
    f.click(f.positionOf("wrecking ball"));
    EXPECT_FALSE(f.ed.referencePick.has_value());
    EXPECT_EQ(f.ed.doc.scene.registry.tryGet<Spring>(spring)->a, f.named("wrecking ball"));
    EXPECT_EQ(f.ed.selection, std::vector<Entity>{spring});
    ASSERT_TRUE(f.ed.undo());
    EXPECT_EQ(f.ed.doc.scene.registry.tryGet<Spring>(spring)->a, f.named("bob"));
    // The entity list calls finishReferencePick with the row's entity; a
    // wall is not a body and is refused.
    f.ed.startReferencePick(*info, *a, {spring});
    EXPECT_FALSE(f.ed.finishReferencePick(f.named("floor")));
    EXPECT_EQ(f.ed.doc.scene.registry.tryGet<Spring>(spring)->a, f.named("bob"));
    // Esc cancels an armed pick.
    f.ed.startReferencePick(*info, *a, {spring});
    EXPECT_TRUE(f.ed.handleShortcut(Key::Escape, 0));
    EXPECT_FALSE(f.ed.referencePick.has_value());
}

TEST(Inspector, RefusesAtEditTimeWhatTheLoaderRefusesNamingEntityAndField) {
    Fixture f("default.json");
    const std::string before = textOf(f.ed.doc.scene);
    const Entity bob = f.named("bob");
    ASSERT_TRUE(f.ed.doc.scene.registry.has<Radius>(bob));
    std::string problem;
    // A second shape.
    EXPECT_FALSE(f.ed.applyEdit("add box", [&](Scene& s) { return addComponentToAll(s, *findComponent("box"), {bob}, &problem) > 0; }));
    EXPECT_EQ(problem, "\"bob\" box: an entity has at most one shape (radius, box, polygon or plane), got 2");
    // A speed whose kinetic energy overflows.
    const ComponentInfo* velocity = findComponent("velocity");
    EXPECT_FALSE(f.ed.applyEdit("v", [&](Scene& s) {
        return setFieldOnAll(s, *velocity, velocity->fields[0], Vec2{1e308, 0.0}, {bob}, &problem) > 0;
    }));
    EXPECT_EQ(problem.rfind("\"bob\" velocity: expected a speed up to 1e150 m/s", 0), 0u) << problem;
    // The same numbers are refused by the loader.
    EXPECT_FALSE(parseScene(R"({"entities": [{"position": {"x": 0, "y": 0}, "velocity": {"x": 1e308, "y": 0}}]})", "t.json"));
    // A duplicate name.
    EXPECT_FALSE(rename(f, bob, "floor", &problem));
    EXPECT_NE(problem.find("duplicate name \"floor\""), std::string::npos) << problem;
    // Removing the position of a body that has a velocity.
    EXPECT_FALSE(f.ed.applyEdit("rm", [&](Scene& s) {
        return removeComponentFromAll(s, *findComponent("position"), {bob}, &problem) > 0;
    }));
    EXPECT_EQ(problem.rfind("\"bob\"", 0), 0u) << problem;
    EXPECT_NE(problem.find("needs \"position\""), std::string::npos) << problem;
    // Mass out of range names the entity and the field.
    const ComponentInfo* mass = findComponent("mass");
    EXPECT_FALSE(f.ed.applyEdit("m", [&](Scene& s) { return setFieldOnAll(s, *mass, mass->fields[0], -1.0, {bob}, &problem) > 0; }));
    EXPECT_EQ(problem, "\"bob\" mass: expected a number > 0");
    // Nothing of it reached the scene.
    EXPECT_EQ(textOf(f.ed.doc.scene), before);
}

TEST(Editing, DeletingABodyWithASpringSaysWhatGoes) {
    Fixture f("default.json");
    f.ed.select({f.named("bob")});
    EXPECT_EQ(f.ed.deleteLabel(f.ed.selection), "delete 1 body and 1 spring");
    ASSERT_TRUE(f.ed.deleteSelection());
    EXPECT_EQ(f.ed.status, "delete 1 body and 1 spring");
    EXPECT_EQ(f.ed.commands.labels().back(), "delete 1 body and 1 spring");
}

TEST(Editing, PasteAndDuplicateLandAtTheCursor) {
    Fixture f("default.json");
    f.ed.select({f.named("bob")});
    f.ed.copySelection();
    f.ed.handleViewportEvent(f.mouse(InputEvent::Type::MouseMove, {6.0, 9.0}));
    ASSERT_TRUE(f.ed.paste());
    ASSERT_EQ(f.ed.selection.size(), 1u);
    const Vec2 pasted = f.ed.doc.scene.registry.tryGet<Position>(f.ed.selection[0])->value;
    EXPECT_NEAR(pasted.x, 6.0, 1e-9);
    EXPECT_NEAR(pasted.y, 9.0, 1e-9);
    f.ed.handleViewportEvent(f.mouse(InputEvent::Type::MouseMove, {-3.0, 10.0}));
    ASSERT_TRUE(f.ed.duplicateSelection());
    const Vec2 dup = f.ed.doc.scene.registry.tryGet<Position>(f.ed.selection[0])->value;
    EXPECT_NEAR(dup.x, -3.0, 1e-9);
    EXPECT_NEAR(dup.y, 10.0, 1e-9);
}

TEST(Simulation, StepCounterIsClearedByResetNewAndOpen) {
    Fixture f("default.json");
    for (int i = 0; i < 5; ++i) f.ed.stepForward();
    ASSERT_EQ(f.ed.sim.steps(), 5u);
    f.ed.resetSimulation();
    EXPECT_EQ(f.ed.sim.steps(), 0u);
    for (int i = 0; i < 3; ++i) f.ed.stepForward();
    f.ed.newDocument();
    EXPECT_EQ(f.ed.sim.steps(), 0u);
    ASSERT_TRUE(f.ed.open(kLevels / "orbit.json"));
    for (int i = 0; i < 2; ++i) f.ed.stepForward();
    ASSERT_TRUE(f.ed.open(kLevels / "default.json"));
    EXPECT_EQ(f.ed.sim.steps(), 0u);
}

TEST(Files, LevelsFolderIsFoundFromTheExecutableNotTheWorkingFolder) {
    TempDir elsewhere;
    // A build folder in a checkout: <src>/build/stepwise -> <src>/levels.
    const std::filesystem::path levels = findLevelsDirectory(std::filesystem::path(STEPWISE_BINARY).parent_path(), elsewhere.path);
    EXPECT_TRUE(std::filesystem::exists(levels / "default.json")) << levels;
    // Nothing beside the executable: the working folder's levels/, then the folder itself.
    EXPECT_EQ(findLevelsDirectory({}, elsewhere.path), std::filesystem::absolute(elsewhere.path));
    // Save as asks before writing over another file, not over the document's own.
    const std::filesystem::path mine = elsewhere.path / "mine.json", other = elsewhere.path / "other.json";
    std::ofstream(mine) << "{}";
    std::ofstream(other) << "{}";
    EXPECT_TRUE(replacesAnotherFile(other, mine));
    EXPECT_FALSE(replacesAnotherFile(mine, mine));
    EXPECT_FALSE(replacesAnotherFile(elsewhere.path / "new.json", mine));
    EXPECT_TRUE(replacesAnotherFile(other, {}));  // untitled
    EXPECT_EQ(dialogFolder(mine, levels), std::filesystem::absolute(elsewhere.path));
    EXPECT_EQ(dialogFolder({}, levels), levels);
}
