// What the debugging overlays show must be true
// and legible. The force overlay offers the applied force (gravity, springs,
// ...) and the net force (m dv/dt over the last step, contacts included), and
// says which is which; gravity stays visible next to a strong attractor; the
// legend's text is readable in the editor's viewport; after a step back the
// contacts (and net forces) shown are those of the restored step.

#include "app/editor.hpp"
#include "frame.hpp"
#include "scene_bounds.hpp"

#include "stepwise/components.hpp"
#include "stepwise/world.hpp"

#include "test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <array>
#include <set>

using namespace stepwise;
using namespace stepwise::render;
namespace fs = std::filesystem;

namespace {

constexpr double kG = 9.81;

/// A 2 kg crate (1 m box) resting on a floor at y = 0, settled for two seconds.
struct RestingCrate {
    Scene scene;
    std::optional<World> world;
    RestingCrate() {
        scene.world.gravity = {0.0, -kG};
        const Entity floor = scene.registry.create();
        scene.registry.emplace<Name>(floor, {"floor"});
        scene.registry.emplace<Plane>(floor, {{0.0, 1.0}, 0.0});
        const Entity crate = scene.registry.create();
        scene.registry.emplace<Name>(crate, {"crate"});
        scene.registry.emplace<Position>(crate, {{0.0, 0.5}});
        scene.registry.emplace<Velocity>(crate, {{0.0, 0.0}});
        scene.registry.emplace<Mass>(crate, {2.0});
        scene.registry.emplace<Box>(crate, {1.0, 1.0});
        Result<World> built = World::build(scene);
        EXPECT_TRUE(built) << built.error();
        world.emplace(std::move(*built));
        for (int i = 0; i < 120; ++i) EXPECT_TRUE(world->step());
        world->writeBack(scene);
    }
};

/// Arrows of one colour in the frame: (from, to) in pixels.
std::vector<std::pair<Vec2, Vec2>> arrowsOf(const DrawData& data, float r, float g, float b) {
    std::vector<std::pair<Vec2, Vec2>> out;
    for (const Batch& batch : data.batches) {
        if (batch.kind != BatchKind::Arrow) continue;
        const std::size_t k = floatsPerInstance(BatchKind::Arrow);
        for (std::size_t i = 0; i + k <= batch.data.size(); i += k) {
            const float* a = &batch.data[i];
            if (std::abs(a[5] - r) < 1e-3f && std::abs(a[6] - g) < 1e-3f && std::abs(a[7] - b) < 1e-3f)
                out.push_back({{a[0], a[1]}, {a[2], a[3]}});
        }
    }
    return out;
}

bool hasNote(const DrawData& data, const std::string& text) {
    return std::find(data.notes.begin(), data.notes.end(), text) != data.notes.end();
}

TEST(ForceOverlay, ARestingCrateFeelsItsWeightAppliedAndAboutNothingNet) {
    RestingCrate c;
    const Vec2 applied = c.world->bodyForces().at(0);
    const std::vector<Vec2> net = c.world->netForces();
    ASSERT_EQ(net.size(), 1u);
    EXPECT_NEAR(applied.x, 0.0, 1e-12);
    EXPECT_NEAR(applied.y, -2.0 * kG, 1e-12);  // m g
    // The floor carries the weight: what is left moves the crate, and it is
    // at rest. Bound: 1% of its weight.
    EXPECT_LT(length(net[0]), 0.01 * 2.0 * kG) << net[0].x << ", " << net[0].y;
}

TEST(ForceOverlay, NetForceIsTheMomentumChangeOfTheLastStepAndUnknownBeforeOne) {
    // A falling ball with no contact: the net force is its weight; after a
    // restore (no step to measure) it is not known.
    Scene s;
    s.world.gravity = {0.0, -kG};
    const Entity ball = s.registry.create();
    s.registry.emplace<Position>(ball, {{0.0, 10.0}});
    s.registry.emplace<Velocity>(ball, {{1.0, 0.0}});
    s.registry.emplace<Mass>(ball, {3.0});
    Result<World> built = World::build(s);
    ASSERT_TRUE(built) << built.error();
    EXPECT_TRUE(built->netForces().empty());
    const WorldState start = built->saveState();
    ASSERT_TRUE(built->step());
    const std::vector<Vec2> net = built->netForces();
    ASSERT_EQ(net.size(), 1u);
    EXPECT_NEAR(net[0].x, 0.0, 1e-9);
    EXPECT_NEAR(net[0].y, -3.0 * kG, 1e-9);
    ASSERT_TRUE(built->restoreState(start));
    EXPECT_TRUE(built->netForces().empty());
}

TEST(ForceOverlay, BothModesAreOfferedAndTheLegendSaysWhichIsShown) {
    Result<OverlaySet> set = parseOverlayList("force,net-force");
    ASSERT_TRUE(set) << set.error();
    EXPECT_TRUE(set->has(Overlay::Force));
    EXPECT_TRUE(set->has(Overlay::NetForce));
    EXPECT_TRUE(set->needsWorld());

    RestingCrate c;
    FrameInput in;
    in.scene = &c.scene;
    in.world = &*c.world;
    in.overlays = *set;
    in.camera = Camera{{0.0, 1.0}, 80.0};
    const DrawData data = buildDrawData(in, 960, 540);
    // The crate's arrows start at its centre (the legend's sample arrows elsewhere).
    const Vec2 centre = Vec2{480.0, 270.0} + (c.world->bodyPosition(0) - in.camera.center) * in.camera.pixelsPerMetre(540);
    const auto fromCrate = [&](std::vector<std::pair<Vec2, Vec2>> arrows) {
        std::erase_if(arrows, [&](const auto& a) { return length(a.first - centre) > 0.5; });
        return arrows;
    };
    // Applied (orange): the weight, pointing down, at least the reference
    // length (m g is the only force, so it is the reference's low end).
    const auto applied = fromCrate(arrowsOf(data, 0xf6 / 255.0f, 0xad / 255.0f, 0x55 / 255.0f));
    ASSERT_EQ(applied.size(), 1u);
    const Vec2 a = applied[0].second - applied[0].first;
    EXPECT_LT(a.y, -0.06 * 540 * 0.9) << "the applied arrow should be about the 32 px reference long";
    EXPECT_NEAR(a.x, 0.0, 1e-3);
    // Net (pink): the same reference, so under 1% of it is under a pixel:
    // no arrow at the crate (the legend still has its row).
    EXPECT_TRUE(fromCrate(arrowsOf(data, 0xf6 / 255.0f, 0x87 / 255.0f, 0xb3 / 255.0f)).empty());
    EXPECT_EQ(data.scales.force, 20.0);  // m g = 19.62 N, rounded up to 1-2-5
    EXPECT_FALSE(hasNote(data, "net force: shown once a step is taken"));
    EXPECT_EQ(data.legend, (std::vector<std::string>{"applied force = 20 N", "net force (m dv/dt) = 20 N"}));

    // Without a step since the build there is no net force to show: a note says so.
    Result<World> fresh = World::build(c.scene);
    ASSERT_TRUE(fresh);
    in.world = &*fresh;
    const DrawData unstepped = buildDrawData(in, 960, 540);
    EXPECT_TRUE(hasNote(unstepped, "net force: shown once a step is taken"));
}

TEST(ForceFieldOverlay, GravityStaysVisibleNextToAStrongAttractor) {
    // Gravity plus a static attractor whose pull is 190 g at the grid sample
    // nearest to it and g at 35 m. With the field's reference the median of
    // the samples above 1% of the largest, gravity's samples would fall
    // under that cut, the attractor's would set the reference, and gravity's
    // arrows would shrink to 2-3 px dots.
    Scene s;
    s.world.gravity = {0.0, -kG};
    const Entity sun = s.registry.create();
    s.registry.emplace<Position>(sun, {{0.0, 0.0}});
    s.registry.emplace<Mass>(sun, {1.2e4});
    s.registry.emplace<Static>(sun, {true});
    s.registry.emplace<Attractor>(sun, {0.5});
    Result<World> world = World::build(s);
    ASSERT_TRUE(world) << world.error();
    FrameInput in;
    in.scene = &s;
    in.world = &*world;
    in.overlays.add(Overlay::ForceField);
    in.camera = Camera{{0.0, 0.0}, 10.0};  // 128 m x 72 m
    const int w = 960, h = 540;
    const DrawData data = buildDrawData(in, w, h);
    const double ppm = in.camera.pixelsPerMetre(h);
    const double spacingPx = std::max(24.0, std::round(h / 20.0));
    int gravityArrows = 0;
    double shortest = 1e9;
    for (const auto& [from, to] : arrowsOf(data, 0xa7 / 255.0f, 0x8b / 255.0f, 0xfa / 255.0f)) {
        const Vec2 mid = 0.5 * (from + to);
        const Vec2 p{(mid.x - 0.5 * w) / ppm, (mid.y - 0.5 * h) / ppm};
        const Vec2 pull = world->probeForce(p) - s.world.gravity;
        // Samples where gravity is most of the field (the pull under g/2).
        if (length(pull) > 0.5 * kG) continue;
        ++gravityArrows;
        shortest = std::min(shortest, length(to - from));
    }
    ASSERT_GT(gravityArrows, 10);
    // A third of the grid spacing (9 px here): an arrow, not a dot.
    EXPECT_GT(shortest, spacingPx / 3.0) << "gravity arrows " << gravityArrows << ", reference "
                                         << data.scales.forceField << " N/kg";
    EXPECT_LE(data.scales.forceField, 20.0);
}

TEST(Legend, TextIsReadableInTheEditorsViewport) {
    // The editor's viewport at 1280x800 is about 715x475 px. The HUD text
    // (caption, scale bar, legend) is drawn last: its tallest stroke is the
    // height of a capital, about as tall as the UI's 13 px font's capitals
    // (about 10 px), not 7 px.
    RestingCrate c;
    FrameInput in;
    in.scene = &c.scene;
    in.world = &*c.world;
    in.overlays.add(Overlay::Force);
    in.caption = "pile.json";
    in.camera = Camera{{0.0, 1.0}, 40.0};
    for (const int h : {475, 540}) {
        const DrawData data = buildDrawData(in, 715, h);
        const Batch* text = nullptr;
        for (const Batch& b : data.batches)
            if (b.kind == BatchKind::Solid) text = &b;  // the last layer's: the HUD
        ASSERT_NE(text, nullptr);
        double tallest = 0.0;
        const std::size_t k = floatsPerInstance(BatchKind::Solid);
        for (std::size_t i = 0; i + 6 * k <= text->data.size(); i += 6 * k) {
            double lo = 1e9, hi = -1e9;
            for (int v = 0; v < 6; ++v) {
                lo = std::min(lo, double(text->data[i + std::size_t(v) * k + 1]));
                hi = std::max(hi, double(text->data[i + std::size_t(v) * k + 1]));
            }
            tallest = std::max(tallest, hi - lo);
        }
        EXPECT_GE(tallest, 10.0) << "at " << h << " px";
        EXPECT_LE(tallest, 14.0) << "at " << h << " px";
    }
}

struct TempDir : stepwise::test::TempDir {
    TempDir() : stepwise::test::TempDir("stepwise-editor-truth") {}
};

bool sameRecords(std::span<const ContactRecord> a, std::span<const ContactRecord> b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (a[i].a != b[i].a || a[i].b != b[i].b || a[i].point != b[i].point || a[i].normal != b[i].normal ||
            a[i].depth != b[i].depth || a[i].normalImpulse != b[i].normalImpulse ||
            a[i].tangentImpulse != b[i].tangentImpulse)
            return false;
    return true;
}

TEST(EditorStepBack, TheContactsShownAreThoseOfTheRestoredStep) {
    TempDir tmp;
    editor::Editor ed;
    ed.configDir = tmp.path / "config";
    ASSERT_TRUE(ed.open(fs::path(STEPWISE_SOURCE_DIR) / "levels" / "default.json")) << ed.errorModal;
    for (int i = 0; i < 60; ++i) ed.stepForward();
    ASSERT_NE(ed.sim.world(), nullptr);
    const std::vector<ContactRecord> at60(ed.sim.world()->contacts().begin(), ed.sim.world()->contacts().end());
    const std::vector<Vec2> net60 = ed.sim.world()->netForces();
    ASSERT_FALSE(at60.empty()) << "default.json has resting contacts after a second";
    ASSERT_FALSE(net60.empty());
    ed.stepForward();
    ed.stepBack();
    ASSERT_NE(ed.sim.world(), nullptr);
    EXPECT_TRUE(sameRecords(ed.sim.world()->contacts(), at60))
        << ed.sim.world()->contacts().size() << " contacts shown after the step back, " << at60.size() << " at step 60";
    EXPECT_EQ(ed.sim.world()->netForces(), net60);
    // Back again (two steps of history left behind it): still that step's.
    ed.stepBack();
    ed.stepForward();
    EXPECT_TRUE(sameRecords(ed.sim.world()->contacts(), at60));
}

} // namespace

