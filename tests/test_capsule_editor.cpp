// Capsules in the editor and the renderer's bounds: picking inside the
// stadium and not beside it, the selection and framing boxes, the kind the
// editor names it by.

#include "app/scene_edit.hpp"
#include "scene_bounds.hpp"

#include "stepwise/components.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace stepwise;

namespace {

/// A capsule at (2, 1) whose segment runs from (-1, 0.5) to (1, 0.5) in its
/// frame, radius 0.25, turned by `angle`.
Scene capsuleScene(double angle, Entity& e) {
    Scene s;
    e = s.registry.create();
    s.registry.emplace<Name>(e, {"pill"});
    s.registry.emplace<Position>(e, {{2.0, 1.0}});
    s.registry.emplace<Angle>(e, {angle});
    s.registry.emplace<Capsule>(e, {{-1.0, 0.5}, {1.0, 0.5}, 0.25});
    return s;
}

Vec2 toWorld(Vec2 local, double angle) {
    return Vec2{2.0, 1.0} + Vec2{std::cos(angle) * local.x - std::sin(angle) * local.y,
                                 std::sin(angle) * local.x + std::cos(angle) * local.y};
}

} // namespace

TEST(CapsuleEditor, PickHitsTheStadiumOnlyAtEveryAngle) {
    for (const double angle : {0.0, 0.4, 1.5707963267948966, -2.5}) {
        Entity e;
        const Scene s = capsuleScene(angle, e);
        // Inside: the middle, near each end's cap, on the rim from inside.
        for (const Vec2 local : {Vec2{0.0, 0.5}, Vec2{1.2, 0.5}, Vec2{-1.2, 0.55}, Vec2{0.3, 0.74}})
            EXPECT_EQ(editor::pick(s, toWorld(local, angle), 0.01), e) << angle << " " << local.x << "," << local.y;
        // Outside: beyond the caps, above and below the sides, and the
        // position itself (the segment is 0.5 m off it).
        for (const Vec2 local : {Vec2{1.3, 0.5}, Vec2{1.2, 0.7}, Vec2{0.0, 0.76}, Vec2{0.0, 0.24}, Vec2{0.0, 0.0}})
            EXPECT_TRUE(editor::pick(s, toWorld(local, angle), 0.01).isNull()) << angle << " " << local.x << "," << local.y;
        EXPECT_EQ(editor::entityKind(s.registry, e), "capsule");
    }
}

TEST(CapsuleEditor, BoundsHoldTheWholeCapsule) {
    for (const double angle : {0.0, 0.4, 1.5707963267948966, -2.5}) {
        Entity e;
        const Scene s = capsuleScene(angle, e);
        // The exact box: the end points' box grown by the radius.
        const Vec2 a = toWorld({-1.0, 0.5}, angle), b = toWorld({1.0, 0.5}, angle);
        const std::optional<render::ShapeBox> box = render::shapeBox(s, e);
        ASSERT_TRUE(box.has_value());
        EXPECT_NEAR(box->centre.x, 0.5 * (a.x + b.x), 1e-12);
        EXPECT_NEAR(box->centre.y, 0.5 * (a.y + b.y), 1e-12);
        EXPECT_NEAR(box->half.x, 0.5 * std::abs(b.x - a.x) + 0.25, 1e-12);
        EXPECT_NEAR(box->half.y, 0.5 * std::abs(b.y - a.y) + 0.25, 1e-12);
        // The editor's selection box is circumscribed (any angle): it holds
        // both caps.
        Vec2 lo, hi;
        ASSERT_TRUE(editor::entityBounds(s.registry, e, lo, hi));
        for (const Vec2 end : {a, b}) {
            EXPECT_LE(lo.x, end.x - 0.25);
            EXPECT_LE(lo.y, end.y - 0.25);
            EXPECT_GE(hi.x, end.x + 0.25);
            EXPECT_GE(hi.y, end.y + 0.25);
        }
    }
}
