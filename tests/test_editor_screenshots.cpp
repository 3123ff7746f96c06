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
    if (const char* u = std::getenv("STEPWISE_UPDATE_GOLDENS"); u && std::string(u) == "1") {
        ASSERT_TRUE(writeFileAtomically(golden, readFile(actualPath)));
        GTEST_SKIP() << "wrote " << golden;
    }
    Result<Image> expected = readPng(golden.string());
    ASSERT_TRUE(expected) << expected.error();
    const ScreenshotSettings settings;
    const ImageDiff diff = compareImages(*expected, *actual, settings.channelTolerance);
    ASSERT_TRUE(diff.sameSize);
    if (diff.fraction() > settings.maxDifferingFraction) {
        const fs::path diffPath = kOut / (std::string("editor_") + c.name + "-diff.png");
        (void)writeFileAtomically(diffPath, encodePng(diff.visual));
        FAIL() << diff.differing << " of " << diff.total << " pixels differ (box " << diff.x0 << "," << diff.y0 << " - "
               << diff.x1 << "," << diff.y1 << "); actual " << actualPath << ", diff " << diffPath;
    }
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
