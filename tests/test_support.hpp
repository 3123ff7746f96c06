#pragma once
/// \file test_support.hpp
/// Small helpers the test files share.

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "stepwise/scene_io.hpp"
#include "stepwise/world.hpp"

#include <stdexcept>

// Memory measurements (peak RSS, mallinfo2) mean nothing under
// AddressSanitizer: its quarantine holds freed memory and it replaces malloc.
#if defined(__SANITIZE_ADDRESS__)
#define STEPWISE_UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define STEPWISE_UNDER_ASAN 1
#endif
#endif

namespace stepwise::test {

/// A fresh folder per test, named after `prefix`, the process and the test;
/// removed with everything in it (made writable first) at the end.
struct TempDir {
    std::filesystem::path path;
    explicit TempDir(const std::string& prefix) {
        path = std::filesystem::temp_directory_path() /
               (prefix + "-" + std::to_string(::getpid()) + "-" +
                ::testing::UnitTest::GetInstance()->current_test_info()->name());
        std::filesystem::remove_all(path);
        std::filesystem::create_directories(path);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    ~TempDir() {
        std::error_code ec;
        std::filesystem::permissions(path, std::filesystem::perms::owner_all, ec);
        std::filesystem::remove_all(path, ec);
    }
};

/// FNV-1a, 64 bit: tiny, stable, and every byte matters (the determinism
/// and scene hashes).
inline std::uint64_t fnv1a(const std::string& bytes) {
    std::uint64_t h = 0xcbf29ce484222325ull;
    for (unsigned char c : bytes) {
        h ^= c;
        h *= 0x100000001b3ull;
    }
    return h;
}

/// A saved scene's text without the three world lines sleeping added
/// ("sleep", "sleep_velocity", "sleep_time", written by default since issue
/// 16): hashes recorded before them still check the rest of the bytes.
inline std::string withoutSleepLines(std::string text) {
    const bool on = text.find("\"sleep\": true") != std::string::npos;
    const std::string lines = std::string(",\n    \"sleep\": ") + (on ? "true" : "false") +
                              ",\n    \"sleep_velocity\": 0.05,\n    \"sleep_time\": 0.5";
    const std::size_t at = text.find(lines);
    EXPECT_NE(at, std::string::npos) << "the world's sleep lines are not where they were";
    if (at != std::string::npos) text.erase(at, lines.size());
    return text;
}

/// 0x followed by 16 hex digits: how the recorded hashes are written.
inline std::string hex(std::uint64_t v) {
    char buffer[24];
    std::snprintf(buffer, sizeof buffer, "0x%016llx", static_cast<unsigned long long>(v));
    return buffer;
}

/// The whole file as bytes; empty when it cannot be read (tests compare
/// against expected contents, so a missing file fails there, visibly).
inline std::string readFile(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

/// The saves-under-fault tests' harness: forks a child that runs `warmUp`
/// once (a fresh child first pays for copy-on-write faults, tens of
/// milliseconds under ASan, so the clock starts after it), tells the parent
/// it is ready, then runs `work` until it fails or is killed. The parent
/// waits `delay` after "ready", kills the child with SIGKILL and reaps it.
/// Returns "" when the child was killed in its loop, else what happened
/// (either function returning false ends the child with exit 1).
inline std::string killWhileWorking(const std::function<bool()>& warmUp, const std::function<bool()>& work,
                                    std::chrono::microseconds delay) {
    int ready[2];
    if (::pipe(ready) != 0) return "pipe failed";
    const pid_t child = ::fork();
    if (child < 0) return "fork failed";
    if (child == 0) {
        ::close(ready[0]);
        if (!warmUp()) _exit(1);
        if (::write(ready[1], "r", 1) != 1) _exit(1);
        while (work()) {
        }
        _exit(1);
    }
    ::close(ready[1]);
    char byte = 0;
    const bool started = ::read(ready[0], &byte, 1) == 1;
    ::close(ready[0]);
    int status = 0;
    if (!started) {
        ::waitpid(child, &status, 0);
        return "the child failed before its loop (status " + std::to_string(status) + ")";
    }
    std::this_thread::sleep_for(delay);
    if (::kill(child, SIGKILL) != 0) return "kill failed";
    if (::waitpid(child, &status, 0) != child) return "waitpid failed";
    if (!(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL))
        return "the child ended by itself (a failed step exits 1), status " + std::to_string(status);
    return "";
}

/// A number written so that it reads back to the same double.
inline std::string exactNumber(double v) {
    char text[40];
    std::snprintf(text, sizeof text, "%.17g", v);
    return text;
}

/// A vector's JSON, {"x": X, "y": Y}, each number exact.
inline std::string vectorJson(double x, double y) {
    return "{\"x\": " + exactNumber(x) + ", \"y\": " + exactNumber(y) + "}";
}

/// A level of `entities` (JSON objects, comma-separated) under gravity
/// 9.81 m/s^2 down, with `world` (more world keys) added when given.
inline std::string levelUnderGravity(const std::string& entities, const std::string& world = "") {
    return "{\"world\": {\"gravity\": {\"x\": 0, \"y\": -9.81}" + (world.empty() ? std::string() : ", " + world) +
           "}, \"entities\": [" + entities + "]}";
}

/// The loader's refusal of `text` (as "t.json"), or "loaded".
inline std::string loadError(const std::string& text) {
    Result<Scene> s = parseScene(text, "t.json");
    return s ? "loaded" : s.error();
}

/// A level parsed from text; throws (failing the test) if it is refused.
inline Scene parseLevel(const std::string& text) {
    Result<Scene> s = parseScene(text, "t.json");
    if (!s) throw std::runtime_error(s.error());
    return std::move(*s);
}

/// A World built from `s`, without the step clock; throws if refused.
inline World buildWorld(const Scene& s) {
    Result<World> w = World::build(s);
    if (!w) throw std::runtime_error(w.error());
    w->setProfiling(false);
    return std::move(*w);
}

/// Every level in levels/ (not the schema), sorted by path.
inline std::vector<std::filesystem::path> shippedLevels() {
    std::vector<std::filesystem::path> out;
    for (const auto& entry : std::filesystem::directory_iterator(std::filesystem::path(STEPWISE_SOURCE_DIR) / "levels"))
        if (entry.path().extension() == ".json" && entry.path().filename() != "scene.schema.json")
            out.push_back(entry.path());
    std::sort(out.begin(), out.end());
    return out;
}

/// A shell command line's exit code and what it printed on standard
/// output (redirect stderr in the line to read it instead).
struct CommandResult {
    int exitCode = -1;
    std::string out;
};
inline CommandResult runCommand(const std::string& line) {
    CommandResult r;
    FILE* pipe = ::popen(line.c_str(), "r");
    if (!pipe) return r;
    char buffer[4096];
    while (std::fgets(buffer, sizeof buffer, pipe)) r.out += buffer;
    r.exitCode = WEXITSTATUS(::pclose(pipe));
    return r;
}

/// The scene as `stepwise run --out` writes it: the world's state written
/// back, and its solver state when it carries any.
inline std::string savedRunText(const World& world, Scene scene) {
    world.writeBack(scene);
    scene.solverState.reset();
    SolverState solver = world.solverState();
    if (!solver.empty()) scene.solverState = std::move(solver);
    return sceneToJsonText(scene);
}

/// The entity called `name` (null when none is).
inline Entity named(const Scene& scene, const std::string& name) {
    for (Entity e : scene.registry.entities())
        if (const Name* n = scene.registry.tryGet<Name>(e); n && n->value == name) return e;
    return {};
}

/// A level loaded from `text` and stepped, with its state written back
/// after each step() as `stepwise run --out` would save it (the warm start
/// and chosen settings in the solver state), for reading bodies by name.
struct Sim {
    Scene scene;
    std::unique_ptr<World> world;
    explicit Sim(const std::string& text) {
        Result<Scene> loaded = parseScene(text, "t.json");
        EXPECT_TRUE(loaded) << loaded.error();
        if (!loaded) return;
        scene = std::move(*loaded);
        Result<World> w = World::build(scene);
        EXPECT_TRUE(w) << w.error();
        if (w) world = std::make_unique<World>(std::move(*w));
    }
    /// Takes `n` steps, calling `each` after every one.
    bool step(int n = 1, const std::function<void()>& each = {}) {
        if (!world) return false;
        for (int i = 0; i < n; ++i) {
            Result<void> r = world->step();
            EXPECT_TRUE(r) << r.error();
            if (!r) return false;
            if (each) each();
        }
        world->writeBack(scene);
        SolverState solver = world->solverState();
        scene.solverState = solver.empty() ? std::nullopt : std::optional<SolverState>(std::move(solver));
        return true;
    }
    Vec2 position(const std::string& name) const { return scene.registry.tryGet<Position>(named(scene, name))->value; }
    Vec2 velocity(const std::string& name) const {
        const Velocity* v = scene.registry.tryGet<Velocity>(named(scene, name));
        return v ? v->value : Vec2{};
    }
    double angle(const std::string& name) const {
        const Angle* a = scene.registry.tryGet<Angle>(named(scene, name));
        return a ? a->value : 0.0;
    }
    double angularVelocity(const std::string& name) const {
        const AngularVelocity* w = scene.registry.tryGet<AngularVelocity>(named(scene, name));
        return w ? w->value : 0.0;
    }
};

} // namespace stepwise::test
