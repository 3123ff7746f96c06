// End to end, in a real window (ctest label `e2e`): the test starts its own
// Xvfb on a free display, runs `stepwise edit LEVEL` against it with
// llvmpipe (LIBGL_ALWAYS_SOFTWARE=1), and drives it with xdotool as a person
// would: Play with Space (bodies must move), pause, reset, place a circle
// with the circle tool, undo it, place another, save with Ctrl+S, and compare
// the saved JSON byte for byte with the level plus that circle. The editor's
// --debug-state file reports the viewport rectangle and camera, so the test
// knows where to click and which world point that is. Everything the test
// starts is stopped by its own process id.

#include "app/scene_edit.hpp"
#include "app/view_camera.hpp"

#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"

#include "test_support.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <sstream>
#include <thread>

extern char** environ;

namespace fs = std::filesystem;
using namespace stepwise;
using namespace std::chrono_literals;

namespace {

using stepwise::test::readFile;

/// A child process started with posix_spawnp; stopped (TERM, then KILL) on scope exit.
struct Child {
    pid_t pid = -1;
    /// `cwd`: the folder the child starts in (empty: this process's).
    Child(std::vector<std::string> argv, const std::vector<std::string>& extraEnv, const fs::path& log,
          const fs::path& cwd = {}) {
        std::vector<std::string> env;
        for (char** e = environ; *e; ++e) env.emplace_back(*e);
        for (const std::string& e : extraEnv) env.push_back(e);
        std::vector<char*> a, v;
        for (std::string& s : argv) a.push_back(s.data());
        a.push_back(nullptr);
        for (std::string& s : env) v.push_back(s.data());
        v.push_back(nullptr);
        posix_spawn_file_actions_t actions;
        posix_spawn_file_actions_init(&actions);
        posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        posix_spawn_file_actions_adddup2(&actions, 1, 2);
        if (!cwd.empty()) posix_spawn_file_actions_addchdir_np(&actions, cwd.c_str());
        if (posix_spawnp(&pid, a[0], &actions, nullptr, a.data(), v.data()) != 0) pid = -1;
        posix_spawn_file_actions_destroy(&actions);
    }
    bool running() {
        if (pid <= 0) return false;
        int status = 0;
        const pid_t r = waitpid(pid, &status, WNOHANG);
        if (r == pid) {
            exitStatus = status;
            pid = -1;
            return false;
        }
        return true;
    }
    bool waitExit(std::chrono::milliseconds timeout) {
        const auto end = std::chrono::steady_clock::now() + timeout;
        while (running()) {
            if (std::chrono::steady_clock::now() > end) return false;
            std::this_thread::sleep_for(20ms);
        }
        return true;
    }
    ~Child() {
        if (!running()) return;
        kill(pid, SIGTERM);
        if (!waitExit(3000ms)) {
            kill(pid, SIGKILL);
            waitpid(pid, nullptr, 0);
        }
    }
    int exitStatus = -1;
};

bool waitFor(const std::function<bool()>& condition, std::chrono::milliseconds timeout) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < end) {
        if (condition()) return true;
        std::this_thread::sleep_for(50ms);
    }
    return condition();
}

int freeDisplay() {
    // Start the search at a number of this process's own: ctest -j runs the
    // e2e tests side by side, and two that both take the first free number
    // (:90) share one X server and drive each other's windows.
    for (int k = 0; k < 110; ++k) {
        const int n = 90 + int((unsigned(::getpid()) + unsigned(k) * 7u) % 110u);
        if (!fs::exists("/tmp/.X" + std::to_string(n) + "-lock") && !fs::exists("/tmp/.X11-unix/X" + std::to_string(n)))
            return n;
    }
    return -1;
}

bool have(const char* program) {
    const std::string cmd = std::string("command -v ") + program + " > /dev/null 2>&1";
    return std::system(cmd.c_str()) == 0;
}

nlohmann::json readState(const fs::path& p) {
    try {
        return nlohmann::json::parse(readFile(p));
    } catch (...) {
        return nlohmann::json();  // mid-write or not there yet: try again
    }
}

