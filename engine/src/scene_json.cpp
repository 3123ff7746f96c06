// Level files: text -> Scene and Scene -> text, driven by the component
// table. One message per refused file, naming where (JSON Pointer or
// line:column) and what was expected and found.

#include "stepwise/scene_io.hpp"

#include "stepwise/component_table.hpp"
#include "stepwise/components.hpp"
#include "stepwise/integrators.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <sstream>

namespace stepwise {

namespace {

using Json = nlohmann::ordered_json;

/// Thrown inside the walk and caught in parseScene; never escapes.
struct Refusal {
    std::string pointer;  ///< JSON Pointer of the bad value ("" = whole file)
    std::string message;
};

std::string escapePointerToken(std::string_view token) {
    std::string out;
    for (char c : token) {
        if (c == '~') out += "~0";
        else if (c == '/') out += "~1";
        else out += c;
    }
    return out;
}

std::string child(const std::string& pointer, std::string_view key) {
    return pointer + "/" + escapePointerToken(key);
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

[[noreturn]] void refuse(std::string pointer, std::string message) {
    throw Refusal{std::move(pointer), std::move(message)};
}

double readNumber(const Json& v, const std::string& pointer, const NumberRange& range) {
    if (!v.is_number()) refuse(pointer, "expected " + range.describe() + ", got " + describeFound(v));
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

Vec2 readVector(const Json& v, const std::string& pointer) {
    const auto a = readAxes<2>(v, pointer, NumberRange{}, "a vector {\"x\": number, \"y\": number}");
    return {a[0], a[1]};
}

Rgb readColor(const Json& v, const std::string& pointer, const NumberRange& range) {
    const auto a = readAxes<3>(v, pointer, range, "a colour {\"x\": r, \"y\": g, \"z\": b} in 0..1");
    return {a[0], a[1], a[2]};
}

void readField(const FieldInfo& field, const Json& v, void* component, const std::string& pointer) {
    void* member = field.address(component);
    switch (field.kind) {
    case FieldKind::Number: *static_cast<double*>(member) = readNumber(v, pointer, field.range); break;
    case FieldKind::OptionalNumber:
        *static_cast<std::optional<double>*>(member) = readNumber(v, pointer, field.range);
        break;
    case FieldKind::Vector: *static_cast<Vec2*>(member) = readVector(v, pointer); break;
    case FieldKind::OptionalVector:
        *static_cast<std::optional<Vec2>*>(member) = readVector(v, pointer);
        break;
    case FieldKind::Color: *static_cast<Rgb*>(member) = readColor(v, pointer, field.range); break;
    case FieldKind::Bool: *static_cast<bool*>(member) = readBool(v, pointer); break;
    case FieldKind::String:
    case FieldKind::EntityName: {
        std::string s = readString(v, pointer);
        if (field.kind == FieldKind::EntityName && s.empty())
            refuse(pointer, "expected the name of an entity, got \"\"");
        *static_cast<std::string*>(member) = std::move(s);
        break;
    }
    }
}

Json vectorJson(Vec2 v) {
    Json j = Json::object();
    j["x"] = v.x;
    j["y"] = v.y;
    return j;
}

/// Field value as JSON, or a discarded value when the field is absent.
Json fieldJson(const FieldInfo& field, const void* component) {
    const void* member = field.address(const_cast<void*>(component));
    switch (field.kind) {
    case FieldKind::Number: return *static_cast<const double*>(member);
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
    case FieldKind::String: return *static_cast<const std::string*>(member);
    case FieldKind::EntityName: {
        const auto& s = *static_cast<const std::string*>(member);
        return s.empty() ? Json(Json::value_t::discarded) : Json(s);
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
                   const std::string& pointer) {
    void* component = info.emplaceDefault(registry, e);
    if (info.inlineValue) {
        readField(info.fields.front(), value, component, pointer);
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
                std::string message = "unknown field \"" + key + "\" in \"" + std::string(info.name) + "\"";
                if (auto guess = closestName(key, known)) message += "; did you mean \"" + std::string(*guess) + "\"?";
                refuse(child(pointer, key), message + " Known fields: " + joinNames(known));
            }
            readField(*it, fieldValue, component, child(pointer, key));
        }
    }
    if (info.finish) {
        const std::string problem = info.finish(component);
        if (!problem.empty()) {
            const auto colon = problem.find(':');
            const std::string where = problem.substr(0, colon);
            refuse(where.empty() ? pointer : child(pointer, where), problem.substr(colon + 2));
        }
    }
}

void readEntity(const Json& entityJson, std::size_t index, Registry& registry) {
    const std::string pointer = child("/entities", index);
    if (!entityJson.is_object())
        refuse(pointer, "expected an entity object {\"component\": value, ...}, got " + describeFound(entityJson));
    const Entity e = registry.create();
    for (const auto& [key, value] : entityJson.items()) {
        const ComponentInfo* info = findComponent(key);
        if (!info) {
            const auto known = componentNames();
            std::string message = "unknown component \"" + key + "\" on " + entityLabel(index, entityJson);
            if (auto guess = closestName(key, known)) message += "; did you mean \"" + std::string(*guess) + "\"?";
            refuse(child(pointer, key), message + " Known components: " + joinNames(known));
        }
        readComponent(*info, value, registry, e, child(pointer, key));
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

void readWorld(const Json& v, WorldSettings& world) {
    const std::string pointer = "/world";
    if (!v.is_object()) refuse(pointer, "expected an object, got " + describeFound(v));
    static constexpr std::array<std::string_view, 8> kKeys{"gravity",  "G",    "integrator",        "dt",
                                                           "substeps", "time", "solver_iterations", "restitution_threshold"};
    for (const auto& [key, value] : v.items()) {
        const std::string at = child(pointer, key);
        if (key == "gravity") world.gravity = readVector(value, at);
        else if (key == "G") world.G = readNumber(value, at, NumberRange{});
        else if (key == "dt") world.dt = readNumber(value, at, NumberRange{0.0, 10.0, true});
        else if (key == "substeps") world.substeps = int(readInteger(value, at, 1, 1000));
        else if (key == "time") world.time = readNumber(value, at, NumberRange{});
        else if (key == "solver_iterations") world.solverIterations = int(readInteger(value, at, 1, 1000));
        else if (key == "restitution_threshold") world.restitutionThreshold = readNumber(value, at, NumberRange{0.0, 1e6});
        else if (key == "integrator") {
            std::string name = readString(value, at);
            if (!isIntegratorName(name)) {
                std::string message = "unknown integrator \"" + name + "\"";
                if (auto guess = closestName(name, integratorNames()))
                    message += "; did you mean \"" + std::string(*guess) + "\"?";
                refuse(at, message + " Known integrators: " + joinNames(integratorNames()));
            }
            world.integrator = std::move(name);
        } else {
            std::string message = "unknown world setting \"" + key + "\"";
            if (auto guess = closestName(key, kKeys)) message += "; did you mean \"" + std::string(*guess) + "\"?";
            refuse(at, message + " Known settings: " + joinNames(kKeys));
        }
    }
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

/// 1-based line and column (in bytes) of byte offset `offset`.
std::pair<std::size_t, std::size_t> lineColumn(std::string_view text, std::size_t offset) {
    offset = std::min(offset, text.size());
    std::size_t line = 1, column = 1;
    for (std::size_t i = 0; i < offset; ++i) {
        if (text[i] == '\n') {
            ++line;
            column = 1;
        } else {
            ++column;
        }
    }
    return {line, column};
}

/// Message for a JSON syntax error at byte `offset` (0-based, at the
/// offending character), with hints for the two mistakes people make most.
std::string syntaxMessage(std::string_view text, std::size_t offset, std::string_view sourceName,
                          std::string detail) {
    // Typographic quotes (U+2018/2019/201C/201D, UTF-8 E2 80 98..9D) pasted
    // from slides: point at the first one, wherever the parser gave up.
    for (std::size_t i = 0; i + 2 < text.size(); ++i) {
        if (static_cast<unsigned char>(text[i]) == 0xE2 && static_cast<unsigned char>(text[i + 1]) == 0x80) {
            const unsigned char c = static_cast<unsigned char>(text[i + 2]);
            if (c == 0x9C || c == 0x9D || c == 0x98 || c == 0x99) {
                const auto [line, column] = lineColumn(text, i);
                const bool dbl = c == 0x9C || c == 0x9D;
                return std::string(sourceName) + ":" + std::to_string(line) + ":" + std::to_string(column) +
                       ": error: typographic quote " + std::string(text.substr(i, 3)) +
                       " where JSON needs a straight quote " + (dbl ? "\"" : "\" (JSON strings use double quotes)") +
                       "; text pasted from slides or a word processor has these. Replace every “ ” ‘ ’ with \"";
            }
        }
    }
    // Trailing comma: the parser stops at '}' or ']' right after a ','.
    if (offset < text.size() && (text[offset] == '}' || text[offset] == ']')) {
        std::size_t j = offset;
        while (j > 0 && std::isspace(static_cast<unsigned char>(text[j - 1]))) --j;
        if (j > 0 && text[j - 1] == ',') {
            const auto [line, column] = lineColumn(text, j - 1);
            return std::string(sourceName) + ":" + std::to_string(line) + ":" + std::to_string(column) +
                   ": error: trailing comma before '" + text[offset] +
                   "'; JSON allows no comma after the last element. Remove this comma";
        }
    }
    const auto [line, column] = lineColumn(text, offset);
    return std::string(sourceName) + ":" + std::to_string(line) + ":" + std::to_string(column) + ": error: " + detail;
}

/// The part of nlohmann's parse_error text after its "line L, column C: "
/// prefix (we compute line and column ourselves, in bytes).
std::string parserDetail(const std::string& what) {
    const auto pos = what.find(": ", what.find("parse error"));
    std::string detail = pos == std::string::npos ? what : what.substr(pos + 2);
    return detail.empty() ? "not valid JSON" : detail;
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
/// characters; such bytes are shown as \xNN (found by fuzzing).
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

} // namespace

std::string checkSceneRelations(const Scene& scene) {
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
        const int shapes = int(registry.has<Radius>(e)) + int(registry.has<Box>(e)) + int(registry.has<Plane>(e));
        if (shapes > 1)
            return child("/entities", i) + ": an entity has at most one shape (radius, box or plane), got " +
                   std::to_string(shapes);
        if (registry.has<Plane>(e) && registry.has<Position>(e))
            return child("/entities", i) + "/position: a plane is placed by its normal and offset, not a position";
        const Spring* spring = registry.tryGet<Spring>(e);
        if (!spring) continue;
        if (registry.has<Position>(e))
            return child("/entities", i) + "/position: a spring entity has no body of its own; remove \"position\"";
        for (const auto& [end, key] : {std::pair{&spring->a, "a"}, std::pair{&spring->b, "b"}}) {
            if (end->empty()) continue;
            const auto it = indexByName.find(*end);
            const std::string at = child("/entities", i) + "/spring/" + key;
            if (it == indexByName.end()) return at + ": no entity is named \"" + *end + "\"";
            if (!registry.has<Position>(entities[it->second]))
                return at + ": entity \"" + *end + "\" has no position, so a spring cannot attach to it";
        }
    }
    return {};
}

namespace {

/// Thrown by LimitedDomParser when a limit is passed; caught in parseScene.
struct LimitHit {
    std::string message;
};

/// nlohmann's DOM builder (the one Json::parse uses) with the loader's
/// limits checked on the way: nesting depth on every container, and the
/// entity count on every object that opens inside the top-level
/// "entities" array. Errors are thrown as by Json::parse.
class LimitedDomParser {
public:
    using Dom = nlohmann::detail::json_sax_dom_parser<Json>;

    LimitedDomParser(Json& root, const LoadLimits& limits) : dom_(root, /*allow_exceptions=*/true), limits_(limits) {}

    bool null() { return dom_.null(); }
    bool boolean(bool v) { return dom_.boolean(v); }
    bool number_integer(Json::number_integer_t v) { return dom_.number_integer(v); }
    bool number_unsigned(Json::number_unsigned_t v) { return dom_.number_unsigned(v); }
    bool number_float(Json::number_float_t v, const Json::string_t& s) { return dom_.number_float(v, s); }
    bool string(Json::string_t& v) { return dom_.string(v); }
    bool binary(Json::binary_t& v) { return dom_.binary(v); }
    bool key(Json::string_t& k) {
        if (open_ == 1) rootKey_ = k;
        return dom_.key(k);
    }
    bool start_object(std::size_t n) {
        enter();
        if (open_ == 3 && inEntities_ && ++entities_ > limits_.maxEntities)
            throw LimitHit{"more than " + std::to_string(limits_.maxEntities) + " entities; the limit is " +
                           std::to_string(limits_.maxEntities)};
        return dom_.start_object(n);
    }
    bool end_object() {
        --open_;
        return dom_.end_object();
    }
    bool start_array(std::size_t n) {
        enter();
        if (open_ == 2 && rootKey_ == "entities") inEntities_ = true;
        return dom_.start_array(n);
    }
    bool end_array() {
        if (open_ == 2) inEntities_ = false;
        --open_;
        return dom_.end_array();
    }
    template <class Exception>
    bool parse_error(std::size_t position, const std::string& token, const Exception& e) {
        return dom_.parse_error(position, token, e);
    }

private:
    void enter() {
        // open_ counts the containers open including this one: the root
        // object is level 1, an entity level 3, a vector in it level 4.
        if (++open_ > limits_.maxDepth)
            throw LimitHit{"JSON nesting deeper than " + std::to_string(limits_.maxDepth) +
                           " levels; a level file needs 4"};
    }

    Dom dom_;
    const LoadLimits& limits_;
    int open_ = 0;
    std::string rootKey_;
    bool inEntities_ = false;
    std::size_t entities_ = 0;
};

Result<Scene> parseSceneUnchecked(std::string_view text, std::string_view sourceName, const LoadLimits& limits) {
    const std::string prefix = std::string(sourceName) + ": error: ";
    if (text.size() > limits.maxFileBytes)
        return Error{prefix + "file is " + std::to_string(text.size()) + " bytes; the limit is " +
                     std::to_string(limits.maxFileBytes) + " bytes"};

    // The depth and entity limits are enforced while parsing, so a hostile
    // file is refused before its DOM is built. Not with nlohmann's parser
    // callback: after every value it scans the whole enclosing array for a
    // discarded element, so 1,000,001 entities took 3 minutes to refuse
    // (quadratic; 200,000 took 7 s). LimitedDomParser forwards to the plain
    // DOM builder, which is linear.
    Json root;
    try {
        LimitedDomParser sax(root, limits);
        Json::sax_parse(text.begin(), text.end(), &sax, nlohmann::detail::input_format_t::json, /*strict=*/true,
                        /*ignore_comments=*/false);
    } catch (const LimitHit& hit) {
        return Error{prefix + hit.message};
    } catch (const Json::parse_error& e) {
        // e.byte is 1-based and points just past the offending character.
        const std::size_t offset = e.byte > 0 ? e.byte - 1 : 0;
        return Error{syntaxMessage(text, offset, sourceName, parserDetail(e.what()))};
    } catch (const Json::out_of_range& e) {
        // A number literal beyond double range (1e999): nlohmann names the
        // literal but not its position, so find the literal in the text.
        const std::string what = e.what();
        const auto open = what.find('\''), close = what.rfind('\'');
        const std::string literal =
            open != std::string::npos && close > open ? what.substr(open + 1, close - open - 1) : std::string();
        const std::size_t at = literal.empty() ? std::string_view::npos : text.find(literal);
        const auto [line, column] = lineColumn(text, at == std::string_view::npos ? 0 : at);
        return Error{std::string(sourceName) + ":" + std::to_string(line) + ":" + std::to_string(column) +
                     ": error: number " + literal + " is out of double range; expected a finite number"};
    } catch (const Json::exception& e) {
        return Error{prefix + "not a valid level: " + e.what()};
    }

    Scene scene;
    try {
        if (!root.is_object())
            refuse("", "expected a level object {\"entities\": [...]}, got " + describeFound(root));
        static constexpr std::array<std::string_view, 4> kTopKeys{"version", "world", "view", "entities"};
        for (const auto& [key, value] : root.items()) {
            if (std::find(kTopKeys.begin(), kTopKeys.end(), key) == kTopKeys.end()) {
                std::string message = "unknown top-level key \"" + key + "\"";
                if (auto guess = closestName(key, kTopKeys)) message += "; did you mean \"" + std::string(*guess) + "\"?";
                refuse(child("", key), message + " Known keys: " + joinNames(kTopKeys));
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
        for (std::size_t i = 0; i < entitiesIt->size(); ++i) readEntity((*entitiesIt)[i], i, scene.registry);
        // Free the DOM before the relation checks: peak memory is one copy.
        root = Json();
        if (std::string problem = checkSceneRelations(scene); !problem.empty()) {
            const auto split = problem.find(": ");
            refuse(problem.substr(0, split), problem.substr(split + 2));
        }
    } catch (const Refusal& r) {
        return Error{prefix + (r.pointer.empty() ? "" : r.pointer + ": ") + r.message};
    }

    // A spring without rest_length rests at its length as loaded.
    std::map<std::string, Vec2> positionByName;
    scene.registry.each<Name, Position>([&](Entity, const Name& n, const Position& p) {
        positionByName.emplace(n.value, p.value);
    });
    const auto& entities = scene.registry.entities();
    for (std::size_t i = 0; i < entities.size(); ++i) {
        Spring* s = scene.registry.tryGet<Spring>(entities[i]);
        if (!s || s->restLength) continue;
        const Vec2 a = positionByName.at(s->a);
        const Vec2 b = s->anchor ? *s->anchor : positionByName.at(s->b);
        const double rest = length(b - a);
        // Ends more than about 1e154 m apart: the squared length overflows,
        // and an infinite rest_length would be saved as null, which does not
        // load. The force code computes the length the same way.
        if (!std::isfinite(rest))
            return Error{prefix + child("/entities", i) +
                         "/spring: the ends are too far apart to compute the length (over 1e154 m); give "
                         "\"rest_length\""};
        s->restLength = rest;
    }
    return scene;
}

} // namespace

Result<Scene> parseScene(std::string_view text, std::string_view sourceName, const LoadLimits& limits) {
    Result<Scene> scene = parseSceneUnchecked(text, sourceName, limits);
    if (!scene) return Error{printableMessage(scene.error())};
    return scene;
}

std::string sceneToJsonText(const Scene& scene) {
    Json root = Json::object();
    root["version"] = scene.version;
    Json world = Json::object();
    world["gravity"] = vectorJson(scene.world.gravity);
    world["G"] = scene.world.G;
    world["integrator"] = scene.world.integrator;
    world["dt"] = scene.world.dt;
    // Settings the file did not give stay absent (0 / no value), so a level
    // that leaves them to the engine keeps doing so after a save.
    if (scene.world.substeps > 0) world["substeps"] = scene.world.substeps;
    world["time"] = scene.world.time;
    if (scene.world.solverIterations > 0) world["solver_iterations"] = scene.world.solverIterations;
    if (scene.world.restitutionThreshold) world["restitution_threshold"] = *scene.world.restitutionThreshold;
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
                entity[std::string(info.name)] = fieldJson(info.fields.front(), component);
                continue;
            }
            Json object = Json::object();
            for (const FieldInfo& field : info.fields) {
                Json value = fieldJson(field, component);
                if (!value.is_discarded()) object[std::string(field.key)] = std::move(value);
            }
            entity[std::string(info.name)] = std::move(object);
        }
        entities.push_back(std::move(entity));
    }
    root["entities"] = std::move(entities);
    std::string out;
    writeJson(root, 0, out);
    out += "\n";
    return out;
}

} // namespace stepwise