namespace {

// A new level was proposed a place inside the program's own levels folder.
TEST(SaveAsSuggestion, AnUntitledLevelGoesToTheWorkingFolderUnderAFreeName) {
    TempDir tmp;
    const fs::path levels = tmp.path / "levels", work = tmp.path / "work";
    fs::create_directories(levels);
    fs::create_directories(work);
    // The working folder, not the levels folder (always absolute).
    EXPECT_EQ(editor::saveAsSuggestion({}, levels, work), work / "untitled.json");
    // A name that is taken is not proposed.
    std::ofstream(work / "untitled.json") << "{}";
    EXPECT_EQ(editor::saveAsSuggestion({}, levels, work), work / "untitled_2.json");
    // A working folder that is not there: not a path that fails on Save.
    const fs::path fallback = editor::saveAsSuggestion({}, levels, tmp.path / "missing");
    EXPECT_TRUE(fs::is_directory(fallback.parent_path())) << fallback;
    EXPECT_EQ(fallback.filename().string().rfind("untitled", 0), 0u) << fallback;
    // A document keeps its own path, made absolute.
    EXPECT_EQ(editor::saveAsSuggestion("some/level.json", levels, work), fs::absolute("some/level.json"));
}

// "Save simulation state" proposed the last Save as path, of another level.
TEST(SaveAsSuggestion, TheStateGoesBesideTheOpenLevelNamedAfterIt) {
    TempDir tmp;
    const fs::path levels = tmp.path / "levels", work = tmp.path / "work", mine = tmp.path / "mine";
    for (const fs::path& d : {levels, work, mine}) fs::create_directories(d);
    EXPECT_EQ(editor::saveStateSuggestion(mine / "bridge.json", levels, work), mine / "bridge_state.json");
    std::ofstream(mine / "bridge_state.json") << "{}";
    EXPECT_EQ(editor::saveStateSuggestion(mine / "bridge.json", levels, work), mine / "bridge_state_2.json");
    EXPECT_EQ(editor::saveStateSuggestion({}, levels, work), work / "untitled_state.json");
}

// The recent list held "levels/a.json" and "/.../levels/a.json" both.
TEST(RecentFiles, OneFileIsOneEntryHoweverItWasNamed) {
    TempDir tmp;
    const fs::path level = tmp.path / "a.json";
    std::ofstream(level) << "{}";
    editor::Settings settings;
    const fs::path before = fs::current_path();
    fs::current_path(tmp.path);
    settings.addRecent("a.json");
    settings.addRecent("./a.json");
    settings.addRecent(level.string());
    settings.addRecent((tmp.path / "sub" / ".." / "a.json").string());
    fs::current_path(before);
    ASSERT_EQ(settings.recentFiles.size(), 1u);
    EXPECT_EQ(settings.recentFiles[0], fs::weakly_canonical(level).string());
    // A settings file written before keeps one entry per file too.
    std::ofstream(tmp.path / "settings.txt") << "recent " << level.string() << "\nrecent " << (tmp.path / "." / "a.json").string() << "\n";
    EXPECT_EQ(editor::Settings::load(tmp.path).recentFiles.size(), 1u);
}

TEST(OpenList, ListsTheLevelFilesButNotTheSchema) {
    const std::vector<std::string> files = editor::levelFiles(fs::path(STEPWISE_SOURCE_DIR) / "levels");
    EXPECT_GT(files.size(), 10u);
    for (const std::string& f : files) EXPECT_EQ(fs::path(f).extension(), ".json") << f;
    EXPECT_EQ(std::count_if(files.begin(), files.end(), [](const std::string& f) { return f.find("schema") != std::string::npos; }), 0);
}

} // namespace