/// An Xvfb (a 1280x800 screen unless given) on a free display, stopped (by its process id) on
/// scope exit; `env` runs the editor on it with its settings under `tmp`.
struct XDisplay {
    std::string name;   ///< ":N"
    std::unique_ptr<Child> server;
    std::vector<std::string> env;
    std::string error;  ///< why it could not be started ("" when it runs)
    explicit XDisplay(const fs::path& tmp, const std::string& screen = "1280x800x24") {
        const int display = freeDisplay();
        if (display <= 0) {
            error = "no free X display number";
            return;
        }
        name = ":" + std::to_string(display);
        server = std::make_unique<Child>(std::vector<std::string>{"Xvfb", name, "-screen", "0", screen,
                                                                  "-nolisten", "tcp"},
                                         std::vector<std::string>{}, tmp / "xvfb.log");
        if (server->pid <= 0 ||
            !waitFor([&] { return fs::exists("/tmp/.X11-unix/X" + std::to_string(display)); }, 10s)) {
            error = "Xvfb did not start: " + readFile(tmp / "xvfb.log");
            return;
        }
        env = {"DISPLAY=" + name, "LIBGL_ALWAYS_SOFTWARE=1", "XDG_CONFIG_HOME=" + (tmp / "config").string()};
    }
    /// Runs `xdotool ARGS` on this display; true when it succeeded.
    bool xdo(const std::string& args) const {
        const std::string cmd = "DISPLAY=" + name + " xdotool " + args + " > /dev/null 2>&1";
        return std::system(cmd.c_str()) == 0;
    }
};

} // namespace

TEST(EditorWindow, PlayPlaceUndoSaveThroughXvfbAndXdotool) {
    if (!have("Xvfb") || !have("xdotool")) GTEST_SKIP() << "needs Xvfb and xdotool (tests/setup-debian.sh installs them)";
    const fs::path tmp = fs::temp_directory_path() / ("stepwise-e2e-" + std::to_string(getpid()));
    fs::remove_all(tmp);
    fs::create_directories(tmp);
    const fs::path level = tmp / "level.json", state = tmp / "state.json";
    fs::copy_file(fs::path(STEPWISE_SOURCE_DIR) / "levels" / "spring_chain.json", level);
    const std::string original = readFile(level);

    const XDisplay x(tmp);
    ASSERT_TRUE(x.error.empty()) << x.error;
    const std::vector<std::string>& env = x.env;
    Child editor({STEPWISE_BINARY, "edit", level.string(), "--size", "1280x800", "--builtin-font", "--font-size", "13",
                  "--debug-state", state.string()},
                 env, tmp / "editor.log");
    ASSERT_GT(editor.pid, 0);
    auto xdo = [&](const std::string& args) { return x.xdo(args); };
    ASSERT_TRUE(waitFor([&] { return !readState(state).is_null(); }, 30s)) << readFile(tmp / "editor.log");
    nlohmann::json s0 = readState(state);
    const auto vp = s0["viewport"];
    const double vx = vp[0], vy = vp[1], vw = vp[2], vh = vp[3];
    ASSERT_GT(vw, 100);
    // The pointer inside the viewport gives the window the keyboard (no
    // window manager: focus follows the pointer).
    ASSERT_TRUE(xdo("mousemove " + std::to_string(int(vx + vw / 2)) + " " + std::to_string(int(vy + 20))));

    // Play: time advances and the chain moves.
    ASSERT_TRUE(xdo("key space"));
    ASSERT_TRUE(waitFor([&] {
        const nlohmann::json s = readState(state);
        return !s.is_null() && s["mode"] == "playing" && double(s["time"]) > 0.2;
    }, 20s)) << readState(state).dump();
    const nlohmann::json moving = readState(state);
    EXPECT_NE(moving["positions"], s0["positions"]) << "bodies did not move";
    // Pause and reset: back to the edited level.
    ASSERT_TRUE(xdo("key space"));
    ASSERT_TRUE(waitFor([&] { return readState(state)["mode"] == "paused"; }, 10s));
    ASSERT_TRUE(xdo("key r"));
    ASSERT_TRUE(waitFor([&] { return readState(state)["mode"] == "editing"; }, 10s));
    EXPECT_EQ(readState(state)["positions"], s0["positions"]);

    // Circle tool (3), click, undo, click elsewhere, save.
    const int entities = s0["entities"];
    const int px1 = int(vx + vw * 0.25), py1 = int(vy + vh * 0.7);
    const int px2 = int(vx + vw * 0.6), py2 = int(vy + vh * 0.8);
    ASSERT_TRUE(xdo("key 3"));
    ASSERT_TRUE(xdo("mousemove " + std::to_string(px1) + " " + std::to_string(py1) + " click 1"));
    ASSERT_TRUE(waitFor([&] { return readState(state)["entities"] == entities + 1; }, 10s)) << readState(state).dump();
    ASSERT_TRUE(xdo("key ctrl+z"));
    ASSERT_TRUE(waitFor([&] { return readState(state)["entities"] == entities; }, 10s)) << readState(state).dump();
    ASSERT_TRUE(xdo("mousemove " + std::to_string(px2) + " " + std::to_string(py2) + " click 1"));
    ASSERT_TRUE(waitFor([&] { return readState(state)["entities"] == entities + 1; }, 10s));
    ASSERT_TRUE(xdo("key ctrl+s"));
    ASSERT_TRUE(waitFor([&] { return readFile(level) != original && readState(state)["dirty"] == false; }, 10s));

    // Expected: the level as it was plus one circle at the clicked world point.
    const nlohmann::json s = readState(state);
    editor::ViewCamera cam;
    cam.width = int(double(s["viewport"][2]));
    cam.height = int(double(s["viewport"][3]));
    cam.camera.center = {double(s["camera"][0]), double(s["camera"][1])};
    cam.camera.zoom = double(s["camera"][2]);
    const Vec2 world = cam.toWorld({double(px2) - double(s["viewport"][0]), double(py2) - double(s["viewport"][1])});
    Result<Scene> expected = parseScene(original, "original");
    ASSERT_TRUE(expected) << expected.error();
    editor::addCircle(*expected, world);
    EXPECT_EQ(readFile(level), sceneToJsonText(*expected));

    // Quit: clean document, so no question; the process ends by itself.
    ASSERT_TRUE(xdo("key ctrl+q"));
    EXPECT_TRUE(editor.waitExit(15s)) << "the editor did not quit on Ctrl+Q";
    fs::remove_all(tmp);
}

