// Screenshot regression tests (ctest label `screenshot`).
//
// Every level in levels/ is rendered with the fixed recipe in
// render/screenshot.hpp and compared with screenshots/<level>.png.
// Regenerate the goldens (after a deliberate visual change, and look at
// them) with:
//     cmake --build build --target update-goldens
// which runs this binary with STEPWISE_UPDATE_GOLDENS=1.

#include "screenshot.hpp"

#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"

#include "golden_image.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;
using namespace stepwise;
using namespace stepwise::render;

namespace {

const fs::path kSource = STEPWISE_SOURCE_DIR;
const fs::path kFailures = fs::path(STEPWISE_BUILD_DIR) / "screenshot-failures";

OffscreenRenderer& headless() {
    const ScreenshotSettings settings;
    static std::unique_ptr<OffscreenRenderer> renderer = [&] {
        auto created = OffscreenRenderer::create(settings.width, settings.height);
        if (!created) {
            std::fprintf(stderr, "cannot create the headless renderer: %s\n", created.error().c_str());
            std::abort();
        }
        return std::move(*created);
    }();
    return *renderer;
}

using stepwise::test::readFile;

/// The shared harness, failures written next to the build.
::testing::AssertionResult matchesGolden(const Image& actual, const fs::path& golden, const std::string& stem) {
    return stepwise::test::matchesGolden(actual, golden, kFailures, stem);
}

std::vector<std::string> levelStems() {
    std::vector<std::string> stems;
    for (const fs::path& p : listLevels(kSource / "levels")) stems.push_back(p.stem().string());
    return stems;
}

class LevelScreenshot : public ::testing::TestWithParam<std::string> {};

TEST_P(LevelScreenshot, MatchesGolden) {
    const std::string stem = GetParam();
    const fs::path level = kSource / "levels" / (stem + ".json");
    const fs::path golden = kSource / "screenshots" / (stem + ".png");
    Result<Screenshot> shot = renderLevelScreenshot(headless(), level);
    ASSERT_TRUE(shot.ok()) << shot.error();
    if (!shot->note.empty()) std::printf("%s: drawn at step 0: %s\n", stem.c_str(), shot->note.c_str());
    if (stepwise::test::updatingGoldens()) {
        Result<void> written = writeFileAtomically(golden, encodePng(shot->image));
        ASSERT_TRUE(written.ok()) << written.error();
        std::printf("updated %s\n", golden.string().c_str());
        return;
    }
    EXPECT_TRUE(matchesGolden(shot->image, golden, stem));
}

INSTANTIATE_TEST_SUITE_P(Levels, LevelScreenshot, ::testing::ValuesIn(levelStems()),
                         [](const ::testing::TestParamInfo<std::string>& param) {
                             std::string name = param.param;
                             for (char& c : name)
                                 if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                             return name;
                         });

// Levels added after this binary was built are not in the list above; this
// test reads levels/ at run time so a level without a golden still fails.
TEST(Screenshots, EveryLevelHasAGolden) {
    for (const fs::path& level : listLevels(kSource / "levels")) {
        const fs::path golden = kSource / "screenshots" / (level.stem().string() + ".png");
        EXPECT_TRUE(fs::exists(golden)) << level.string() << " has no golden " << golden.string()
                                        << "; run: cmake --build build --target update-goldens";
    }
}

// ---- the tolerance catches what matters and forgives what does not -------

Scene showcase() {
    Result<Scene> scene = loadSceneFile(kSource / "levels" / "render_showcase.json");
    if (!scene) ADD_FAILURE() << scene.error();
    return scene ? std::move(*scene) : Scene{};
}

Entity entityNamed(const Scene& scene, const std::string& name) {
    for (Entity e : scene.registry.entities())
        if (const Name* n = scene.registry.tryGet<Name>(e); n && n->value == name) return e;
    return {};
}

TEST(Screenshots, MovedBodyFailsTheComparison) {
    Scene scene = showcase();
    // Pin the camera: a fitted camera would follow the moved body's bounds.
    // Draw the scene as placed (no steps): stepping would let the moved ball
    // change the whole simulation through its contacts.
    ScreenshotSettings still;
    still.steps = 0;
    const Camera cam = fitCamera(scene, still.width, still.height);
    scene.view = View{cam.center, cam.zoom};
    Result<Screenshot> before = renderSceneScreenshot(headless(), scene, "showcase", still);
    ASSERT_TRUE(before.ok()) << before.error();
    // Move the ball 0.3 m (about a third of its diameter) to the right.
    Entity ball = entityNamed(scene, "ball");
    ASSERT_FALSE(ball.isNull());
    scene.registry.tryGet<Position>(ball)->value.x += 0.3;
    Result<Screenshot> after = renderSceneScreenshot(headless(), scene, "showcase", still);
    ASSERT_TRUE(after.ok()) << after.error();
    const ScreenshotSettings settings;
    const ImageDiff diff = compareImages(before->image, after->image, settings.channelTolerance);
    EXPECT_GT(diff.fraction(), settings.maxDifferingFraction)
        << "a moved body must fail the screenshot comparison; only " << diff.differing << " pixels differ";
    // ... and the difference is where the ball is, not all over the image.
    EXPECT_LT(diff.x1 - diff.x0, settings.width / 4);
    EXPECT_LT(diff.y1 - diff.y0, settings.height / 4);
}

TEST(Screenshots, RecolouredBodyFailsTheComparison) {
    Scene scene = showcase();
    Result<Screenshot> before = renderSceneScreenshot(headless(), scene, "showcase");
    ASSERT_TRUE(before.ok());
    scene.registry.tryGet<Color>(entityNamed(scene, "crate"))->value = Rgb{0.2, 0.4, 0.9};
    Result<Screenshot> after = renderSceneScreenshot(headless(), scene, "showcase");
    ASSERT_TRUE(after.ok());
    const ScreenshotSettings settings;
    EXPECT_GT(compareImages(before->image, after->image, settings.channelTolerance).fraction(),
              settings.maxDifferingFraction);
}

TEST(Screenshots, SmallRasterNoisePassesTheComparison) {
    // What a Mesa update typically does: every channel a few levels off,
    // plus a scatter of edge pixels that flip completely.
    Result<Screenshot> shot = renderLevelScreenshot(headless(), kSource / "levels" / "render_showcase.json");
    ASSERT_TRUE(shot.ok());
    Image noisy = shot->image;
    unsigned state = 12345;
    std::size_t flipped = 0;
    for (std::size_t i = 0; i < noisy.rgb.size(); ++i) {
        state = state * 1103515245u + 12345u;
        const int delta = int((state >> 16) % 17) - 8;  // -8..8
        noisy.rgb[i] = std::uint8_t(std::clamp(int(noisy.rgb[i]) + delta, 0, 255));
    }
    for (std::size_t p = 0; p < noisy.rgb.size() / 3; p += 5003, ++flipped)
        noisy.rgb[p * 3] = std::uint8_t(255 - noisy.rgb[p * 3]);
    const ScreenshotSettings settings;
    const ImageDiff diff = compareImages(shot->image, noisy, settings.channelTolerance);
    EXPECT_LE(diff.fraction(), settings.maxDifferingFraction) << diff.differing << " pixels differ";
    EXPECT_GT(diff.differing, 0u);  // the flipped pixels do count, just not enough to fail
}

TEST(Screenshots, FailureWritesActualAndDiffImages) {
    Result<Screenshot> shot = renderLevelScreenshot(headless(), kSource / "levels" / "render_showcase.json");
    ASSERT_TRUE(shot.ok());
    Image broken = shot->image;
    // A white block in the dark top-right corner: 60 x 40 pixels.
    for (int y = 60; y < 100; ++y)
        for (int x = 880; x < 940; ++x) {
            std::uint8_t* p = broken.pixel(x, y);
            p[0] = p[1] = p[2] = 255;
        }
    fs::path golden = fs::path(STEPWISE_BUILD_DIR) / "golden-under-test.png";
    ASSERT_TRUE(writeFileAtomically(golden, encodePng(shot->image)).ok());
    const ::testing::AssertionResult r = matchesGolden(broken, golden, "self_test");
    ASSERT_FALSE(r);
    const std::string message = r.message();
    EXPECT_NE(message.find("2400 of 518400 pixels differ"), std::string::npos) << message;
    EXPECT_NE(message.find("x 880..939, y 60..99"), std::string::npos) << message;
    EXPECT_TRUE(fs::exists(kFailures / "self_test-actual.png"));
    EXPECT_TRUE(fs::exists(kFailures / "self_test-diff.png"));
    Result<Image> diffImage = readPng((kFailures / "self_test-diff.png").string());
    ASSERT_TRUE(diffImage.ok());
    const std::uint8_t* magenta = diffImage->pixel(900, 70);
    EXPECT_EQ(magenta[0], 255);
    EXPECT_EQ(magenta[1], 0);
    EXPECT_EQ(magenta[2], 255);
    fs::remove(golden);
}

TEST(Screenshots, CrowdedAabbLayerDrawsWhatTheBoxQuadsDraw) {
    // 2,000 touching circles with the aabb overlay: the outlines drawn on
    // the CPU as one layer (BatchKind::Image) and drawn by box.frag as one
    // quad per box give the same picture through llvmpipe, to the 8-bit
    // rounding of alpha (a tolerance of 8, a quarter of the goldens').
    Scene scene;
    for (int r = 0; r < 40; ++r)
        for (int c = 0; c < 50; ++c) {
            const Entity e = scene.registry.create();
            scene.registry.emplace<Position>(e, {{0.5 * c, 0.25 + 0.5 * r}});
            scene.registry.emplace<Radius>(e, {0.25});
        }
    OffscreenRenderer& gl = headless();
    FrameInput input;
    input.scene = &scene;
    input.camera = fitCamera(scene, gl.width(), gl.height());
    input.overlays.add(Overlay::Aabb);
    input.hud = false;
    const auto draw = [&](bool layers) {
        const DrawData data = buildDrawData(input, gl.width(), gl.height(), BuildOptions{.pixelLayers = layers});
        EXPECT_EQ(data.images.size(), layers ? 1u : 0u);
        gl.renderer().draw(data);
        return gl.renderer().readPixels(gl.width(), gl.height());
    };
    const Image layered = draw(true), quads = draw(false);
    const ImageDiff diff = compareImages(quads, layered, 8);
    EXPECT_EQ(diff.differing, 0u) << "between x " << diff.x0 << ".." << diff.x1 << ", y " << diff.y0 << ".." << diff.y1;
    // ... and the outlines are there: the overlay's green on a box's left edge.
    const ImageDiff withoutOutlines = compareImages(quads, [&] {
        input.overlays = OverlaySet{};
        const DrawData data = buildDrawData(input, gl.width(), gl.height());
        gl.renderer().draw(data);
        return gl.renderer().readPixels(gl.width(), gl.height());
    }(), 32);
    EXPECT_GT(withoutOutlines.fraction(), 0.05);
}

// ---- determinism ---------------------------------------------------------

TEST(Screenshots, SameBuildRendersIdenticalBytesTwiceInProcess) {
    for (const std::string level : {"render_showcase", "orbit"}) {
        const fs::path path = kSource / "levels" / (level + ".json");
        if (!fs::exists(path)) continue;
        Result<Screenshot> a = renderLevelScreenshot(headless(), path);
        Result<Screenshot> b = renderLevelScreenshot(headless(), path);
        ASSERT_TRUE(a.ok() && b.ok());
        EXPECT_EQ(encodePng(a->image), encodePng(b->image)) << level;
    }
}

int runCli(const std::string& args) {
    const int status = std::system((std::string(STEPWISE_BINARY) + " " + args).c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(Screenshots, SameBuildRendersIdenticalBytesTwiceAcrossProcesses) {
    const fs::path dir = fs::path(STEPWISE_BUILD_DIR) / "screenshot-determinism";
    fs::create_directories(dir);
    const std::string level = (kSource / "levels" / "render_showcase.json").string();
    const std::string common = "render " + level + " --width 640 --height 360 --overlay velocity,aabb,trails --select ball";
    ASSERT_EQ(runCli(common + " --out " + (dir / "a.png").string() + " > /dev/null"), 0);
    ASSERT_EQ(runCli(common + " --out " + (dir / "b.png").string() + " > /dev/null"), 0);
    const std::string a = readFile(dir / "a.png"), b = readFile(dir / "b.png");
    EXPECT_GT(a.size(), 1000u);
    EXPECT_EQ(a, b);
}

} // namespace