namespace {

// default.json after 900 steps: the crates and one ball sleep. Their
// residual velocities (about 1e-5 m/s) got arrows and set the reference,
// so resting bodies showed long arrows.
TEST(VelocityOverlay, SleepingBodiesGetNoArrowAndDoNotSetTheScale) {
    editor::Editor ed;
    ASSERT_TRUE(ed.open(fs::path(STEPWISE_SOURCE_DIR) / "levels" / "default.json"));
    for (int i = 0; i < 900; ++i) ed.stepForward();
    ASSERT_TRUE(ed.sim.ensureWorld(ed.doc.scene));
    const std::vector<Entity> asleep = ed.sim.world()->sleepingBodies();
    ASSERT_EQ(asleep.size(), 11u);
    ed.setViewportSize(800, 600);
    ed.fitView();
    FrameInput in = ed.frameInput();
    in.overlays = OverlaySet{};
    in.overlays.add(Overlay::Velocity);
    const DrawData data = buildDrawData(in, 800, 600);
    // No arrow starts at a sleeping body.
    std::size_t arrowsAtSleepers = 0, arrows = 0;
    for (const Batch& b : data.batches) {
        if (b.kind != BatchKind::Arrow) continue;
        const std::size_t k = floatsPerInstance(BatchKind::Arrow);
        for (std::size_t i = 0; i + k <= b.data.size(); i += k) {
            ++arrows;
            const Vec2 from{b.data[i], b.data[i + 1]};
            for (Entity e : asleep) {
                const Vec2 view = ed.view.toPixels(ed.doc.scene.registry.tryGet<Position>(e)->value);
                const Vec2 at{view.x, 600.0 - view.y};  // the frame counts rows from the bottom
                if (length(at - from) < 1.0) ++arrowsAtSleepers;
            }
        }
    }
    EXPECT_EQ(arrowsAtSleepers, 0u) << "of " << asleep.size() << " sleeping bodies";
    EXPECT_EQ(arrows, 5u) << "the four moving bodies' arrows and the legend's sample";
}

} // namespace

