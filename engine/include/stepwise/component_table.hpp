#pragma once
/// \file component_table.hpp
/// The one table of components. Each entry names a component, lists its
/// fields (JSON key, kind, valid range, unit) and carries type-erased
/// registry operations. The loader, the saver, the validator, the JSON
/// schema generator and the editor's inspector all read this table; there is
/// no if/else chain over component names anywhere.

#include "stepwise/entity.hpp"
#include "stepwise/registry.hpp"
#include "stepwise/result.hpp"

#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace stepwise {

/// What a field holds; decides how it is read, written, checked and edited.
enum class FieldKind {
    Number,          ///< double
    /// int, a JSON integer; `range` bounds it (world settings such as
    /// substeps; no component field is an integer)
    Integer,
    OptionalNumber,  ///< std::optional<double>; absent in JSON = nullopt
    Vector,          ///< Vec2, JSON {"x","y"}
    OptionalVector,  ///< std::optional<Vec2>
    Color,           ///< Rgb, JSON {"x","y","z"}, channels in 0..1
    Bool,            ///< bool
    String,          ///< std::string, free text
    /// Entity handle to another entity (null = absent). In files it is that
    /// entity's name: the loader resolves names to handles once, after every
    /// entity exists, and the saver writes the current name, so a rename
    /// never breaks the reference.
    EntityRef,
    /// std::vector<Vec2>, JSON [{"x","y"}, ...]; `range` bounds the count
    VectorList,
    /// std::uint32_t bit field, a JSON integer in [0, 2^32 - 1] (collision
    /// categories and masks); every value is valid
    Bits,
    /// std::vector<int>, JSON [n, ...] (an emitter's copy numbers); each
    /// item within `range`; written only when not empty
    IntegerList,
    /// std::vector<CompoundShape> (the `shapes` component), JSON
    /// [{"circle"|"box"|"polygon"|"capsule": {...}, ...}, ...]; `range`
    /// bounds the count
    ShapeList,
};

/// Inclusive/exclusive bounds for Number fields. Every number must also be
/// finite.
struct NumberRange {
    double min = -std::numeric_limits<double>::infinity();
    double max = std::numeric_limits<double>::infinity();
    bool minExclusive = false;

    bool contains(double v) const {
        return (minExclusive ? v > min : v >= min) && v <= max;
    }
    /// "a number > 0", "a number in [0, 1]", "a number >= 0", "a finite
    /// number"; with `integer`, "an integer in [1, 1000]" and so on.
    std::string describe(bool integer = false) const;
};

/// The largest magnitude any quantity in a level may have, in its SI unit
/// (coordinates, speeds, spins, masses, stiffnesses, G, gravity...), and the
/// smallest size (radius, box side, polygon extent) or mass. Within them
/// every product a step forms (m v^2 and I w^2 up to 1e150, m g y, k x^2,
/// G m m / r) stays far from a double's 1.8e308, so any level the loader
/// accepts can be stepped; a run that carries a body past them stops as
/// diverged, so everything a run saves loads again.
inline constexpr double kMaxMagnitude = 1e30;
inline constexpr double kMinSize = 1e-30;
inline constexpr NumberRange kAnyMagnitude{-kMaxMagnitude, kMaxMagnitude};
/// The fastest linear (m/s) or angular (rad/s) speed. Tighter than
/// kMaxMagnitude because a contact's answer is a difference of speeds: at
/// 1e20 m/s the 120 m/s that closes a 2 m gap in a 60 Hz step is below the
/// speed's rounding (16,384 m/s), and a ball fired at a wall stops where it
/// starts. At 1e9 the rounding is 1.2e-7 m/s, a 2e-9 m error per step.
inline constexpr double kMaxSpeed = 1e9;
inline constexpr NumberRange kAnySpeed{-kMaxSpeed, kMaxSpeed};

struct FieldInfo {
    std::string_view key;          ///< JSON key; empty for an inline component
    FieldKind kind;
    /// Number and OptionalNumber: the value; Vector and OptionalVector: each
    /// axis; VectorList: the count.
    NumberRange range;
    std::string_view unit;         ///< "m", "kg", "m/s", "" ...
    std::string_view description;  ///< one line, for tooltips and the schema
    void* (*address)(void* component); ///< points at the member inside the struct
    /// String fields only: the values allowed (empty = any string). The
    /// schema lists them as an enum and the inspector offers them in a combo.
    std::span<const std::string_view> choices = {};
};

