// Renderer unit tests that need no GL context: overlay parsing, camera
// fitting, batching and arrow scales (render/frame.hpp).

#include "frame.hpp"

#include "stepwise/components.hpp"
#include "stepwise/world.hpp"

#include <gtest/gtest.h>

#include <optional>
#include <set>
#include <stdexcept>

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

/// rows x columns circles of radius 0.25 m touching in a square packing on
/// a floor: about two contacts per body once stepped.
Scene packedCircles(int rows, int columns) {
    Scene scene;
    const Entity floor = scene.registry.create();
    scene.registry.emplace<Plane>(floor, {{0.0, 1.0}, 0.0});
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < columns; ++c) {
            Entity e = scene.registry.create();
            // append(), not "c" + ...: GCC 12 warns falsely (-Wrestrict) on the latter.
            scene.registry.emplace<Name>(e, {std::string("c").append(std::to_string(r * columns + c))});
            scene.registry.emplace<Position>(e, {{0.5 * c, 0.25 + 0.5 * r}});
            scene.registry.emplace<Velocity>(e, {{0.1 * (c % 5), -0.2}});
            scene.registry.emplace<Mass>(e, {1.0});
            scene.registry.emplace<Radius>(e, {0.25});
        }
    return scene;
}

std::size_t countOf(const DrawData& data, BatchKind kind) {
    std::size_t n = 0;
    for (const Batch& b : data.batches)
        if (b.kind == kind) n += b.count();
    return n;
}

