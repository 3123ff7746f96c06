// The Editor (editor/app/editor): tools driven by viewport events, editing
// gestures, springs and joints picked in the viewport. No window and no GL:
// the same Editor the UI drives.

#include "editor_fixture.hpp"

#include "app/contact_rows.hpp"
#include "app/tools/tools.hpp"

#include <set>

using namespace stepwise;
using namespace stepwise::editor;
using namespace stepwise::editor_test;
using stepwise::test::readFile;

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
    EXPECT_EQ(checkSceneRelations(f.ed.doc.scene), std::nullopt);
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
    EXPECT_EQ(checkSceneRelations(f.ed.doc.scene), std::nullopt);
    const std::string text = sceneToJsonText(f.ed.doc.scene);
    Result<Scene> again = parseScene(text, "joined.json");
    ASSERT_TRUE(again) << again.error();
    EXPECT_EQ(sceneToJsonText(*again), text);
    EXPECT_TRUE(World::build(f.ed.doc.scene));
    // Deleting a body takes its joints with it (they would name nothing).
    f.ed.selection = {reg.tryGet<Joint>(reg.entities().back())->a};
    ASSERT_TRUE(f.ed.deleteSelection());
    for (Entity e : reg.entities()) EXPECT_FALSE(reg.has<Joint>(e) && reg.tryGet<Joint>(e)->type == "rope");
    EXPECT_EQ(checkSceneRelations(f.ed.doc.scene), std::nullopt);
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
    EXPECT_EQ(checkSceneRelations(f.ed.doc.scene), std::nullopt);
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
    EXPECT_EQ(checkSceneRelations(f.ed.doc.scene), std::nullopt);
    // Delete link3: the springs to link2 and link4 go with it.
    const std::size_t springs = springsAttachedTo(reg, f.named("link3")).size();
    ASSERT_GT(springs, 0u);
    const std::size_t before = reg.size();
    f.ed.select({f.named("link3")});
    ASSERT_TRUE(f.ed.handleShortcut(Key::Delete, 0));
    EXPECT_EQ(reg.size(), before - 1 - springs);
    EXPECT_EQ(checkSceneRelations(f.ed.doc.scene), std::nullopt);
}

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
    EXPECT_EQ(polygonProblem(preview), std::nullopt);
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
        e = addPolygon(s, {{0, 0}, {2, 0}, {2, 2}, {0, 2}}).value();
        return !e.isNull();
    }));
    const ComponentInfo* info = findComponent("polygon");
    const std::vector<Vec2> before = f.ed.doc.scene.registry.tryGet<Polygon>(e)->vertices;
    const std::vector<Vec2> dent{{-1, -1}, {1, -1}, {-0.25, -0.25}, {-1, 1}};
    const Result<std::size_t> refused = setFieldOnAll(f.ed.doc.scene, *info, info->fields[0], dent, {e});
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error(), "\"polygon\" polygon.vertices/2: not convex: the outline turns clockwise at vertex 2 {\"x\": -0.25, \"y\": "
                       "-0.25}; "
                       "a polygon shape must be convex (split the shape into convex pieces)");
    EXPECT_EQ(f.ed.doc.scene.registry.tryGet<Polygon>(e)->vertices, before);
    const std::vector<Vec2> kite{{-1, -1}, {1, -1}, {1.5, 0.5}, {-1, 1}};
    const Result<std::size_t> changed = setFieldOnAll(f.ed.doc.scene, *info, info->fields[0], kite, {e});
    ASSERT_TRUE(changed) << changed.error();
    EXPECT_EQ(*changed, 1u);
    EXPECT_EQ(f.ed.doc.scene.registry.tryGet<Polygon>(e)->vertices, kite);
}