namespace {

// "velocity" (teal, 4fd1c5) and "velocity field" (38b2ac) were drawn in
// nearly the same colour, a sum of channel differences of 79 out of 765.
TEST(VelocityOverlay, TheVelocityFieldHasAColourOfItsOwn) {
    editor::Editor ed;
    ASSERT_TRUE(ed.open(fs::path(STEPWISE_SOURCE_DIR) / "levels" / "flock.json"));
    ed.setViewportSize(800, 600);
    ed.fitView();
    FrameInput in = ed.frameInput();
    in.overlays = OverlaySet{};
    std::vector<std::array<int, 3>> colours;
    for (const Overlay o : {Overlay::Velocity, Overlay::VelocityField}) {
        in.overlays.bits = std::uint32_t(o);
        const DrawData data = buildDrawData(in, 800, 600);
        std::set<std::array<int, 3>> seen;
        for (const Batch& b : data.batches)
            if (b.kind == BatchKind::Arrow)
                for (std::size_t i = 0; i + 9 <= b.data.size(); i += 9)
                    seen.insert({int(std::lround(b.data[i + 5] * 255)), int(std::lround(b.data[i + 6] * 255)),
                                 int(std::lround(b.data[i + 7] * 255))});
        ASSERT_EQ(seen.size(), 1u) << "one colour per overlay";
        colours.push_back(*seen.begin());
    }
    const int distance = std::abs(colours[0][0] - colours[1][0]) + std::abs(colours[0][1] - colours[1][1]) +
                         std::abs(colours[0][2] - colours[1][2]);
    EXPECT_GE(distance, 150);
}

} // namespace

