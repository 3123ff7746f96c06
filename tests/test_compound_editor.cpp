// Compound bodies in the editor: a click on any shape picks the body and a
// click between them does not; the selection box holds every shape; the
// shapes list is one field that undo and redo restore exactly.

#include "app/command_stack.hpp"
#include "app/scene_edit.hpp"
#include "scene_bounds.hpp"

#include "stepwise/scene_io.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace stepwise;

namespace {

// An L turned by 0.5 rad: a foot (2 x 0.5) at the origin and a post (0.5 x
// 1.5) at (0.75, 1), with a disc at (-1.5, 1).
const char* kLevel = R"({"entities": [{"name": "ell", "position": {"x": 3, "y": 2}, "angle": 0.5, "shapes": [
  {"box": {"center": {"x": 0, "y": 0}, "width": 2, "height": 0.5, "angle": 0}},
  {"box": {"center": {"x": 0.75, "y": 1}, "width": 0.5, "height": 1.5, "angle": 0}},
  {"circle": {"center": {"x": -1.5, "y": 1}, "radius": 0.3}}]}]})";

Vec2 toWorld(Vec2 local, double angle = 0.5) {
    const double c = std::cos(angle), s = std::sin(angle);
    return Vec2{3, 2} + Vec2{c * local.x - s * local.y, s * local.x + c * local.y};
}

} // namespace

TEST(CompoundEditor, AnyShapePicksTheBodyAndTheGapsDoNot) {
    Result<Scene> scene = parseScene(kLevel, "t.json");
    ASSERT_TRUE(scene) << scene.error();
    const Entity ell = scene->registry.entities()[0];
    for (const Vec2 local : {Vec2{-0.9, 0.2}, Vec2{0.9, -0.2}, Vec2{0.75, 1.7}, Vec2{0.6, 0.4}, Vec2{-1.5, 1.25},
                             Vec2{-1.3, 1.0}})
        EXPECT_EQ(editor::pick(*scene, toWorld(local), 0.01), ell) << local.x << ", " << local.y;
    for (const Vec2 local : {Vec2{0.0, 1.0}, Vec2{-1.5, 0.55}, Vec2{1.2, 1.0}, Vec2{0.0, -0.4}})
        EXPECT_TRUE(editor::pick(*scene, toWorld(local), 0.01).isNull()) << local.x << ", " << local.y;
}

TEST(CompoundEditor, TheBoundsHoldEveryShape) {
    Result<Scene> scene = parseScene(kLevel, "t.json");
    ASSERT_TRUE(scene) << scene.error();
    const Entity ell = scene->registry.entities()[0];
    const std::optional<render::ShapeBox> box = render::shapeBox(*scene, ell);
    ASSERT_TRUE(box);
    Vec2 lo{1e9, 1e9}, hi{-1e9, -1e9};
    const auto add = [&](Vec2 p) {
        lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)};
        hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
    };
    for (const Vec2 corner : {Vec2{-1, -0.25}, Vec2{1, -0.25}, Vec2{1, 0.25}, Vec2{-1, 0.25}, Vec2{0.5, 0.25},
                              Vec2{1, 0.25}, Vec2{1, 1.75}, Vec2{0.5, 1.75}})
        add(toWorld(corner));
    add(toWorld({-1.5, 1}) - Vec2{0.3, 0.3});
    add(toWorld({-1.5, 1}) + Vec2{0.3, 0.3});
    EXPECT_NEAR(box->centre.x - box->half.x, lo.x, 1e-12);
    EXPECT_NEAR(box->centre.y - box->half.y, lo.y, 1e-12);
    EXPECT_NEAR(box->centre.x + box->half.x, hi.x, 1e-12);
    EXPECT_NEAR(box->centre.y + box->half.y, hi.y, 1e-12);
    Vec2 elo, ehi;
    ASSERT_TRUE(editor::entityBounds(scene->registry, ell, elo, ehi));
    EXPECT_LE(elo.x, lo.x);
    EXPECT_LE(elo.y, lo.y);
    EXPECT_GE(ehi.x, hi.x);
    EXPECT_GE(ehi.y, hi.y);
}

TEST(CompoundEditor, AnEditOfTheShapesListUndoesAndRedoesExactly) {
    Result<Scene> scene = parseScene(kLevel, "t.json");
    ASSERT_TRUE(scene) << scene.error();
    const Entity ell = scene->registry.entities()[0];
    const std::string before = sceneToJsonText(*scene);
    editor::CommandStack stack;
    ASSERT_TRUE(stack.apply(*scene, "widen the foot", [&](Scene& s) {
        Shapes& shapes = *s.registry.tryGet<Shapes>(ell);
        shapes.items[0].width = 3.0;
        shapes.items[2].density = 4.5;
        shapes.items[2].filter = Filter{2, 5, -1};
        shapes.items.push_back(shapes.items[1]);
        return true;
    }));
    const std::string after = sceneToJsonText(*scene);
    EXPECT_NE(after, before);
    EXPECT_EQ(stack.undo(*scene), "widen the foot");
    EXPECT_EQ(sceneToJsonText(*scene), before);
    EXPECT_EQ(stack.redo(*scene), "widen the foot");
    EXPECT_EQ(sceneToJsonText(*scene), after);
}