TEST(Springs, RenamingABodyKeepsItsSpringPlaysAndSavesTheNewName) {
    // default.json: "pendulum spring" holds "bob" 2.2 m below an anchor.
    Fixture f("default.json");
    const Entity bob = f.named("bob");
    ASSERT_FALSE(bob.isNull());
    ASSERT_EQ(springsAttachedTo(f.ed.doc.scene.registry, bob).size(), 1u);
    ASSERT_TRUE(rename(f, bob, "pendulum").value());
    EXPECT_EQ(f.named("bob"), Entity{});
    EXPECT_EQ(springsAttachedTo(f.ed.doc.scene.registry, bob).size(), 1u) << "the spring follows the body, not its old name";
    EXPECT_EQ(checkSceneRelations(f.ed.doc.scene), std::nullopt);

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

// The inspector shows a refusal in red by the flag the refusal set, not
// by the text: a status that merely begins "refused" is not one.
TEST(Springs, ARefusedPickMarksTheStatusAsARefusal) {
    Fixture f("default.json");
    const Entity spring = f.named("pendulum spring");
    const ComponentInfo* info = findComponent("spring");
    // Both ends on the bob: a spring from a body to itself.
    f.ed.startReferencePick(*info, info->fields[1], {spring});
    EXPECT_FALSE(f.ed.finishReferencePick(f.named("bob")));
    EXPECT_EQ(f.ed.status.rfind("refused: ", 0), 0u) << f.ed.status;
    EXPECT_TRUE(f.ed.statusRefused);
    f.ed.startReferencePick(*info, info->fields[0], {spring});
    EXPECT_FALSE(f.ed.statusRefused);
    f.ed.note("refused-looking text of a plain note");
    EXPECT_FALSE(f.ed.statusRefused);
    f.ed.select({f.named("bob")});
    ASSERT_TRUE(f.ed.deleteSelection());
    EXPECT_FALSE(f.ed.statusRefused);
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

// ---- one table of tools -----------------------------------------------------

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

// The Debug panel's contacts table: the filter matches either body's name,
// and each column sorts stably both ways (names as strings, a plane as "").
TEST(ContactTable, FiltersByEitherNameAndSortsStablyByTheChosenColumn) {
    Registry reg;
    const Entity c2 = reg.create(), c10 = reg.create(), wall = reg.create();
    reg.emplace<Name>(c2, Name{"c2"});
    reg.emplace<Name>(c10, Name{"c10"});
    reg.emplace<Name>(wall, Name{"wall"});
    std::vector<ContactRecord> contacts(4);
    contacts[0] = {c2, wall, {1.0, 0.0}, {0.0, 1.0}, 0.010, 2.0, 0.1};
    contacts[1] = {c10, Entity{}, {-1.0, 0.0}, {0.0, -1.0}, -0.002, 0.0, 0.0};  // against a plane
    contacts[2] = {c2, c10, {0.5, 0.0}, {1.0, 0.0}, 0.005, 1.0, -0.3};
    contacts[3] = {wall, c2, {0.0, 0.0}, {0.0, 1.0}, 0.001, 3.0, 0.2};
    using V = std::vector<std::size_t>;
    const auto rows = [&](const std::string& filter, ContactSort sort) { return contactRows(contacts, reg, filter, sort); };

    EXPECT_EQ(rows("", {}), (V{0, 1, 2, 3}));
    EXPECT_EQ(rows("c1", {}), (V{1, 2}));      // c10 on side a, then on side b
    EXPECT_EQ(rows("wall", {}), (V{0, 3}));
    EXPECT_EQ(rows("nobody", {}), V{});
    EXPECT_EQ(rows("", {true, ContactColumn::A, false}), (V{1, 0, 2, 3}));  // "c10" < "c2" < "wall"; 0 stays before 2
    EXPECT_EQ(rows("", {true, ContactColumn::A, true}), (V{3, 0, 2, 1}));
    EXPECT_EQ(rows("", {true, ContactColumn::B, false}), (V{1, 2, 3, 0}));  // "" (the plane) < "c10" < "c2" < "wall"
    EXPECT_EQ(rows("", {true, ContactColumn::Depth, false}), (V{1, 3, 2, 0}));
    EXPECT_EQ(rows("", {true, ContactColumn::NormalImpulse, true}), (V{3, 0, 2, 1}));
    EXPECT_EQ(rows("", {true, ContactColumn::NormalY, false}), (V{1, 2, 0, 3}));  // -1, 0, then the two 1s in step order
    EXPECT_EQ(rows("c1", {true, ContactColumn::TangentImpulse, false}), (V{2, 1}));
    // Two bodies with one name sort as equals: their rows keep step order.
    const Entity twin = reg.create();
    reg.emplace<Name>(twin, Name{"c2"});
    contacts.push_back({twin, wall, {2.0, 0.0}, {0.0, 1.0}, 0.003, 0.5, 0.0});
    contacts.push_back({c2, c10, {3.0, 0.0}, {1.0, 0.0}, 0.004, 0.7, 0.0});
    EXPECT_EQ(rows("", {true, ContactColumn::A, false}), (V{1, 0, 2, 4, 5, 3}));
    EXPECT_EQ(rows("", {true, ContactColumn::A, true}), (V{3, 0, 2, 4, 5, 1}));
}

// ---- recovery copies live only as long as the changes they hold ------------

namespace {

/// A copy of levels/`level` in the fixture's folder, opened, edited (G) and
/// autosaved: its recovery copy exists.
std::filesystem::path editAndAutosave(Fixture& f, const std::string& level, const std::string& as) {
    const std::filesystem::path file = f.tmp.path / as;
    std::filesystem::copy_file(kLevels / level, file);
    EXPECT_TRUE(f.ed.open(file)) << f.ed.errorModal;
    EXPECT_FALSE(f.ed.tickAutosave(0.0));
    EXPECT_TRUE(f.ed.applyEdit("G", [](Scene& s) {
        s.world.G = 7.0;
        return true;
    }));
    EXPECT_TRUE(f.ed.tickAutosave(31.0));
    EXPECT_TRUE(std::filesystem::exists(f.ed.doc.recoveryPath(f.ed.configDir)));
    return file;
}

/// Whether a fresh editor opening `file` would be offered a recovery copy.
bool offeredOnReopen(const Fixture& f, const std::filesystem::path& file) {
    Editor again;
    again.configDir = f.ed.configDir;
    EXPECT_TRUE(again.open(file)) << again.errorModal;
    return again.recoveryAvailable().has_value();
}

} // namespace

// Recover, then open another level and choose Discard: reopening the first
// level offered the discarded changes again.
TEST(Recovery, RecoveredChangesDiscardedForAnotherLevelAreNotOfferedAgain) {
    Fixture f("orbit.json");
    const std::filesystem::path bridge = editAndAutosave(f, "default.json", "bridge.json");
    Editor crashed;  // the editor that autosaved is gone; a new one recovers
    crashed.configDir = f.ed.configDir;
    ASSERT_TRUE(crashed.open(bridge));
    const auto copy = crashed.recoveryAvailable();
    ASSERT_TRUE(copy);
    ASSERT_TRUE(crashed.recover(*copy));
    ASSERT_TRUE(crashed.dirty());
    crashed.request(PendingAction::Open, kLevels / "orbit.json");
    ASSERT_EQ(crashed.uiRequest, UiRequest::ConfirmDiscard);
    crashed.resolvePending(Editor::Resolution::Discard);
    EXPECT_EQ(crashed.doc.title(), "orbit.json");
    EXPECT_FALSE(std::filesystem::exists(*copy));
    EXPECT_FALSE(offeredOnReopen(f, bridge));
}

// Opening another level or a new one and discarding the changes deletes
// their copy; choosing Save writes them and deletes it too.
TEST(Recovery, ChangesReplacedByAnotherLevelTakeTheirCopyWithThem) {
    for (const PendingAction action : {PendingAction::Open, PendingAction::New}) {
        for (const Editor::Resolution answer : {Editor::Resolution::Discard, Editor::Resolution::Save}) {
            Fixture f("orbit.json");
            const std::filesystem::path file = editAndAutosave(f, "default.json", "level.json");
            const std::filesystem::path copy = f.ed.doc.recoveryPath(f.ed.configDir);
            f.ed.request(action, kLevels / "orbit.json");
            ASSERT_EQ(f.ed.uiRequest, UiRequest::ConfirmDiscard);
            f.ed.resolvePending(answer);
            EXPECT_EQ(f.ed.doc.title(), action == PendingAction::Open ? "orbit.json" : "untitled");
            EXPECT_FALSE(std::filesystem::exists(copy)) << int(action) << " " << int(answer);
            EXPECT_FALSE(offeredOnReopen(f, file)) << int(action) << " " << int(answer);
        }
    }
}

// A rename, autosaved, then undone back to the file's state: the copy went
// on to be offered later.
TEST(Recovery, UndoingBackToTheFilesStateDeletesTheCopy) {
    Fixture f("orbit.json");
    const std::filesystem::path file = f.tmp.path / "level.json";
    std::filesystem::copy_file(kLevels / "default.json", file);
    ASSERT_TRUE(f.ed.open(file));
    EXPECT_FALSE(f.ed.tickAutosave(0.0));
    ASSERT_TRUE(rename(f, f.named("bob"), "robert").value());
    ASSERT_TRUE(f.ed.tickAutosave(31.0));
    const std::filesystem::path copy = f.ed.doc.recoveryPath(f.ed.configDir);
    ASSERT_TRUE(std::filesystem::exists(copy));
    ASSERT_TRUE(f.ed.undo());
    EXPECT_FALSE(f.ed.dirty());
    EXPECT_FALSE(std::filesystem::exists(copy));
    EXPECT_FALSE(offeredOnReopen(f, file));
    // Redo makes the changes unsaved again; the next autosave writes a copy.
    ASSERT_TRUE(f.ed.redo());
    EXPECT_TRUE(f.ed.tickAutosave(62.0));
    EXPECT_TRUE(offeredOnReopen(f, file));
}

// ---- break on contact ------------------------------------------------------

namespace {

/// Steps until the simulation's message changes (at most `limit` steps).
std::string nextBreak(Fixture& f, int limit = 400) {
    const std::string before = f.ed.sim.message();
    for (int i = 0; i < limit && f.ed.sim.message() == before; ++i) f.ed.stepForward();
    return f.ed.sim.message();
}

} // namespace

// The ball rolling down default.json's ramp first met it as a speculative
// contact (a gap of 2.35 cm), and the message said "touches".
TEST(BreakOnContact, TheMessageSaysWhetherThePairTouchesOrIsAboutTo) {
    Fixture f("default.json");
    f.ed.setBreakOnContact(f.named("ball 1"));
    EXPECT_EQ(nextBreak(f), "break on contact: ball 1 is about to touch ramp at t = 0.4000 s (speculative contact, gap 0.0235 m)");
    EXPECT_EQ(f.ed.status, f.ed.sim.message());
    // A pair seen about to touch pauses again when it touches.
    std::string touching;
    for (int i = 0; i < 20 && touching.empty(); ++i)
        if (const std::string m = nextBreak(f); m.find(" touches ") != std::string::npos) touching = m;
    EXPECT_EQ(touching, "break on contact: ball 1 touches ramp at t = 1.4833 s (depth 2.78e-17 m)");
    // Crates resting on the floor meet it at a depth of zero within round-off.
    Fixture g("default.json");
    g.ed.setBreakOnContact(g.named("crate 1"));
    EXPECT_EQ(nextBreak(g), "break on contact: crate 1 touches floor at t = 0.0167 s (depth 0 m)");
}

// Break on sensor pauses at the step a body enters or leaves a sensor,
// names both, and logs every event of the run; the script turns it on and
// a new level turns it off.
TEST(BreakOnSensor, PausesAtEachEventAndTheLogKeepsThemAll) {
    Fixture f("sensors.json");
    RecordingHost host;
    ASSERT_TRUE(runLine(f.ed, host, "breakonsensor on"));
    EXPECT_TRUE(f.ed.sim.breakOnSensor);
    // The same events a headless run gives, in order (stepwise run --contacts).
    Scene scene = f.ed.doc.scene;
    World world = stepwise::test::buildWorld(scene);
    std::vector<std::string> expected;
    for (int s = 0; s < 240; ++s) {
        ASSERT_TRUE(world.step());
        const std::span<const SensorEvent> events = world.sensorEvents();
        if (events.empty()) continue;
        char when[48];
        std::snprintf(when, sizeof when, " at t = %.4f s", world.time());
        const auto& e = events.front();
        expected.push_back("break on sensor: " + displayName(scene.registry, e.body) + (e.begin ? " entered " : " left ") +
                           displayName(scene.registry, e.sensor) + when +
                           (events.size() > 1 ? " (and " + std::to_string(events.size() - 1) + " more)" : std::string()));
    }
    ASSERT_GE(expected.size(), 4u);
    for (std::size_t k = 0; k < 4; ++k) EXPECT_EQ(nextBreak(f), expected[k]) << k;
    EXPECT_GE(f.ed.sim.sensorLog().size(), 4u);
    ASSERT_TRUE(runLine(f.ed, host, "open " + (kLevels / "spring_chain.json").string()));
    EXPECT_FALSE(f.ed.sim.breakOnSensor);
    EXPECT_FALSE(runLine(f.ed, host, "breakonsensor maybe"));
    EXPECT_EQ(host.errors.back().substr(host.errors.back().find("breakonsensor")),
              "breakonsensor: expected on or off, got \"maybe\"");
}

// The watched body stayed whatever was selected later, nothing named it, and
// it stayed watched in the next level opened.
TEST(BreakOnContact, TheWatchedBodyIsNamedKeptAndClearedWithTheLevel) {
    Fixture f("orbit.json");
    RecordingHost host;
    EXPECT_EQ(f.ed.breakOnLabel(), "off");
    ASSERT_TRUE(runLine(f.ed, host, "breakon comet"));
    EXPECT_EQ(f.ed.sim.breakOnContact, f.named("comet"));
    EXPECT_EQ(f.ed.breakOnLabel(), "comet");
    EXPECT_EQ(f.ed.status, "break on contact: watching comet");
    f.ed.select({f.named("planet")});
    EXPECT_EQ(f.ed.breakOnLabel(), "comet") << "a choice, not the selection";
    ASSERT_TRUE(runLine(f.ed, host, "open " + (kLevels / "spring_chain.json").string()));
    EXPECT_TRUE(f.ed.sim.breakOnContact.isNull());
    EXPECT_EQ(f.ed.breakOnLabel(), "off");
    // Deleting the watched body stops the watch.
    ASSERT_TRUE(runLine(f.ed, host, "breakon link5"));
    f.ed.select({f.named("link5")});
    ASSERT_TRUE(f.ed.deleteSelection());
    EXPECT_TRUE(f.ed.sim.breakOnContact.isNull());
    EXPECT_EQ(f.ed.breakOnLabel(), "off");
    EXPECT_TRUE(host.errors.empty());
}

// ---- number fields name the field edited -----------------------------------

// Setting a hinge's upper below its lower was refused with a message that
// named lower, the field not touched.
TEST(NumberFields, ARefusalOfUpperBelowLowerNamesUpper) {
    TempDir tmp;
    Editor ed;
    ed.configDir = tmp.path / "config";
    ASSERT_TRUE(ed.open(std::filesystem::path(STEPWISE_SOURCE_DIR) / "tests" / "data" / "joints_every_type.json"));
    const Entity hinge = findByName(ed.doc.scene.registry, "hinge");
    const ComponentInfo* joint = findComponent("joint");
    ASSERT_NE(joint, nullptr);
    const auto fieldNamed = [&](std::string_view key) {
        for (const FieldInfo& f : joint->fields)
            if (f.key == key) return &f;
        return static_cast<const FieldInfo*>(nullptr);
    };
    const std::string before = textOf(ed.doc.scene);
    Result<std::size_t> refused =
        setFieldOnAll(ed.doc.scene, *joint, *fieldNamed("upper"), std::optional<double>(-1.0), {hinge});
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error(), "\"hinge\" joint.upper: conflicts with joint.lower: expected at most upper (-1), got -0.5");
    EXPECT_EQ(textOf(ed.doc.scene), before);
    // Editing lower above upper names lower, as before.
    refused = setFieldOnAll(ed.doc.scene, *joint, *fieldNamed("lower"), std::optional<double>(1.0), {hinge});
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error(), "\"hinge\" joint.lower: expected at most upper (0.5), got 1");
    EXPECT_EQ(textOf(ed.doc.scene), before);
}

