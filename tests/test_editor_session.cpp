// The whole editor (panels, dialogs, shortcuts) run headless by its script
// runner, `stepwise edit LEVEL --script S --debug-state D`: a script types,
// clicks and presses keys as a person would, and the debug-state file says
// what the window showed after the last frame (modal, status line, error
// text, tool, the rectangles of the fields a test clicks).

#include "stepwise/components.hpp"
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

// ---- typing into number fields -------------------------------------------------

namespace {

/// The level a script saved with `saveas`.
stepwise::Scene savedLevel(const fs::path& file) {
    stepwise::Result<stepwise::Scene> s = stepwise::loadSceneFile(file);
    EXPECT_TRUE(s) << s.error();
    return s ? std::move(*s) : stepwise::Scene{};
}

/// The entity named `name` in `scene` (null when none).
stepwise::Entity findNamed(const stepwise::Scene& scene, const std::string& name) {
    for (stepwise::Entity e : scene.registry.entities())
        if (const stepwise::Name* n = scene.registry.tryGet<stepwise::Name>(e); n && n->value == name) return e;
    return {};
}

/// "X Y" of a point `dx` pixels into a widget, at its middle height.
std::string into(const nlohmann::json& state, const std::string& widget, int dx) {
    const nlohmann::json& r = state.at("widgets").at(widget);
    return std::to_string(int(r[0].get<double>()) + dx) + " " +
           std::to_string(int(r[1].get<double>() + r[3].get<double>() / 2));
}

} // namespace

// World fields needed a double click: after a single click, typing "0.01"
// switched tools (0 is Polygon) and Ctrl+A selected every entity.
TEST_F(EditorSession, ASingleClickTypesIntoAWorldFieldAndNoShortcutFires) {
    const Run layout = run(level("default.json"), "wait 1\n");
    ASSERT_EQ(layout.exitCode, 0) << layout.err;
    const fs::path out = tmp.path / "out.json";
    const Run r = run(level("default.json"), "click " + centre(layout.state, "world/dt") +
                                                 "\nkey 0\nkey Ctrl+A\ntext \"0.01\"\nkey Enter\nwait 2\nsaveas " +
                                                 out.string() + "\n");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(r.state.at("tool"), "Select") << "the 0 went to the tool keys";
    EXPECT_EQ(r.state.at("selection"), 0) << "Ctrl+A went to Select all";
    EXPECT_EQ(savedLevel(out).world.dt, 0.01);
}

// A colour channel took typing only after a double click too.
TEST_F(EditorSession, ASingleClickTypesIntoAColourChannel) {
    const Run layout = run(level("default.json"), "select bob\nwait 1\n");
    ASSERT_EQ(layout.exitCode, 0) << layout.err;
    const fs::path out = tmp.path / "out.json";
    const Run r = run(level("default.json"), "select bob\nclick " + into(layout.state, "inspector/color", 15) +
                                                 "\ntext \"0.5\"\nkey Enter\nwait 2\nsaveas " + out.string() + "\n");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(r.state.at("tool"), "Select");
    const stepwise::Scene saved = savedLevel(out);
    const stepwise::Entity bob = findNamed(saved, "bob");
    ASSERT_FALSE(bob.isNull());
    EXPECT_EQ(saved.registry.tryGet<stepwise::Color>(bob)->value.r, 0.5);
}

