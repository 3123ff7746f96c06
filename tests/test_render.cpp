// Renderer unit tests that need no GL context: overlay parsing, camera
// fitting, batching and arrow scales (editor/render/frame.hpp).

#include "render/frame.hpp"

#include "stepwise/components.hpp"

#include <gtest/gtest.h>

using namespace stepwise;
using namespace stepwise::render;

namespace {

Scene ringOfCircles(int n) {
    Scene scene;
    for (int i = 0; i < n; ++i) {
        Entity e = scene.registry.create();
        const double a = 6.283185307179586 * i / n;
        scene.registry.emplace<Position>(e, {{10.0 * std::cos(a) + 3.0, 10.0 * std::sin(a) - 2.0}});
        scene.registry.emplace<Velocity>(e, {{double(i % 7), 1.0}});
        scene.registry.emplace<Radius>(e, {0.2});
    }
    return scene;
}

TEST(RenderOverlays, ParsesNamesAllAndNone) {
    Result<OverlaySet> set = parseOverlayList("velocity,force-field");
    ASSERT_TRUE(set.ok());
    EXPECT_TRUE(set->has(Overlay::Velocity));
    EXPECT_TRUE(set->has(Overlay::ForceField));
    EXPECT_FALSE(set->has(Overlay::Force));
    Result<OverlaySet> all = parseOverlayList("all");
    ASSERT_TRUE(all.ok());
    for (const auto& [name, o] : overlayNames()) EXPECT_TRUE(all->has(o)) << name;
    Result<OverlaySet> none = parseOverlayList("");
    ASSERT_TRUE(none.ok());
    EXPECT_EQ(none->bits, 0u);
}

TEST(RenderOverlays, UnknownNameIsNamedInTheError) {
    Result<OverlaySet> set = parseOverlayList("velocity,forcefield");
    ASSERT_FALSE(set.ok());
    EXPECT_NE(set.error().find("\"forcefield\""), std::string::npos) << set.error();
    EXPECT_NE(set.error().find("force-field"), std::string::npos) << set.error();
}

TEST(RenderCamera, FitShowsEveryBody) {
    Scene scene = ringOfCircles(64);
    for (auto [w, h] : {std::pair{1920, 1080}, std::pair{400, 800}}) {
        const Camera cam = fitCamera(scene, w, h);
        const double ppm = cam.pixelsPerMetre(h);
        scene.registry.each<Position, Radius>([&](Entity, const Position& p, const Radius& r) {
            const double x = (p.value.x - cam.center.x) * ppm + 0.5 * w;
            const double y = (p.value.y - cam.center.y) * ppm + 0.5 * h;
            EXPECT_GE(x - r.value * ppm, 0.0);
            EXPECT_LE(x + r.value * ppm, double(w));
            EXPECT_GE(y - r.value * ppm, 0.0);
            EXPECT_LE(y + r.value * ppm, double(h));
        });
        EXPECT_NEAR(cam.center.x, 3.0, 1e-9);
        EXPECT_NEAR(cam.center.y, -2.0, 1e-9);
    }
}

TEST(RenderCamera, LevelViewWinsAndZoomScalesWithHeight) {
    Scene scene = ringOfCircles(8);
    scene.view = View{{1.0, 2.0}, 50.0};
    const Camera cam = sceneCamera(scene, 1920, 1080);
    EXPECT_EQ(cam.center, (Vec2{1.0, 2.0}));
    EXPECT_DOUBLE_EQ(cam.pixelsPerMetre(720), 50.0);
    EXPECT_DOUBLE_EQ(cam.pixelsPerMetre(1080), 75.0);
}

TEST(RenderBatching, ThousandCirclesAreOneBatch) {
    Scene scene = ringOfCircles(1000);
    FrameInput input;
    input.scene = &scene;
    input.camera = fitCamera(scene, 800, 600);
    input.hud = false;
    const DrawData data = buildDrawData(input, 800, 600);
    std::size_t discBatches = 0, discs = 0;
    for (const Batch& b : data.batches)
        if (b.kind == BatchKind::Disc) ++discBatches, discs += b.count();
    EXPECT_EQ(discBatches, 1u);
    EXPECT_EQ(discs, 1000u);
}

TEST(RenderBatching, VelocityArrowsUseARoundReferenceAndLogLength) {
    Scene scene = ringOfCircles(100);
    FrameInput input;
    input.scene = &scene;
    input.camera = fitCamera(scene, 800, 600);
    input.overlays.add(Overlay::Velocity);
    const DrawData data = buildDrawData(input, 800, 600);
    // Speeds are sqrt(k^2 + 1), k = 0..6: median sqrt(10) = 3.16 -> 5 m/s.
    EXPECT_DOUBLE_EQ(data.scales.velocity, 5.0);
    std::size_t arrows = 0;
    for (const Batch& b : data.batches)
        if (b.kind == BatchKind::Arrow) arrows += b.count();
    EXPECT_GE(arrows, 100u);  // one per body (+ the legend sample)
    // A frozen reference is kept as given.
    input.scales.velocity = 2.0;
    EXPECT_DOUBLE_EQ(buildDrawData(input, 800, 600).scales.velocity, 2.0);
}

TEST(RenderBatching, OffscreenBodiesAreCulled) {
    Scene scene = ringOfCircles(100);
    FrameInput input;
    input.scene = &scene;
    input.camera = Camera{{1000.0, 1000.0}, 40.0};
    input.hud = false;
    const DrawData data = buildDrawData(input, 800, 600);
    // Only the grid (Solid geometry) remains: no body is near the camera.
    for (const Batch& b : data.batches) EXPECT_EQ(b.kind, BatchKind::Solid);
}

TEST(RenderBatching, SameInputSameFloats) {
    Scene scene = ringOfCircles(300);
    FrameInput input;
    input.scene = &scene;
    input.camera = fitCamera(scene, 640, 480);
    input.overlays = *parseOverlayList("velocity,velocity-field,aabb");
    const DrawData a = buildDrawData(input, 640, 480), b = buildDrawData(input, 640, 480);
    ASSERT_EQ(a.batches.size(), b.batches.size());
    for (std::size_t i = 0; i < a.batches.size(); ++i) EXPECT_EQ(a.batches[i].data, b.batches[i].data);
}

} // namespace
