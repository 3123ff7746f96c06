#include "app/editor.hpp"

#include "app/scene_edit.hpp"

#include "stepwise/components.hpp"

// The Spring and Joint tools: a first click on a body, a second on another
// body or on empty space (an anchor, or the world).

namespace stepwise::editor {

bool Editor::takeFirstEnd(Entity hit, std::string_view toolWord, std::string_view otherwise) {
    if (!springStart_.isNull()) return false;
    const std::string word(toolWord);
    if (!hit.isNull() && isBody(doc.scene.registry, hit)) {
        springStart_ = hit;
        note(word + ": click a second body, or " + std::string(otherwise) + " (Esc cancels)");
    } else {
        note(word + ": click a body first");
    }
    return true;
}

void Editor::pressSpring(const ToolPress& press) {
    const Vec2 world = press.world;
    const Entity hit = press.hit;
    const Registry& reg = doc.scene.registry;
    if (takeFirstEnd(hit, "spring", "empty space for an anchor")) return;
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
    if (takeFirstEnd(hit, "joint", "empty space to join to the world")) return;
    const Entity a = springStart_;
    springStart_ = {};
    const Entity b = !hit.isNull() && hit != a && isBody(reg, hit) ? hit : Entity{};
    Entity created;
    const Result<bool> placed = tryEdit("place " + jointType + " joint", [&](Scene& s) {
        return createdInto(addJoint(s, jointType, a, b, snapped(world)), created);
    });
    if (placed && *placed) selection = {created};
    else if (!placed) note("joint refused: " + placed.error());
}

} // namespace stepwise::editor
