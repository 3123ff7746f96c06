#include "app/tools/tools.hpp"

#include "app/editor.hpp"

namespace stepwise::editor {

std::string_view toolName(Tool t) {
    switch (t) {
    case Tool::Select: return "Select";
    case Tool::Rotate: return "Rotate";
    case Tool::Circle: return "Circle";
    case Tool::Box: return "Box";
    case Tool::Plane: return "Wall";
    case Tool::Spring: return "Spring";
    case Tool::Attractor: return "Attractor";
    case Tool::Boids: return "Boids";
    case Tool::Joint: return "Joint";
    case Tool::Polygon: return "Polygon";
    case Tool::Count: break;
    }
    return "?";
}

// Keys 1..9 pick the first nine tools and 0 the tenth, as on a keyboard's row.
Key toolKey(Tool t) {
    return std::uint16_t(t) < 9 ? Key(std::uint16_t(Key::Num1) + std::uint16_t(t)) : Key::Num0;
}

const std::array<ToolInfo, kToolCount>& toolTable() {
    static const std::array<ToolInfo, kToolCount> table = {{
        {Tool::Select, &Editor::pressSelectOrRotate},
        {Tool::Rotate, &Editor::pressSelectOrRotate},
        {Tool::Circle, &Editor::pressPlace},
        {Tool::Box, &Editor::pressPlace},
        {Tool::Plane, &Editor::pressWall},
        {Tool::Spring, &Editor::pressSpring},
        {Tool::Attractor, &Editor::pressPlace},
        {Tool::Boids, &Editor::pressBoids},
        {Tool::Joint, &Editor::pressJoint},
        {Tool::Polygon, &Editor::pressPolygon},
    }};
    return table;
}

} // namespace stepwise::editor
