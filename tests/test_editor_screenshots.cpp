// Screenshot tests of the editor UI (ctest label `screenshot`): the scripted
// headless mode (`stepwise edit LEVEL --script FILE --screenshot OUT.png`)
// renders the whole editor, ImGui panels and viewport, through OSMesa; the
// result is compared with screenshots/editor_<case>.png using the renderer
// tests' tolerance (render/screenshot.hpp). ImGui's built-in font keeps the
// images independent of the fonts a machine has.
// Regenerate after a deliberate change (and look at the images):
//     STEPWISE_UPDATE_GOLDENS=1 build/tests/test_editor_screenshots

#include "image.hpp"
#include "screenshot.hpp"

#include "stepwise/scene_io.hpp"

#include "golden_image.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;
using namespace stepwise;
using namespace stepwise::render;

namespace {

const fs::path kSource = STEPWISE_SOURCE_DIR;
const fs::path kOut = fs::path(STEPWISE_BUILD_DIR) / "screenshot-failures";

struct Case {
    const char* name;    // golden: screenshots/editor_<name>.png
    const char* level;   // relative to the source folder (messages name it)
    const char* script;  // tests/editor_scripts/<script>.txt, or "" for none
    int exitCode;
};

const Case kCases[] = {
    {"spring_chain_play", "levels/spring_chain.json", "spring_chain_play", 0},
    {"orbit_tools", "levels/orbit.json", "orbit_tools", 0},
    {"help", "levels/spring_chain.json", "help", 0},
    // A bad level: the editor starts with a new level and shows the loader's message.
    {"bad_level", "tests/data/bad_level.json", "", 2},
};

using stepwise::test::readFile;

/// Runs the scripted editor from the source folder; returns its exit code.
int runEditor(const Case& c, const fs::path& out) {
    std::string cmd = "cd '" + kSource.string() + "' && '" + std::string(STEPWISE_BINARY) + "' edit " + c.level +
                      " --builtin-font --size 1280x800 --screenshot '" + out.string() + "'";
    if (*c.script) cmd += std::string(" --script tests/editor_scripts/") + c.script + ".txt";
    cmd += " 2>/dev/null";
    const int status = std::system(cmd.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

class EditorScreenshot : public ::testing::TestWithParam<Case> {};

} // namespace

TEST_P(EditorScreenshot, MatchesGolden) {
    const Case& c = GetParam();
    fs::create_directories(kOut);
    const fs::path actualPath = kOut / (std::string("editor_") + c.name + "-actual.png");
    ASSERT_EQ(runEditor(c, actualPath), c.exitCode);
    Result<Image> actual = readPng(actualPath.string());
    ASSERT_TRUE(actual) << actual.error();
    EXPECT_EQ(actual->width, 1280);
    EXPECT_EQ(actual->height, 800);
    const fs::path golden = kSource / "screenshots" / (std::string("editor_") + c.name + ".png");
    if (stepwise::test::updatingGoldens()) {
        ASSERT_TRUE(writeFileAtomically(golden, readFile(actualPath)));
        GTEST_SKIP() << "wrote " << golden;
    }
    const ::testing::AssertionResult same =
        stepwise::test::matchesGolden(*actual, golden, kOut, std::string("editor_") + c.name);
    ASSERT_TRUE(same);
    fs::remove(actualPath);
}

INSTANTIATE_TEST_SUITE_P(Editor, EditorScreenshot, ::testing::ValuesIn(kCases),
                         [](const ::testing::TestParamInfo<Case>& p) { return std::string(p.param.name); });

TEST(EditorScreenshotDeterminism, SameScriptSameBytes) {
    fs::create_directories(kOut);
    const fs::path a = kOut / "editor_det_a.png", b = kOut / "editor_det_b.png";
    ASSERT_EQ(runEditor(kCases[1], a), 0);
    ASSERT_EQ(runEditor(kCases[1], b), 0);
    const std::string bytesA = readFile(a), bytesB = readFile(b);
    EXPECT_FALSE(bytesA.empty());
    EXPECT_TRUE(bytesA == bytesB) << "two runs of the same script gave different PNG bytes";
    fs::remove(a);
    fs::remove(b);
}

TEST(EditorScreenshotDetects, AMovedBodyFailsTheComparison) {
    // The tolerance must not hide a real change: the same script with one
    // body's starting velocity changed (it then moves differently) differs
    // visibly.
    fs::create_directories(kOut);
    const fs::path level = kOut / "orbit_heavy.json";
    std::string text = readFile(kSource / "levels" / "orbit.json");
    const std::string from = "\"y\": 19.364916731037084";
    ASSERT_NE(text.find(from), std::string::npos);
    text.replace(text.find(from), from.size(), "\"y\": 12.0");
    ASSERT_TRUE(writeFileAtomically(level, text));
    const fs::path out = kOut / "editor_orbit_changed.png";
    std::string cmd = "cd '" + kSource.string() + "' && '" + std::string(STEPWISE_BINARY) + "' edit '" + level.string() +
                      "' --builtin-font --size 1280x800 --screenshot '" + out.string() +
                      "' --script tests/editor_scripts/orbit_tools.txt 2>/dev/null";
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    Result<Image> actual = readPng(out.string());
    Result<Image> golden = readPng((kSource / "screenshots" / "editor_orbit_tools.png").string());
    ASSERT_TRUE(actual && golden);
    const ScreenshotSettings settings;
    EXPECT_GT(compareImages(*golden, *actual, settings.channelTolerance).fraction(), settings.maxDifferingFraction);
    fs::remove(out);
    fs::remove(level);
}

// ---- the viewport shows what `stepwise render` shows --------------------------------
//
// The editor draws its viewport into a rectangle of a larger window; the
// renderer alone draws a whole image. The two must agree pixel for pixel
// (within the golden tolerance) for the same level, camera and size, at any
// window size: a shader that measures from the window instead of the
// rectangle (it draws planes 254 px low at 1280x800) fails here, even if
// the editor's own goldens were recorded with the fault.

namespace {

struct ViewportState {
    int x = 0, y = 0, w = 0, h = 0;
    double cx = 0, cy = 0, zoom = 0;
};

/// The viewport rectangle and camera from `--debug-state` output.
bool readViewportState(const fs::path& file, ViewportState& s) {
    const std::string text = readFile(file);
    const auto vp = text.find("\"viewport\": [");
    const auto cam = text.find("\"camera\": [");
    if (vp == std::string::npos || cam == std::string::npos) return false;
    double x, y, w, h;
    if (std::sscanf(text.c_str() + vp, "\"viewport\": [%lf, %lf, %lf, %lf]", &x, &y, &w, &h) != 4) return false;
    if (std::sscanf(text.c_str() + cam, "\"camera\": [%lf, %lf, %lf]", &s.cx, &s.cy, &s.zoom) != 3) return false;
    s.x = int(x);
    s.y = int(y);
    s.w = int(w);
    s.h = int(h);
    return true;
}

Image crop(const Image& image, int x0, int y0, int w, int h) {
    Image out{w, h, std::vector<std::uint8_t>(std::size_t(w) * std::size_t(h) * 3)};
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            std::copy_n(image.pixel(x0 + x, y0 + y), 3, out.pixel(x, y));
    return out;
}

class ViewportMatchesRender : public ::testing::TestWithParam<const char*> {};

} // namespace

TEST_P(ViewportMatchesRender, AtThisWindowSize) {
    const std::string size = GetParam();
    fs::create_directories(kOut);
    const std::string stem = "viewport_" + size;
    const fs::path editorPng = kOut / (stem + "-editor.png"), statePath = kOut / (stem + "-state.json");
    const fs::path renderPng = kOut / (stem + "-render.png");
    const std::string level = "levels/default.json";  // a floor plane, boxes and circles resting on it
    std::string cmd = "cd '" + kSource.string() + "' && '" + std::string(STEPWISE_BINARY) + "' edit " + level +
                      " --builtin-font --size " + size + " --screenshot '" + editorPng.string() + "' --debug-state '" +
                      statePath.string() + "' 2>/dev/null";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    ViewportState vs;
    ASSERT_TRUE(readViewportState(statePath, vs)) << readFile(statePath);
    ASSERT_GE(vs.w, 16);
    ASSERT_GE(vs.h, 16);
    Result<Image> editor = readPng(editorPng.string());
    ASSERT_TRUE(editor) << editor.error();
    ASSERT_LE(vs.x + vs.w, editor->width);
    ASSERT_LE(vs.y + vs.h, editor->height);

    // The editor starts editing (no World: contacts are not drawn) with the
    // velocity overlay, and its viewport has the HUD without a caption.
    char camera[128];
    std::snprintf(camera, sizeof camera, "%.17g,%.17g,%.17g", vs.cx, vs.cy, vs.zoom);
    cmd = "cd '" + kSource.string() + "' && '" + std::string(STEPWISE_BINARY) + "' render " + level + " --width " +
          std::to_string(vs.w) + " --height " + std::to_string(vs.h) + " --camera " + camera +
          " --overlay velocity --no-caption --out '" + renderPng.string() + "' 2>/dev/null >/dev/null";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    Result<Image> rendered = readPng(renderPng.string());
    ASSERT_TRUE(rendered) << rendered.error();

    Image viewport = crop(*editor, vs.x, vs.y, vs.w, vs.h);
    // The cursor readout (ImGui text, bottom right of the viewport) is the
    // editor's own: taken from the render so it does not count.
    for (int y = std::max(0, vs.h - 24); y < vs.h; ++y)
        for (int x = std::max(0, vs.w - 270); x < vs.w; ++x) std::copy_n(rendered->pixel(x, y), 3, viewport.pixel(x, y));
    const ScreenshotSettings settings;
    const ImageDiff diff = compareImages(*rendered, viewport, settings.channelTolerance);
    ASSERT_TRUE(diff.sameSize);
    if (diff.fraction() > settings.maxDifferingFraction) {
        const fs::path diffPath = kOut / (stem + "-diff.png");
        (void)writeFileAtomically(kOut / (stem + "-viewport.png"), encodePng(viewport));
        (void)writeFileAtomically(diffPath, encodePng(diff.visual));
        FAIL() << size << ": " << diff.differing << " of " << diff.total << " viewport pixels differ from `stepwise render` (box "
               << diff.x0 << "," << diff.y0 << " - " << diff.x1 << "," << diff.y1 << "); diff " << diffPath;
    }
    fs::remove(editorPng);
    fs::remove(renderPng);
    fs::remove(statePath);
}

INSTANTIATE_TEST_SUITE_P(Sizes, ViewportMatchesRender, ::testing::Values("1600x900", "1280x720", "1280x800", "480x360", "320x240"),
                         [](const ::testing::TestParamInfo<const char*>& p) { return std::string(p.param); });
