#include "app/collision_pairs.hpp"

#include "stepwise/components.hpp"

#include <utility>

namespace stepwise::editor {

namespace {

bool hasShape(const Registry& reg, Entity e) {
    return reg.has<Radius>(e) || reg.has<Box>(e) || reg.has<Polygon>(e) || reg.has<Capsule>(e) || reg.has<Chain>(e) ||
           reg.has<Plane>(e) || reg.has<Shapes>(e);
}

/// Planes are static; so is a body marked static.
bool isStatic(const Registry& reg, Entity e) {
    if (reg.has<Plane>(e)) return true;
    const Static* s = reg.tryGet<Static>(e);
    return s && s->value;
}

Filter filterOf(const Registry& reg, Entity e) {
    const Filter* f = reg.tryGet<Filter>(e);
    return f ? *f : Filter{};
}

} // namespace

std::vector<ExcludedPartner> excludedPartners(const Scene& scene, Entity of) {
    const Registry& reg = scene.registry;
    std::vector<ExcludedPartner> out;
    if (!reg.alive(of) || !hasShape(reg, of)) return out;
    const Filter mine = filterOf(reg, of);
    // The joints that hold `of` without collide_connected: one pass, so
    // the whole is linear in the scene (the inspector asks every frame).
    std::vector<std::pair<Entity, std::string>> joined;
    for (const Entity j : reg.entities()) {
        const Joint* joint = reg.tryGet<Joint>(j);
        if (!joint || joint->collideConnected || (joint->a != of && joint->b != of)) continue;
        const Name* name = reg.tryGet<Name>(j);
        joined.emplace_back(joint->a == of ? joint->b : joint->a,
                            "joint " + (name ? name->value : std::string("(unnamed)")));
    }
    for (const Entity other : reg.entities()) {
        if (other == of || !hasShape(reg, other) || (isStatic(reg, of) && isStatic(reg, other))) continue;
        if (!shouldCollide(mine, filterOf(reg, other))) {
            out.push_back({other, "filter"});
            continue;
        }
        for (const auto& [partner, reason] : joined)
            if (partner == other) {
                out.push_back({other, reason});
                break;
            }
    }
    return out;
}

} // namespace stepwise::editor