// Started from another folder, the Open list is not empty and Save
// as of an untitled level proposes a folder it can write; Save as onto an
// existing file asks, and Cancel keeps the file; renaming a body that a
// spring uses (typed into the inspector) keeps the spring: Play runs and
// the save names the spring's end by the new name.
TEST(EditorWindow, FromAnotherFolderRenameThenPlayAndSaveAsAsksBeforeReplacing) {
    if (!have("Xvfb") || !have("xdotool")) GTEST_SKIP() << "needs Xvfb and xdotool (tests/setup-debian.sh installs them)";
    const fs::path tmp = fs::temp_directory_path() / ("stepwise-e2e-folder-" + std::to_string(getpid()));
    fs::remove_all(tmp);
    fs::create_directories(tmp / "elsewhere");
    const fs::path level = tmp / "level.json", other = tmp / "other.json", state = tmp / "state.json";
    fs::copy_file(fs::path(STEPWISE_SOURCE_DIR) / "levels" / "spring_chain.json", level);
    fs::copy_file(fs::path(STEPWISE_SOURCE_DIR) / "levels" / "default.json", other);
    const std::string original = readFile(level), otherText = readFile(other);

    const XDisplay x(tmp, "1600x900x24");  // not the 1280x800 the other test uses: nothing here is at fixed pixels
    ASSERT_TRUE(x.error.empty()) << x.error;
    const std::vector<std::string>& env = x.env;
    auto xdo = [&](const std::string& args) { return x.xdo(args); };
    auto at = [](double px, double py) { return std::to_string(int(px)) + " " + std::to_string(int(py)); };

    // Started in an empty folder with no level: an untitled document.
    {
        Child editor({STEPWISE_BINARY, "edit", "--size", "1600x900", "--builtin-font", "--font-size", "13",
                      "--debug-state", state.string()},
                     env, tmp / "editor-untitled.log", tmp / "elsewhere");
        ASSERT_GT(editor.pid, 0);
        ASSERT_TRUE(waitFor([&] { return !readState(state).is_null(); }, 30s)) << readFile(tmp / "editor-untitled.log");
        const nlohmann::json s = readState(state);
        const auto vp = s["viewport"];
        ASSERT_TRUE(xdo("mousemove " + at(double(vp[0]) + double(vp[2]) / 2, double(vp[1]) + 20)));
        // The Open dialog lists the repository's levels, found from the
        // executable's place, not from the working folder.
        ASSERT_TRUE(xdo("key ctrl+o"));
        ASSERT_TRUE(waitFor([&] { return readState(state)["modal"] == "Open level"; }, 10s)) << readState(state).dump();
        const nlohmann::json open = readState(state);
        EXPECT_TRUE(fs::equivalent(std::string(open["open_folder"]), fs::path(STEPWISE_SOURCE_DIR) / "levels"))
            << open["open_folder"];
        EXPECT_GT(int(open["open_files"]), 10);
        // Save as proposes an absolute path in a folder that exists and can be written.
        const fs::path proposed = std::string(open["save_as_suggestion"]);
        EXPECT_TRUE(proposed.is_absolute()) << proposed;
        EXPECT_TRUE(fs::is_directory(proposed.parent_path())) << proposed;
        EXPECT_EQ(::access(proposed.parent_path().c_str(), W_OK), 0) << proposed;
    }  // the editor is stopped (TERM) here
    fs::remove(state);

    Child editor({STEPWISE_BINARY, "edit", level.string(), "--size", "1600x900", "--builtin-font", "--font-size", "13",
                  "--debug-state", state.string()},
                 env, tmp / "editor.log", tmp / "elsewhere");
    ASSERT_GT(editor.pid, 0);
    ASSERT_TRUE(waitFor([&] { return !readState(state).is_null(); }, 30s)) << readFile(tmp / "editor.log");
    const nlohmann::json s0 = readState(state);
    const double vx = s0["viewport"][0], vy = s0["viewport"][1];
    editor::ViewCamera cam;
    cam.width = int(double(s0["viewport"][2]));
    cam.height = int(double(s0["viewport"][3]));
    cam.camera.center = {double(s0["camera"][0]), double(s0["camera"][1])};
    cam.camera.zoom = double(s0["camera"][2]);
    ASSERT_TRUE(xdo("mousemove " + at(vx + cam.width / 2.0, vy + 20)));
    EXPECT_EQ(s0["open_folder"], tmp.string()) << "the document's own folder";

    // Rename link5 (both chain springs spring4 and spring5 hold it) by
    // clicking it and typing into the inspector's name field.
    Result<Scene> parsed = parseScene(original, "original");
    ASSERT_TRUE(parsed) << parsed.error();
    const Entity link5 = editor::findByName(parsed->registry, "link5");
    ASSERT_FALSE(link5.isNull());
    const Vec2 body = cam.toPixels(parsed->registry.tryGet<Position>(link5)->value);
    ASSERT_TRUE(xdo("key 1"));
    ASSERT_TRUE(xdo("mousemove " + at(vx + body.x, vy + body.y) + " click 1"));
    ASSERT_TRUE(waitFor([&] { return readState(state)["selection"] == 1; }, 10s)) << readState(state).dump();
    // The inspector's name field, wherever this window size's layout puts it
    // (--debug-state reports the fields' rectangles).
    nlohmann::json field;
    ASSERT_TRUE(waitFor([&] {
        field = readState(state)["widgets"]["inspector/name"];
        return field.is_array() && field.size() == 4;
    }, 10s)) << readState(state).dump();
    const nlohmann::json inspector = readState(state)["windows"]["Inspector"];
    ASSERT_TRUE(inspector.is_array()) << readState(state).dump();
    EXPECT_GT(double(field[0]), double(inspector[0])) << "the field lies in the Inspector";
    EXPECT_LT(double(field[0]) + double(field[2]), double(inspector[0]) + double(inspector[2]) + 1);
    ASSERT_TRUE(xdo("mousemove " + at(double(field[0]) + double(field[2]) / 2, double(field[1]) + double(field[3]) / 2) +
                    " click 1"));
    std::this_thread::sleep_for(300ms);
    ASSERT_TRUE(xdo("key ctrl+a"));
    ASSERT_TRUE(xdo("type --delay 30 bob"));
    ASSERT_TRUE(xdo("key Return"));
    ASSERT_TRUE(waitFor([&] { return readState(state)["dirty"] == true; }, 10s)) << readState(state).dump();
    // Play runs (a spring that lost its end would be refused) and moves the chain.
    ASSERT_TRUE(xdo("mousemove " + at(vx + cam.width / 2.0, vy + 20)));
    ASSERT_TRUE(xdo("key space"));
    ASSERT_TRUE(waitFor([&] {
        const nlohmann::json s = readState(state);
        return !s.is_null() && s["mode"] == "playing" && double(s["time"]) > 0.2;
    }, 20s)) << readState(state).dump();
    EXPECT_NE(readState(state)["positions"], s0["positions"]);
    ASSERT_TRUE(xdo("key space"));
    ASSERT_TRUE(waitFor([&] { return readState(state)["mode"] == "paused"; }, 10s));
    ASSERT_TRUE(xdo("key r"));
    ASSERT_TRUE(waitFor([&] { return readState(state)["mode"] == "editing"; }, 10s));
    ASSERT_TRUE(xdo("key ctrl+s"));
    ASSERT_TRUE(waitFor([&] { return readState(state)["dirty"] == false; }, 10s)) << readState(state).dump();
    // Saved: the level with link5 called bob, and both springs naming bob.
    parsed->registry.tryGet<Name>(link5)->value = "bob";
    EXPECT_EQ(readFile(level), sceneToJsonText(*parsed));
    const std::string saved = readFile(level);
    EXPECT_EQ(saved.find("\"link5\""), std::string::npos);
    EXPECT_NE(saved.find("\"a\": \"bob\""), std::string::npos);

    // Save as onto other.json: asks, and Cancel keeps the file.
    ASSERT_TRUE(xdo("key ctrl+shift+s"));
    ASSERT_TRUE(waitFor([&] { return readState(state)["modal"] == "Save as"; }, 10s)) << readState(state).dump();
    std::this_thread::sleep_for(300ms);
    ASSERT_TRUE(xdo("key ctrl+a"));
    ASSERT_TRUE(xdo("type --delay 20 " + other.string()));
    ASSERT_TRUE(xdo("key Return"));
    ASSERT_TRUE(waitFor([&] { return readState(state)["modal"] == "Replace file?"; }, 10s)) << readState(state).dump();
    EXPECT_EQ(readFile(other), otherText) << "written before asking";
    ASSERT_TRUE(xdo("key Escape"));
    ASSERT_TRUE(waitFor([&] { return readState(state)["modal"] == ""; }, 10s)) << readState(state).dump();
    EXPECT_EQ(readState(state)["status"], "not saved: " + other.string() + " was kept");
    EXPECT_EQ(readFile(other), otherText);

    ASSERT_TRUE(xdo("key ctrl+q"));
    EXPECT_TRUE(editor.waitExit(15s)) << "the editor did not quit on Ctrl+Q";
    fs::remove_all(tmp);
}


