#include "app/editor.hpp"

#include "app/scene_edit.hpp"

#include "stepwise/components.hpp"

// The Circle, Box and Attractor tools (a click places one) and the Wall
// tool (a click makes a floor, a drag points the wall's normal).

namespace stepwise::editor {

void Editor::placeAt(Vec2 world) {
    const Vec2 at = snapped(world);
    Entity created;
    const std::string label = std::string("place ") + std::string(toolName(tool));
    const bool done = applyEdit(label, [&](Scene& s) {
        switch (tool) {
        case Tool::Circle: created = addCircle(s, at); break;
        case Tool::Box: created = addBox(s, at); break;
        case Tool::Attractor: created = addAttractor(s, at); break;
        default: return false;
        }
        return true;
    });
    if (done) selection = {created};
}

void Editor::pressPlace(const ToolPress& press) { placeAt(press.world); }

void Editor::pressWall(const ToolPress&) { drag_ = Drag::Plane; }

void Editor::releaseWall(Vec2 px) {
    const Vec2 world = view.toWorld(px);
    const Vec2 through = snapped(dragStartWorld_);
    // Dragging points the normal (the side bodies stay on); a click
    // makes a floor.
    const Vec2 normal = length(px - dragStartPx_) > 5.0 ? world - dragStartWorld_ : Vec2{0.0, 1.0};
    Entity created;
    if (applyEdit("place wall", [&](Scene& s) {
            created = addPlane(s, through, normal);
            return true;
        }))
        selection = {created};
}

} // namespace stepwise::editor