/// Pixel position of a world point under `input`'s camera (frame.cpp's transform).
Vec2 pixelOf(const FrameInput& input, Vec2 p, int w, int h) {
    const double ppm = input.camera.pixelsPerMetre(h);
    return {(p.x - input.camera.center.x) * ppm + 0.5 * w, (p.y - input.camera.center.y) * ppm + 0.5 * h};
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

TEST(RenderBatching, OnlyBatchesWithoutRareFeaturesArePlain) {
    // Batch::plain lets the renderer use a shader without the selection
    // ring, hatching and glow: it must be false whenever one is needed.
    Scene scene = ringOfCircles(100);
    const Entity chosen = scene.registry.entities().front();
    FrameInput input;
    input.scene = &scene;
    input.camera = fitCamera(scene, 800, 600);
    input.overlays.add(Overlay::Aabb);
    auto discs = [&](bool plain) {
        std::size_t n = 0;
        for (const Batch& b : buildDrawData(input, 800, 600).batches)
            if (b.kind == BatchKind::Disc && b.plain == plain) n += b.count();
        return n;
    };
    EXPECT_EQ(discs(true), 100u);
    EXPECT_EQ(discs(false), 0u);
    input.selection = {chosen};
    EXPECT_EQ(discs(true), 99u);
    EXPECT_EQ(discs(false), 1u);
    scene.registry.emplace<Static>(scene.registry.entities()[1], {true});
    EXPECT_EQ(discs(false), 2u);
    // Bounding boxes and HUD panels are plain boxes; no box body here.
    for (const Batch& b : buildDrawData(input, 800, 600).batches) {
        if (b.kind == BatchKind::Box) {
            EXPECT_TRUE(b.plain);
        }
    }
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

TEST(RenderBatching, ContactMarkersAndAnchoredSpringsDoNotSplitBatches) {
    // A contact is an arrow and a dot, an anchored spring a pin and
    // segments. Drawn item by item they would start a new batch (a draw
    // call) per item: 4,000 draw calls for 2,000 contacts.
    Scene scene = packedCircles(10, 20);
    const std::vector<Entity> order = scene.registry.entities();  // the floor, then c0 .. c199
    for (int i = 0; i < 20; ++i) {
        Entity s = scene.registry.create();
        scene.registry.emplace<Spring>(s, {order.at(std::size_t(1 + 180 + i)), Entity{}, Vec2{0.5 * i, 8.0}, 50.0, 0.5, 2.0});
    }
    Result<World> world = World::build(scene);
    ASSERT_TRUE(world.ok()) << world.error();
    ASSERT_TRUE(world->step());
    const std::size_t contacts = world->contacts().size();
    ASSERT_GT(contacts, 300u);  // past CellThinner's limit, so some are thinned
    FrameInput input;
    input.scene = &scene;
    input.world = &*world;
    input.camera = fitCamera(scene, 1280, 800);
    input.overlays.add(Overlay::Contacts);
    const DrawData data = buildDrawData(input, 1280, 800);
    // Grid, planes, springs, bodies, contacts, HUD: a handful of batches.
    EXPECT_LE(data.batches.size(), 14u);
    // Every kept contact has its arrow and its dot (the legend adds one arrow).
    std::size_t contactDots = 0;
    for (const Batch& b : data.batches)
        if (b.kind == BatchKind::Disc)
            for (std::size_t i = 0; i < b.count(); ++i) contactDots += b.data[i * 9 + 2] <= 3.0f ? 1 : 0;
    EXPECT_EQ(countOf(data, BatchKind::Arrow), contactDots + 1);
    EXPECT_GT(contactDots, 100u);
    EXPECT_LT(contactDots, contacts);
}

TEST(RenderLevelOfDetail, FewArrowsAreAllDrawnEvenWhenCrowded) {
    // 300 bodies (CellThinner's limit) 2 px apart: every arrow is drawn.
    Scene scene = packedCircles(15, 20);
    FrameInput input;
    input.scene = &scene;
    input.camera = Camera{{5.0, 4.0}, 4.0};
    input.overlays.add(Overlay::Velocity);
    input.hud = false;
    EXPECT_EQ(countOf(buildDrawData(input, 1280, 800), BatchKind::Arrow), 300u);
}

TEST(RenderLevelOfDetail, CrowdedArrowsKeepOnePerCellAndTheSelection) {
    Scene scene = packedCircles(40, 50);  // 2,000 bodies
    FrameInput input;
    input.scene = &scene;
    input.camera = fitCamera(scene, 1280, 800);
    input.overlays.add(Overlay::Velocity);
    input.hud = false;
    const int w = 1280, h = 800;
    // One arrow per cell of max(24 px, half the 0.06 h reference arrow).
    const double cell = std::max(24.0, 0.5 * 0.06 * h);
    const double ppm = input.camera.pixelsPerMetre(h);
    ASSERT_LT(0.5 * ppm, cell);  // bodies are closer than a cell
    const DrawData thinned = buildDrawData(input, w, h);
    const std::size_t arrows = countOf(thinned, BatchKind::Arrow);
    const double bodiesSpanPx = 25.0 * ppm * 20.0 * ppm;  // 25 m x 20 m of bodies
    EXPECT_LE(double(arrows), bodiesSpanPx / (cell * cell) + 2.0 * (25.0 + 20.0) * ppm / cell + 1.0);
    EXPECT_GE(double(arrows), 0.5 * bodiesSpanPx / (cell * cell));
    // Each kept arrow starts in its own cell.
    std::set<std::pair<int, int>> cells;
    for (const Batch& b : thinned.batches) {
        if (b.kind != BatchKind::Arrow) continue;
        for (std::size_t i = 0; i < b.count(); ++i) {
            EXPECT_TRUE(cells.insert({int(b.data[i * 9] / cell), int(b.data[i * 9 + 1] / cell)}).second);
        }
    }
    // A selected body keeps its arrow even when its cell went to another.
    auto arrowAt = [&](const DrawData& d, Vec2 at) {
        for (const Batch& b : d.batches)
            if (b.kind == BatchKind::Arrow)
                for (std::size_t i = 0; i < b.count(); ++i)
                    if (std::abs(b.data[i * 9] - at.x) < 1e-3 && std::abs(b.data[i * 9 + 1] - at.y) < 1e-3) return true;
        return false;
    };
    std::optional<Entity> dropped;
    scene.registry.each<Position, Velocity>([&](Entity e, const Position& p, const Velocity&) {
        if (!dropped && !arrowAt(thinned, pixelOf(input, p.value, w, h))) dropped = e;
    });
    ASSERT_TRUE(dropped.has_value());
    input.selection = {*dropped};
    const Vec2 at = pixelOf(input, scene.registry.tryGet<Position>(*dropped)->value, w, h);
    EXPECT_TRUE(arrowAt(buildDrawData(input, w, h), at));
}

/// A 40 x 50 square packing of circles (2,000 bounding boxes) at 720x476
/// with the aabb overlay and no HUD: the editor bench's crowd.
FrameInput crowdedAabb(const Scene& scene, int w, int h) {
    FrameInput input;
    input.scene = &scene;
    input.camera = fitCamera(scene, w, h);
    input.overlays.add(Overlay::Aabb);
    input.hud = false;
    return input;
}

TEST(RenderAabb, CrowdedOutlinesAreOneLayerWithTheBoxShadersCoverage) {
    const int w = 720, h = 476;
    const Scene scene = packedCircles(40, 50);
    const FrameInput input = crowdedAabb(scene, w, h);
    const DrawData data = buildDrawData(input, w, h);
    ASSERT_EQ(countOf(data, BatchKind::Image), 1u);
    ASSERT_EQ(data.images.size(), 1u);
    EXPECT_EQ(countOf(data, BatchKind::Box), 0u) << "no outline is drawn twice";
    const Batch* layerBatch = nullptr;
    for (const Batch& b : data.batches)
        if (b.kind == BatchKind::Image) layerBatch = &b;
    const int x0 = int(layerBatch->data[0]), y0 = int(layerBatch->data[1]);
    const PixelLayer& layer = data.images[0];
    EXPECT_EQ(int(layerBatch->data[2]) - x0, layer.width);
    EXPECT_EQ(int(layerBatch->data[3]) - y0, layer.height);
    ASSERT_EQ(layer.coverage.size(), std::size_t(layer.width) * std::size_t(layer.height));
    const auto alphaAt = [&](int x, int y) { return int(layer.coverage[std::size_t(y - y0) * std::size_t(layer.width) + std::size_t(x - x0)]); };
    // Cells and outlines share the layer: an occupied cell of the grid (1 m
    // here, twice the median extent) is a fill of alpha 0.06, 1 px in from
    // the cell's sides, and the outlines are composited "over" it in 8 bits,
    // as the quads would blend into the framebuffer.
    const int cellFill = int(0.06 * 255.0 + 0.5);
    const auto over = [](int dst, int a) { return a + (dst * (255 - a) + 127) / 255; };
    // box.frag's outline coverage clamp(1.1 - |d|) x 0.75, d the distance
    // from the pixel centre to the box's edge, to the 8-bit rounding.
    const auto outline = [](double d) { return int(std::clamp(1.1 - d, 0.0, 1.0) * 0.75 * 255.0 + 0.5); };
    // The bottom-left circle: its box's left edge (x = -0.25 m, inside the
    // cell from -1 to 0 m) has no neighbour.
    const double ppm = input.camera.pixelsPerMetre(h);
    const Vec2 c = pixelOf(input, {0.0, 0.25}, w, h);
    const double half = 0.25 * ppm;
    const int y = int(std::floor(c.y));  // a row through the middle of the box
    for (int x = int(std::floor(c.x - half)) - 2; x <= int(std::floor(c.x - half)) + 2; ++x) {
        const double d = std::abs(std::abs(x + 0.5 - c.x) - half);
        EXPECT_NEAR(alphaAt(x, y), over(cellFill, outline(d)), 1.0) << "pixel " << x << ", " << y;
    }
    // Inside the box, away from its edges: the cell's fill alone ...
    EXPECT_EQ(alphaAt(int(std::floor(pixelOf(input, {-0.125, 0.25}, w, h).x)), y), cellFill);
    // ... and at its centre, x = 0 m, the 2 px gap between two cells: nothing.
    EXPECT_EQ(alphaAt(int(std::floor(c.x)), y), 0);
    // The layer is drawn in the overlay's colour (0x68d391).
    EXPECT_EQ(int(layer.colour[0] * 255.0f + 0.5f), 0x68);
    EXPECT_EQ(int(layer.colour[1] * 255.0f + 0.5f), 0xd3);
    EXPECT_EQ(int(layer.colour[2] * 255.0f + 0.5f), 0x91);
    // Where two boxes' outlines meet, each covers the pixel, one over the
    // other: the shared edge of the two bottom-left boxes, at x = 0.25 m.
    const double edge = pixelOf(input, {0.25, 0.25}, w, h).x;
    for (int x = int(std::floor(edge)) - 1; x <= int(std::floor(edge)) + 1; ++x) {
        const int a = outline(std::abs(x + 0.5 - edge));
        EXPECT_NEAR(alphaAt(x, y), over(over(cellFill, a), a), 1.0) << "pixel " << x << ", " << y;
    }
    // Asked not to, the same frame draws one box quad per body.
    const DrawData quads = buildDrawData(input, w, h, BuildOptions{.pixelLayers = false});
    EXPECT_EQ(countOf(quads, BatchKind::Image), 0u);
    EXPECT_EQ(countOf(quads, BatchKind::Box), 2000u);
}

TEST(RenderAabb, FewOutlinesStayOneQuadEach) {
    // A ring of 100 small circles spread over the image: one layer over
    // them all would shade far more pixels than their 100 quads.
    const Scene scene = ringOfCircles(100);
    const FrameInput input = crowdedAabb(scene, 800, 600);
    const DrawData data = buildDrawData(input, 800, 600);
    EXPECT_EQ(countOf(data, BatchKind::Image), 0u);
    EXPECT_TRUE(data.images.empty());
    EXPECT_EQ(countOf(data, BatchKind::Box), 100u);
}

TEST(RenderFields, VelocityFieldIsTheGaussianWeightedMeanOfTheBodiesNearASample) {
    // 640x480 at 24 px a metre: the field's samples sit 24 px = 1 m apart,
    // at the centres of the metre cells. Two bodies near the sample at
    // (0.5, 0.5) m: one 0.3 m to its right moving +x, one 1 m above moving
    // +y. The field there is their mean weighted by exp(-r^2 / 2) (r in
    // sample spacings), so its arrow points at atan2(wB, wA).
    Scene scene;
    const auto body = [&](Vec2 p, Vec2 v) {
        const Entity e = scene.registry.create();
        scene.registry.emplace<Position>(e, {p});
        scene.registry.emplace<Velocity>(e, {v});
        scene.registry.emplace<Mass>(e, {1.0});
        scene.registry.emplace<Radius>(e, {0.1});
    };
    body({0.8, 0.5}, {1.0, 0.0});
    body({0.5, 1.5}, {0.0, 1.0});
    FrameInput input;
    input.scene = &scene;
    input.camera = Camera{{0.0, 0.0}, 36.0};  // 36 x 480 / 720 = 24 px a metre
    input.overlays = *parseOverlayList("velocity-field");
    input.hud = false;
    const DrawData data = buildDrawData(input, 640, 480);
    const auto arrowCentredAt = [&](double x, double y) -> const float* {
        for (const Batch& b : data.batches) {
            if (b.kind != BatchKind::Arrow) continue;
            for (std::size_t i = 0; i < b.count(); ++i) {
                const float* a = b.data.data() + i * 9;
                if (std::abs(0.5 * (a[0] + a[2]) - x) < 1e-3 && std::abs(0.5 * (a[1] + a[3]) - y) < 1e-3) return a;
            }
        }
        return nullptr;
    };
    const float* a = arrowCentredAt(320.0 + 0.5 * 24.0, 240.0 + 0.5 * 24.0);
    ASSERT_NE(a, nullptr) << "no arrow at the sample (0.5, 0.5) m";
    const double wA = std::exp(-0.5 * 0.3 * 0.3), wB = std::exp(-0.5 * 1.0);
    EXPECT_NEAR(std::atan2(a[3] - a[1], a[2] - a[0]), std::atan2(wB, wA), 1e-5);
    // The sample at (1.5, 0.5) m: A is 0.7 m away, B sqrt(2) m.
    const float* right = arrowCentredAt(320.0 + 1.5 * 24.0, 240.0 + 0.5 * 24.0);
    ASSERT_NE(right, nullptr) << "no arrow at the sample (1.5, 0.5) m";
    EXPECT_NEAR(std::atan2(right[3] - right[1], right[2] - right[0]), std::atan2(std::exp(-1.0), std::exp(-0.5 * 0.49)), 1e-5);
    // Beyond two spacings of every body, no sample has a value: no arrow.
    EXPECT_EQ(arrowCentredAt(320.0 + 4.5 * 24.0, 240.0 + 4.5 * 24.0), nullptr);
    EXPECT_EQ(arrowCentredAt(320.0 - 3.5 * 24.0, 240.0 + 0.5 * 24.0), nullptr);
}

TEST(RenderTrails, ATrailThatIsOnePointIsKnownAsOneAndDrawsNothing) {
    // Capacity 4. A body that moves, then stops: its trail is one point
    // once all four recorded positions are equal, not before.
    Scene scene;
    const Entity mover = scene.registry.create();
    scene.registry.emplace<Position>(mover, {{0.0, 0.0}});
    const Entity still = scene.registry.create();
    scene.registry.emplace<Position>(still, {{2.0, 0.0}});
    TrailRecorder trails(4);
    const auto trailOf = [&](Entity e) -> const TrailRecorder::Trail& {
        for (const TrailRecorder::Trail& t : trails.trails())
            if (t.entity == e) return t;
        throw std::runtime_error("no trail");
    };
    trails.record(scene);
    scene.registry.tryGet<Position>(mover)->value = {1.0, 0.0};
    for (int k = 0; k < 3; ++k) trails.record(scene);
    EXPECT_EQ(trailOf(mover).points.size(), 4u);
    EXPECT_FALSE(trailOf(mover).isPoint()) << "the first point is elsewhere";
    EXPECT_TRUE(trailOf(still).isPoint());
    // Drawn, the moving trail has its segment and the still one none.
    FrameInput input;
    input.scene = &scene;
    input.camera = Camera{{1.0, 0.0}, 100.0};
    input.overlays = *parseOverlayList("trails");
    input.trails = &trails;
    input.hud = false;
    EXPECT_EQ(countOf(buildDrawData(input, 640, 480), BatchKind::Segment), 1u);
    trails.record(scene);  // the move leaves the window of four
    EXPECT_TRUE(trailOf(mover).isPoint());
    EXPECT_EQ(trailOf(mover).points.size(), 4u);
    EXPECT_EQ(countOf(buildDrawData(input, 640, 480), BatchKind::Segment), 0u);
    // Moving again starts a line.
    scene.registry.tryGet<Position>(mover)->value = {1.5, 0.0};
    trails.record(scene);
    EXPECT_FALSE(trailOf(mover).isPoint());
    EXPECT_EQ(countOf(buildDrawData(input, 640, 480), BatchKind::Segment), 1u);
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

TEST(RenderContacts, AFloorContactArrowPointsOutOfTheFloor) {
    // A ball resting on y = 0: the contact's normal points from the ball
    // into the floor; the arrow shows the impulse on the ball, upwards.
    Scene scene;
    const Entity floor = scene.registry.create();
    scene.registry.emplace<Plane>(floor, {{0.0, 1.0}, 0.0});
    const Entity ball = scene.registry.create();
    scene.registry.emplace<Position>(ball, {{0.0, 0.49}});
    scene.registry.emplace<Velocity>(ball, {{0.0, 0.0}});
    scene.registry.emplace<Mass>(ball, {1.0});
    scene.registry.emplace<Radius>(ball, {0.5});
    Result<World> world = World::build(scene);
    ASSERT_TRUE(world.ok()) << world.error();
    ASSERT_TRUE(world->step());
    ASSERT_FALSE(world->contacts().empty());
    FrameInput input;
    input.scene = &scene;
    input.world = &*world;
    input.camera = Camera{{0.0, 0.0}, 40.0};
    input.overlays = *parseOverlayList("contacts");
    input.hud = false;
    const DrawData data = buildDrawData(input, 400, 300);
    int arrows = 0;
    for (const Batch& b : data.batches) {
        if (b.kind != BatchKind::Arrow) continue;
        for (std::size_t i = 0; i < b.count(); ++i, ++arrows)
            EXPECT_GT(b.data[i * 9 + 3], b.data[i * 9 + 1]) << "tip below the base: the arrow points into the floor";
    }
    EXPECT_GT(arrows, 0);
}

} // namespace

TEST(RenderPolygons, FanOutlineAndRingFollowTheTurnedOutline) {
    // An off-centre triangle turned 90 degrees: vertex (2, 0) about position
    // (1, 1) lands at (1, 3). The fill is one fan triangle per edge, the
    // outline one segment per edge (plus two per corner of the selection
    // ring when selected), and no point-mass dot.
    Scene scene;
    const Entity e = scene.registry.create();
    scene.registry.emplace<Position>(e, {{1.0, 1.0}});
    scene.registry.emplace<Angle>(e, {1.5707963267948966});
    scene.registry.emplace<Polygon>(e, {{{1.0, -0.5}, {2.0, 0.0}, {1.0, 0.5}}});
    FrameInput input;
    input.scene = &scene;
    input.camera = Camera{{1.0, 2.0}, 100.0};
    input.hud = false;
    const DrawData plain = buildDrawData(input, 800, 600);
    Scene empty;
    FrameInput gridOnly = input;
    gridOnly.scene = &empty;
    const std::size_t grid = countOf(buildDrawData(gridOnly, 800, 600), BatchKind::Solid);  // the grid is Solid too
    EXPECT_EQ(countOf(plain, BatchKind::Solid) - grid, 3u * 3u) << "three fan triangles, three vertices each";
    EXPECT_EQ(countOf(plain, BatchKind::Segment), 3u);
    EXPECT_EQ(countOf(plain, BatchKind::Disc), 0u);
    const Vec2 apex = pixelOf(input, {1.0, 3.0}, 800, 600);
    bool found = false;
    for (const Batch& b : plain.batches)
        if (b.kind == BatchKind::Segment)
            for (std::size_t i = 0; i < b.count(); ++i) {
                const float* s = b.data.data() + i * floatsPerInstance(BatchKind::Segment);
                found = found || (std::abs(s[0] - apex.x) < 1e-3 && std::abs(s[1] - apex.y) < 1e-3);
            }
    EXPECT_TRUE(found) << "an outline segment starts at the turned vertex";
    input.selection = {e};
    EXPECT_EQ(countOf(buildDrawData(input, 800, 600), BatchKind::Segment), 3u + 6u);
    // The camera fit and the AABB overlay use the turned outline: y from 2 to 3 here, x from 0.5 to 1.5.
    input.selection.clear();
    input.overlays.add(Overlay::Aabb);
    const DrawData boxes = buildDrawData(input, 800, 600);
    bool aabbFound = false;
    const double ppm = input.camera.pixelsPerMetre(600);
    const Vec2 centrePx = pixelOf(input, {1.0, 2.5}, 800, 600);
    for (const Batch& b : boxes.batches)
        if (b.kind == BatchKind::Box)
            for (std::size_t i = 0; i < b.count(); ++i) {
                const float* r = b.data.data() + i * floatsPerInstance(BatchKind::Box);
                aabbFound = aabbFound || (std::abs(r[0] - centrePx.x) < 1e-3 && std::abs(r[1] - centrePx.y) < 1e-3 &&
                                          std::abs(r[2] - 0.5 * ppm) < 1e-3 && std::abs(r[3] - 0.5 * ppm) < 1e-3);
            }
    EXPECT_TRUE(aabbFound) << "a 1 m x 1 m box centred on (1, 2.5)";
}