// A plank of the bridge goes with the two joints that hold it; the label
// called them "2 entities".
TEST(Editing, DeletingAPlankCountsItsJointsAsJoints) {
    Fixture f("bridge.json");
    f.ed.select({f.named("plank 2")});
    EXPECT_EQ(f.ed.deleteLabel(f.ed.selection), "delete 1 body and 2 joints");
    ASSERT_TRUE(f.ed.deleteSelection());
    EXPECT_EQ(f.ed.status, "delete 1 body and 2 joints");
    EXPECT_EQ(f.ed.commands.labels().back(), "delete 1 body and 2 joints");
}

// ---- edits while the simulation runs ---------------------------------------

// Edits made while paused changed the running state with nothing to say so:
// no `*`, Save wrote the level as at Play and Reset dropped them silently.
TEST(RunningEdits, TheModeSaysWhereEditsGoAndResetSaysWhatItDiscards) {
    Fixture f("default.json");
    EXPECT_EQ(f.ed.runningEditsNote(), "");
    f.ed.stepForward();
    EXPECT_EQ(f.ed.runningEditsNote(),
              "editing the running state: Reset discards any edit; Save writes the level as it was at Play");
    ASSERT_TRUE(rename(f, f.named("crate 1"), "heavy").value());
    EXPECT_EQ(f.ed.editsSincePlay(), 1u);
    EXPECT_EQ(f.ed.runningEditsNote(),
              "editing the running state: Reset discards 1 edit; Save writes the level as it was at Play");
    EXPECT_FALSE(f.ed.dirty()) << "the level is as it was at Play";
    f.ed.select({f.named("heavy")});
    ASSERT_TRUE(f.ed.deleteSelection());
    EXPECT_EQ(f.ed.editsSincePlay(), 2u);
    f.ed.resetSimulation();
    EXPECT_EQ(f.ed.status, "reset to the edited level; discarded 2 edits made while running");
    EXPECT_FALSE(f.named("crate 1").isNull());
    EXPECT_EQ(f.ed.runningEditsNote(), "");
    EXPECT_EQ(f.ed.editsSincePlay(), 0u);
}
// Every edit while paused emptied the contacts table (and the overlay): the
// World it recompiles has no contacts until its next step. An edit that
// leaves the contacts as they were keeps them; one that moves a body does not.
TEST(RunningEdits, AnEditThatLeavesTheContactsKeepsTheTable) {
    Fixture f("default.json");
    for (int i = 0; i < 60; ++i) f.ed.stepForward();
    ASSERT_TRUE(f.ed.sim.ensureWorld(f.ed.doc.scene));
    const std::vector<ContactRecord> before(f.ed.sim.contacts().begin(), f.ed.sim.contacts().end());
    ASSERT_EQ(before.size(), 33u);
    const ComponentInfo* mass = findComponent("mass");
    ASSERT_TRUE(f.ed.tryEdit("mass", [&](Scene& s) {
        return changedAny(setFieldOnAll(s, *mass, mass->fields[0], 3.0, {f.named("crate 1")}));
    }).value());
    ASSERT_TRUE(rename(f, f.named("crate 2"), "heavy").value());
    ASSERT_TRUE(f.ed.sim.ensureWorld(f.ed.doc.scene));
    EXPECT_EQ(f.ed.sim.world()->contacts().size(), 0u) << "the recompiled World has none of its own";
    ASSERT_EQ(f.ed.sim.contacts().size(), before.size());
    for (std::size_t i = 0; i < before.size(); ++i) {
        EXPECT_EQ(f.ed.sim.contacts()[i].a, before[i].a);
        EXPECT_EQ(f.ed.sim.contacts()[i].b, before[i].b);
        EXPECT_EQ(f.ed.sim.contacts()[i].depth, before[i].depth);
    }
    EXPECT_EQ(f.ed.frameInput().contacts->size(), before.size()) << "the overlay draws them too";
    // A step makes its own; a move changes them.
    f.ed.stepForward();
    EXPECT_EQ(f.ed.sim.contacts().data(), f.ed.sim.world()->contacts().data());
    const Entity crate = f.named("crate 3");
    ASSERT_TRUE(f.ed.applyEdit("move", [&](Scene& s) {
        s.registry.tryGet<Position>(crate)->value.x += 0.5;
        return true;
    }));
    ASSERT_TRUE(f.ed.sim.ensureWorld(f.ed.doc.scene));
    EXPECT_EQ(f.ed.sim.contacts().data(), f.ed.sim.world()->contacts().data());
}