// The default 1280x800 window on a 720-pixel screen opened with its menu bar
// above the top edge. It now fits the screen it opens on.
TEST(EditorWindow, TheDefaultWindowFitsA1280x720Screen) {
    if (!have("Xvfb") || !have("xdotool")) GTEST_SKIP() << "needs Xvfb and xdotool (tests/setup-debian.sh installs them)";
    const fs::path tmp = fs::temp_directory_path() / ("stepwise-e2e-fit-" + std::to_string(getpid()));
    fs::remove_all(tmp);
    fs::create_directories(tmp);
    const fs::path state = tmp / "state.json";
    const XDisplay x(tmp, "1280x720x24");
    ASSERT_TRUE(x.error.empty()) << x.error;
    {
        Child editor({STEPWISE_BINARY, "edit", (fs::path(STEPWISE_SOURCE_DIR) / "levels" / "default.json").string(),
                      "--builtin-font", "--font-size", "13", "--debug-state", state.string()},
                     x.env, tmp / "editor.log");
        ASSERT_GT(editor.pid, 0);
        ASSERT_TRUE(waitFor([&] { return !readState(state).is_null(); }, 30s)) << readFile(tmp / "editor.log");
        const nlohmann::json s = readState(state);
        EXPECT_EQ(double(s["window"][0]), 1280.0) << s.dump();
        EXPECT_LE(double(s["window"][1]), 720.0) << s.dump();
        // The window's place on the screen: whole, from its top edge down.
        const std::string geometry = tmp / "geometry.txt";
        const std::string cmd = "DISPLAY=" + x.name + " xdotool search --name Stepwise getwindowgeometry --shell > " +
                                geometry + " 2>&1";
        ASSERT_EQ(std::system(cmd.c_str()), 0) << readFile(geometry);
        const std::string g = readFile(geometry);
        const auto value = [&](const std::string& key) {
            const std::size_t at = g.find(key + "=");
            return at == std::string::npos ? -1 : std::stoi(g.substr(at + key.size() + 1));
        };
        EXPECT_GE(value("Y"), 0) << g;
        EXPECT_LE(value("Y") + value("HEIGHT"), 720) << g;
    }  // the editor is stopped (TERM) here
    fs::remove_all(tmp);
}
