// The whole editor (panels, dialogs, shortcuts) run headless by its script
// runner, `stepwise edit LEVEL --script S --debug-state D`: a script types,
// clicks and presses keys as a person would, and the debug-state file says
// what the window showed after the last frame (modal, status line, error
// text, tool, the rectangles of the fields a test clicks).

#include "stepwise/scene_io.hpp"

#include "test_support.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace fs = std::filesystem;
using stepwise::test::readFile;

namespace {

class EditorSession : public ::testing::Test {
protected:
    stepwise::test::TempDir tmp{"stepwise-editor-session"};

    fs::path write(const std::string& name, const std::string& text) {
        const fs::path p = tmp.path / name;
        std::ofstream(p, std::ios::binary) << text;
        return p;
    }
    static std::string level(const std::string& name) {
        return (fs::path(STEPWISE_SOURCE_DIR) / "levels" / name).string();
    }

    struct Run {
        int exitCode = -1;
        std::string err;
        nlohmann::json state;  ///< the debug state after the last frame
    };
    /// Runs `script` on `levelPath` at `size` and reads the last debug state.
    Run run(const std::string& levelPath, const std::string& script, const std::string& size = "1280x720") {
        const fs::path s = write("script.txt", script), state = tmp.path / "state.json", err = tmp.path / "err.txt";
        fs::remove(state);
        const std::string command = std::string(STEPWISE_BINARY) + " edit " + levelPath +
                                    " --builtin-font --size " + size + " --config " + (tmp.path / "cfg").string() +
                                    " --script " + s.string() + " --debug-state " + state.string() + " >/dev/null 2>" +
                                    err.string() + " </dev/null";
        const int status = std::system(command.c_str());
        Run r;
        r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        r.err = readFile(err);
        const std::string text = readFile(state);
        if (!text.empty()) r.state = nlohmann::json::parse(text);
        return r;
    }
    /// "X Y" of the centre of a widget the debug state reports.
    static std::string centre(const nlohmann::json& state, const std::string& widget) {
        const nlohmann::json& r = state.at("widgets").at(widget);
        return std::to_string(int(r[0].get<double>() + r[2].get<double>() / 2)) + " " +
               std::to_string(int(r[1].get<double>() + r[3].get<double>() / 2));
    }
};

const char* kBrokenJson = "{\n  \"entities\": [\n    {\"name\": \"ball\",, \"position\": {\"x\": 0, \"y\": 1}}\n  ]\n}\n";

} // namespace

// ---- a failed open shows the loader's message ---------------------------------

// Enter in the Open dialog's path field: the Enter that confirmed the path
// also dismissed the Error modal it opened, and the status line said only
// "open failed: PATH".
TEST_F(EditorSession, EnterOnABrokenFileShowsTheLoadersMessageInTheModalAndTheStatusLine) {
    const fs::path broken = write("broken.json", kBrokenJson);
    const std::string loader = stepwise::loadSceneFile(broken).error();
    ASSERT_EQ(loader.rfind(broken.string() + ":3:21: error: ", 0), 0u) << "the loader names the line and column: " << loader;
    const Run r = run(level("default.json"), "key Ctrl+O\nwait 2\ntext \"" + broken.string() + "\"\nkey Enter\nwait 3\n");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(r.state.at("modal"), "Error");
    EXPECT_EQ(r.state.at("error"), loader);
    EXPECT_EQ(r.state.at("status"), "open failed: " + loader);
}

// The Open button, on a file that is not there: the reason, in both places.
TEST_F(EditorSession, TheOpenButtonOnAMissingFileGivesTheReasonInTheModalAndTheStatusLine) {
    const Run layout = run(level("default.json"), "key Ctrl+O\nwait 2\n");
    ASSERT_EQ(layout.exitCode, 0) << layout.err;
    EXPECT_EQ(layout.state.at("modal"), "Open level");
    const fs::path missing = tmp.path / "gone.json";
    const Run r = run(level("default.json"), "key Ctrl+O\nwait 2\ntext \"" + missing.string() + "\"\nclick " +
                                                 centre(layout.state, "open/button") + "\nwait 3\n");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const std::string loader = missing.string() + ": error: no such file";
    EXPECT_EQ(stepwise::loadSceneFile(missing).error(), loader);
    EXPECT_EQ(r.state.at("modal"), "Error");
    EXPECT_EQ(r.state.at("error"), loader);
    EXPECT_EQ(r.state.at("status"), "open failed: " + loader);
}

// Ctrl+O puts the keys in the path field, and what is typed replaces the
// path the field still holds from the last open instead of being appended.
TEST_F(EditorSession, TypingAfterCtrlOReplacesThePathInTheField) {
    const fs::path a = write("a.json", readFile(level("default.json")));
    const fs::path b = write("b.json", readFile(level("orbit.json")));
    const Run r = run(level("orbit.json"), "key Ctrl+O\nwait 2\ntext \"" + a.string() + "\"\nkey Enter\nwait 2\n"
                                           "key Ctrl+O\nwait 2\ntext \"" + b.string() + "\"\nkey Enter\nwait 3\n");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(r.state.at("modal"), "");
    EXPECT_EQ(r.state.at("status"), "opened " + b.string());
}