// A mass edit on a sleeping crate wakes its island (the ten crates and the
// ball resting on them); undoing it left them awake, with no contacts.
TEST(RunningEdits, UndoingAnEditBeforeAnyStepPutsTheIslandsItWokeBackToSleep) {
    Fixture f("default.json");
    for (int i = 0; i < 900; ++i) f.ed.stepForward();
    ASSERT_TRUE(f.ed.sim.ensureWorld(f.ed.doc.scene));
    const std::vector<Entity> asleep = f.ed.sim.world()->sleepingBodies();
    ASSERT_EQ(asleep.size(), 11u);
    const std::size_t contacts = f.ed.sim.contacts().size();
    const std::string before = textOf(f.ed.doc.scene);
    const ComponentInfo* mass = findComponent("mass");
    ASSERT_TRUE(f.ed.tryEdit("mass", [&](Scene& s) {
        return changedAny(setFieldOnAll(s, *mass, mass->fields[0], 3.0, {f.named("crate 1")}));
    }).value());
    ASSERT_TRUE(f.ed.sim.ensureWorld(f.ed.doc.scene));
    EXPECT_EQ(f.ed.sim.world()->sleepingBodyCount(), 0u) << "the edit wakes the crate's island";
    ASSERT_TRUE(f.ed.undo());
    ASSERT_TRUE(f.ed.sim.ensureWorld(f.ed.doc.scene));
    EXPECT_EQ(textOf(f.ed.doc.scene), before);
    EXPECT_EQ(f.ed.sim.world()->sleepingBodies(), asleep);
    EXPECT_EQ(f.ed.sim.contacts().size(), contacts);
    // The run goes on as it would have without the edit and its undo.
    Fixture g("default.json");
    for (int i = 0; i < 960; ++i) g.ed.stepForward();
    for (int i = 0; i < 60; ++i) f.ed.stepForward();
    EXPECT_EQ(textOf(f.ed.doc.scene), textOf(g.ed.doc.scene));
}
