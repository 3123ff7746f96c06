#include "app/tools/tools.hpp"

#include "app/editor.hpp"

namespace stepwise::editor {

const std::array<ToolInfo, kToolCount>& toolTable() {
    static constexpr std::array<ToolInfo, kToolCount> table = {{
        {Tool::Select, "select", "Select", "select", &Editor::pressSelectOrRotate},
        {Tool::Rotate, "rotate", "Rotate", "rotate", &Editor::pressSelectOrRotate},
        {Tool::Circle, "circle", "Circle", "circle", &Editor::pressPlace},
        {Tool::Box, "box", "Box", "box", &Editor::pressPlace},
        {Tool::Plane, "plane", "Wall", "wall", &Editor::pressWall},
        {Tool::Spring, "spring", "Spring", "spring", &Editor::pressSpring},
        {Tool::Attractor, "attractor", "Attractor", "attractor", &Editor::pressPlace},
        {Tool::Boids, "boids", "Boids", "boid brush", &Editor::pressBoids},
        {Tool::Joint, "joint", "Joint", "joint", &Editor::pressJoint},
        {Tool::Polygon, "polygon", "Polygon", "polygon", &Editor::pressPolygon},
    }};
    // (Whether each row has a handler is checked by ToolTable.* at run
    // time: GCC's UndefinedBehaviorSanitizer makes a member-pointer null
    // test non-constant, so it cannot be in the static_assert.)
    static_assert([] {
        for (std::size_t i = 0; i < kToolCount; ++i)
            if (table[i].tool != Tool(i) || table[i].scriptName.empty()) return false;
        return true;
    }(), "one entry per tool, in Tool order");
    return table;
}

std::string_view toolName(Tool t) { return t < Tool::Count ? toolTable()[std::size_t(t)].label : "?"; }

// Keys 1..9 pick the first nine tools and 0 the tenth, as on a keyboard's row.
Key toolKey(Tool t) {
    return std::uint16_t(t) < 9 ? Key(std::uint16_t(Key::Num1) + std::uint16_t(t)) : Key::Num0;
}

std::optional<Tool> toolForKey(Key key) {
    for (const ToolInfo& info : toolTable())
        if (toolKey(info.tool) == key) return info.tool;
    return std::nullopt;
}

std::optional<Tool> toolFromScriptName(std::string_view name) {
    for (const ToolInfo& info : toolTable())
        if (info.scriptName == name) return info.tool;
    return std::nullopt;
}

std::string toolScriptNames(std::string_view separator) {
    std::string out;
    for (const ToolInfo& info : toolTable()) out += (out.empty() ? "" : std::string(separator)) + std::string(info.scriptName);
    return out;
}

std::string toolHelpNames() {
    std::string out;
    for (const ToolInfo& info : toolTable()) out += (out.empty() ? "" : ", ") + std::string(info.helpName);
    return out;
}

} // namespace stepwise::editor
