// Chains and rounded polygons in the editor and the renderer's bounds:
// picking a chain by distance to its polyline (after the bodies resting on
// it), a rounded polygon within its radius of the outline, the selection and
// framing boxes, and the kind the editor names a chain by.

#include "app/scene_edit.hpp"
#include "scene_bounds.hpp"

#include "stepwise/components.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace stepwise;

namespace {

Vec2 turned(Vec2 origin, Vec2 local, double angle) {
    return origin + Vec2{std::cos(angle) * local.x - std::sin(angle) * local.y,
                         std::sin(angle) * local.x + std::cos(angle) * local.y};
}

} // namespace

TEST(ChainEditor, PickByDistanceToThePolylineAfterTheBodiesOnIt) {
    for (const double angle : {0.0, 0.5, -2.0}) {
        for (const bool loop : {false, true}) {
            Scene s;
            const Entity chain = s.registry.create();
            s.registry.emplace<Name>(chain, {"ground"});
            s.registry.emplace<Position>(chain, {{1.0, -1.0}});
            s.registry.emplace<Static>(chain, {true});
            s.registry.emplace<Angle>(chain, {angle});
            s.registry.emplace<Chain>(chain, {{{3.0, 0.0}, {0.0, 1.0}, {-3.0, 0.0}}, loop});
            const Vec2 origin{1.0, -1.0};
            // On each segment and near it (within the pick radius 0.1).
            for (const Vec2 local : {Vec2{1.5, 0.5}, Vec2{-1.5, 0.5}, Vec2{0.0, 1.05}, Vec2{3.05, 0.0}})
                EXPECT_EQ(editor::pick(s, turned(origin, local, angle), 0.1), chain) << angle;
            // The closing segment of a loop runs from (-3, 0) back to (3, 0).
            EXPECT_EQ(editor::pick(s, turned(origin, {0.0, 0.0}, angle), 0.1).isNull(), !loop) << angle;
            // Away from every segment: nothing, the position included.
            EXPECT_TRUE(editor::pick(s, turned(origin, {0.0, 0.6}, angle), 0.1).isNull()) << angle;
            EXPECT_TRUE(editor::pick(s, turned(origin, {0.0, -0.3}, angle), 0.1).isNull()) << angle;
            EXPECT_EQ(editor::entityKind(s.registry, chain), "chain");
            // A ball resting on the chain keeps the clicks inside it, even
            // listed before the chain.
            Scene withBall;
            const Entity ball = withBall.registry.create();
            withBall.registry.emplace<Position>(ball, {turned(origin, {1.5, 0.7}, angle)});
            withBall.registry.emplace<Radius>(ball, {0.3});
            const Entity c2 = withBall.registry.create();
            withBall.registry.emplace<Position>(c2, {origin});
            withBall.registry.emplace<Static>(c2, {true});
            withBall.registry.emplace<Angle>(c2, {angle});
            withBall.registry.emplace<Chain>(c2, {{{3.0, 0.0}, {0.0, 1.0}, {-3.0, 0.0}}, loop});
            EXPECT_EQ(editor::pick(withBall, turned(origin, {1.5, 0.5}, angle), 0.1), ball);
            EXPECT_EQ(editor::pick(withBall, turned(origin, {-1.5, 0.5}, angle), 0.1), c2);
            // Bounds: the turned points' box, and a selection box holding
            // every point.
            const std::optional<render::ShapeBox> box = render::shapeBox(s, chain);
            ASSERT_TRUE(box.has_value());
            Vec2 lo, hi;
            ASSERT_TRUE(editor::entityBounds(s.registry, chain, lo, hi));
            for (const Vec2 local : {Vec2{3.0, 0.0}, Vec2{0.0, 1.0}, Vec2{-3.0, 0.0}}) {
                const Vec2 p = turned(origin, local, angle);
                EXPECT_LE(std::abs(p.x - box->centre.x), box->half.x + 1e-12);
                EXPECT_LE(std::abs(p.y - box->centre.y), box->half.y + 1e-12);
                EXPECT_LE(lo.x, p.x);
                EXPECT_LE(lo.y, p.y);
                EXPECT_GE(hi.x, p.x);
                EXPECT_GE(hi.y, p.y);
            }
        }
    }
}

TEST(ChainEditor, RoundedPolygonsArePickedWithinTheirRadiusAndBoundedByIt) {
    Scene s;
    const Entity e = s.registry.create();
    s.registry.emplace<Position>(e, {{0.0, 0.0}});
    Polygon p;
    p.vertices = {{-0.5, -0.5}, {0.5, -0.5}, {0.5, 0.5}, {-0.5, 0.5}};
    p.radius = 0.2;
    s.registry.emplace<Polygon>(e, p);
    EXPECT_EQ(editor::pick(s, {0.65, 0.0}, 0.01), e);   // in the edge strip
    EXPECT_EQ(editor::pick(s, {0.62, 0.62}, 0.01), e);  // in the corner's arc (0.17 from the corner)
    EXPECT_TRUE(editor::pick(s, {0.66, 0.66}, 0.01).isNull());  // past the arc (0.23 from it)
    EXPECT_TRUE(editor::pick(s, {0.75, 0.0}, 0.01).isNull());
    const std::optional<render::ShapeBox> box = render::shapeBox(s, e);
    ASSERT_TRUE(box.has_value());
    EXPECT_NEAR(box->half.x, 0.7, 1e-12);
    EXPECT_NEAR(box->half.y, 0.7, 1e-12);
    Vec2 lo, hi;
    ASSERT_TRUE(editor::entityBounds(s.registry, e, lo, hi));
    EXPECT_LE(hi.x, 0.5 * std::sqrt(2.0) + 0.2 + 1e-12);
    EXPECT_GE(hi.x, 0.7);
}
