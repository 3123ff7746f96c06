// Chains and rounded polygons in the editor and the renderer: picking a
// chain by distance to its polyline (after the bodies resting on it), a
// rounded polygon within its radius of the outline, the selection and
// framing boxes, the kind the editor names a chain by, and what a frame
// draws of them (the segments with ticks on the solid side; the rounded
// outline).

#include "app/scene_edit.hpp"
#include "frame.hpp"
#include "scene_bounds.hpp"

#include "stepwise/components.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

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

namespace {

std::vector<std::array<float, 4>> segmentsOf(const render::DrawData& data) {
    std::vector<std::array<float, 4>> out;
    for (const render::Batch& b : data.batches)
        if (b.kind == render::BatchKind::Segment)
            for (std::size_t i = 0; i < b.count(); ++i) {
                const float* s = b.data.data() + i * render::floatsPerInstance(render::BatchKind::Segment);
                out.push_back({s[0], s[1], s[2], s[3]});
            }
    return out;
}

} // namespace

TEST(ChainRender, SegmentsWithTicksOnTheSolidSideAndNoDot) {
    // A floor drawn right to left (solid side up) and the same points left
    // to right (solid side down): every segment is drawn, and every tick
    // (a short line from a segment's middle) points to the solid side.
    for (const bool up : {true, false}) {
        Scene scene;
        const Entity e = scene.registry.create();
        scene.registry.emplace<Position>(e, {{0.0, 0.0}});
        scene.registry.emplace<Static>(e, {true});
        std::vector<Vec2> points{{3.0, 0.0}, {1.0, 0.0}, {-1.0, 0.0}, {-3.0, 0.0}};
        if (!up) std::reverse(points.begin(), points.end());
        scene.registry.emplace<Chain>(e, {points, false});
        render::FrameInput input;
        input.scene = &scene;
        input.camera = render::Camera{{0.0, 0.0}, 120.0};  // 100 px per metre at 600 px
        input.hud = false;
        const std::vector<std::array<float, 4>> segs = segmentsOf(render::buildDrawData(input, 800, 600));
        int lines = 0, ticks = 0;
        for (const auto& s : segs) {
            if (std::abs(s[1] - s[3]) < 1e-3) {
                ++lines;  // along the floor (pixel y = 300)
                EXPECT_NEAR(s[1], 300.0, 1e-3);
                EXPECT_NEAR(std::abs(s[2] - s[0]), 200.0, 1e-3);
            } else {
                ++ticks;
                EXPECT_NEAR(s[1], 300.0, 1e-3);
                EXPECT_NEAR(s[3] - s[1], up ? 6.0 : -6.0, 1e-3) << "the tick points to the solid side";
            }
        }
        EXPECT_EQ(lines, 3);
        EXPECT_EQ(ticks, 3);  // 200 px segments: one tick each
        int discs = 0;
        for (const render::Batch& b : render::buildDrawData(input, 800, 600).batches)
            if (b.kind == render::BatchKind::Disc) discs += int(b.count());
        EXPECT_EQ(discs, 0) << "no point-mass dot at the chain's position";
    }
}

TEST(ChainRender, ARoundedPolygonIsDrawnAsItsRoundedOutline) {
    // Every outline vertex lies at the radius from the core outline, and
    // the corners take more vertices than the sharp square's four.
    for (const double r : {0.1, 0.4}) {
        Scene scene;
        const Entity e = scene.registry.create();
        scene.registry.emplace<Position>(e, {{0.0, 0.0}});
        Polygon p;
        p.vertices = {{-0.5, -0.5}, {0.5, -0.5}, {0.5, 0.5}, {-0.5, 0.5}};
        p.radius = r;
        scene.registry.emplace<Polygon>(e, p);
        render::FrameInput input;
        input.scene = &scene;
        input.camera = render::Camera{{0.0, 0.0}, 120.0};  // 100 px per metre at 600 px
        input.hud = false;
        const std::vector<std::array<float, 4>> segs = segmentsOf(render::buildDrawData(input, 800, 600));
        EXPECT_GT(segs.size(), 12u);
        for (const auto& s : segs) {
            // Back to metres: the distance to the unit square's core.
            const Vec2 q{(s[0] - 400.0) / 100.0, (s[1] - 300.0) / 100.0};
            const Vec2 outside{std::max(std::abs(q.x) - 0.5, 0.0), std::max(std::abs(q.y) - 0.5, 0.0)};
            EXPECT_NEAR(length(outside), r, 1e-5);
        }
    }
}

