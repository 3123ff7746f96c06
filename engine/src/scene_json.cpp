// Level files: text -> Scene and Scene -> text, driven by the component
// table. One message per refused file, naming where (JSON Pointer or
// line:column) and what was expected and found.

#include "stepwise/scene_io.hpp"

#include "stepwise/component_table.hpp"
#include "stepwise/components.hpp"
#include "stepwise/world.hpp"
#include "stepwise/world_fields.hpp"

#include "json_reader.hpp"
#include "templates.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <tuple>
#include <unordered_map>
#include <unordered_set>

namespace stepwise {

namespace {

using Json = nlohmann::ordered_json;

/// Thrown inside the walk and caught in parseScene; never escapes.
struct Refusal {
    std::string pointer;  ///< JSON Pointer of the bad value ("" = whole file)
    std::string message;
};

std::string child(const std::string& pointer, std::string_view key) {
    return pointer + "/" + detail::escapePointerToken(key);
}
std::string child(const std::string& pointer, std::size_t index) {
    return pointer + "/" + std::to_string(index);
}

/// How a found value is shown in messages: short, JSON-ish.
std::string describeFound(const Json& v) {
    switch (v.type()) {
    case Json::value_t::object: return v.empty() ? "an empty object" : "an object";
    case Json::value_t::array: return v.empty() ? "an empty array" : "an array";
    case Json::value_t::null: return "null";
    case Json::value_t::number_float:
        if (std::isnan(v.get<double>())) return "NaN";
        if (std::isinf(v.get<double>())) return "an infinite number (out of double range)";
        [[fallthrough]];
    default: {
        std::string s = v.dump();
        if (s.size() > 60) {
            // Cut on a UTF-8 character boundary, never inside a character.
            std::size_t cut = 57;
            while (cut > 0 && (static_cast<unsigned char>(s[cut]) & 0xC0) == 0x80) --cut;
            s = s.substr(0, cut) + "...";
        }
        return s;
    }
    }
}

std::string joinNames(std::span<const std::string_view> names) {
    std::string out;
    for (std::size_t i = 0; i < names.size(); ++i) {
        if (i) out += ", ";
        out += names[i];
    }
    return out;
}

// "unknown X "key"; did you mean "Y"? Known Xs: ..." (or "unknown X "key".
// Known Xs: ..." when nothing is close), one sentence shape for every name.
std::string unknownNameMessage(std::string message, std::string_view key,
                               std::span<const std::string_view> known, std::string_view knownLabel) {
    if (auto guess = closestName(key, known)) message += "; did you mean \"" + std::string(*guess) + "\"?";
    else message += ".";
    return message + " Known " + std::string(knownLabel) + ": " + joinNames(known);
}

[[noreturn]] void refuse(std::string pointer, std::string message) {
    throw Refusal{std::move(pointer), std::move(message)};
}

/// A JSON number in `range`. `expected` (default: `range`) is what a value
/// of the wrong type is told to be: a field's own range, when the range
/// itself is checked later by fieldValueProblem.
double readNumber(const Json& v, const std::string& pointer, const NumberRange& range,
                  const std::optional<NumberRange>& expected = std::nullopt, bool integer = false) {
    if (!v.is_number())
        refuse(pointer, "expected " + expected.value_or(range).describe(integer) + ", got " + describeFound(v));
    const double d = v.get<double>();
    if (!std::isfinite(d)) refuse(pointer, "expected a finite number, got " + describeFound(v));
    if (!range.contains(d)) refuse(pointer, "expected " + range.describe() + ", got " + describeFound(v));
    return d;
}

long readInteger(const Json& v, const std::string& pointer, long min, long max) {
    const std::string expected =
        "an integer in [" + std::to_string(min) + ", " + std::to_string(max) + "]";
    if (!v.is_number()) refuse(pointer, "expected " + expected + ", got " + describeFound(v));
    const double d = v.get<double>();
    if (!std::isfinite(d) || d != std::floor(d) || d < double(min) || d > double(max))
        refuse(pointer, "expected " + expected + ", got " + describeFound(v));
    return long(d);
}

std::string readString(const Json& v, const std::string& pointer) {
    if (!v.is_string()) refuse(pointer, "expected a string, got " + describeFound(v));
    return v.get<std::string>();
}

bool readBool(const Json& v, const std::string& pointer) {
    if (!v.is_boolean()) refuse(pointer, "expected true or false, got " + describeFound(v));
    return v.get<bool>();
}

/// Reads {"x": .., "y": .. [, "z": ..]} with the given axes. A missing axis
/// takes 0, as the course notes' Vector2D::fromJson does.
template <std::size_t N>
std::array<double, N> readAxes(const Json& v, const std::string& pointer, const NumberRange& range,
                               const char* what) {
    static constexpr std::array<std::string_view, 3> kAxes{"x", "y", "z"};
    if (!v.is_object()) refuse(pointer, std::string("expected ") + what + ", got " + describeFound(v));
    std::array<double, N> out{};
    for (const auto& [key, value] : v.items()) {
        const auto it = std::find(kAxes.begin(), kAxes.begin() + N, key);
        if (it == kAxes.begin() + N)
            refuse(child(pointer, key), std::string("unknown key \"") + key + "\" in " + what);
        out[std::size_t(it - kAxes.begin())] = readNumber(value, child(pointer, key), range);
    }
    return out;
}

/// Coordinates and the like are bounded by the level's largest magnitude,
/// velocities by its largest speed; impulses pass NumberRange{} (any finite
/// number).
Vec2 readVector(const Json& v, const std::string& pointer, const NumberRange& range = kAnyMagnitude) {
    const auto a = readAxes<2>(v, pointer, range, "a vector {\"x\": number, \"y\": number}");
    return {a[0], a[1]};
}

Rgb readColor(const Json& v, const std::string& pointer, const NumberRange& range) {
    const auto a = readAxes<3>(v, pointer, range, "a colour {\"x\": r, \"y\": g, \"z\": b} in 0..1");
    return {a[0], a[1], a[2]};
}

/// Entity names of the file being read, to their handles: built before any
/// component is read, so a reference may name an entity further down.
struct EntityNames {
    std::unordered_map<std::string, Entity> byName;
    /// References to names no entity has: "POINTER: message", refused once
    /// every entity is read (so a component's own complaint comes first).
    mutable std::vector<std::string> unresolved;
};

/// The keys of one compound shape's object ("circle": {...} and the rest).
constexpr std::array<std::string_view, 4> kShapeKinds{"circle", "box", "polygon", "capsule"};
constexpr std::array<std::string_view, 9> kShapeItemKeys{"circle",      "box",    "polygon", "capsule", "density",
                                                         "friction",    "restitution", "sensor", "filter"};

/// Reads an object's keys, refusing any not in `known` (what: "a box").
template <std::size_t N, typename Fn>
void readKeys(const Json& v, const std::string& pointer, const std::array<std::string_view, N>& known,
              const std::string& what, Fn&& fn) {
    if (!v.is_object()) refuse(pointer, "expected " + what + " object, got " + describeFound(v));
    for (const auto& [key, value] : v.items()) {
        if (std::find(known.begin(), known.end(), key) == known.end())
            refuse(child(pointer, key), unknownNameMessage("unknown key \"" + key + "\" in " + what, key,
                                                           std::span<const std::string_view>(known), "keys"));
        fn(key, value, child(pointer, key));
    }
}

CompoundShape readCompoundShape(const Json& v, const std::string& pointer) {
    constexpr NumberRange size{kMinSize, kMaxMagnitude, false};
    CompoundShape s;
    int kinds = 0;
    readKeys(v, pointer, kShapeItemKeys, "a compound shape", [&](const std::string& key, const Json& value,
                                                                   const std::string& at) {
        if (key == "circle") {
            ++kinds;
            s.kind = CompoundShape::Kind::Circle;
            readKeys(value, at, std::array<std::string_view, 2>{"center", "radius"}, "a circle",
                     [&](const std::string& k, const Json& fv, const std::string& fa) {
                         if (k == "center") s.center = readVector(fv, fa);
                         else s.radius = readNumber(fv, fa, size);
                     });
        } else if (key == "box") {
            ++kinds;
            s.kind = CompoundShape::Kind::Box;
            readKeys(value, at, std::array<std::string_view, 4>{"center", "width", "height", "angle"}, "a box",
                     [&](const std::string& k, const Json& fv, const std::string& fa) {
                         if (k == "center") s.center = readVector(fv, fa);
                         else if (k == "width") s.width = readNumber(fv, fa, size);
                         else if (k == "height") s.height = readNumber(fv, fa, size);
                         else s.angle = readNumber(fv, fa, kAnyMagnitude);
                     });
        } else if (key == "polygon") {
            ++kinds;
            s.kind = CompoundShape::Kind::Polygon;
            readKeys(value, at, std::array<std::string_view, 2>{"vertices", "radius"}, "a polygon",
                     [&](const std::string& k, const Json& fv, const std::string& fa) {
                         if (k == "radius") {
                             s.cornerRadius = readNumber(fv, fa, NumberRange{0.0, kMaxMagnitude, false});
                             return;
                         }
                         if (!fv.is_array()) refuse(fa, "expected an array of vectors, got " + describeFound(fv));
                         for (std::size_t i = 0; i < fv.size(); ++i) s.vertices.push_back(readVector(fv[i], child(fa, i)));
                     });
        } else if (key == "capsule") {
            ++kinds;
            s.kind = CompoundShape::Kind::Capsule;
            readKeys(value, at, std::array<std::string_view, 3>{"a", "b", "radius"}, "a capsule",
                     [&](const std::string& k, const Json& fv, const std::string& fa) {
                         if (k == "a") s.a = readVector(fv, fa);
                         else if (k == "b") s.b = readVector(fv, fa);
                         else s.radius = readNumber(fv, fa, size);
                     });
        } else if (key == "density") {
            s.density = readNumber(value, at, size);
        } else if (key == "friction") {
            s.friction = readNumber(value, at, NumberRange{0.0, kMaxMagnitude, false});
        } else if (key == "restitution") {
            s.restitution = readNumber(value, at, NumberRange{0.0, 1.0, false});
        } else if (key == "sensor") {
            s.sensor = readBool(value, at);
        } else {
            Filter f;
            readKeys(value, at, std::array<std::string_view, 3>{"category", "mask", "group"}, "a filter",
                     [&](const std::string& k, const Json& fv, const std::string& fa) {
                         if (k == "category") f.category = std::uint32_t(readInteger(fv, fa, 0, 0xFFFFFFFFL));
                         else if (k == "mask") f.mask = std::uint32_t(readInteger(fv, fa, 0, 0xFFFFFFFFL));
                         else f.group = int(readInteger(fv, fa, -2147483647L, 2147483647L));
                     });
            s.filter = f;
        }
    });
    if (kinds != 1)
        refuse(pointer, "expected exactly one of circle, box, polygon, capsule in a compound shape, got " +
                            std::to_string(kinds));
    return s;
}

Json compoundShapeJson(const CompoundShape& s) {
    const auto vec = [](Vec2 p) { return Json{{"x", p.x}, {"y", p.y}}; };
    Json j = Json::object();
    switch (s.kind) {
    case CompoundShape::Kind::Circle: j["circle"] = Json{{"center", vec(s.center)}, {"radius", s.radius}}; break;
    case CompoundShape::Kind::Box:
        j["box"] = Json{{"center", vec(s.center)}, {"width", s.width}, {"height", s.height}, {"angle", s.angle}};
        break;
    case CompoundShape::Kind::Polygon: {
        Json list = Json::array();
        for (const Vec2 p : s.vertices) list.push_back(vec(p));
        j["polygon"] = Json{{"vertices", list}};
        if (s.cornerRadius) j["polygon"]["radius"] = *s.cornerRadius;
        break;
    }
    case CompoundShape::Kind::Capsule: j["capsule"] = Json{{"a", vec(s.a)}, {"b", vec(s.b)}, {"radius", s.radius}}; break;
    }
    if (s.density) j["density"] = *s.density;
    if (s.friction) j["friction"] = *s.friction;
    if (s.restitution) j["restitution"] = *s.restitution;
    if (s.sensor) j["sensor"] = *s.sensor;
    if (s.filter) j["filter"] = Json{{"category", s.filter->category}, {"mask", s.filter->mask}, {"group", s.filter->group}};
    return j;
}

void readField(const FieldInfo& field, const Json& v, void* component, const std::string& pointer,
               const EntityNames& names) {
    void* member = field.address(component);
    // The JSON type is checked here; the value (range, choices) by
    // fieldValueProblem below, the check the editor makes too.
    switch (field.kind) {
    case FieldKind::Number: *static_cast<double*>(member) = readNumber(v, pointer, NumberRange{}, field.range); break;
    case FieldKind::Integer: {
        const double d = readNumber(v, pointer, NumberRange{}, field.range, true);
        // Whole and within int: range-checked below like any value; else
        // refused here in the same words.
        if (d != std::floor(d) || std::abs(d) > double(std::numeric_limits<int>::max()))
            refuse(pointer, "expected " + field.range.describe(true) + ", got " + formatNumber(d));
        *static_cast<int*>(member) = int(d);
        break;
    }
    case FieldKind::OptionalNumber:
        *static_cast<std::optional<double>*>(member) = readNumber(v, pointer, NumberRange{}, field.range);
        break;
    case FieldKind::Bits:
        *static_cast<std::uint32_t*>(member) = std::uint32_t(readInteger(v, pointer, 0, 0xFFFFFFFFL));
        break;
    case FieldKind::Vector: *static_cast<Vec2*>(member) = readVector(v, pointer, field.range); break;
    case FieldKind::OptionalVector:
        *static_cast<std::optional<Vec2>*>(member) = readVector(v, pointer, field.range);
        break;
    case FieldKind::Color: *static_cast<Rgb*>(member) = readColor(v, pointer, field.range); break;
    case FieldKind::Bool: *static_cast<bool*>(member) = readBool(v, pointer); break;
    case FieldKind::VectorList: {
        // The count (field.range) is checked by the component's finish, whose
        // message names the entity.
        if (!v.is_array()) refuse(pointer, "expected an array of vectors, got " + describeFound(v));
        auto& list = *static_cast<std::vector<Vec2>*>(member);
        list.clear();
        for (std::size_t i = 0; i < v.size(); ++i) list.push_back(readVector(v[i], child(pointer, i)));
        break;
    }
    case FieldKind::IntegerList: {
        if (!v.is_array()) refuse(pointer, "expected an array of integers, got " + describeFound(v));
        auto& list = *static_cast<std::vector<int>*>(member);
        list.clear();
        for (std::size_t i = 0; i < v.size(); ++i) {
            const std::string at = child(pointer, i);
            const double d = readNumber(v[i], at, NumberRange{}, field.range, true);
            if (d != std::floor(d) || !field.range.contains(d) || std::abs(d) > double(std::numeric_limits<int>::max()))
                refuse(at, "expected " + field.range.describe(true) + ", got " + formatNumber(d));
            list.push_back(int(d));
        }
        break;
    }
    case FieldKind::ShapeList: {
        if (!v.is_array()) refuse(pointer, "expected an array of shapes, got " + describeFound(v));
        auto& list = *static_cast<std::vector<CompoundShape>*>(member);
        list.clear();
        for (std::size_t i = 0; i < v.size(); ++i) list.push_back(readCompoundShape(v[i], child(pointer, i)));
        break;
    }
    case FieldKind::String: *static_cast<std::string*>(member) = readString(v, pointer); break;
    case FieldKind::EntityRef: {
        // Resolved here, once: in memory the field is a handle.
        const std::string s = readString(v, pointer);
        if (s.empty()) refuse(pointer, "expected the name of an entity, got \"\"");
        const auto it = names.byName.find(s);
        if (it == names.byName.end()) {
            // A placeholder that is not null (so finish() sees the field as
            // given) and never alive; the refusal follows after reading.
            names.unresolved.push_back(pointer + ": no entity is named \"" + s + "\"");
            *static_cast<Entity*>(member) = Entity{Entity::kInvalidIndex - 1, 0};
            break;
        }
        *static_cast<Entity*>(member) = it->second;
        break;
    }
    }
    if (auto problem = fieldValueProblem(field, member)) refuse(pointer, problem->message);
}

Json vectorJson(Vec2 v) {
    Json j = Json::object();
    j["x"] = v.x;
    j["y"] = v.y;
    return j;
}

/// Field value as JSON, or a discarded value when the field is absent.
/// `registry` names the entities that reference fields point at.
Json fieldJson(const FieldInfo& field, const void* component, const Registry& registry) {
    const void* member = field.address(const_cast<void*>(component));
    switch (field.kind) {
    case FieldKind::Number: return *static_cast<const double*>(member);
    case FieldKind::Integer: return *static_cast<const int*>(member);
    case FieldKind::Bits: return *static_cast<const std::uint32_t*>(member);
    case FieldKind::OptionalNumber: {
        const auto& o = *static_cast<const std::optional<double>*>(member);
        return o ? Json(*o) : Json(Json::value_t::discarded);
    }
    case FieldKind::Vector: return vectorJson(*static_cast<const Vec2*>(member));
    case FieldKind::OptionalVector: {
        const auto& o = *static_cast<const std::optional<Vec2>*>(member);
        return o ? vectorJson(*o) : Json(Json::value_t::discarded);
    }
    case FieldKind::Color: {
        const Rgb c = *static_cast<const Rgb*>(member);
        Json j = Json::object();
        j["x"] = c.r;
        j["y"] = c.g;
        j["z"] = c.b;
        return j;
    }
    case FieldKind::Bool: return *static_cast<const bool*>(member);
    case FieldKind::VectorList: {
        Json list = Json::array();
        for (const Vec2 p : *static_cast<const std::vector<Vec2>*>(member)) list.push_back(vectorJson(p));
        return list;
    }
    case FieldKind::IntegerList: {
        const auto& values = *static_cast<const std::vector<int>*>(member);
        if (values.empty()) return Json(Json::value_t::discarded);
        Json list = Json::array();
        for (const int n : values) list.push_back(n);
        return list;
    }
    case FieldKind::ShapeList: {
        Json list = Json::array();
        for (const CompoundShape& s : *static_cast<const std::vector<CompoundShape>*>(member))
            list.push_back(compoundShapeJson(s));
        return list;
    }
    case FieldKind::String: return *static_cast<const std::string*>(member);
    case FieldKind::EntityRef: {
        // The end's name now (checkSceneRelations refuses an unnamed or
        // dead end before a save).
        const Entity ref = *static_cast<const Entity*>(member);
        const Name* name = ref.isNull() ? nullptr : registry.tryGet<Name>(ref);
        return name ? Json(name->value) : Json(Json::value_t::discarded);
    }
    }
    return Json(Json::value_t::discarded);
}

std::string entityLabel(std::size_t index, const Json& entity) {
    std::string label = "entity " + std::to_string(index);
    if (entity.is_object()) {
        const auto it = entity.find("name");
        if (it != entity.end() && it->is_string()) label += " (\"" + it->get<std::string>() + "\")";
    }
    return label;
}

void readComponent(const ComponentInfo& info, const Json& value, Registry& registry, Entity e,
                   const std::string& pointer, const EntityNames& names, const std::string& entity) {
    void* component = info.emplaceDefault(registry, e);
    if (info.inlineValue) {
        readField(info.fields.front(), value, component, pointer, names);
    } else {
        if (!value.is_object())
            refuse(pointer, "expected an object for component \"" + std::string(info.name) + "\", got " +
                                describeFound(value));
        for (const auto& [key, fieldValue] : value.items()) {
            // Not captured directly: clang 14 (the fuzz build) cannot capture
            // a structured binding in a lambda.
            const std::string& fieldKey = key;
            const auto it = std::find_if(info.fields.begin(), info.fields.end(),
                                         [&](const FieldInfo& f) { return f.key == fieldKey; });
            if (it == info.fields.end()) {
                std::vector<std::string_view> known;
                for (const FieldInfo& f : info.fields) known.push_back(f.key);
                refuse(child(pointer, key),
                       unknownNameMessage("unknown field \"" + key + "\" in \"" + std::string(info.name) + "\"", key,
                                          known, "fields"));
            }
            const std::size_t unresolvedBefore = names.unresolved.size();
            readField(*it, fieldValue, component, child(pointer, key), names);
            // A name no entity has: say whose reference it is.
            if (names.unresolved.size() > unresolvedBefore)
                names.unresolved.back() += " (" + std::string(info.name) + " on " + entity + ")";
        }
    }
    if (info.finish) {
        if (const std::optional<Error> refused = info.finish(component)) {
            // `where` may go deeper than one field ("vertices/3").
            std::string at = pointer;
            for (std::size_t from = 0; from < refused->where.size();) {
                const std::size_t slash = std::min(refused->where.find('/', from), refused->where.size());
                at = child(at, refused->where.substr(from, slash - from));
                from = slash + 1;
            }
            refuse(at, (info.finishNamesEntity ? entity + ": " : std::string()) + refused->message);
        }
    }
}

void readEntity(const Json& entityJson, std::size_t index, Registry& registry, Entity e, const EntityNames& names) {
    const std::string pointer = child("/entities", index);
    if (!entityJson.is_object())
        refuse(pointer, "expected an entity object {\"component\": value, ...}, got " + describeFound(entityJson));
    for (const auto& [key, value] : entityJson.items()) {
        const ComponentInfo* info = findComponent(key);
        if (!info) {
            const auto known = componentNames();
            refuse(child(pointer, key),
                   unknownNameMessage("unknown component \"" + key + "\" on " + entityLabel(index, entityJson), key,
                                      known, "components"));
        }
        readComponent(*info, value, registry, e, child(pointer, key), names, entityLabel(index, entityJson));
    }
    for (const ComponentInfo& info : componentTable()) {
        if (!info.has(registry, e)) continue;
        for (std::string_view needed : info.requires_) {
            if (!findComponent(needed)->has(registry, e))
                refuse(pointer, "component \"" + std::string(info.name) + "\" on " + entityLabel(index, entityJson) +
                                    " needs \"" + std::string(needed) + "\", which is missing");
        }
    }
}

/// The `world` object, field by field from the world-settings table.
void readWorld(const Json& v, WorldSettings& world) {
    const std::string pointer = "/world";
    if (!v.is_object()) refuse(pointer, "expected an object, got " + describeFound(v));
    static const EntityNames kNoNames;  // world settings name no entity
    for (const auto& [key, value] : v.items()) {
        const std::string at = child(pointer, key);
        const WorldFieldInfo* info = findWorldField(key);
        if (!info) {
            const std::vector<std::string_view> known = worldFieldNames();
            refuse(at, unknownNameMessage("unknown world setting \"" + key + "\"", key, known, "settings"));
        }
        readField(info->field, value, &world, at, kNoNames);
    }
    if (std::optional<Error> problem = adaptiveStepProblem(world)) refuse(child(pointer, "adaptive_step"), problem->message);
}

/// Whether the entity has a shape, so contacts (and their warm start) can
/// name it.
bool collides(const Registry& registry, Entity e) {
    return registry.has<Radius>(e) || registry.has<Box>(e) || registry.has<Polygon>(e) || registry.has<Capsule>(e) ||
           registry.has<Chain>(e) || registry.has<Plane>(e) || registry.has<Shapes>(e);
}

/// Reads one `solver_state` entry: an object with the given keys, each read
/// by `readField(key, value, pointer)`; `required` keys must be present.
template <std::size_t N, typename ReadField>
void readEntry(const Json& entry, const std::string& at, std::string_view what,
               const std::array<std::string_view, N>& keys, std::size_t required, ReadField readField) {
    if (!entry.is_object()) refuse(at, "expected " + std::string(what) + " {" + joinNames(keys) + "}, got " + describeFound(entry));
    std::array<bool, N> seen{};
    for (const auto& [field, fv] : entry.items()) {
        const auto k = std::find(keys.begin(), keys.end(), field);
        if (k == keys.end())
            refuse(child(at, field), "unknown key \"" + field + "\" in " + std::string(what) + ". Known keys: " + joinNames(keys));
        seen[std::size_t(k - keys.begin())] = true;
        readField(field, fv, child(at, field));
    }
    for (std::size_t k = 0; k < required; ++k)
        if (!seen[k]) refuse(at, "missing \"" + std::string(keys[k]) + "\"");
}

/// `solver_state` (an addition): the warm start a resumed run needs. Read
/// after the entities, since its entries name them. An entity is named by
/// its `name`, or by its index in `entities` when it has none.
SolverState readSolverState(const Json& v, const Registry& registry) {
    const std::string pointer = "/solver_state";
    if (!v.is_object())
        refuse(pointer, "expected an object {\"contacts\": [...], \"joints\": [...], \"bodies\": [...]}, got " +
                            describeFound(v));
    const auto& entities = registry.entities();
    std::map<std::string, Entity, std::less<>> byName;
    for (const Entity e : entities)
        if (const Name* n = registry.tryGet<Name>(e)) byName.emplace(n->value, e);
    auto entityAt = [&](const Json& ref, const std::string& at) -> Entity {
        if (ref.is_string()) {
            const auto it = byName.find(ref.get<std::string>());
            if (it == byName.end()) refuse(at, "no entity is named " + ref.dump());
            return it->second;
        }
        if (ref.is_number_integer() || ref.is_number_unsigned())
            return entities[std::size_t(readInteger(ref, at, 0, long(entities.size()) - 1))];
        refuse(at, "expected an entity name or index, got " + describeFound(ref));
    };
    auto shapeAt = [&](const Json& ref, const std::string& at) {
        const Entity e = entityAt(ref, at);
        if (!collides(registry, e))
            refuse(at, "entity " + ref.dump() + " has no shape (radius, box, polygon, capsule, chain or plane), so it has no contacts");
        return e;
    };
    // shape_a and shape_b (a compound body's shape index) are optional: 0.
    static constexpr std::array<std::string_view, 7> kContactKeys{"a", "b", "feature", "normal_impulse",
                                                                  "tangent_impulse", "shape_a", "shape_b"};
    // "joint" is required; an impulse left out is +0.
    static constexpr std::array<std::string_view, 7> kJointKeys{
        "joint", "linear_impulse", "angular_impulse", "axial_impulse", "motor_impulse", "lower_impulse", "upper_impulse"};
    SolverState state;
    for (const auto& [key, value] : v.items()) {
        const std::string at = child(pointer, key);
        if (key != "contacts" && key != "joints" && key != "bodies" && key != "chosen")
            refuse(at, "unknown key \"" + key + "\" in solver_state. Known keys: contacts, joints, bodies, chosen");
        if (key == "chosen") {
            // What the engine chose for the run that wrote this file: the
            // substeps and iterations (both required), the contacts'
            // stiffness cap and their stiffness (optional).
            static constexpr std::array<std::string_view, 4> kChosenKeys{"substeps", "solver_iterations",
                                                                         "contact_hertz_fraction", "contact_hertz"};
            ChosenSettings chosen;
            readEntry(value, at, "the engine's chosen settings", kChosenKeys, 2,
                      [&](const std::string& field, const Json& fv, const std::string& fa) {
                          if (field == "contact_hertz_fraction") {
                              chosen.contactHertzFraction = readNumber(fv, fa, NumberRange{0.0, 0.25, true});
                              return;
                          }
                          if (field == "contact_hertz") {
                              chosen.contactHertz = readNumber(fv, fa, NumberRange{kContactHertz, 1e9, false});
                              return;
                          }
                          const int count = int(readInteger(fv, fa, 1, kMaxLevelSubsteps));
                          if (field == "substeps") chosen.substeps = count;
                          else chosen.solverIterations = count;
                      });
            state.chosen = chosen;
            continue;
        }
        if (!value.is_array()) refuse(at, "expected an array of " + key + ", got " + describeFound(value));
        if (key == "contacts") {
            state.contacts.reserve(value.size());
            // What a run writes: one entry per (pair, feature), between two
            // entities, with a normal impulse that only ever pushes.
            using Side = std::pair<std::uint64_t, std::uint32_t>;
            std::map<std::tuple<Side, Side, std::uint32_t>, std::size_t> seenContacts;
            const NumberRange pushes{0.0, std::numeric_limits<double>::infinity(), false};
            for (std::size_t i = 0; i < value.size(); ++i) {
                ContactImpulse c;
                readEntry(value[i], child(at, i), "a contact", kContactKeys, 5,
                          [&](const std::string& field, const Json& fv, const std::string& fa) {
                              if (field == "a") c.a = shapeAt(fv, fa);
                              else if (field == "b") c.b = shapeAt(fv, fa);
                              else if (field == "feature") c.feature = std::uint32_t(readInteger(fv, fa, 0, 0xFFFF));
                              else if (field == "normal_impulse") c.normalImpulse = readNumber(fv, fa, pushes, NumberRange{});
                              else if (field == "shape_a") c.shapeA = std::uint32_t(readInteger(fv, fa, 0, 255));
                              else if (field == "shape_b") c.shapeB = std::uint32_t(readInteger(fv, fa, 0, 255));
                              else c.tangentImpulse = readNumber(fv, fa, NumberRange{});
                          });
                if (c.a == c.b) refuse(child(child(at, i), "b"), "a contact joins an entity to itself");
                // Pairs of shapes of the same two compound bodies are
                // different contacts.
                const auto ka = std::make_pair((std::uint64_t(c.a.index) << 32) | c.a.generation, c.shapeA);
                const auto kb = std::make_pair((std::uint64_t(c.b.index) << 32) | c.b.generation, c.shapeB);
                const auto [it, fresh] = seenContacts.emplace(std::make_tuple(std::min(ka, kb), std::max(ka, kb), c.feature), i);
                if (!fresh)
                    refuse(child(at, i), "this pair and feature have an entry already (" + child(at, it->second) + ")");
                state.contacts.push_back(c);
            }
            continue;
        }
        if (key == "bodies") {
            // Sleep timers and islands (an addition): "body" is required.
            static constexpr std::array<std::string_view, 6> kBodyKeys{"body", "sleep_time", "still_at", "still_angle",
                                                                       "still_velocity", "island"};
            std::unordered_set<Entity> seenBodies;
            const auto dynamicAt = [&](const Json& ref, const std::string& fa) {
                const Entity e = entityAt(ref, fa);
                const Static* st = registry.tryGet<Static>(e);
                if (!registry.has<Position>(e) || (st && st->value))
                    refuse(fa, "entity " + ref.dump() + " is not a dynamic body (it needs a position and no static)");
                return e;
            };
            for (std::size_t i = 0; i < value.size(); ++i) {
                BodySleep b;
                readEntry(value[i], child(at, i), "a body", kBodyKeys, 1,
                          [&](const std::string& field, const Json& fv, const std::string& fa) {
                              if (field == "body") {
                                  b.body = dynamicAt(fv, fa);
                                  if (!seenBodies.insert(b.body).second)
                                      refuse(fa, "body " + fv.dump() + " has an entry already");
                              } else if (field == "sleep_time") {
                                  b.sleepTime = readNumber(fv, fa, NumberRange{0.0, 1e300});
                              } else if (field == "still_at") {
                                  b.stillAt = readVector(fv, fa);
                              } else if (field == "still_angle") {
                                  b.stillAngle = readNumber(fv, fa, kAnyMagnitude);
                              } else if (field == "still_velocity") {
                                  b.stillVelocity = readVector(fv, fa, kAnySpeed);
                              } else {
                                  b.island = dynamicAt(fv, fa);
                              }
                          });
                state.bodies.push_back(b);
            }
            continue;
        }
        state.joints.reserve(value.size());
        std::unordered_set<Entity> seenJoints;
        for (std::size_t i = 0; i < value.size(); ++i) {
            JointImpulse j;
            // Limits and a rope only push one way: their impulses are >= 0.
            const NumberRange oneSided{0.0, std::numeric_limits<double>::infinity(), false};
            readEntry(value[i], child(at, i), "a joint", kJointKeys, 1,
                      [&](const std::string& field, const Json& fv, const std::string& fa) {
                          if (field == "joint") {
                              j.joint = entityAt(fv, fa);
                              if (!registry.has<Joint>(j.joint)) refuse(fa, "entity " + fv.dump() + " is not a joint");
                              if (!seenJoints.insert(j.joint).second)
                                  refuse(fa, "joint " + fv.dump() + " has an entry already");
                          } else if (field == "linear_impulse") j.linear = readVector(fv, fa, NumberRange{});
                          else if (field == "angular_impulse") j.angular = readNumber(fv, fa, NumberRange{});
                          else if (field == "axial_impulse") j.axial = readNumber(fv, fa, NumberRange{});
                          else if (field == "motor_impulse") j.motor = readNumber(fv, fa, NumberRange{});
                          else if (field == "lower_impulse") j.lower = readNumber(fv, fa, oneSided);
                          else j.upper = readNumber(fv, fa, oneSided);
                      });
            state.joints.push_back(j);
        }
    }
    return state;
}

View readView(const Json& v) {
    const std::string pointer = "/view";
    if (!v.is_object()) refuse(pointer, "expected an object {\"center\": vector, \"zoom\": number}, got " + describeFound(v));
    View view;
    for (const auto& [key, value] : v.items()) {
        if (key == "center") view.center = readVector(value, child(pointer, key));
        else if (key == "zoom") view.zoom = readNumber(value, child(pointer, key), NumberRange{0.0, 1e9, true});
        else refuse(child(pointer, key), "unknown key \"" + key + "\" in view. Known keys: center, zoom");
    }
    return view;
}

/// Pretty printer for level files: small all-scalar objects (vectors,
/// colours, boxes) stay on one line, everything else is indented by two.
void writeJson(const Json& v, int indent, std::string& out) {
    const auto pad = [&](int n) { out.append(std::size_t(n), ' '); };
    if (v.is_object()) {
        if (v.empty()) {
            out += "{}";
            return;
        }
        const bool compact = v.size() <= 4 && std::all_of(v.begin(), v.end(), [](const Json& c) {
                                 return c.is_primitive();
                             });
        if (compact) {
            out += "{";
            bool first = true;
            for (const auto& [key, value] : v.items()) {
                if (!first) out += ", ";
                first = false;
                out += Json(key).dump() + ": " + value.dump();
            }
            out += "}";
            return;
        }
        out += "{\n";
        bool first = true;
        for (const auto& [key, value] : v.items()) {
            if (!first) out += ",\n";
            first = false;
            pad(indent + 2);
            out += Json(key).dump() + ": ";
            writeJson(value, indent + 2, out);
        }
        out += "\n";
        pad(indent);
        out += "}";
    } else if (v.is_array()) {
        if (v.empty()) {
            out += "[]";
            return;
        }
        out += "[\n";
        for (std::size_t i = 0; i < v.size(); ++i) {
            if (i) out += ",\n";
            pad(indent + 2);
            writeJson(v[i], indent + 2, out);
        }
        out += "\n";
        pad(indent);
        out += "]";
    } else {
        out += v.dump();
    }
}

/// Refusals are printed on a terminal and shown in the editor: one line of
/// valid UTF-8. The parser's messages quote the bytes it stopped at, which
/// may be any bytes of a broken file, and keys may hold escaped control
/// characters; such bytes are shown as \xNN.
std::string printableMessage(std::string_view message) {
    std::string out;
    out.reserve(message.size());
    const auto hex = [&](unsigned char c) {
        static constexpr char kDigits[] = "0123456789ABCDEF";
        out += "\\x";
        out += kDigits[c >> 4];
        out += kDigits[c & 0xF];
    };
    std::size_t i = 0;
    while (i < message.size()) {
        const auto c = static_cast<unsigned char>(message[i]);
        if (c < 0x20 || c == 0x7F) {
            hex(c);
            ++i;
            continue;
        }
        if (c < 0x80) {
            out += char(c);
            ++i;
            continue;
        }
        // Length from the lead byte; continuation bytes are 10xxxxxx. No
        // overlong forms, surrogates or values past U+10FFFF.
        const std::size_t n = (c >= 0xC2 && c <= 0xDF) ? 2 : (c >= 0xE0 && c <= 0xEF) ? 3 : (c >= 0xF0 && c <= 0xF4) ? 4 : 0;
        bool valid = n != 0 && i + n <= message.size();
        for (std::size_t k = 1; valid && k < n; ++k)
            valid = (static_cast<unsigned char>(message[i + k]) & 0xC0) == 0x80;
        if (valid && n >= 3) {
            const auto c1 = static_cast<unsigned char>(message[i + 1]);
            if ((c == 0xE0 && c1 < 0xA0) || (c == 0xED && c1 >= 0xA0) || (c == 0xF0 && c1 < 0x90) ||
                (c == 0xF4 && c1 >= 0x90))
                valid = false;
        }
        if (!valid) {
            hex(c);
            ++i;
            continue;
        }
        out.append(message.substr(i, n));
        i += n;
    }
    return out;
}

/// "entity 7 (\"axle\")" for entity `index` of `registry`.
std::string entityLabelOf(const Registry& registry, std::size_t index) {
    std::string label = "entity " + std::to_string(index);
    const Name* name = registry.tryGet<Name>(registry.entities()[index]);
    if (name && !name->value.empty()) label += " (\"" + name->value + "\")";
    return label;
}

/// What a joint end is called in messages: its name, or "entity N".
std::string endLabel(const Registry& registry, Entity end) {
    if (end.isNull()) return "the world";
    const Name* name = registry.tryGet<Name>(end);
    if (name && !name->value.empty()) return "\"" + name->value + "\"";
    const auto& order = registry.entities();
    const auto it = std::find(order.begin(), order.end(), end);
    return "entity " + std::to_string(std::size_t(it - order.begin()));
}

/// The joint rules that need the whole scene: ends that exist and have a
/// position, not the same body twice, not two static ends, a usable slider
/// axis. "" when fine, else "POINTER: message" naming the joint's entity.
std::string checkJoint(const Registry& registry, std::size_t index, const Joint& joint) {
    const std::string at = child("/entities", index) + "/joint";
    const std::string who = "joint on " + entityLabelOf(registry, index);
    if (registry.has<Position>(registry.entities()[index]))
        return child("/entities", index) + "/position: " + who +
               ": a joint entity has no body of its own; remove \"position\"";
    if (joint.a.isNull()) return at + "/a: " + who + ": expected the name of a body, got nothing";
    bool isStatic[2] = {true, true};
    for (const auto& [end, key, slot] : {std::tuple{joint.a, "a", 0}, std::tuple{joint.b, "b", 1}}) {
        if (end.isNull()) continue;  // b: the world
        if (!registry.alive(end)) return at + "/" + key + ": " + who + ": the body it names no longer exists";
        if (!registry.has<Position>(end))
            return at + "/" + key + ": " + who + ": entity " + endLabel(registry, end) +
                   " has no position, so a joint cannot attach to it";
        const Static* st = registry.tryGet<Static>(end);
        isStatic[slot] = st && st->value;
    }
    if (joint.a == joint.b) return at + "/b: " + who + ": a joint cannot join " + endLabel(registry, joint.a) + " to itself";
    if (isStatic[0] && isStatic[1])
        return at + ": " + who + ": joins two static bodies (" + endLabel(registry, joint.a) + " and " +
               endLabel(registry, joint.b) + "); at least one end must be dynamic";
    if ((joint.type == "slider" || joint.type == "wheel") && joint.axis &&
        !(std::hypot(joint.axis->x, joint.axis->y) > 1e-12))
        return at + "/axis: " + who + ": a " + joint.type + " axis needs a non-zero length, got {\"x\": " +
               describeFound(Json(joint.axis->x)) + ", \"y\": " + describeFound(Json(joint.axis->y)) + "}";
    return {};
}

} // namespace

namespace {

/// Templates and emitters (docs/format.md, "Templates and emitters"): a
/// template body is a dynamic body with a shape; its joints and springs stay
/// within it; an emitter names an existing template, one emitter per
/// template, and its run state names copies that exist. "" when fine.
const std::string kNoTemplate;

std::string templatesProblem(const Registry& registry) {
    const auto& entities = registry.entities();
    if (registry.count<Template>() == 0 && registry.count<Emitter>() == 0) return {};
    std::map<std::string, std::size_t> firstOf;  // template value -> its first entity
    for (std::size_t i = 0; i < entities.size(); ++i) {
        const Entity e = entities[i];
        const Template* t = registry.tryGet<Template>(e);
        if (!t) continue;
        const std::string at = child("/entities", i) + "/template";
        const std::string who = entityLabelOf(registry, i);
        if (t->value.empty()) return at + ": " + who + ": expected a template name, got \"\"";
        if (t->value.find('#') != std::string::npos)
            return at + ": " + who + ": a template name cannot contain '#' (its copies are named \"" + t->value +
                   "#N\"), got \"" + t->value + "\"";
        firstOf.emplace(t->value, i);
        if (registry.has<Joint>(e) || registry.has<Spring>(e)) continue;
        for (const auto& [name, present] :
             {std::pair<const char*, bool>{"static", registry.has<Static>(e) && registry.tryGet<Static>(e)->value},
              {"kinematic", registry.has<Kinematic>(e) && registry.tryGet<Kinematic>(e)->value},
              {"plane", registry.has<Plane>(e)},
              {"attractor", registry.has<Attractor>(e)},
              {"boid", registry.has<Boid>(e)},
              {"emitter", registry.has<Emitter>(e)}})
            if (present)
                return at + ": " + who + ": a template entity is a dynamic body with a shape; remove \"" + name + "\"";
        if (!registry.has<Position>(e))
            return at + ": " + who + ": a template entity is a dynamic body with a shape; it has no position";
        if (!registry.has<Radius>(e) && !registry.has<Box>(e) && !registry.has<Polygon>(e) && !registry.has<Capsule>(e) &&
            !registry.has<Shapes>(e))
            return at + ": " + who +
                   ": a template body needs a shape (radius, box, polygon, capsule or shapes): its copies are added to the "
                   "contact solver as they appear";
    }
    // Joints and springs: all of their ends in one template, or none.
    for (std::size_t i = 0; i < entities.size(); ++i) {
        const Entity e = entities[i];
        const Joint* joint = registry.tryGet<Joint>(e);
        const Spring* spring = registry.tryGet<Spring>(e);
        if (!joint && !spring) continue;
        const Template* own = registry.tryGet<Template>(e);
        const Entity ends[2] = {joint ? joint->a : spring->a, joint ? joint->b : spring->b};
        const char* kind = joint ? "joint" : "spring";
        const std::string* expected = own ? &own->value : nullptr;
        const std::string* first = nullptr;
        for (const Entity end : ends) {
            if (end.isNull() || !registry.alive(end)) continue;
            const Template* t = registry.tryGet<Template>(end);
            const std::string* value = t ? &t->value : nullptr;
            if (!first) first = value ? value : &kNoTemplate;
            const std::string& have = value ? *value : kNoTemplate;
            const std::string& want = expected ? *expected : *first;
            if (have != want)
                return child(child("/entities", i), kind) + ": " + kind + " on " + entityLabelOf(registry, i) +
                       ": joins " + (have.empty() ? "" : "template \"" + have + "\" entity ") + endLabel(registry, end) +
                       (want.empty() ? " to bodies outside any template" : " to template \"" + want + "\"") +
                       "; a template's joints and springs stay within it";
        }
    }
    // Copy names already claimed by an emitter's run state: by whom.
    std::map<std::string, std::size_t> claimedBy;
    std::unordered_set<std::string> names;
    if (registry.count<Emitter>() > 0)
        for (const Entity e : entities)
            if (const Name* n = registry.tryGet<Name>(e)) names.insert(n->value);
    for (std::size_t i = 0; i < entities.size(); ++i) {
        const Emitter* em = registry.tryGet<Emitter>(entities[i]);
        if (!em) continue;
        const std::string at = child("/entities", i) + "/emitter";
        const std::string who = "emitter on " + entityLabelOf(registry, i);
        if (firstOf.find(em->templateName) == firstOf.end())
            return at + "/template: " + who + ": no entity has \"template\": \"" + em->templateName + "\"";
        if (em->alive > em->count)
            return at + "/alive: " + who + ": " + std::to_string(em->alive) + " copies alive, more than count " +
                   std::to_string(em->count);
        if (em->alive > em->emitted)
            return at + "/alive: " + who + ": " + std::to_string(em->alive) + " copies alive, more than the " +
                   std::to_string(em->emitted) + " emitted";
        if (em->alive > 0 && (!em->oldest || !em->next))
            return at + "/oldest: " + who + ": with copies alive the run state needs \"next\" and \"oldest\"";
        if (!em->copies.empty()) {
            if (int(em->copies.size()) != em->alive)
                return at + "/copies: " + who + ": " + std::to_string(em->copies.size()) + " copy numbers for " +
                       std::to_string(em->alive) + " copies alive";
            for (std::size_t k = 1; k < em->copies.size(); ++k)
                if (em->copies[k] <= em->copies[k - 1])
                    return child(at + "/copies", k) + ": " + who + ": copy numbers go up, oldest first; " +
                           std::to_string(em->copies[k]) + " follows " + std::to_string(em->copies[k - 1]);
        }
        // The copies alive, by the names they were given.
        for (const int k : copyNumbers(*em)) {
            const std::string copy = em->templateName + "#" + std::to_string(k);
            if (!names.contains(copy))
                return at + "/alive: " + who + ": copy \"" + copy + "\" is alive in its run state but not in the scene";
            if (const auto [it, inserted] = claimedBy.emplace(copy, i); !inserted)
                return at + "/copies: " + who + ": copy \"" + copy + "\" is alive in the run state of " +
                       entityLabelOf(registry, it->second) + " already";
        }
    }
    // Names of a template's copies belong to its emitters' run: only those
    // alive may be in the scene, or a later copy would take a name in use.
    std::map<std::string, std::vector<std::size_t>> emittersOf;  // template value -> its emitters
    for (std::size_t i = 0; i < entities.size(); ++i)
        if (const Emitter* em = registry.tryGet<Emitter>(entities[i])) emittersOf[em->templateName].push_back(i);
    for (std::size_t j = 0; j < entities.size() && !emittersOf.empty(); ++j) {
        const Name* n = registry.tryGet<Name>(entities[j]);
        const std::size_t hash = n ? n->value.find('#') : std::string::npos;
        if (hash == std::string::npos) continue;
        const auto of = emittersOf.find(n->value.substr(0, hash));
        if (of == emittersOf.end() || !detail::copyNumberIn(n->value, of->first)) continue;
        if (claimedBy.contains(n->value.substr(0, n->value.find('/')))) continue;
        const std::string name = child("/entities", j) + "/name: \"" + n->value + "\"";
        if (of->second.size() > 1)
            return name + " is a name the emitters of template \"" + of->first +
                   "\" give their copies, and no emitter has that copy alive in its run state";
        const Emitter& em = *registry.tryGet<Emitter>(entities[of->second.front()]);
        return name + " is a name the emitter on " + entityLabelOf(registry, of->second.front()) +
               " gives its copies, and that copy is not alive in its run state (" + std::to_string(em.alive) +
               " alive of " + std::to_string(em.emitted) + " emitted)";
    }
    return {};
}

/// checkSceneRelations' walk: "" when fine (internal; the public function
/// returns the message as an Error).
std::string relationsProblem(const Scene& scene) {
    const Registry& registry = scene.registry;
    const auto& entities = registry.entities();
    std::map<std::string, std::size_t> indexByName;
    for (std::size_t i = 0; i < entities.size(); ++i) {
        const Name* name = registry.tryGet<Name>(entities[i]);
        if (!name) continue;
        if (name->value.empty()) return child("/entities", i) + "/name: expected a non-empty name, got \"\"";
        const auto [it, inserted] = indexByName.emplace(name->value, i);
        if (!inserted)
            return child("/entities", i) + "/name: duplicate name \"" + name->value + "\" (also entity " +
                   std::to_string(it->second) + "); names must be unique";
    }
    for (std::size_t i = 0; i < entities.size(); ++i) {
        const Entity e = entities[i];
        const int shapes = int(registry.has<Radius>(e)) + int(registry.has<Box>(e)) + int(registry.has<Polygon>(e)) +
                           int(registry.has<Capsule>(e)) + int(registry.has<Chain>(e)) + int(registry.has<Plane>(e));
        if (registry.has<Shapes>(e) && shapes > 0) {
            const Name* name = registry.tryGet<Name>(e);
            return child("/entities", i) + ": entity " + std::to_string(i) +
                   (name && !name->value.empty() ? " (\"" + name->value + "\")" : std::string()) +
                   " has both shapes and a single shape (radius, box, polygon, capsule, chain or plane); a compound body "
                   "lists every shape in shapes";
        }
        if (shapes > 1)
            return child("/entities", i) +
                   ": an entity has at most one shape (radius, box, polygon, capsule, chain or plane), got " +
                   std::to_string(shapes);
        // A chain has no area: no mass or inertia for a dynamic body to move
        // by. Static and kinematic bodies need none.
        if (registry.has<Chain>(e) && !(registry.has<Static>(e) && registry.tryGet<Static>(e)->value) &&
            !(registry.has<Kinematic>(e) && registry.tryGet<Kinematic>(e)->value))
            return child("/entities", i) + "/chain: " + entityLabelOf(registry, i) + ": " + kChainOnDynamicBody;
        if (registry.has<Static>(e) && registry.tryGet<Static>(e)->value && registry.has<Kinematic>(e) &&
            registry.tryGet<Kinematic>(e)->value)
            return child("/entities", i) + "/kinematic: a body is static or kinematic, not both";
        if (registry.has<Plane>(e) && registry.has<Position>(e))
            return child("/entities", i) + "/position: a plane is placed by its normal and offset, not a position";
        // The loader checks this per entity as it reads (readEntity); a scene
        // edited in memory gets the same rule here.
        for (const ComponentInfo& info : componentTable()) {
            if (!info.has(registry, e)) continue;
            for (std::string_view needed : info.requires_)
                if (!findComponent(needed)->has(registry, e))
                    return child("/entities", i) + ": component \"" + std::string(info.name) + "\" needs \"" +
                           std::string(needed) + "\", which is missing";
        }
        if (const Joint* joint = registry.tryGet<Joint>(e)) {
            if (std::string problem = checkJoint(registry, i, *joint); !problem.empty()) return problem;
        }
        const Spring* spring = registry.tryGet<Spring>(e);
        if (spring && registry.has<Position>(e))
            return child("/entities", i) + "/position: a spring entity has no body of its own; remove \"position\"";
        // Every entity reference (spring ends, joint bodies): alive, named
        // (files refer by name) and a body.
        std::string problem;
        forEachEntityRef(registry, e, [&](const ComponentInfo& info, const FieldInfo& field, Entity ref) {
            if (!problem.empty() || ref.isNull()) return;
            const std::string at = child(child(child("/entities", i), info.name), field.key);
            const std::string attached = "a " + std::string(info.name);
            if (!registry.alive(ref)) {
                problem = at + ": the entity it named was deleted";
                return;
            }
            const Name* name = registry.tryGet<Name>(ref);
            if (!name || name->value.empty()) {
                problem = at + ": the entity it attaches to has no name, and a file refers to it by name";
                return;
            }
            if (!registry.has<Position>(ref))
                problem = at + ": entity \"" + name->value + "\" has no position, so " + attached + " cannot attach to it";
        });
        if (!problem.empty()) return problem;
        if (spring && !spring->b.isNull() && spring->a == spring->b)
            return child("/entities", i) + "/spring/b: a spring cannot join \"" + registry.tryGet<Name>(spring->a)->value +
                   "\" to itself";
    }
    return templatesProblem(registry);
}

} // namespace

std::optional<Error> checkSceneRelations(const Scene& scene) {
    std::string problem = relationsProblem(scene);
    if (problem.empty()) return std::nullopt;
    return Error{std::move(problem)};
}

namespace {

Result<Scene> parseSceneUnchecked(std::string_view text, std::string_view sourceName, const LoadLimits& limits) {
    const std::string prefix = std::string(sourceName) + ": error: ";
    if (text.size() > limits.maxFileBytes)
        return Error{prefix + "file is " + std::to_string(text.size()) + " bytes; the limit is " +
                     std::to_string(limits.maxFileBytes) + " bytes"};

    // The text layer (json_reader.cpp) checks the limits and the rules of
    // the JSON itself (NUL bytes, duplicate keys) while parsing, so a
    // hostile file is refused before its DOM is built.
    Json root;
    if (Result<void> parsed = detail::parseLevelJson(text, sourceName, limits, root); !parsed)
        return Error{parsed.error()};

    Scene scene;
    try {
        if (!root.is_object())
            refuse("", "expected a level object {\"entities\": [...]}, got " + describeFound(root));
        static constexpr std::array<std::string_view, 5> kTopKeys{"version", "world", "view", "entities",
                                                                  "solver_state"};
        for (const auto& [key, value] : root.items()) {
            if (std::find(kTopKeys.begin(), kTopKeys.end(), key) == kTopKeys.end()) {
                refuse(child("", key), unknownNameMessage("unknown top-level key \"" + key + "\"", key, kTopKeys, "keys"));
            }
        }
        if (auto it = root.find("version"); it != root.end()) {
            scene.version = int(readInteger(*it, "/version", 1, 1000000));
            if (scene.version != 1)
                refuse("/version", "this build reads version 1 files, got version " + std::to_string(scene.version));
        }
        if (auto it = root.find("world"); it != root.end()) readWorld(*it, scene.world);
        if (auto it = root.find("view"); it != root.end()) scene.view = readView(*it);
        const auto entitiesIt = root.find("entities");
        if (entitiesIt == root.end()) refuse("", "missing \"entities\": a level needs a list of entities");
        if (!entitiesIt->is_array())
            refuse("/entities", "expected an array of entities, got " + describeFound(*entitiesIt));
        scene.registry.reserve(entitiesIt->size());
        // Every entity exists, with its name known, before any component is
        // read: an entity reference may name an entity defined after it.
        EntityNames names;
        names.byName.reserve(entitiesIt->size());
        for (std::size_t i = 0; i < entitiesIt->size(); ++i) {
            const Entity e = scene.registry.create();
            const Json& entityJson = (*entitiesIt)[i];
            if (!entityJson.is_object()) continue;
            if (const auto it = entityJson.find("name"); it != entityJson.end() && it->is_string())
                names.byName.emplace(it->get<std::string>(), e);  // a duplicate is refused by checkSceneRelations
        }
        for (std::size_t i = 0; i < entitiesIt->size(); ++i)
            readEntity((*entitiesIt)[i], i, scene.registry, scene.registry.entities()[i], names);
        if (!names.unresolved.empty()) {
            const std::string& first = names.unresolved.front();
            const auto split = first.find(": ");
            refuse(first.substr(0, split), first.substr(split + 2));
        }
        if (auto it = root.find("solver_state"); it != root.end())
            scene.solverState = readSolverState(*it, scene.registry);
        // Free the DOM before the relation checks: peak memory is one copy.
        root = Json();
        if (const std::optional<Error> refused = checkSceneRelations(scene)) {
            const std::string& problem = refused->message;
            const auto split = problem.find(": ");
            refuse(problem.substr(0, split), problem.substr(split + 2));
        }
    } catch (const Refusal& r) {
        return Error{prefix + (r.pointer.empty() ? "" : r.pointer + ": ") + r.message};
    }

    // A spring without rest_length rests at its length as loaded.
    const auto& entities = scene.registry.entities();
    for (std::size_t i = 0; i < entities.size(); ++i) {
        Spring* s = scene.registry.tryGet<Spring>(entities[i]);
        if (!s || s->restLength) continue;
        const Vec2 a = scene.registry.tryGet<Position>(s->a)->value;
        const Vec2 b = s->anchor ? *s->anchor : scene.registry.tryGet<Position>(s->b)->value;
        const double rest = length(b - a);
        // Ends up to 2.8e30 m apart may be given, but the saved rest_length
        // must load again.
        if (!(rest <= kMaxMagnitude))
            return Error{prefix + child("/entities", i) + "/spring: the ends are " + formatNumber(rest) +
                         " m apart, past the " + formatNumber(kMaxMagnitude) +
                         " m a rest_length may be; give \"rest_length\""};
        s->restLength = rest;
    }
    for (std::size_t i = 0; i < entities.size(); ++i) {
        Joint* joint = scene.registry.tryGet<Joint>(entities[i]);
        if (!joint) continue;
        if (std::optional<Error> problem = completeJoint(scene.registry, *joint))
            return Error{prefix + child("/entities", i) + "/joint/" + problem->where + ": joint on " +
                         entityLabelOf(scene.registry, i) + ": " + problem->message};
    }
    return scene;
}

} // namespace

std::optional<Error> completeJoint(const Registry& registry, Joint& joint) {
    // Pose of an end: position and angle of a body, the identity for the world.
    struct Pose {
        Vec2 position;
        double angle = 0.0;
    };
    const auto poseOf = [&](Entity e) {
        Pose pose;
        if (e.isNull() || !registry.alive(e)) return pose;
        if (const Position* p = registry.tryGet<Position>(e)) pose.position = p->value;
        if (const Angle* an = registry.tryGet<Angle>(e)) pose.angle = an->value;
        return pose;
    };
    // World point of a local point, and back (rotation by the body's angle).
    const auto toWorld = [](const Pose& pose, Vec2 local) {
        const double c = std::cos(pose.angle), s = std::sin(pose.angle);
        return pose.position + Vec2{c * local.x - s * local.y, s * local.x + c * local.y};
    };
    const auto toLocal = [](const Pose& pose, Vec2 world) {
        const double c = std::cos(pose.angle), s = std::sin(pose.angle);
        const Vec2 d = world - pose.position;
        return Vec2{c * d.x + s * d.y, -s * d.x + c * d.y};
    };
    const Pose a = poseOf(joint.a), b = poseOf(joint.b);
    if (joint.anchor) {
        const Vec2 localA = toLocal(a, *joint.anchor), localB = toLocal(b, *joint.anchor);
        // Derived values are saved, so they must be what a level may hold.
        const auto inRange = [](Vec2 v) { return std::abs(v.x) <= kMaxMagnitude && std::abs(v.y) <= kMaxMagnitude; };
        if (!inRange(localA) || !inRange(localB))
            return Error{"too far from the bodies to express in their frames (past " + formatNumber(kMaxMagnitude) +
                             " m on an axis)",
                         "anchor"};
        joint.localA = localA;
        joint.localB = localB;
        joint.anchor.reset();
    }
    const bool angular = joint.type == "hinge" || joint.type == "slider" || joint.type == "weld";
    if (angular && !joint.referenceAngle) {
        const double reference = b.angle - a.angle;
        if (!(std::abs(reference) <= kMaxMagnitude))
            return Error{"the bodies' angles differ by more than " + formatNumber(kMaxMagnitude) +
                             " rad; give \"reference_angle\"",
                         "reference_angle"};
        joint.referenceAngle = reference;
    }
    const bool hasLength = joint.type == "distance" || joint.type == "rope";
    if (hasLength && !joint.length) {
        const double d = length(toWorld(b, joint.localB) - toWorld(a, joint.localA));
        // As a spring's rest length: the saved length must load again.
        if (!(d <= kMaxMagnitude))
            return Error{"the anchors are " + formatNumber(d) + " m apart, past the " + formatNumber(kMaxMagnitude) +
                             " m a length may be; give \"length\"",
                         "length"};
        joint.length = d;
    }
    return std::nullopt;
}

Result<Scene> parseScene(std::string_view text, std::string_view sourceName, const LoadLimits& limits) {
    Result<Scene> scene = parseSceneUnchecked(text, sourceName, limits);
    // Escaped first, then cut: escaping control bytes as \xNN makes a
    // message up to four times longer, so cutting first would let it pass
    // the 4,096-byte bound (a fuzzed key: 4,977 bytes).
    if (!scene) return Error{detail::shortenForMessage(printableMessage(scene.error()))};
    return scene;
}

namespace {

/// Appends `"solver_state": {...}` as the last key of the written root
/// object (`out` ends with its closing brace). One line per contact or
/// joint: a settled pile has thousands. Numbers read back to the same
/// double, so a resumed run is bit-identical. Entries naming an entity no
/// longer in the scene, or no longer a shape (a joint), are dropped; a
/// joint's impulses that are +0 are left out (absent reads as +0).
void appendSolverState(const SolverState& state, const Registry& registry, std::string& out) {
    std::unordered_map<Entity, std::size_t> indexOf;
    const auto& entities = registry.entities();
    for (std::size_t i = 0; i < entities.size(); ++i) indexOf.emplace(entities[i], i);
    // Gone, or no longer what the entry needs (edited since): the loader
    // would refuse the entry, and there is nothing it could warm anyway.
    auto ref = [&](Entity e, bool usable) -> std::optional<std::string> {
        const auto it = indexOf.find(e);
        if (it == indexOf.end() || !usable) return std::nullopt;
        if (const Name* n = registry.tryGet<Name>(e); n && !n->value.empty()) return Json(n->value).dump();
        return std::to_string(it->second);
    };
    const auto number = [](double v) { return Json(v).dump(); };
    out.erase(out.size() - 2);  // "\n}"
    out += ",\n  \"solver_state\": {\n";
    if (state.chosen) {
        out += "    \"chosen\": {\"substeps\": " + std::to_string(state.chosen->substeps) +
               ", \"solver_iterations\": " + std::to_string(state.chosen->solverIterations);
        if (state.chosen->contactHertzFraction)
            out += ", \"contact_hertz_fraction\": " + number(*state.chosen->contactHertzFraction);
        if (state.chosen->contactHertz) out += ", \"contact_hertz\": " + number(*state.chosen->contactHertz);
        out += "},\n";
    }
    out += "    \"contacts\": [";
    bool first = true;
    for (const ContactImpulse& c : state.contacts) {
        const std::optional<std::string> a = ref(c.a, collides(registry, c.a)), b = ref(c.b, collides(registry, c.b));
        if (!a || !b) continue;
        out += first ? "\n      " : ",\n      ";
        first = false;
        out += "{\"a\": " + *a + ", \"b\": " + *b + ", \"feature\": " + std::to_string(c.feature) +
               ", \"normal_impulse\": " + number(c.normalImpulse) + ", \"tangent_impulse\": " + number(c.tangentImpulse);
        if (c.shapeA != 0) out += ", \"shape_a\": " + std::to_string(c.shapeA);
        if (c.shapeB != 0) out += ", \"shape_b\": " + std::to_string(c.shapeB);
        out += "}";
    }
    out += first ? "]" : "\n    ]";
    if (!state.joints.empty()) {
        const auto plusZero = [](double v) { return v == 0.0 && !std::signbit(v); };
        out += ",\n    \"joints\": [";
        first = true;
        for (const JointImpulse& j : state.joints) {
            const std::optional<std::string> joint = ref(j.joint, registry.has<Joint>(j.joint));
            if (!joint) continue;
            out += first ? "\n      " : ",\n      ";
            first = false;
            out += "{\"joint\": " + *joint;
            if (!plusZero(j.linear.x) || !plusZero(j.linear.y))
                out += ", \"linear_impulse\": {\"x\": " + number(j.linear.x) + ", \"y\": " + number(j.linear.y) + "}";
            const std::pair<const char*, double> scalars[] = {{"angular_impulse", j.angular}, {"axial_impulse", j.axial},
                                                              {"motor_impulse", j.motor},     {"lower_impulse", j.lower},
                                                              {"upper_impulse", j.upper}};
            for (const auto& [key, value] : scalars)
                if (!plusZero(value)) out += ", \"" + std::string(key) + "\": " + number(value);
            out += "}";
        }
        out += first ? "]" : "\n    ]";
    }
    const auto dynamic = [&](Entity e) {
        const Static* st = registry.tryGet<Static>(e);
        return registry.has<Position>(e) && !(st && st->value);
    };
    bool anyBody = false;
    for (const BodySleep& b : state.bodies) {
        const std::optional<std::string> body = ref(b.body, dynamic(b.body));
        if (!body) continue;
        out += anyBody ? ",\n      " : ",\n    \"bodies\": [\n      ";
        anyBody = true;
        out += "{\"body\": " + *body + ", \"sleep_time\": " + number(b.sleepTime);
        if (b.stillAt)
            out += ", \"still_at\": {\"x\": " + number(b.stillAt->x) + ", \"y\": " + number(b.stillAt->y) +
                   "}, \"still_angle\": " + number(b.stillAngle);
        if (b.stillAt && b.stillVelocity)
            out += ", \"still_velocity\": {\"x\": " + number(b.stillVelocity->x) + ", \"y\": " +
                   number(b.stillVelocity->y) + "}";
        if (!b.island.isNull())
            if (const std::optional<std::string> island = ref(b.island, dynamic(b.island))) out += ", \"island\": " + *island;
        out += "}";
    }
    if (anyBody) out += "\n    ]";
    out += "\n  }\n}";
}

} // namespace

std::string sceneToJsonText(const Scene& scene) {
    Json root = Json::object();
    root["version"] = scene.version;
    Json world = Json::object();
    // Settings the file did not give stay absent (0 / no value), so a level
    // that leaves them to the engine keeps doing so after a save.
    for (const WorldFieldInfo& info : worldFieldTable())
        if (!info.isUnset(scene.world))
            world[std::string(info.field.key)] = fieldJson(info.field, &scene.world, scene.registry);
    root["world"] = std::move(world);
    if (scene.view) {
        Json view = Json::object();
        view["center"] = vectorJson(scene.view->center);
        view["zoom"] = scene.view->zoom;
        root["view"] = std::move(view);
    }
    Json entities = Json::array();
    const Registry& registry = scene.registry;
    for (const Entity e : registry.entities()) {
        Json entity = Json::object();
        for (const ComponentInfo& info : componentTable()) {
            const void* component = info.getConst(registry, e);
            if (!component) continue;
            if (info.inlineValue) {
                entity[std::string(info.name)] = fieldJson(info.fields.front(), component, registry);
                continue;
            }
            Json object = Json::object();
            for (const FieldInfo& field : info.fields) {
                Json value = fieldJson(field, component, registry);
                if (!value.is_discarded()) object[std::string(field.key)] = std::move(value);
            }
            entity[std::string(info.name)] = std::move(object);
        }
        entities.push_back(std::move(entity));
    }
    root["entities"] = std::move(entities);
    std::string out;
    writeJson(root, 0, out);
    if (scene.solverState) appendSolverState(*scene.solverState, registry, out);
    out += "\n";
    return out;
}

} // namespace stepwise
