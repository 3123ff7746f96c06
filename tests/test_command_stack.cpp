// The undo stack (editor/app/command_stack): exact bytes back, no empty
// steps, a bounded history.

#include "editor_fixture.hpp"

using namespace stepwise;
using namespace stepwise::editor;
using namespace stepwise::editor_test;
using stepwise::test::readFile;

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

// The stack records what an edit reaches, not a copy of the scene: an edit
// that gives up after creating, changing and destroying entities leaves the
// scene and its handles as they were.
TEST(CommandStack, AnEditThatGivesUpLeavesNoTrace) {
    Fixture f("pile.json");
    Scene& scene = f.ed.doc.scene;
    const std::string original = textOf(scene);
    const Registry::Slots slots = scene.registry.slots();
    const std::vector<Entity> before = scene.registry.entities();
    ASSERT_GE(before.size(), 3u);
    CommandStack stack;
    EXPECT_FALSE(stack.apply(scene, "give up", [&](Scene& s) {
        addCircle(s, {1.0, 2.0}, 0.5);
        s.registry.tryGet<Position>(before[0])->value.x += 3.0;
        (void)s.registry.destroy(before[1]);
        s.registry.reorder(before[2], 0);
        s.world.G = 7.0;
        return false;
    }));
    EXPECT_EQ(textOf(scene), original);
    EXPECT_TRUE(scene.registry.slots() == slots) << "the same handles, free list and order";
    EXPECT_FALSE(stack.canUndo());

}

TEST(CommandStack, AnEditKeepsOnlyTheEntitiesWhoseComponentsChanged) {
    Fixture f("pile.json");
    Scene& scene = f.ed.doc.scene;
    const std::string original = textOf(scene);
    const std::vector<Entity> all = scene.registry.entities();
    ASSERT_GE(all.size(), 2000u);
    CommandStack stack;
    // Every body reached through a mutable pointer, one written: the record
    // holds that body (about 1 KiB with the command's own fields); one of
    // every body reached would be 2,000 x 2 encodings, over 100 KiB.
    ASSERT_TRUE(stack.apply(scene, "move one", [&](Scene& s) {
        for (Entity e : all)
            if (Position* p = s.registry.tryGet<Position>(e); p && e == all[1]) p->value.y += 1.5;
        return true;
    }));
    EXPECT_LT(stack.bytes(), 4096u);
    const std::string moved = textOf(scene);
    EXPECT_NE(moved, original);
    EXPECT_FALSE(stack.undo(scene).empty());
    EXPECT_EQ(textOf(scene), original);
    EXPECT_FALSE(stack.redo(scene).empty());
    EXPECT_EQ(textOf(scene), moved);
}

// Replacing the whole scene (recover unsaved changes) is one undoable step
// like any other.
TEST(CommandStack, ReplacingTheWholeSceneUndoesToTheSameBytesAndHandles) {
    Fixture f("course_notes.json");
    Scene& scene = f.ed.doc.scene;
    const std::string original = textOf(scene);
    const Registry::Slots slots = scene.registry.slots();
    Scene other;
    addCircle(other, {4.0, 5.0}, 0.25);
    const std::string replaced = textOf(other);
    CommandStack stack;
    ASSERT_TRUE(stack.apply(scene, "replace", [&](Scene& s) {
        s = other;
        return true;
    }));
    EXPECT_EQ(textOf(scene), replaced);
    (void)stack.undo(scene);
    EXPECT_EQ(textOf(scene), original);
    EXPECT_TRUE(scene.registry.slots() == slots);
    (void)stack.redo(scene);
    EXPECT_EQ(textOf(scene), replaced);
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

TEST(CommandStack, UndoOfADeletedPolygonRestoresItsVertices) {
    // The undo record of an entity is written field by field from the
    // component table; every kind needs its case there (a vertex list and
    // an integer too), or an undone delete brings a polygon back with no
    // vertices.
    Fixture f("default.json");
    Entity polygon;
    ASSERT_TRUE(f.ed.applyEdit("add", [&](Scene& s) {
        polygon = addPolygon(s, {{0.0, 0.0}, {1.0, 0.0}, {1.25, 0.75}, {0.5, 1.5}}).value();
        return !polygon.isNull();
    }));
    const std::string before = textOf(f.ed.doc.scene);
    ASSERT_EQ(f.ed.doc.scene.registry.tryGet<Polygon>(polygon)->vertices.size(), 4u);
    ASSERT_TRUE(f.ed.applyEdit("delete", [&](Scene& s) { return destroyWithSprings(s, {polygon}) > 0; }));
    ASSERT_TRUE(f.ed.undo());
    EXPECT_EQ(textOf(f.ed.doc.scene), before);
    ASSERT_TRUE(f.ed.redo());
    ASSERT_TRUE(f.ed.undo());
    EXPECT_EQ(textOf(f.ed.doc.scene), before);
}
