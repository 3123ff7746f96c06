#include "app/editor.hpp"

#include "app/scene_edit.hpp"

#include "stepwise/components.hpp"

// The Spring and Joint tools: a first click on a body, a second on another
// body or on empty space (an anchor, or the world).

namespace stepwise::editor {

void Editor::pressSpring(const ToolPress& press) {
    const Vec2 world = press.world;
    const Entity hit = press.hit;
    const Registry& reg = doc.scene.registry;
    if (springStart_.isNull()) {
        if (!hit.isNull() && isBody(reg, hit)) {
            springStart_ = hit;
            note("spring: click a second body, or empty space for an anchor (Esc cancels)");
        } else {
            note("spring: click a body first");
        }
        return;
    }
    const Entity a = springStart_;
    springStart_ = {};
    Entity created;
    const bool toBody = !hit.isNull() && hit != a && isBody(reg, hit);
    const Vec2 anchor = snapped(world);
    if (applyEdit("place spring", [&](Scene& s) {
            created = toBody ? addSpring(s, a, hit) : addAnchoredSpring(s, a, anchor);
            return true;
        }))
        selection = {created};
}

void Editor::pressJoint(const ToolPress& press) {
    const Vec2 world = press.world;
    const Entity hit = press.hit;
    const Registry& reg = doc.scene.registry;
    // First click: body a. Second click: body b, or empty space for
    // the world; the second click's point is the anchor (for
    // distance and rope, b's end: a's end is its centre).
    if (springStart_.isNull()) {
        if (!hit.isNull() && isBody(reg, hit)) {
            springStart_ = hit;
            note("joint: click a second body, or empty space to join to the world (Esc cancels)");
        } else {
            note("joint: click a body first");
        }
        return;
    }
    const Entity a = springStart_;
    springStart_ = {};
    const Entity b = !hit.isNull() && hit != a && isBody(reg, hit) ? hit : Entity{};
    Entity created;
    std::string problem;
    if (applyEdit("place " + jointType + " joint", [&](Scene& s) {
            created = addJoint(s, jointType, a, b, snapped(world), &problem);
            return !created.isNull();
        }))
        selection = {created};
    else if (!problem.empty())
        note("joint refused: " + problem);
}

} // namespace stepwise::editor
