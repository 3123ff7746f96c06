#pragma once
/// \file tools.hpp
/// The viewport tools and their one table: for each tool its names (the
/// script's, the toolbar's, the help window's), its key (its place in the
/// table: 1..9, then 0) and what a left click in the viewport does with it
/// (an Editor member in editor/app/tools/, one file per tool family).
/// Adding a tool is adding an enum value and its table entry (tools.cpp).

#include "app/events.hpp"

#include "stepwise/entity.hpp"
#include "stepwise/vec2.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace stepwise::editor {

enum class Tool : std::uint8_t { Select, Rotate, Circle, Box, Plane, Spring, Attractor, Boids, Joint, Polygon, Count };
inline constexpr std::size_t kToolCount = std::size_t(Tool::Count);

/// The toolbar's and status line's name ("Wall").
std::string_view toolName(Tool t);
/// Shortcut key of each tool ("1" .. "9", then "0").
Key toolKey(Tool t);
/// The tool a shortcut key picks, if any.
std::optional<Tool> toolForKey(Key key);
/// The tool the script's `tool NAME` names ("plane"), if any.
std::optional<Tool> toolFromScriptName(std::string_view name);
/// Every script name joined by `separator` ("select|rotate|...").
std::string toolScriptNames(std::string_view separator);
/// Every help name joined by ", " ("select, rotate, ..., boid brush, ...").
std::string toolHelpNames();

class Editor;

/// A left-button press in the viewport, as a tool receives it.
struct ToolPress {
    Vec2 px;     ///< viewport pixels, origin top-left
    Vec2 world;  ///< metres, not snapped
    Entity hit;  ///< the entity under the cursor (within the pick radius), or null
};

struct ToolInfo {
    Tool tool;
    std::string_view scriptName;  ///< `tool NAME` in scripts: lower case, one word
    std::string_view label;       ///< toolbar, status line and undo labels
    std::string_view helpName;    ///< the help window's list of tools
    /// What a left click in the viewport does with this tool.
    void (Editor::*press)(const ToolPress& press);
};

/// One entry per tool, in Tool order.
const std::array<ToolInfo, kToolCount>& toolTable();

} // namespace stepwise::editor
