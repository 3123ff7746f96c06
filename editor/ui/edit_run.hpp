#pragma once
/// \file edit_run.hpp
/// What `stepwise edit`'s two ways of running share: the options, the
/// --bench-bodies level, the --debug-state file and the frame-time report.
/// The window loop is platform/sdl_window.cpp, the headless scripted runner
/// cli/edit_scripted.cpp; edit_command.cpp parses the options and picks one.

#include "ui/session.hpp"

#include "stepwise/scene.hpp"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace stepwise::ui {

struct EditOptions {
    std::string level;
    std::string script;
    std::string screenshot;
    std::string size = "1280x800";
    float fontSize = 0.0f;
    bool builtinFont = false;
    std::string configDir;
    int benchFrames = 0;
    int benchBodies = 0;
    std::string debugState;
    bool headless = false;
    bool showTimings = false;
    bool noVsync = false;
    std::string overlays;
};

constexpr double kFrameSeconds = 1.0 / 60.0;  // scripted frames: fixed, so runs are deterministic

/// Writes the editor's state (mode, time, steps, viewport, camera, the first
/// 64 positions) as JSON, atomically, for tests that watch a running editor.
void writeDebugState(const std::string& path, Session& session, std::uint64_t frame);

struct FrameTimes {
    std::vector<double> ms;
    UiState::FrameParts sum;  ///< the parts summed over the recorded frames
    UiState::FrameParts last; ///< the last recorded frame's parts
    /// CPU seconds of the whole process (every thread: the editor's and the
    /// rasteriser's) at the first and the last add(). On a shared machine
    /// the CPU time a frame takes moves less than its wall time.
    double processCpuStart = -1.0, processCpuLast = 0.0;

    void add(double frameMs, const UiState::FrameParts& parts);
    /// Prints the mean, median, p95 and max frame time and where a frame goes.
    void report(const char* what, std::size_t bodies) const;
};


} // namespace stepwise::ui
