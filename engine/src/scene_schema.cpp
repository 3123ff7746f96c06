// JSON Schema of the level format, generated from the component table so the
// schema can never disagree with the loader about names, kinds or ranges.

#include "stepwise/component_table.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world_fields.hpp"

#include <nlohmann/json.hpp>

#include <cmath>

namespace stepwise {

namespace {

using Json = nlohmann::ordered_json;

Json numberSchema(const NumberRange& range, std::string_view description) {
    Json j = Json::object();
    j["type"] = "number";
    if (std::isfinite(range.min)) j[range.minExclusive ? "exclusiveMinimum" : "minimum"] = range.min;
    if (std::isfinite(range.max)) j["maximum"] = range.max;
    if (!description.empty()) j["description"] = description;
    return j;
}

Json ref(const char* name) { return Json{{"$ref", std::string("#/$defs/") + name}}; }

Json fieldSchema(const FieldInfo& f) {
    Json j;
    switch (f.kind) {
    case FieldKind::Number:
    case FieldKind::OptionalNumber: return numberSchema(f.range, f.description);
    case FieldKind::Integer:
        j = Json{{"type", "integer"}};
        if (std::isfinite(f.range.min)) j[f.range.minExclusive ? "exclusiveMinimum" : "minimum"] = long(f.range.min);
        if (std::isfinite(f.range.max)) j["maximum"] = long(f.range.max);
        break;
    case FieldKind::Bits: j = Json{{"type", "integer"}, {"minimum", 0}, {"maximum", 4294967295u}}; break;
    case FieldKind::Vector:
    case FieldKind::OptionalVector:
        // Speeds have a tighter bound than the shared vector's.
        j = f.range.min == kAnyMagnitude.min && f.range.max == kAnyMagnitude.max ? ref("vector") : ref("speed");
        break;
    case FieldKind::Color: j = ref("color"); break;
    case FieldKind::Bool: j = Json{{"type", "boolean"}}; break;
    case FieldKind::String:
        j = Json{{"type", "string"}};
        if (!f.choices.empty()) {
            Json names = Json::array();
            for (std::string_view c : f.choices) names.push_back(std::string(c));
            j["enum"] = names;
        }
        break;
    case FieldKind::EntityRef: j = Json{{"type", "string"}, {"minLength", 1}}; break;
    case FieldKind::ShapeList: {
        const auto object = [](Json properties, const char* description) {
            return Json{{"type", "object"}, {"description", description}, {"properties", std::move(properties)},
                        {"additionalProperties", false}};
        };
        const Json size{{"type", "number"}, {"exclusiveMinimum", 0}};
        const Json number{{"type", "number"}};
        Json item = object(
            Json{{"circle", object(Json{{"center", ref("vector")}, {"radius", size}}, "circle: centre in the body frame, m")},
                 {"box", object(Json{{"center", ref("vector")}, {"width", size}, {"height", size}, {"angle", number}},
                                "box: centre in the body frame, full sizes (m), turn in the body frame (rad)")},
                 {"polygon", object(Json{{"vertices", Json{{"type", "array"}, {"items", ref("vector")}, {"minItems", 3},
                                                           {"maxItems", 8}}},
                                         {"radius", Json{{"type", "number"}, {"minimum", 0}}}},
                                    "convex polygon: 3 to 8 vertices in the body frame, counter-clockwise, its "
                                    "corners rounded by radius (m)")},
                 {"capsule", object(Json{{"a", ref("vector")}, {"b", ref("vector")}, {"radius", size}},
                                    "capsule: a segment in the body frame swept by a radius")},
                 {"density", Json{{"type", "number"}, {"exclusiveMinimum", 0}, {"description", "kg/m^2; absent: 1"}}},
                 {"friction", Json{{"type", "number"}, {"minimum", 0}}},
                 {"restitution", Json{{"type", "number"}, {"minimum", 0}, {"maximum", 1}}},
                 {"sensor", Json{{"type", "boolean"}}},
                 {"filter", object(Json{{"category", Json{{"type", "integer"}, {"minimum", 0}, {"maximum", 4294967295u}}},
                                        {"mask", Json{{"type", "integer"}, {"minimum", 0}, {"maximum", 4294967295u}}},
                                        {"group", Json{{"type", "integer"}}}},
                                   "this shape's collision filter")}},
            "one shape: exactly one of circle, box, polygon, capsule, with its own material");
        item["oneOf"] = Json::array({Json{{"required", Json::array({"circle"})}}, Json{{"required", Json::array({"box"})}},
                                     Json{{"required", Json::array({"polygon"})}},
                                     Json{{"required", Json::array({"capsule"})}}});
        j = Json{{"type", "array"}, {"items", item}, {"minItems", int(f.range.min)}, {"maxItems", int(f.range.max)}};
        break;
    }
    case FieldKind::IntegerList: {
        Json item{{"type", "integer"}};
        if (std::isfinite(f.range.min)) item["minimum"] = std::int64_t(f.range.min);
        if (std::isfinite(f.range.max)) item["maximum"] = std::int64_t(f.range.max);
        j = Json{{"type", "array"}, {"items", item}};
        break;
    }
    case FieldKind::VectorList:
        j = Json{{"type", "array"}, {"items", ref("vector")}};
        if (std::isfinite(f.range.min)) j["minItems"] = int(f.range.min);
        if (std::isfinite(f.range.max)) j["maxItems"] = int(f.range.max);
        break;
    }
    if (!f.description.empty()) j["description"] = f.description;
    return j;
}

Json axesSchema(std::initializer_list<const char*> axes, Json axis, const char* description) {
    Json properties = Json::object();
    for (const char* a : axes) properties[a] = axis;
    return Json{{"type", "object"},
                {"description", description},
                {"properties", properties},
                {"additionalProperties", false}};
}

} // namespace

std::string sceneJsonSchema() {
    Json defs = Json::object();
    const auto axis = [](const NumberRange& r) {
        return Json{{"type", "number"}, {"minimum", r.min}, {"maximum", r.max}};
    };
    defs["vector"] = axesSchema({"x", "y"}, axis(kAnyMagnitude), "2D vector; a missing axis is 0");
    defs["speed"] = axesSchema({"x", "y"}, axis(kAnySpeed), "2D velocity, m/s; a missing axis is 0");
    defs["color"] = axesSchema({"x", "y", "z"}, Json{{"type", "number"}, {"minimum", 0}, {"maximum", 1}},
                               "RGB colour, channels in 0..1");

    Json components = Json::object();
    for (const ComponentInfo& info : componentTable()) {
        Json c;
        if (info.inlineValue) {
            c = fieldSchema(info.fields.front());
            c["description"] = info.description;
        } else {
            Json properties = Json::object();
            for (const FieldInfo& f : info.fields) properties[std::string(f.key)] = fieldSchema(f);
            c = Json{{"type", "object"},
                     {"description", info.description},
                     {"properties", properties},
                     {"additionalProperties", false}};
            if (info.name == "joint") c["required"] = Json::array({"type", "a"});
            if (info.name == "spring") {
                c["required"] = Json::array({"a"});
                c["oneOf"] = Json::array({Json{{"required", Json::array({"b"})}},
                                          Json{{"required", Json::array({"anchor"})}}});
            }
        }
        components[std::string(info.name)] = c;
    }
    defs["entity"] = Json{{"type", "object"},
                          {"description", "an entity: one key per component"},
                          {"properties", components},
                          {"additionalProperties", false}};

    // The world object from the world-settings table: the loader reads the
    // same rows, so the two cannot disagree about keys or ranges.
    Json worldProperties = Json::object();
    const WorldSettings defaults;
    for (const WorldFieldInfo& info : worldFieldTable()) {
        Json property = fieldSchema(info.field);
        if (!info.field.unit.empty())
            property["description"] = std::string(info.field.description) + " [" + std::string(info.field.unit) + "]";
        // Defaults of the scalar settings a file may leave out (the optional
        // ones have none: the engine chooses).
        const void* member = info.field.address(const_cast<WorldSettings*>(&defaults));
        if (!info.optional) {
            if (info.field.kind == FieldKind::Number) property["default"] = *static_cast<const double*>(member);
            if (info.field.kind == FieldKind::String) property["default"] = *static_cast<const std::string*>(member);
        }
        worldProperties[std::string(info.field.key)] = std::move(property);
    }
    Json world = Json{{"type", "object"}, {"additionalProperties", false}, {"properties", worldProperties}};
    Json view = Json{{"type", "object"},
                     {"description", "camera: centre in metres, zoom in pixels per metre at 720 px image height"},
                     {"additionalProperties", false},
                     {"properties", Json{{"center", ref("vector")},
                                         {"zoom", Json{{"type", "number"}, {"exclusiveMinimum", 0}}}}}};

    const Json entityRef = Json{
        {"description", "an entity's name, or its index in entities when it has no name"},
        {"oneOf", Json::array({Json{{"type", "string"}}, Json{{"type", "integer"}, {"minimum", 0}}})}};
    Json contact = Json{
        {"type", "object"},
        {"description", "accumulated impulses of one contact point at the end of the last step (warm start)"},
        {"additionalProperties", false},
        {"required", Json::array({"a", "b", "feature", "normal_impulse", "tangent_impulse"})},
        {"properties", Json{{"a", entityRef},
                            {"b", entityRef},
                            {"feature", Json{{"type", "integer"}, {"minimum", 0}, {"maximum", 65535}}},
                            {"normal_impulse", Json{{"type", "number"}, {"minimum", 0}, {"description", "N*s; a contact only pushes"}}},
                            {"tangent_impulse", Json{{"type", "number"}, {"description", "N*s"}}},
                            {"shape_a", Json{{"type", "integer"}, {"minimum", 0}, {"maximum", 255},
                                             {"description", "a's shape in its shapes list (compound bodies); absent: 0"}}},
                            {"shape_b", Json{{"type", "integer"}, {"minimum", 0}, {"maximum", 255},
                                             {"description", "b's shape in its shapes list (compound bodies); absent: 0"}}}}}};
    const auto impulse = [](const char* description) {
        return Json{{"type", "number"}, {"description", description}};
    };
    const auto oneSided = [](const char* description) {
        return Json{{"type", "number"}, {"minimum", 0}, {"description", description}};
    };
    Json joint = Json{
        {"type", "object"},
        {"description", "accumulated impulses of one joint at the end of the last step (warm start); an impulse "
                        "left out is 0, and a joint without an entry starts from zero"},
        {"additionalProperties", false},
        {"required", Json::array({"joint"})},
        {"properties",
         Json{{"joint", entityRef},
              {"linear_impulse", Json{{"$ref", "#/$defs/vector"},
                                      {"description", "hinge, weld: the shared point, N*s; slider: (across the axis "
                                                      "N*s, relative rotation N*m*s); wheel: (across the axis N*s, 0)"}}},
              {"angular_impulse", impulse("weld: relative rotation; hinge: its spring (spring_hz), N*m*s")},
              {"axial_impulse", impulse("distance: along the anchors' line; wheel: its axis spring, N*s")},
              {"motor_impulse", impulse("hinge and wheel motor N*m*s, slider motor N*s")},
              {"lower_impulse", oneSided("hinge, slider, wheel: lower limit")},
              {"upper_impulse", oneSided("hinge, slider, wheel: upper limit; rope: its pull, N*s")}}}};
    Json bodySleep = Json{
        {"type", "object"},
        {"description", "one dynamic body's sleep state: seconds it has been still and, while it sleeps, its island "
                        "(one of the island's bodies); an awake body with no time still has no entry"},
        {"additionalProperties", false},
        {"required", Json::array({"body"})},
        {"properties", Json{{"body", entityRef},
                            {"sleep_time", Json{{"type", "number"}, {"minimum", 0}, {"description", "s"}}},
                            {"still_at", Json{{"$ref", "#/$defs/vector"},
                                              {"description", "where its still window began, m"}}},
                            {"still_angle", Json{{"type", "number"}, {"description", "its angle then, rad"}}},
                            {"still_velocity", Json{{"$ref", "#/$defs/vector"},
                                                    {"description", "its velocity at the window's middle (latest until then), m/s; absent: its velocity now"}}},
                            {"island", entityRef}}}};
    Json solverState = Json{
        {"type", "object"},
        {"description", "what the solver carries between steps, written with a running state (stepwise run --out, the "
                        "editor's Save simulation state) so that a resumed run is bit-identical; absent: a cold start"},
        {"additionalProperties", false},
        {"properties", Json{{"chosen", Json{{"type", "object"},
                                            {"description", "what the engine chose for the run, run again on resume: the "
                                                            "substeps and solver_iterations of a level that leaves them "
                                                            "out, and the contacts' stiffness cap and stiffness"},
                                            {"additionalProperties", false},
                                            {"required", Json::array({"substeps", "solver_iterations"})},
                                            {"properties", Json{{"substeps", Json{{"type", "integer"}, {"minimum", 1}, {"maximum", 1000}}},
                                                                {"solver_iterations", Json{{"type", "integer"}, {"minimum", 1}, {"maximum", 1000}}},
                                                                {"contact_hertz_fraction",
                                                                 Json{{"type", "number"}, {"exclusiveMinimum", 0}, {"maximum", 0.25},
                                                                      {"description", "the contacts' stiffness cap as a fraction of the "
                                                                                      "substep rate (1/4, or 1/8 for a deep column)"}}},
                                                                {"contact_hertz",
                                                                 Json{{"type", "number"}, {"minimum", 60}, {"maximum", 1e9},
                                                                      {"description", "the contacts' stiffness, Hz, when the engine raised "
                                                                                      "it above 60 for a tall stack or a strong load "
                                                                                      "(absent: 60)"}}}}}}},
                            {"contacts", Json{{"type", "array"}, {"items", contact}}},
                            {"joints", Json{{"type", "array"}, {"items", joint}}},
                            {"bodies", Json{{"type", "array"}, {"items", bodySleep}}}}}};

    Json schema = Json::object();
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema";
    schema["title"] = "Stepwise level";
    schema["description"] = "Generated by `stepwise schema` from the component table. See docs/format.md.";
    schema["type"] = "object";
    schema["required"] = Json::array({"entities"});
    schema["additionalProperties"] = false;
    schema["properties"] = Json{{"version", Json{{"const", 1}}},
                                {"world", world},
                                {"view", view},
                                {"entities", Json{{"type", "array"}, {"items", ref("entity")}}},
                                {"solver_state", solverState}};
    schema["$defs"] = defs;
    return schema.dump(2) + "\n";
}

} // namespace stepwise
