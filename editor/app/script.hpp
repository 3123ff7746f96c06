#pragma once
/// \file script.hpp
/// The scripted mode's input file: one command per line, replayed as
/// InputEvents through the same handlers a person's input goes through
/// (docs/editor.md, "Scripted, headless", documents the format). Parsing reports the line
/// and what was expected; a bad script is refused whole before anything runs.
///
///   # comment                     key Space | key Ctrl+Shift+Z
///   keydown KEY / keyup KEY       move X Y | move world X Y
///   click [world] X Y [right|middle] [shift] [ctrl]
///   drag [world] X0 Y0 X1 Y1 [N] [right|middle] [shift] [ctrl]   (N moves, default 8)
///   wheel NOTCHES [X Y]           text "hello"
///   wait N                        (N frames; every command takes at least one)
///   play | pause | step [N] | stepback [N] | reset | undo | redo
///   tool select|rotate|circle|box|plane|spring|attractor|boids|joint|polygon (toolScriptNames)
///   select NAME...  | select none   overlay NAME on|off   system NAME on|off
///   snap on|off     timescale X     breakon NAME|none     fit
///   new | open PATH | save | saveas PATH | savestate PATH | screenshot PATH
///   window tools|entities|inspector|world|debug|help on|off
///   tab contacts|plots|profile|history   (the Debug panel's tab)

#include "app/events.hpp"

#include "stepwise/result.hpp"
#include "stepwise/vec2.hpp"

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace stepwise::editor {

struct ScriptPoint {
    Vec2 value;
    bool world = false;  ///< metres (through the viewport camera) instead of window pixels
};

struct ScriptCommand {
    enum class Kind : std::uint8_t { Key, KeyDown, KeyUp, Move, Click, Drag, Wheel, Text, Wait, Action };
    Kind kind = Kind::Wait;
    int line = 0;
    Key key = Key::None;
    std::uint8_t mods = kModNone;
    MouseButton button = MouseButton::Left;
    ScriptPoint a, b;
    bool hasPoint = false;
    int count = 1;               ///< wait frames, drag moves, step count
    double number = 0.0;         ///< wheel notches, time scale
    std::string text;            ///< typed text; action name
    std::vector<std::string> args;  ///< action arguments
};

/// Parses a whole script. `name` prefixes messages ("demo.txt:3: ...").
Result<std::vector<ScriptCommand>> parseScript(std::string_view text, std::string_view name);

/// A finite number written whole ("1.5", "-2", "1e3"); false otherwise.
bool parseScriptNumber(const std::string& text, double& out);

/// "Ctrl+Shift+Z" -> key and modifiers.
Result<std::pair<Key, std::uint8_t>> parseChord(std::string_view chord);

} // namespace stepwise::editor
