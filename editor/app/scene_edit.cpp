#include "app/scene_edit.hpp"

#include "generated_scenes.hpp"

#include "stepwise/scene_io.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <type_traits>
#include <unordered_map>
#include <unordered_set>

namespace stepwise::editor {


FieldValue readField(const FieldInfo& field, const void* component) {
    const void* at = field.address(const_cast<void*>(component));
    switch (field.kind) {
    case FieldKind::Number: return *static_cast<const double*>(at);
    case FieldKind::Integer: return *static_cast<const int*>(at);
    case FieldKind::Bits: return *static_cast<const std::uint32_t*>(at);
    case FieldKind::OptionalNumber: return *static_cast<const std::optional<double>*>(at);
    case FieldKind::Vector: return *static_cast<const Vec2*>(at);
    case FieldKind::OptionalVector: return *static_cast<const std::optional<Vec2>*>(at);
    case FieldKind::Color: return *static_cast<const Rgb*>(at);
    case FieldKind::Bool: return *static_cast<const bool*>(at);
    case FieldKind::VectorList: return *static_cast<const std::vector<Vec2>*>(at);
    case FieldKind::ShapeList: return *static_cast<const std::vector<CompoundShape>*>(at);
    case FieldKind::IntegerList: return *static_cast<const std::vector<int>*>(at);
    case FieldKind::String: return *static_cast<const std::string*>(at);
    case FieldKind::EntityRef: return *static_cast<const Entity*>(at);
    }
    return 0.0;
}

void writeField(const FieldInfo& field, void* component, const FieldValue& value) {
    void* at = field.address(component);
    std::visit(
        [&](const auto& v) {
            using V = std::decay_t<decltype(v)>;
            // The kind decides the member's type; a mismatched value is a
            // programmer error in the caller and is ignored here.
            const bool matches =
                (std::is_same_v<V, double> && field.kind == FieldKind::Number) ||
                (std::is_same_v<V, int> && field.kind == FieldKind::Integer) ||
                (std::is_same_v<V, std::uint32_t> && field.kind == FieldKind::Bits) ||
                (std::is_same_v<V, std::optional<double>> && field.kind == FieldKind::OptionalNumber) ||
                (std::is_same_v<V, Vec2> && field.kind == FieldKind::Vector) ||
                (std::is_same_v<V, std::optional<Vec2>> && field.kind == FieldKind::OptionalVector) ||
                (std::is_same_v<V, Rgb> && field.kind == FieldKind::Color) ||
                (std::is_same_v<V, bool> && field.kind == FieldKind::Bool) ||
                (std::is_same_v<V, std::vector<Vec2>> && field.kind == FieldKind::VectorList) ||
                (std::is_same_v<V, std::vector<CompoundShape>> && field.kind == FieldKind::ShapeList) ||
                (std::is_same_v<V, std::vector<int>> && field.kind == FieldKind::IntegerList) ||
                (std::is_same_v<V, std::string> && field.kind == FieldKind::String) ||
                (std::is_same_v<V, Entity> && field.kind == FieldKind::EntityRef);
            if (matches) *static_cast<V*>(at) = v;
        },
        value);
}

bool valueFitsKind(const FieldInfo& field, const FieldValue& value) {
    return std::visit(
        [&](const auto& v) {
            using V = std::decay_t<decltype(v)>;
            switch (field.kind) {
            case FieldKind::Number: return std::is_same_v<V, double>;
            case FieldKind::Integer: return std::is_same_v<V, int>;
            case FieldKind::Bits: return std::is_same_v<V, std::uint32_t>;
            case FieldKind::OptionalNumber: return std::is_same_v<V, std::optional<double>>;
            case FieldKind::Vector: return std::is_same_v<V, Vec2>;
            case FieldKind::OptionalVector: return std::is_same_v<V, std::optional<Vec2>>;
            case FieldKind::Color: return std::is_same_v<V, Rgb>;
            case FieldKind::Bool: return std::is_same_v<V, bool>;
            case FieldKind::VectorList: return std::is_same_v<V, std::vector<Vec2>>;
            case FieldKind::ShapeList: return std::is_same_v<V, std::vector<CompoundShape>>;
            case FieldKind::IntegerList: return std::is_same_v<V, std::vector<int>>;
            case FieldKind::String: return std::is_same_v<V, std::string>;
            case FieldKind::EntityRef: return std::is_same_v<V, Entity>;
            }
            return false;
        },
        value);
}

std::optional<Error> checkField(const FieldInfo& field, const FieldValue& value) {
    if (!valueFitsKind(field, value)) return Error{std::string(field.key) + ": a value of the wrong type for this field"};
    // The loader's own check (fieldValueProblem), so a value refused in a
    // file is refused here in the same words.
    const std::optional<Error> problem =
        std::visit([&](const auto& v) { return fieldValueProblem(field, &v); }, value);
    if (!problem) return std::nullopt;
    return Error{std::string(field.key) + ": " + problem->message};
}

std::optional<Error> setWorldField(Scene& scene, const WorldFieldInfo& info, const FieldValue& value) {
    if (std::optional<Error> why = checkField(info.field, value)) return Error{"world." + why->message};
    writeField(info.field, &scene.world, value);
    return std::nullopt;
}

namespace {

/// "component.field" ("velocity" for an inline component).
std::string fieldPath(const ComponentInfo& component, std::string_view key) {
    std::string out(component.name);
    if (!key.empty()) {
        out += '.';
        out += key;
    }
    return out;
}

/// A component finish() refusal as "component.field: why".
std::string finishMessage(const ComponentInfo& component, const Error& why) {
    return fieldPath(component, why.where) + ": " + why.message;
}

} // namespace

std::string fieldPathName(const ComponentInfo& component, std::string_view key) { return fieldPath(component, key); }

std::string describeRefusal(const Scene& scene, const std::string& problem, const std::string& context) {
    static constexpr std::string_view kPrefix = "/entities/";
    if (problem.rfind(kPrefix, 0) != 0) return problem;
    const std::size_t colon = problem.find(": ");
    const std::string pointer = problem.substr(0, colon);
    const std::string message = colon == std::string::npos ? std::string() : problem.substr(colon + 2);
    const std::size_t indexEnd = pointer.find('/', kPrefix.size());
    const std::string digits = pointer.substr(kPrefix.size(), indexEnd == std::string::npos ? std::string::npos
                                                                                            : indexEnd - kPrefix.size());
    const std::size_t index = digits.empty() ? 0 : std::size_t(std::stoull(digits));
    std::string where = indexEnd == std::string::npos ? context : pointer.substr(indexEnd + 1);
    std::replace(where.begin(), where.end(), '/', '.');
    const auto& entities = scene.registry.entities();
    const std::string who = index < entities.size() ? displayName(scene.registry, entities[index])
                                                    : "entity " + std::to_string(index);
    return "\"" + who + "\"" + (where.empty() ? std::string() : " " + where) + ": " + message;
}

std::optional<Error> checkEdited(Scene& scene, const std::vector<Entity>& entities, const std::string& context) {
    Registry& reg = scene.registry;
    for (Entity e : entities) {
        if (!reg.alive(e)) continue;
        for (const ComponentInfo& info : componentTable()) {
            void* c = info.get(reg, e);
            if (!c) continue;
            for (const FieldInfo& f : info.fields)
                if (std::optional<Error> why = checkField(f, readField(f, c)))
                    return Error{"\"" + displayName(reg, e) + "\" " + fieldPath(info, f.key) + why->message.substr(f.key.size())};
            if (info.finish)
                if (std::optional<Error> why = info.finish(c))
                    return Error{"\"" + displayName(reg, e) + "\" " + finishMessage(info, *why)};
        }
    }
    if (std::optional<Error> problem = checkSceneRelations(scene)) return Error{describeRefusal(scene, problem->message, context)};
    return std::nullopt;
}

namespace {

/// Static and kinematic exclude each other: turning one on for `entities`
/// turns the other off in the same edit, and returns the entities it turned
/// off (for a rollback). Two edits in either order would not do: a static
/// chain unticked first is a chain on a dynamic body, ticked kinematic
/// first is both, and the loader refuses each.
std::vector<Entity> turnOffOtherBodyKind(Scene& scene, std::string_view turnedOn, const std::vector<Entity>& entities) {
    std::vector<Entity> off;
    Registry& reg = scene.registry;
    for (Entity e : entities) {
        if (turnedOn == "kinematic" && reg.has<Kinematic>(e) && reg.tryGet<Kinematic>(e)->value && reg.has<Static>(e) &&
            reg.tryGet<Static>(e)->value) {
            reg.tryGet<Static>(e)->value = false;
            off.push_back(e);
        } else if (turnedOn == "static" && reg.has<Static>(e) && reg.tryGet<Static>(e)->value && reg.has<Kinematic>(e) &&
                   reg.tryGet<Kinematic>(e)->value) {
            reg.tryGet<Kinematic>(e)->value = false;
            off.push_back(e);
        }
    }
    return off;
}

void turnBackOn(Scene& scene, std::string_view turnedOn, const std::vector<Entity>& off) {
    for (Entity e : off) {
        if (turnedOn == "kinematic") scene.registry.tryGet<Static>(e)->value = true;
        else scene.registry.tryGet<Kinematic>(e)->value = true;
    }
}

} // namespace

Result<std::size_t> setFieldOnAll(Scene& scene, const ComponentInfo& component, const FieldInfo& field,
                                  const FieldValue& value, const std::vector<Entity>& entities) {
    // Write, check the way the loader would, and put the old values back
    // on a refusal: the scene is never left in a state a file could not hold.
    std::vector<std::pair<Entity, FieldValue>> old;
    for (Entity e : entities) {
        void* c = component.get(scene.registry, e);
        if (!c) continue;
        old.emplace_back(e, readField(field, c));
        writeField(field, c, value);
    }
    if (old.empty()) return 0;
    std::vector<Entity> touched;
    for (const auto& [e, v] : old) touched.push_back(e);
    const std::vector<Entity> off = turnOffOtherBodyKind(scene, component.name, touched);
    // Springs and joints that point at a touched entity are checked too.
    for (Entity s : attachedTo(scene.registry, touched)) touched.push_back(s);
    if (std::optional<Error> why = checkEdited(scene, touched, fieldPath(component, field.key))) {
        std::string message = why->message;
        // A component's own check names the field it finds wrong, which can
        // be another one than the field edited (upper set below lower is
        // reported on lower): the message then starts with the edited field.
        if (!checkField(field, value) && component.finish)
            for (const auto& [e, v] : old)
                if (std::optional<Error> own = component.finish(component.get(scene.registry, e));
                    own && !own->where.empty() &&
                    own->where.substr(0, own->where.find_first_of("/.")) != field.key) {
                    message = "\"" + displayName(scene.registry, e) + "\" " + fieldPath(component, field.key) +
                              ": conflicts with " + finishMessage(component, *own);
                    break;
                }
        for (const auto& [e, v] : old) writeField(field, component.get(scene.registry, e), v);
        turnBackOn(scene, component.name, off);
        return Error{message};
    }
    return old.size();
}

Result<std::size_t> addComponentToAll(Scene& scene, const ComponentInfo& component,
                                      const std::vector<Entity>& entities) {
    std::vector<Entity> added;
    for (Entity e : entities)
        if (scene.registry.alive(e) && !component.has(scene.registry, e)) {
            component.emplaceDefault(scene.registry, e);
            added.push_back(e);
        }
    const std::vector<Entity> off = turnOffOtherBodyKind(scene, component.name, added);
    if (std::optional<Error> why = checkEdited(scene, added, std::string(component.name))) {
        for (Entity e : added) component.remove(scene.registry, e);
        turnBackOn(scene, component.name, off);
        return *why;
    }
    return added.size();
}

Result<std::size_t> removeComponentFromAll(Scene& scene, const ComponentInfo& component,
                                           const std::vector<Entity>& entities) {
    // Removal is checked on a copy of what goes: a body that loses its
    // position while it keeps a velocity would not load.
    std::vector<Entity> from;
    for (Entity e : entities)
        if (component.has(scene.registry, e)) from.push_back(e);
    if (from.empty()) return 0;
    Scene trial = scene;
    for (Entity e : from) component.remove(trial.registry, e);
    std::vector<Entity> touched = from;
    for (Entity s : attachedTo(trial.registry, from)) touched.push_back(s);
    if (std::optional<Error> why = checkEdited(trial, touched, std::string(component.name))) return *why;
    std::size_t n = 0;
    for (Entity e : from) n += component.remove(scene.registry, e) ? 1 : 0;
    return n;
}


Entity findByName(const Registry& registry, std::string_view name) {
    if (name.empty()) return {};
    for (Entity e : registry.entities())
        if (const Name* n = registry.tryGet<Name>(e); n && n->value == name) return e;
    return {};
}

NameAllocator::NameAllocator(const Registry& registry) {
    for (Entity e : registry.entities())
        if (const Name* n = registry.tryGet<Name>(e)) used_.insert(n->value);
}

std::string NameAllocator::take(const std::string& base) {
    if (used_.insert(base).second) return base;
    // "ball_3" -> stem "ball" so copies of copies count on, not "ball_3_2".
    std::string stem = base;
    if (const auto u = stem.rfind('_'); u != std::string::npos && u + 1 < stem.size() &&
                                        std::all_of(stem.begin() + std::ptrdiff_t(u) + 1, stem.end(), ::isdigit))
        stem.resize(u);
    int& next = nextNumber_.try_emplace(stem, 2).first->second;
    for (;; ++next) {
        std::string candidate = stem + "_" + std::to_string(next);
        if (used_.insert(candidate).second) {
            ++next;
            return candidate;
        }
    }
}

std::string uniqueName(const Registry& registry, const std::string& base) { return NameAllocator(registry).take(base); }

std::string displayName(const Registry& registry, Entity e) {
    if (const Name* n = registry.tryGet<Name>(e); n && !n->value.empty()) return n->value;
    const auto& order = registry.entities();
    const auto it = std::find(order.begin(), order.end(), e);
    return "entity " + std::to_string(it - order.begin());
}

std::string_view entityKind(const Registry& registry, Entity e) {
    if (registry.has<Spring>(e)) return "spring";
    if (registry.has<Joint>(e)) return "joint";
    if (registry.has<Plane>(e)) return "wall";
    if (registry.has<Box>(e)) return "box";
    if (registry.has<Radius>(e)) return "circle";
    if (registry.has<Polygon>(e)) return "polygon";
    if (registry.has<Capsule>(e)) return "capsule";
    if (registry.has<Shapes>(e)) return "compound";
    if (registry.has<Chain>(e)) return "chain";
    if (registry.has<Attractor>(e)) return "attractor";
    if (registry.has<Boid>(e)) return "boid";
    if (registry.has<Emitter>(e)) return "emitter";
    return "point";
}

bool isBody(const Registry& registry, Entity e) { return registry.has<Position>(e) && !registry.has<Spring>(e); }

namespace {

double distanceToSegment(Vec2 p, Vec2 a, Vec2 b) {
    const Vec2 ab = b - a;
    const double l2 = lengthSquared(ab);
    const double t = l2 > 0.0 ? std::clamp(dot(p - a, ab) / l2, 0.0, 1.0) : 0.0;
    return length(p - (a + t * ab));
}

/// Spring end points (metres); false when an end cannot be found.
bool springEnds(const Registry& reg, const Spring& s, Vec2& pa, Vec2& pb) {
    const Position* A = reg.tryGet<Position>(s.a);
    if (!A) return false;
    pa = A->value;
    if (s.anchor) {
        pb = *s.anchor;
        return true;
    }
    const Position* B = reg.tryGet<Position>(s.b);
    if (!B) return false;
    pb = B->value;
    return true;
}

} // namespace

Entity pick(const Scene& scene, Vec2 world, double pickRadius) {
    const Registry& reg = scene.registry;
    const auto& order = reg.entities();
    // Bodies first (topmost = drawn last), then springs, then planes: a
    // plane under a body should not steal its clicks.
    for (auto it = order.rbegin(); it != order.rend(); ++it) {
        const Entity e = *it;
        const Position* p = reg.tryGet<Position>(e);
        if (!p || reg.has<Spring>(e) || reg.has<Chain>(e)) continue;
        const Vec2 d = world - p->value;
        if (const Radius* r = reg.tryGet<Radius>(e)) {
            if (length(d) <= r->value) return e;
        } else if (const Box* b = reg.tryGet<Box>(e)) {
            const Angle* a = reg.tryGet<Angle>(e);
            const double th = a ? a->value : 0.0;
            // Rotate the offset into the box frame.
            const double lx = std::cos(th) * d.x + std::sin(th) * d.y;
            const double ly = -std::sin(th) * d.x + std::cos(th) * d.y;
            if (std::abs(lx) <= 0.5 * b->width && std::abs(ly) <= 0.5 * b->height) return e;
        } else if (const Polygon* poly = reg.tryGet<Polygon>(e)) {
            const Angle* a = reg.tryGet<Angle>(e);
            const double th = a ? a->value : 0.0;
            const Vec2 local{std::cos(th) * d.x + std::sin(th) * d.y, -std::sin(th) * d.x + std::cos(th) * d.y};
            // Inside a counter-clockwise convex outline: left of every edge.
            bool inside = poly->vertices.size() >= 3;
            for (std::size_t i = 0; inside && i < poly->vertices.size(); ++i) {
                const Vec2 v0 = poly->vertices[i], v1 = poly->vertices[(i + 1) % poly->vertices.size()];
                inside = cross(v1 - v0, local - v0) >= 0.0;
            }
            // A rounded polygon reaches its radius beyond the outline.
            if (const double r = poly->radius.value_or(0.0); !inside && r > 0.0)
                for (std::size_t i = 0; !inside && i < poly->vertices.size(); ++i)
                    inside = distanceToSegment(local, poly->vertices[i],
                                               poly->vertices[(i + 1) % poly->vertices.size()]) <= r;
            if (inside) return e;
        } else if (const Capsule* cap = reg.tryGet<Capsule>(e)) {
            const Angle* a = reg.tryGet<Angle>(e);
            const double th = a ? a->value : 0.0;
            const Vec2 local{std::cos(th) * d.x + std::sin(th) * d.y, -std::sin(th) * d.x + std::cos(th) * d.y};
            if (distanceToSegment(local, cap->a, cap->b) <= cap->radius) return e;
        } else if (const Shapes* shapes = reg.tryGet<Shapes>(e)) {
            // A compound body is picked by any of its shapes.
            const Angle* a = reg.tryGet<Angle>(e);
            const double th = a ? a->value : 0.0;
            const Vec2 local{std::cos(th) * d.x + std::sin(th) * d.y, -std::sin(th) * d.x + std::cos(th) * d.y};
            for (const CompoundShape& s : shapes->items)
                if (compoundShapeContains(s, local)) return e;
        } else if (length(d) <= pickRadius) {
            return e;
        }
    }
    // Chains by distance to their polyline: they are lines, and bodies
    // resting on them take the clicks inside themselves first.
    for (auto it = order.rbegin(); it != order.rend(); ++it) {
        const Chain* chain = reg.tryGet<Chain>(*it);
        const Position* p = reg.tryGet<Position>(*it);
        if (!chain || !p || chain->points.size() < 2) continue;
        const Angle* a = reg.tryGet<Angle>(*it);
        const double th = a ? a->value : 0.0;
        const Vec2 d = world - p->value;
        const Vec2 local{std::cos(th) * d.x + std::sin(th) * d.y, -std::sin(th) * d.x + std::cos(th) * d.y};
        const std::size_t n = chain->points.size(), segments = chain->loop ? n : n - 1;
        for (std::size_t k = 0; k < segments; ++k)
            if (distanceToSegment(local, chain->points[k], chain->points[(k + 1) % n]) <= pickRadius) return *it;
    }
    for (auto it = order.rbegin(); it != order.rend(); ++it)
        if (const Spring* s = reg.tryGet<Spring>(*it)) {
            Vec2 a, b;
            if (springEnds(reg, *s, a, b) && distanceToSegment(world, a, b) <= pickRadius) return *it;
        }
    for (auto it = order.rbegin(); it != order.rend(); ++it)
        if (const Plane* pl = reg.tryGet<Plane>(*it))
            if (std::abs(dot(pl->normal, world) - pl->offset) <= pickRadius) return *it;
    return {};
}

std::vector<Entity> entitiesInRect(const Scene& scene, Vec2 cornerA, Vec2 cornerB) {
    const Vec2 lo{std::min(cornerA.x, cornerB.x), std::min(cornerA.y, cornerB.y)};
    const Vec2 hi{std::max(cornerA.x, cornerB.x), std::max(cornerA.y, cornerB.y)};
    auto inside = [&](Vec2 p) { return p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y; };
    std::vector<Entity> out;
    const Registry& reg = scene.registry;
    for (Entity e : reg.entities()) {
        if (const Spring* s = reg.tryGet<Spring>(e)) {
            Vec2 a, b;
            if (springEnds(reg, *s, a, b) && inside(0.5 * (a + b))) out.push_back(e);
        } else if (const Position* p = reg.tryGet<Position>(e); p && inside(p->value)) {
            out.push_back(e);
        }
    }
    return out;
}

std::vector<Entity> springsAttachedTo(const Registry& registry, Entity e) {
    std::vector<Entity> out;
    if (e.isNull()) return out;
    for (Entity s : registry.entities())
        if (const Spring* sp = registry.tryGet<Spring>(s); sp && (sp->a == e || sp->b == e)) out.push_back(s);
    return out;
}

std::vector<Entity> attachedTo(const Registry& registry, const std::vector<Entity>& entities) {
    std::unordered_set<Entity> targets(entities.begin(), entities.end());
    std::vector<Entity> out;
    for (Entity s : registry.entities()) {
        if (targets.count(s)) continue;
        bool attached = false;
        forEachEntityRef(registry, s, [&](const ComponentInfo&, const FieldInfo&, Entity ref) {
            attached = attached || (!ref.isNull() && targets.count(ref) != 0);
        });
        if (attached) out.push_back(s);
    }
    return out;
}

std::size_t destroyWithSprings(Scene& scene, const std::vector<Entity>& entities) {
    // A deleted emitter's copies alive stay, as the designer's own bodies:
    // their names lose the '#' (as a pasted copy's do), or another emitter
    // of the template would find names it gives that no run has alive.
    std::unordered_set<std::string> orphaned;
    for (const Entity e : entities)
        if (const Emitter* em = scene.registry.alive(e) ? scene.registry.tryGet<Emitter>(e) : nullptr)
            for (const int k : copyNumbers(*em)) orphaned.insert(em->templateName + "#" + std::to_string(k));
    if (!orphaned.empty()) {
        NameAllocator names(scene.registry);
        for (const Entity e : scene.registry.entities()) {
            Name* n = scene.registry.tryGet<Name>(e);
            if (!n || !orphaned.contains(n->value.substr(0, n->value.find('/')))) continue;
            std::string base = n->value;
            std::replace(base.begin(), base.end(), '#', ' ');
            n->value = names.take(base);
        }
    }
    std::vector<Entity> doomed = entities;
    for (Entity s : attachedTo(scene.registry, entities)) doomed.push_back(s);
    std::size_t count = 0;
    for (Entity e : doomed) count += scene.registry.destroy(e) ? 1 : 0;  // duplicates are stale the second time
    return count;
}

std::vector<Entity> cloneEntities(const Registry& src, const std::vector<Entity>& entities, Scene& dst, Vec2 offset,
                                  OutsideRefs outside) {
    std::vector<Entity> created;
    std::unordered_map<Entity, Entity> copyOf;  // source handle -> its copy
    NameAllocator names(dst.registry);  // before the copies exist, so they do not see themselves
    // A whole template pasted (every body of it) is a template of its own,
    // named like an entity ("doll_2"), and a pasted emitter of it copies
    // the new one: else the pasted bodies would join the template and the
    // copies alive, made without them, would no longer match it. Some of a
    // template's bodies pasted join it (a designer adding a part).
    std::unordered_map<std::string, std::size_t> partsOf;
    std::map<std::string, std::size_t> partsCloned;  // in name order: the new names do not hang on hashing
    for (Entity e : src.entities())
        if (const Template* t = src.tryGet<Template>(e)) ++partsOf[t->value];
    const std::unordered_set<Entity> cloned(entities.begin(), entities.end());
    for (Entity e : cloned)
        if (const Template* t = src.alive(e) ? src.tryGet<Template>(e) : nullptr) ++partsCloned[t->value];
    std::unordered_set<std::string> templateNames;
    const Registry& existing = dst.registry;  // read only: nothing there changes
    for (Entity e : existing.entities())
        if (const Template* t = existing.tryGet<Template>(e)) templateNames.insert(t->value);
    NameAllocator templates(std::move(templateNames));
    std::unordered_map<std::string, std::string> templateOf;  // source template name -> the copies'
    for (const auto& [name, count] : partsCloned)
        templateOf.emplace(name, count == partsOf[name] ? templates.take(name) : name);
    for (Entity e : entities) {
        if (!src.alive(e)) continue;
        const Entity c = dst.registry.create();
        copyComponents(src, e, dst.registry, c);
        if (Name* n = dst.registry.tryGet<Name>(c)) {
            // '#' marks what an emitter made ("doll#3/head"): a pasted or
            // duplicated copy is the designer's own body, which the run would
            // otherwise take for one of the emitter's and drop.
            std::string base = n->value.empty() ? std::string("entity") : n->value;
            std::replace(base.begin(), base.end(), '#', ' ');
            n->value = names.take(base);
        }
        if (Template* t = dst.registry.tryGet<Template>(c)) t->value = templateOf.at(t->value);
        if (Emitter* em = dst.registry.tryGet<Emitter>(c)) {
            if (auto it = templateOf.find(em->templateName); it != templateOf.end()) em->templateName = it->second;
            // A new emitter: it has made nothing yet.
            em->next.reset();
            em->emitted = em->alive = 0;
            em->oldest.reset();
            em->copies.clear();
        }
        if (Position* p = dst.registry.tryGet<Position>(c)) p->value += offset;
        if (Plane* pl = dst.registry.tryGet<Plane>(c)) pl->offset += dot(pl->normal, offset);
        if (Spring* s = dst.registry.tryGet<Spring>(c); s && s->anchor) *s->anchor += offset;  // moves with the copy
        if (Joint* j = dst.registry.tryGet<Joint>(c); j && j->b.isNull()) j->localB += offset;  // a world anchor too
        copyOf.emplace(e, c);
        created.push_back(c);
    }
    // References follow their targets when those were copied too; others
    // keep pointing at the original (or are cut when that cannot be reached
    // from `dst`), and whatever is left without a valid end goes.
    std::vector<Entity> kept;
    for (Entity c : created) {
        bool valid = true;
        forEachEntityRefMutable(dst.registry, c, [&](const ComponentInfo&, const FieldInfo&, Entity& ref) {
            if (ref.isNull()) return;
            if (auto it = copyOf.find(ref); it != copyOf.end()) ref = it->second;
            else if (outside == OutsideRefs::Drop) ref = Entity{};
            valid = valid && !ref.isNull();
        });
        kept.push_back(c);
        if (!valid) kept.pop_back();
    }
    for (Entity c : created)
        if (std::find(kept.begin(), kept.end(), c) == kept.end()) dst.registry.destroy(c);
    // A kept reference to an outside entity must still reach a body of dst.
    if (outside == OutsideRefs::Carry) return kept;
    std::vector<Entity> out;
    for (Entity c : kept) {
        bool valid = true;
        forEachEntityRef(dst.registry, c, [&](const ComponentInfo&, const FieldInfo&, Entity ref) {
            valid = valid && (ref.isNull() || (dst.registry.alive(ref) && dst.registry.has<Position>(ref)));
        });
        if (valid) out.push_back(c);
        else dst.registry.destroy(c);
    }
    return out;
}

namespace {
Entity newBody(Scene& scene, const std::string& base, Vec2 at, Rgb color) {
    Registry& reg = scene.registry;
    const std::string name = uniqueName(reg, base);
    const Entity e = reg.create();
    reg.emplace(e, Name{name});
    reg.emplace(e, Position{at});
    reg.emplace(e, Velocity{});
    reg.emplace(e, Mass{1.0});
    reg.emplace(e, Color{color});
    return e;
}
} // namespace

Entity addCircle(Scene& scene, Vec2 at, double radius) {
    const Entity e = newBody(scene, "circle", at, Rgb{0.35, 0.65, 0.95});
    scene.registry.emplace(e, Radius{radius});
    return e;
}

std::vector<Vec2> convexHull(std::vector<Vec2> points) {
    // Andrew's monotone chain: sort by x then y, build the lower and upper
    // chains, dropping points that do not turn left (so collinear and
    // repeated points vanish). Counter-clockwise from the leftmost point.
    std::sort(points.begin(), points.end(), [](Vec2 a, Vec2 b) { return a.x != b.x ? a.x < b.x : a.y < b.y; });
    points.erase(std::unique(points.begin(), points.end()), points.end());
    if (points.size() < 3) return points;
    std::vector<Vec2> hull(2 * points.size());
    std::size_t k = 0;
    for (const Vec2 p : points) {
        while (k >= 2 && cross(hull[k - 1] - hull[k - 2], p - hull[k - 2]) <= 0.0) --k;
        hull[k++] = p;
    }
    for (std::size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {
        const Vec2 p = points[i];
        while (k >= lower && cross(hull[k - 1] - hull[k - 2], p - hull[k - 2]) <= 0.0) --k;
        hull[k++] = p;
    }
    hull.resize(k - 1);  // the last point repeats the first
    return hull;
}

std::vector<Vec2> regularPolygon(int sides, double radius, double angle) {
    std::vector<Vec2> v;
    for (int i = 0; i < sides; ++i) {
        const double a = angle + 2.0 * std::numbers::pi * double(i) / double(sides);
        v.push_back({radius * std::cos(a), radius * std::sin(a)});
    }
    return v;
}

Result<Entity> addPolygon(Scene& scene, const std::vector<Vec2>& worldVertices) {
    // The position is the centroid, so the centre of mass is the position
    // and the outline is stored about it.
    if (std::optional<Error> why = polygonProblem(worldVertices)) return Error{"polygon: " + why->message};
    const Vec2 centroid = polygonMassProperties(worldVertices).centroid;
    Polygon poly;
    poly.vertices.clear();
    for (const Vec2 v : worldVertices) poly.vertices.push_back(v - centroid);
    if (std::optional<Error> why = polygonProblem(poly.vertices))  // rounding can merge tiny edges
        return Error{"polygon: " + why->message};
    const Entity e = newBody(scene, "polygon", centroid, Rgb{0.62, 0.55, 0.95});
    scene.registry.emplace(e, std::move(poly));
    scene.registry.emplace(e, Angle{0.0});
    return e;
}

Entity addBox(Scene& scene, Vec2 at, double width, double height) {
    const Entity e = newBody(scene, "box", at, Rgb{0.95, 0.6, 0.3});
    scene.registry.emplace(e, Box{width, height});
    scene.registry.emplace(e, Angle{0.0});
    return e;
}

Entity addPlane(Scene& scene, Vec2 through, Vec2 normal) {
    const double l = length(normal);
    const Vec2 n = l > 0.0 && std::isfinite(l) ? normal / l : Vec2{0.0, 1.0};
    Registry& reg = scene.registry;
    const Entity e = reg.create();
    reg.emplace(e, Name{uniqueName(reg, "wall")});
    reg.emplace(e, Plane{n, dot(n, through)});
    reg.emplace(e, Color{Rgb{0.55, 0.58, 0.62}});
    return e;
}

Scene benchScene(int bodies) {
    Scene s;
    s.view = View{{0.0, 10.0}, 30.0};
    const int columns = int(std::ceil(std::sqrt(double(bodies) * 1.6)));
    addPlane(s, {0.0, 0.0}, {0.0, 1.0});
    addPlane(s, {-0.3 * columns - 1.0, 0.0}, {1.0, 0.0});
    addPlane(s, {0.3 * columns + 1.0, 0.0}, {-1.0, 0.0});
    scenes::CircleGrid grid;
    grid.count = bodies;
    grid.columns = columns;
    grid.first = {-0.3 * columns, 0.5};  // x: the grid's left edge, centred in its cell below
    grid.pitch = {0.6, 0.6};
    grid.centring = 0.3;
    grid.jitter = scenes::Jitter::Lcg;
    grid.jitterAmplitude = 0.025;
    grid.velocityPerJitter = 20.0;
    grid.mass = 1.0;
    grid.namePrefix = "c";
    grid.colours = scenes::CircleColours::Gradient;
    scenes::addCircleGrid(s, grid);
    return s;
}

namespace {
/// A file names a spring's ends: gives an unnamed body a name first.
Entity nameForSpring(Registry& reg, Entity body) {
    if (const Name* n = reg.tryGet<Name>(body); !n || n->value.empty()) reg.emplace(body, Name{uniqueName(reg, "body")});
    return body;
}

/// The palette's spring from body `a` to `other` (a body's name or an
/// anchor point), 50 N/m and 0.5 N s/m, resting at its current length.
Entity addPaletteSpring(Registry& reg, Entity a, Spring s, Vec2 otherEnd) {
    s.a = nameForSpring(reg, a);
    s.k = 50.0;
    s.damping = 0.5;
    s.restLength = length(reg.tryGet<Position>(a)->value - otherEnd);
    const Entity e = reg.create();
    reg.emplace(e, Name{uniqueName(reg, "spring")});
    reg.emplace(e, std::move(s));
    return e;
}
} // namespace

Entity addSpring(Scene& scene, Entity a, Entity b) {
    Registry& reg = scene.registry;
    nameForSpring(reg, a);  // a before b, so unnamed ends become body, body_2 in that order
    Spring s;
    s.b = nameForSpring(reg, b);
    return addPaletteSpring(reg, a, std::move(s), reg.tryGet<Position>(b)->value);
}

Entity addAnchoredSpring(Scene& scene, Entity a, Vec2 anchor) {
    Spring s;
    s.anchor = anchor;
    return addPaletteSpring(scene.registry, a, std::move(s), anchor);
}

Result<Entity> addJoint(Scene& scene, const std::string& type, Entity a, Entity b, Vec2 anchor) {
    Registry& reg = scene.registry;
    const auto isFixed = [&](Entity e) {
        if (e.isNull()) return true;
        const Static* st = reg.tryGet<Static>(e);
        return st && st->value;
    };
    if (isFixed(a) && isFixed(b)) return Error{"a joint needs at least one dynamic body"};
    nameForSpring(reg, a);
    if (!b.isNull()) nameForSpring(reg, b);
    Joint j;
    j.type = type;
    j.a = a;
    j.b = b;
    if (type == "distance" || type == "rope") {
        // a's end at its centre, b's at the click (a world point for the world).
        j.localA = {};
        if (b.isNull()) {
            j.localB = anchor;
        } else {
            const Vec2 d = anchor - reg.tryGet<Position>(b)->value;
            const Angle* an = reg.tryGet<Angle>(b);
            const double t = an ? an->value : 0.0;
            j.localB = {std::cos(t) * d.x + std::sin(t) * d.y, -std::sin(t) * d.x + std::cos(t) * d.y};
        }
    } else {
        j.anchor = anchor;
    }
    if (std::optional<Error> why = completeJoint(reg, j)) return Error{why->text()};
    const Entity e = reg.create();
    reg.emplace(e, Name{uniqueName(reg, "joint")});
    reg.emplace(e, std::move(j));
    return e;
}

Entity addAttractor(Scene& scene, Vec2 at, double mass) {
    Registry& reg = scene.registry;
    const Entity e = reg.create();
    reg.emplace(e, Name{uniqueName(reg, "attractor")});
    reg.emplace(e, Position{at});
    reg.emplace(e, Static{true});
    reg.emplace(e, Mass{mass});
    reg.emplace(e, Attractor{0.1});
    reg.emplace(e, Color{Rgb{1.0, 0.8, 0.2}});
    return e;
}

Entity addBoid(Scene& scene, Vec2 at, Vec2 velocity) {
    const Entity e = newBody(scene, "boid", at, Rgb{0.6, 0.9, 0.6});
    scene.registry.emplace(e, Velocity{velocity});
    scene.registry.emplace(e, Boid{});
    return e;
}

bool entityBounds(const Registry& registry, Entity e, Vec2& lo, Vec2& hi) {
    const Position* p = registry.tryGet<Position>(e);
    if (!p || registry.has<Spring>(e)) return false;
    double rx = 0.0, ry = 0.0;
    if (const Radius* r = registry.tryGet<Radius>(e)) rx = ry = r->value;
    if (const Box* b = registry.tryGet<Box>(e)) {
        // Circumscribed: enough for box select and framing.
        rx = ry = 0.5 * std::hypot(b->width, b->height);
    }
    if (const Polygon* poly = registry.tryGet<Polygon>(e))
        for (const Vec2 v : poly->vertices) rx = ry = std::max(rx, length(v) + poly->radius.value_or(0.0));  // any angle
    if (const Capsule* cap = registry.tryGet<Capsule>(e))
        rx = ry = std::max(length(cap->a), length(cap->b)) + cap->radius;  // any angle
    if (const Shapes* shapes = registry.tryGet<Shapes>(e))
        for (const CompoundShape& s : shapes->items) {
            const ShapeOutline outline = compoundShapeOutline(s);
            for (const Vec2 v : outline.points) rx = ry = std::max(rx, length(v) + outline.radius);  // any angle
        }
    if (const Chain* chain = registry.tryGet<Chain>(e))
        for (const Vec2 v : chain->points) rx = ry = std::max(rx, length(v));  // any angle
    lo = {p->value.x - rx, p->value.y - ry};
    hi = {p->value.x + rx, p->value.y + ry};
    return true;
}

} // namespace stepwise::editor