namespace {

// With every overlay on, the legend grew up from the bottom right over the
// right half of a pyramid standing on the floor; it now takes the top right
// when fewer bodies are there (and is a few rows high: test_editor_ui.cpp).
TEST(Legend, GoesToTheCornerWhereItHidesTheFewestBodies) {
    editor::Editor ed;
    ASSERT_TRUE(ed.open(fs::path(STEPWISE_SOURCE_DIR) / "levels" / "pyramid.json"));
    ed.setViewportSize(715, 475);  // the editor's viewport at 1280x800
    ed.fitView();
    ed.stepForward();
    ASSERT_TRUE(ed.sim.ensureWorld(ed.doc.scene));
    FrameInput in = ed.frameInput();
    in.overlays.bits = ~std::uint32_t(0);
    const DrawData data = buildDrawData(in, 715, 475);
    ASSERT_GE(data.legend.size(), 6u);
    // Pixels of a rectangle (y up) over the moving bodies' boxes, measured here.
    const auto covered = [&](double x, double y, double w, double h) {
        double area = 0.0;
        for (Entity e : ed.doc.scene.registry.entities()) {
            const std::optional<ShapeBox> b = shapeBox(ed.doc.scene, e);
            if (!b || isStatic(ed.doc.scene, e)) continue;
            const Vec2 c = ed.view.toPixels(b->centre), half = b->half * ed.view.pixelsPerMetre();
            const double cy = 475.0 - c.y;
            const double ox = std::min(x + w, c.x + half.x) - std::max(x, c.x - half.x);
            const double oy = std::min(y + h, cy + half.y) - std::max(y, cy - half.y);
            if (ox > 0 && oy > 0) area += ox * oy;
        }
        return area;
    };
    const auto [x, y, w, h] = data.legendBox;
    // The bottom-right place: the same margin below as the top one has above,
    // or above the scale bar (half that margin between) for a legend wide
    // enough to meet it there, as the one that shares rows is.
    const double margin = 475.0 - y - h;
    const auto [sx, sy, sw, sh] = data.scaleBarBox;
    ASSERT_GT(sw, 0.0);
    const double bottom = covered(x, x < sx + sw + margin ? sy + sh + 0.5 * margin : margin, w, h);
    EXPECT_GT(y, 475.0 / 2) << "at the top";
    EXPECT_NEAR(data.legendCoversPx, covered(x, y, w, h), 1e-6);
    EXPECT_EQ(data.legendCoversPx, 0.0) << "the top right is free of bodies";
    EXPECT_LT(data.legendCoversPx, 0.5 * bottom) << "covers " << data.legendCoversPx << " px there, " << bottom
                                                 << " px at the bottom right";
}

} // namespace
