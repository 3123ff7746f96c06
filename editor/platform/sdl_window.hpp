#pragma once
/// \file sdl_window.hpp
/// The editor in an SDL2 window with an OpenGL 3.3 core context: SDL's
/// events translated to the editor's InputEvents, real-time frames, vsync.
/// The only file that knows SDL.

#include "ui/edit_run.hpp"

#include "stepwise/result.hpp"

namespace stepwise::platform {

/// Opens the window and runs the editor until it quits. Fails, saying why,
/// when there is no display or no OpenGL 3.3 context.
Result<void> runWindow(const ui::EditOptions& o, int width, int height);

} // namespace stepwise::platform
