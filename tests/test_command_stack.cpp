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
        polygon = addPolygon(s, {{0.0, 0.0}, {1.0, 0.0}, {1.25, 0.75}, {0.5, 1.5}});
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
