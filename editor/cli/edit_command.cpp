// stepwise edit [LEVEL]: the editor in an SDL2 window (OpenGL 3.3 core), or
// headless with --script/--screenshot: the same Session drawn through OSMesa,
// input replayed from a script file through the same handlers. This file
// parses the options and picks one: the window is platform/sdl_window.cpp,
// the headless runner cli/edit_scripted.cpp.

#include "cli/cli_common.hpp"
#include "cli/option_checks.hpp"
#include "cli/commands.hpp"
#include "ui/edit_run.hpp"

#include "app/document.hpp"
#include "platform/sdl_window.hpp"
#include "overlay_set.hpp"

#include <cstdio>
#include <filesystem>
#include <memory>

namespace stepwise::cli {

using ui::EditOptions;

namespace {

bool parseSize(const std::string& text, int& w, int& h) {
    char x = 0, extra = 0;
    return std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) == 3 && (x == 'x' || x == 'X') && w >= 320 &&
           h >= 240 && w <= 8192 && h <= 8192;
}

} // namespace

void addEditCommand(CLI::App& app, int& exitCode) {
    auto o = std::make_shared<EditOptions>();
    CLI::App* cmd = app.add_subcommand("edit", "Open the editor (SDL2 window; headless with --script/--screenshot)");
    cmd->add_option("level", o->level, "Level to open")->default_val("levels/default.json");
    cmd->add_option("--script", o->script, "Replay input from this file (headless, OSMesa); see docs/editor.md");
    cmd->add_option("--screenshot", o->screenshot, "Headless: write the whole editor as a PNG at the end");
    cmd->add_option("--size", o->size, "Window size WxH")->default_val("1280x800");
    cmd->add_option("--font-size", o->fontSize, "UI font size in pixels (default: 13 x display DPI / 96)")
        ->check(CLI::Range(8.0f, 48.0f));
    cmd->add_flag("--builtin-font", o->builtinFont, "Use ImGui's embedded font (the screenshot tests do)");
    cmd->add_option("--config", o->configDir, "Settings folder (default $XDG_CONFIG_HOME/stepwise)");
    cmd->add_option("--bench-frames", o->benchFrames, "Play and report the frame time over N frames")
        ->check(CLI::Range(1, 100000));
    cmd->add_option("--bench-bodies", o->benchBodies, "Benchmark a generated level of N circles instead of LEVEL")
        ->check(CLI::Range(1, 1000000));
    cmd->add_option("--debug-state", o->debugState, "Write the editor's state (mode, time, positions) to this JSON file")
        ->check(outputFileName());
    cmd->add_flag("--headless", o->headless, "Run through OSMesa without a window (implied by --script/--screenshot)");
    cmd->add_flag("--show-timings", o->showTimings, "Headless: show wall-clock timings (screenshots then differ run to run)");
    cmd->add_flag("--no-vsync", o->noVsync, "Window: do not wait for the display's refresh");
    cmd->add_option("--overlay", o->overlays, "Overlays to start with: velocity,force-field,...|all (default velocity,contacts)");
    cmd->callback([o, &exitCode] {
        int w = 0, h = 0;
        if (!parseSize(o->size, w, h)) {
            reportError("--size: expected WxH between 320x240 and 8192x8192, got \"" + o->size + "\"");
            exitCode = kExitBadInput;
            return;
        }
        if (Result<render::OverlaySet> ov = render::parseOverlayList(o->overlays); !ov) {
            reportError("--overlay: " + ov.error());
            exitCode = kExitBadInput;
            return;
        }
        // Started from another folder with no level named: the default level
        // beside the executable, not a "levels/default.json" that is not there.
        std::error_code ec;
        if (o->level == "levels/default.json" && !std::filesystem::exists(o->level, ec))
            o->level = (editor::findLevelsDirectory(editor::executableDirectory(), std::filesystem::current_path(ec)) /
                        "default.json")
                           .string();
        const bool headless = o->headless || !o->script.empty() || !o->screenshot.empty();
        if (headless) {
            exitCode = runScripted(*o, w, h);
        } else if (Result<void> ran = platform::runWindow(*o, w, h); !ran) {
            reportError(ran.error());
            exitCode = kExitFailure;
        } else {
            exitCode = kExitOk;
        }
    });
}

} // namespace stepwise::cli
