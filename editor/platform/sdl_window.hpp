#pragma once
/// \file sdl_window.hpp
/// The editor in an SDL2 window with an OpenGL 3.3 core context: SDL's
/// events translated to the editor's InputEvents, real-time frames, vsync.
/// The only file that knows SDL.

#include "cli/edit_run.hpp"

namespace stepwise::platform {

/// Opens the window and runs the editor until it quits. Returns the process
/// exit code (failures to open a display or a context are reported).
int runWindow(const cli::EditOptions& o, int width, int height);

} // namespace stepwise::platform