/// The one check of a field's value, made by the loader (once it has read a
/// value of the right JSON type) and by the editor (checkField, the World
/// panel), so both refuse the same value with the same words. `member`
/// points at a value of the field's C++ type (FieldKind). Nothing when the
/// value is acceptable, else what was expected and found, without the
/// field's name (callers say where): "expected an integer in [1, 1000], got
/// 5000", "expected one of hinge, slider, ..., got \"hing\"; did you mean
/// \"hinge\"?". Cross-field rules are the component's `finish`.
std::optional<Error> fieldValueProblem(const FieldInfo& field, const void* member);

/// A number as messages show it: the shortest text that reads back to the
/// same double ("0.1", "5000", "1e-07").
std::string formatNumber(double value);

/// One row of the table.
struct ComponentInfo {
    std::string_view name;         ///< JSON key on the entity object
    std::string_view description;
    /// True when the component's JSON is its single field's value
    /// (`"mass": 2`), false when it is an object of fields (`"box": {...}`).
    bool inlineValue = false;
    /// Other components this one is meaningless without (e.g. "position").
    std::vector<std::string_view> requires_;
    std::vector<FieldInfo> fields;

    bool (*has)(const Registry&, Entity) = nullptr;
    void* (*get)(Registry&, Entity) = nullptr; ///< nullptr when absent
    const void* (*getConst)(const Registry&, Entity) = nullptr;
    /// Adds the component with its default value (replacing any present).
    void* (*emplaceDefault)(Registry&, Entity) = nullptr;
    bool (*remove)(Registry&, Entity) = nullptr;
    /// Cross-field check and normalisation after the fields are read.
    /// Nothing when fine, else an Error "FIELD: message" (FIELD may be empty).
    std::optional<Error> (*finish)(void* component) = nullptr;
    /// The loader's message for a `finish` refusal also names the entity
    /// ("entity 3 (\"wedge\"): ..."): for shapes, whose problems are about
    /// the body as a whole.
    bool finishNamesEntity = false;
};

/// The table, in the order components are written to files.
std::span<const ComponentInfo> componentTable();

/// Row for `name`, or nullptr.
const ComponentInfo* findComponent(std::string_view name);

/// The known name closest to `name` by edit distance, if close enough to be
/// a plausible typo ("did you mean").
std::optional<std::string_view> closestName(std::string_view name,
                                            std::span<const std::string_view> candidates);

/// Every component name, in table order.
std::vector<std::string_view> componentNames();

/// Calls fn(component, field, handle) for every entity-reference field
/// (FieldKind::EntityRef) of every component on `e`, null ones included:
/// the loader, the saver's checks and the editor's delete, copy and paste
/// all find references this way, whatever component holds them.
template <class Fn>
void forEachEntityRef(const Registry& registry, Entity e, Fn&& fn) {
    for (const ComponentInfo& info : componentTable()) {
        const void* component = info.getConst(registry, e);
        if (!component) continue;
        for (const FieldInfo& field : info.fields)
            if (field.kind == FieldKind::EntityRef)
                fn(info, field, *static_cast<const Entity*>(field.address(const_cast<void*>(component))));
    }
}

/// Copies every component of `from` (in `src`) onto `to` (in `dst`), field
/// by field through the table; entity references are copied as they are.
/// A paste, a duplicate and an emitter's copy all go through it.
void copyComponents(const Registry& src, Entity from, Registry& dst, Entity to);

/// Same, with the handle writable (to rewire a copy, or clear a reference).
template <class Fn>
void forEachEntityRefMutable(Registry& registry, Entity e, Fn&& fn) {
    for (const ComponentInfo& info : componentTable()) {
        void* component = info.get(registry, e);
        if (!component) continue;
        for (const FieldInfo& field : info.fields)
            if (field.kind == FieldKind::EntityRef) fn(info, field, *static_cast<Entity*>(field.address(component)));
    }
}

} // namespace stepwise