TEST(ChainEditor, EditsAreRefusedWithTheLoadersWords) {
    // The inspector's edits go through setFieldOnAll / addComponentToAll:
    // what the loader refuses is refused, naming the entity and the field,
    // and the scene is left as it was; a good edit goes through.
    Scene s;
    const Entity chain = s.registry.create();
    s.registry.emplace<Name>(chain, {"ground"});
    s.registry.emplace<Position>(chain, {{0.0, 0.0}});
    s.registry.emplace<Static>(chain, {true});
    s.registry.emplace<Chain>(chain, {{{2.0, 0.0}, {-2.0, 0.0}}, false});
    const Entity ball = s.registry.create();
    s.registry.emplace<Name>(ball, {"ball"});
    s.registry.emplace<Position>(ball, {{0.0, 1.0}});
    const ComponentInfo& info = *findComponent("chain");
    const FieldInfo& points = info.fields[0];
    const FieldInfo& loop = info.fields[1];
    // A loop needs three points.
    Result<std::size_t> edited = editor::setFieldOnAll(s, info, loop, true, {chain});
    ASSERT_FALSE(edited);
    EXPECT_EQ(edited.error(), "\"ground\" chain.loop: conflicts with chain.points: expected 3 to 1024 points in a loop, got 2");
    EXPECT_FALSE(s.registry.tryGet<Chain>(chain)->loop);
    // Two consecutive points the same.
    edited = editor::setFieldOnAll(s, info, points, std::vector<Vec2>{{2.0, 0.0}, {2.0, 0.0}}, {chain});
    ASSERT_FALSE(edited);
    EXPECT_NE(edited.error().find("point 1 {\"x\": 2, \"y\": 0} is the same point as point 0"), std::string::npos)
        << edited.error();
    EXPECT_EQ(s.registry.tryGet<Chain>(chain)->points.size(), 2u);
    EXPECT_EQ(s.registry.tryGet<Chain>(chain)->points[1], (Vec2{-2.0, 0.0}));
    // A chain on a dynamic body.
    edited = editor::addComponentToAll(s, info, {ball});
    ASSERT_FALSE(edited);
    EXPECT_NE(edited.error().find("a chain must be on a static or kinematic body"), std::string::npos)
        << edited.error();
    EXPECT_FALSE(s.registry.has<Chain>(ball));
    // Three points and a loop: accepted.
    edited = editor::setFieldOnAll(s, info, points, std::vector<Vec2>{{2.0, 0.0}, {0.0, 1.0}, {-2.0, 0.0}}, {chain});
    ASSERT_TRUE(edited) << edited.error();
    EXPECT_EQ(*edited, 1u);
    edited = editor::setFieldOnAll(s, info, loop, true, {chain});
    ASSERT_TRUE(edited) << edited.error();
    EXPECT_EQ(*edited, 1u);
    EXPECT_TRUE(s.registry.tryGet<Chain>(chain)->loop);
}

// Static and kinematic turn each other off in one edit, so a static chain
// becomes a moving one (and back) from the inspector: in two edits either
// order passes through a level the loader refuses (a chain on a dynamic
// body, or a body both static and kinematic).
TEST(ChainEditor, TickingKinematicOnAStaticChainUnticksStatic) {
    Scene s;
    const Entity chain = s.registry.create();
    s.registry.emplace<Name>(chain, {"belt"});
    s.registry.emplace<Position>(chain, {{0.0, 0.0}});
    s.registry.emplace<Static>(chain, {true});
    s.registry.emplace<Chain>(chain, {{{2.0, 0.0}, {-2.0, 0.0}}, false});
    const ComponentInfo& kinematic = *findComponent("kinematic");
    const ComponentInfo& still = *findComponent("static");
    // Unticking static alone is refused, with the loader's words.
    Result<std::size_t> edited = editor::setFieldOnAll(s, still, still.fields[0], false, {chain});
    ASSERT_FALSE(edited);
    EXPECT_NE(edited.error().find("a chain must be on a static or kinematic body"), std::string::npos)
        << edited.error();
    EXPECT_TRUE(s.registry.tryGet<Static>(chain)->value);
    // Adding kinematic turns static off.
    edited = editor::addComponentToAll(s, kinematic, {chain});
    ASSERT_TRUE(edited) << edited.error();
    EXPECT_TRUE(s.registry.tryGet<Kinematic>(chain)->value);
    EXPECT_FALSE(s.registry.tryGet<Static>(chain)->value);
    // And ticking static again turns kinematic off.
    edited = editor::setFieldOnAll(s, still, still.fields[0], true, {chain});
    ASSERT_TRUE(edited) << edited.error();
    EXPECT_TRUE(s.registry.tryGet<Static>(chain)->value);
    EXPECT_FALSE(s.registry.tryGet<Kinematic>(chain)->value);
    edited = editor::setFieldOnAll(s, kinematic, kinematic.fields[0], true, {chain});
    ASSERT_TRUE(edited) << edited.error();
    EXPECT_TRUE(s.registry.tryGet<Kinematic>(chain)->value);
    EXPECT_FALSE(s.registry.tryGet<Static>(chain)->value);
}
