#pragma once
/// \file events.hpp
/// Input as plain data. The SDL window and the scripted (headless) mode both
/// turn what happens into these events and hand them to the same handlers
/// (EditorUi feeds ImGui, then Editor::handleViewportEvent / handleShortcut),
/// so a script exercises exactly the code a person's clicks do.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace stepwise::editor {

/// Keys the editor knows. Letters and digits are contiguous so a script's
/// "key A" maps without a table per letter.
enum class Key : std::uint16_t {
    None = 0,
    Space, Left, Right, Up, Down, Delete, Backspace, Escape, Enter, Tab, Home, End, PageUp, PageDown,
    F1, F2, F3, F4, F5,
    A, B, C, D, E, F, G, H, I, J, K, L, M, N, O, P, Q, R, S, T, U, V, W, X, Y, Z,
    Num0, Num1, Num2, Num3, Num4, Num5, Num6, Num7, Num8, Num9,
    Count
};

/// Modifier bits.
enum Mod : std::uint8_t { kModNone = 0, kModCtrl = 1, kModShift = 2, kModAlt = 4 };

enum class MouseButton : std::uint8_t { Left = 0, Right = 1, Middle = 2 };

struct InputEvent {
    enum class Type : std::uint8_t { KeyDown, KeyUp, MouseMove, MouseDown, MouseUp, Wheel, Text };
    Type type = Type::MouseMove;
    Key key = Key::None;
    std::uint8_t mods = kModNone;
    MouseButton button = MouseButton::Left;
    double x = 0.0, y = 0.0;  ///< window pixels, origin top-left, y down
    double wheel = 0.0;       ///< notches, positive = away from the user (zoom in)
    std::string text;         ///< UTF-8, for Type::Text
};

/// "Space", "Left", "Ctrl+Z" parts: a key name (case-insensitive) -> Key.
std::optional<Key> keyFromName(std::string_view name);
std::string_view keyName(Key key);

} // namespace stepwise::editor
