#include "app/editor.hpp"

#include "app/scene_edit.hpp"

#include "stepwise/components.hpp"

#include <cmath>

// The Polygon tool: clicked vertices make their convex hull (Enter, a right
// click or a click on the first vertex finishes it), or with polygonSides
// 3..8 a drag from the centre makes a regular polygon.

namespace stepwise::editor {

void Editor::pressPolygon(const ToolPress& press) {
    const Vec2 px = press.px, world = press.world;
    const Vec2 at = snapped(world);
    if (polygonSides >= 3) {
        drag_ = Drag::RegularPolygon;
        dragStartWorld_ = at;
        return;
    }
    // A click on the first vertex closes the outline.
    if (polygonClicks_.size() >= 3 && length(px - view.toPixels(polygonClicks_.front())) <= 8.0) {
        finishPolygon();
        return;
    }
    std::vector<Vec2> next = polygonClicks_;
    next.push_back(at);
    if (convexHull(next).size() > 8) {
        note("polygon: at most 8 vertices; press Enter to make it");
        return;
    }
    polygonClicks_ = std::move(next);
    note("polygon: " + std::to_string(polygonClicks_.size()) +
         " clicked; click more, then Enter, a right click or the first vertex (Esc cancels)");
}

void Editor::releaseRegularPolygon() {
    const std::vector<Vec2> outline = regularOutline();
    if (outline.empty()) {
        note("polygon: drag out its size from the centre");
        return;
    }
    Entity created;
    const Result<bool> placed =
        tryEdit("place polygon", [&](Scene& s) { return createdInto(addPolygon(s, outline), created); });
    if (placed && *placed) selection = {created};
    else if (!placed) note("refused: " + placed.error(), true);
}

std::vector<Vec2> Editor::polygonPreview() const {
    if (tool != Tool::Polygon) return {};
    const Vec2 cursor = snapped(view.toWorld(mouse_));
    if (polygonSides >= 3) return drag_ == Drag::RegularPolygon ? regularOutline() : std::vector<Vec2>{};
    if (polygonClicks_.empty()) return {};
    // The hull with the cursor as the next vertex, unless that breaks the limit.
    std::vector<Vec2> points = polygonClicks_;
    points.push_back(cursor);
    std::vector<Vec2> hull = convexHull(points);
    if (hull.size() > 8 || hull.size() < 3) hull = convexHull(polygonClicks_);
    return hull;
}

std::vector<Vec2> Editor::regularOutline() const {
    const Vec2 arm = snapped(view.toWorld(mouse_)) - dragStartWorld_;
    const double radius = length(arm);
    if (!(radius > 1e-3) || polygonSides < 3) return {};  // a click, not a drag
    std::vector<Vec2> outline = regularPolygon(polygonSides, radius, std::atan2(arm.y, arm.x));
    for (Vec2& v : outline) v += dragStartWorld_;
    return outline;
}

bool Editor::finishPolygon() {
    const std::vector<Vec2> hull = convexHull(polygonClicks_);
    polygonClicks_.clear();
    Entity created;
    if (hull.size() < 3) {
        note("polygon: needs 3 vertices that are not on one line");
        return false;
    }
    const Result<bool> placed =
        tryEdit("place polygon", [&](Scene& s) { return createdInto(addPolygon(s, hull), created); });
    if (!placed || !*placed) {
        note(placed ? "nothing changed" : "refused: " + placed.error(), !placed);
        return false;
    }
    selection = {created};
    return true;
}

} // namespace stepwise::editor
