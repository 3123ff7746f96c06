#include "app/editor.hpp"

#include "app/scene_edit.hpp"

#include "stepwise/components.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

// The Select and Rotate tools: pick, box-select, move and rotate the
// selection (and, while playing, pull a body with a mouse spring).

namespace stepwise::editor {

void Editor::pressSelectOrRotate(const ToolPress& press) {
    const Vec2 world = press.world;
    Entity hit = press.hit;
    const Registry& reg = doc.scene.registry;
    if (hit.isNull() && tool == Tool::Rotate && !selection.empty() && !additive_) {
        hit = selection.front();  // rotate the selection about its first entity from anywhere
    } else if (hit.isNull()) {
        if (!additive_) selection.clear();
        drag_ = Drag::BoxSelect;
        return;
    }
    const bool selected = std::find(selection.begin(), selection.end(), hit) != selection.end();
    if (additive_) {
        if (selected) std::erase(selection, hit);
        else selection.push_back(hit);
        return;
    }
    if (!selected) selection = {hit};
    dragPrimary_ = hit;
    dragKey_ = newMergeKey();
    if (sim.state() == SimState::Playing && tool == Tool::Select && reg.has<Position>(hit) &&
        !(reg.has<Static>(hit) && reg.tryGet<Static>(hit)->value)) {
        // Playing: a mouse spring, not an edit.
        drag_ = Drag::MouseSpring;
        sim.mouseSpring = std::make_pair(hit, world);
        return;
    }
    dragStart_.clear();
    angleStart_.clear();
    planeStart_.clear();
    for (Entity s : selection) {
        if (const Position* p = reg.tryGet<Position>(s)) dragStart_.push_back({s, p->value});
        if (const Plane* pl = reg.tryGet<Plane>(s)) planeStart_.push_back({s, pl->offset});
        if (reg.has<Box>(s) || reg.has<Polygon>(s) || reg.has<Capsule>(s) || reg.has<Chain>(s) || reg.has<Shapes>(s) ||
            reg.has<Angle>(s)) {
            const Angle* a = reg.tryGet<Angle>(s);
            angleStart_.push_back({s, a ? a->value : 0.0});
        }
    }
    drag_ = tool == Tool::Rotate ? Drag::Rotate : Drag::Move;
}

void Editor::dragMove(Vec2 world) {
    Vec2 offset = world - dragStartWorld_;
    // Snap the grabbed entity's position to the grid; the rest keep
    // their offsets to it.
    for (const auto& [ent, start] : dragStart_)
        if (ent == dragPrimary_) offset = snapped(start + offset) - start;
    if (offset == Vec2{}) return;
    applyEdit("move", [&](Scene& s) {
        for (const auto& [ent, start] : dragStart_)
            if (Position* p = s.registry.tryGet<Position>(ent)) p->value = start + offset;
        for (const auto& [ent, off0] : planeStart_)
            if (Plane* pl = s.registry.tryGet<Plane>(ent)) pl->offset = off0 + dot(pl->normal, offset);
        return true;
    }, dragKey_);
}

void Editor::dragRotate(Vec2 world) {
    const Registry& reg = doc.scene.registry;
    const Position* p = reg.tryGet<Position>(dragPrimary_);
    if (!p) return;
    const Vec2 a = dragStartWorld_ - p->value, b = world - p->value;
    double delta = std::atan2(cross(a, b), dot(a, b));
    if (snap) delta = std::round(delta / (std::numbers::pi / 12.0)) * (std::numbers::pi / 12.0);  // 15 degrees
    applyEdit("rotate", [&](Scene& s) {
        for (const auto& [ent, start] : angleStart_) s.registry.emplace(ent, Angle{start + delta});
        return !angleStart_.empty();
    }, dragKey_);
}

void Editor::releaseBoxSelect(Vec2 px) {
    if (length(px - dragStartPx_) < 3.0) return;  // a click on empty space: selection already cleared
    std::vector<Entity> inside = entitiesInRect(doc.scene, dragStartWorld_, view.toWorld(px));
    if (additive_) {
        for (Entity ent : inside)
            if (std::find(selection.begin(), selection.end(), ent) == selection.end()) selection.push_back(ent);
    } else {
        selection = std::move(inside);
    }
}

} // namespace stepwise::editor