// "nan" typed into a number field was dropped without a word.
TEST_F(EditorSession, NanTypedIntoANumberFieldIsRefusedWithAMessageNamingTheField) {
    const Run layout = run(level("default.json"), "select bob\nwait 1\n");
    ASSERT_EQ(layout.exitCode, 0) << layout.err;
    const std::string why = ": \"nan\" is not a number (digits, '.', 'e', '+', '-', '*' and '/' can be typed)";
    const fs::path out = tmp.path / "out.json";
    Run r = run(level("default.json"), "click " + centre(layout.state, "world/dt") + "\ntext \"nan\"\nwait 1\n");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(r.state.at("status"), "refused: world.dt" + why);
    r = run(level("default.json"), "select bob\nclick " + centre(layout.state, "inspector/mass") +
                                       "\ntext \"nan\"\nwait 1\nkey Enter\nwait 1\nsaveas " + out.string() + "\n");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(r.state.at("tool"), "Select");
    const stepwise::Scene saved = savedLevel(out);
    EXPECT_EQ(saved.registry.tryGet<stepwise::Mass>(findNamed(saved, "bob"))->value, 1.5);
    r = run(level("default.json"), "select bob\nclick " + centre(layout.state, "inspector/mass") + "\ntext \"nan\"\nwait 1\n");
    EXPECT_EQ(r.state.at("status"), "refused: \"bob\" mass" + why);
    // The snap spacing, a number field of the Tools panel, the same.
    r = run(level("default.json"), "click " + centre(layout.state, "tools/snap") + "\ntext \"inf\"\nwait 1\n");
    EXPECT_EQ(r.state.at("status"), "refused: snap spacing: \"inf\" is not a number (digits, '.', 'e', '+', '-', '*' and '/' can be typed)");
    EXPECT_EQ(r.state.at("tool"), "Select");
}

// ---- drags are linear ---------------------------------------------------------

// The drag speed followed the value (0.5% of it a pixel), so a drag
// compounded: 400 px on motor_speed went from 1 to -259 rad/s. The speed is
// now fixed when the drag starts: 0.5% of 1.5 a pixel, 400 px = 3.
TEST_F(EditorSession, DraggingMotorSpeedIsLinear) {
    const std::string joints = (fs::path(STEPWISE_SOURCE_DIR) / "tests" / "data" / "joints_every_type.json").string();
    // 1000 px high: the field is below the fold at 720.
    const Run layout = run(joints, "select hinge\nwait 1\n", "1280x1000");
    ASSERT_EQ(layout.exitCode, 0) << layout.err;
    const nlohmann::json& r = layout.state.at("widgets").at("inspector/joint.motor_speed");
    const int x = int(r[0].get<double>()) + 60, y = int(r[1].get<double>() + r[3].get<double>() / 2);
    for (const int dx : {-400, 400}) {
        const fs::path out = tmp.path / "out.json";
        const Run d = run(joints, "select hinge\ndrag " + std::to_string(x) + " " + std::to_string(y) + " " +
                                      std::to_string(x + dx) + " " + std::to_string(y) + " 40\nwait 1\nsaveas " +
                                      out.string() + "\n", "1280x1000");
        ASSERT_EQ(d.exitCode, 0) << d.err;
        const stepwise::Scene saved = savedLevel(out);
        const double speed = *saved.registry.tryGet<stepwise::Joint>(findNamed(saved, "hinge"))->motorSpeed;
        EXPECT_NEAR(speed, 1.5 + dx * 0.0075, 1e-9) << dx << " px";
    }
}

// ---- layout at common sizes ----------------------------------------------------

// At 1600x900 the joint type was below the fold of the Tools panel, among
// the overlay boxes; at 1280x720 the overlay labels were cut ("velocity-f").
TEST_F(EditorSession, TheToolsPanelShowsTheJointTypeAndWholeOverlayLabels) {
    for (const std::string size : {"1280x720", "1600x900"}) {
        const Run r = run(level("default.json"), "tool joint\nwait 1\n", size);
        ASSERT_EQ(r.exitCode, 0) << r.err;
        const nlohmann::json& panel = r.state.at("windows").at("Tools");
        const double right = panel[0].get<double>() + panel[2].get<double>();
        const double bottom = panel[1].get<double>() + panel[3].get<double>();
        const nlohmann::json& joint = r.state.at("widgets").at("tools/jointtype");
        EXPECT_LE(joint[1].get<double>() + joint[3].get<double>(), bottom) << size << ": the joint type is below the fold";
        int overlays = 0;
        for (const auto& [key, rect] : r.state.at("widgets").items()) {
            if (key.rfind("tools/overlay/", 0) != 0) continue;
            ++overlays;
            // The box and its whole label inside the panel, less its padding
            // (8 px) and a scrollbar (14 px) that may be there.
            EXPECT_LE(rect[0].get<double>() + rect[2].get<double>(), right - 22.0) << size << ": " << key << " is cut";
        }
        EXPECT_EQ(overlays, 9) << size;
    }
}
