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
    Child(std::vector<std::string> argv, const std::vector<std::string>& extraEnv, const fs::path& log) {
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
    for (int n = 90; n < 200; ++n)
        if (!fs::exists("/tmp/.X" + std::to_string(n) + "-lock") && !fs::exists("/tmp/.X11-unix/X" + std::to_string(n)))
            return n;
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

} // namespace

TEST(EditorWindow, PlayPlaceUndoSaveThroughXvfbAndXdotool) {
    if (!have("Xvfb") || !have("xdotool")) GTEST_SKIP() << "needs Xvfb and xdotool (tests/setup-debian.sh installs them)";
    const fs::path tmp = fs::temp_directory_path() / ("stepwise-e2e-" + std::to_string(getpid()));
    fs::remove_all(tmp);
    fs::create_directories(tmp);
    const fs::path level = tmp / "level.json", state = tmp / "state.json";
    fs::copy_file(fs::path(STEPWISE_SOURCE_DIR) / "levels" / "spring_chain.json", level);
    const std::string original = readFile(level);

    const int display = freeDisplay();
    ASSERT_GT(display, 0) << "no free X display number";
    const std::string disp = ":" + std::to_string(display);
    Child xvfb({"Xvfb", disp, "-screen", "0", "1280x800x24", "-nolisten", "tcp"}, {}, tmp / "xvfb.log");
    ASSERT_GT(xvfb.pid, 0);
    ASSERT_TRUE(waitFor([&] { return fs::exists("/tmp/.X11-unix/X" + std::to_string(display)); }, 10s))
        << readFile(tmp / "xvfb.log");

    const std::vector<std::string> env{"DISPLAY=" + disp, "LIBGL_ALWAYS_SOFTWARE=1",
                                       "XDG_CONFIG_HOME=" + (tmp / "config").string()};
    Child editor({STEPWISE_BINARY, "edit", level.string(), "--size", "1280x800", "--builtin-font", "--font-size", "13",
                  "--debug-state", state.string()},
                 env, tmp / "editor.log");
    ASSERT_GT(editor.pid, 0);
    auto xdo = [&](const std::string& args) {
        const std::string cmd = "DISPLAY=" + disp + " xdotool " + args + " > /dev/null 2>&1";
        return std::system(cmd.c_str()) == 0;
    };
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
