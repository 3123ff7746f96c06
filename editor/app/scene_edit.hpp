#pragma once
/// \file scene_edit.hpp
/// Scene operations the tools are made of, all driven by the component
/// table (no list of component types here): copying an entity field by field
/// (each FieldInfo says where its value lives and what type it is), unique
/// names, picking under the cursor, and the entity builders of the palette.

#include "stepwise/component_table.hpp"
#include "stepwise/components.hpp"
#include "stepwise/scene.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world_fields.hpp"

#include <cstdint>
#include <optional>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <variant>
#include <vector>

namespace stepwise::editor {

/// A field's value, by kind (FieldKind -> alternative).
using FieldValue = std::variant<double, std::optional<double>, Vec2, std::optional<Vec2>, Rgb, bool, std::string, Entity,
                                std::vector<Vec2>, int, std::uint32_t, std::vector<CompoundShape>, std::vector<int>>;
FieldValue readField(const FieldInfo& field, const void* component);
void writeField(const FieldInfo& field, void* component, const FieldValue& value);
/// True when `value` holds the C++ type of `field`'s kind.
bool valueFitsKind(const FieldInfo& field, const FieldValue& value);
/// Nothing when `value` is acceptable for `field` (finite, in range, one of
/// the choices), else an Error "KEY: why" in the loader's words
/// (fieldValueProblem).
std::optional<Error> checkField(const FieldInfo& field, const FieldValue& value);

/// Sets one world setting (a row of worldFieldTable()) after the loader's
/// check: nothing when set, else an Error "world.KEY: why" and the scene is
/// unchanged. The World panel's edits go through here.
std::optional<Error> setWorldField(Scene& scene, const WorldFieldInfo& info, const FieldValue& value);

/// "component.field" ("velocity" for an inline component, whose field has
/// no key): how messages name a field.
std::string fieldPathName(const ComponentInfo& component, std::string_view key);

/// The checks the loader makes, on entities edited in memory: every field of
/// every component (finite, in range), each component's own check
/// (`finish`, which e.g. normalises a plane's normal) and the relations
/// between entities (checkSceneRelations). Nothing when a file could hold
/// the scene, else the refusal naming the entity and the field:
/// `"circle" box: an entity has at most one shape (radius, box, polygon, capsule, chain or plane), got 2`.
/// `context` ("box") names the field when the loader's message names none.
std::optional<Error> checkEdited(Scene& scene, const std::vector<Entity>& entities, const std::string& context);
/// A checkSceneRelations message ("/entities/20/spring/a: ...") with the
/// entity's name for the index: `"spring" spring.a: ...`.
std::string describeRefusal(const Scene& scene, const std::string& problem, const std::string& context = {});

/// Sets one field on every entity of `entities` that has the component, then
/// runs checkEdited. Returns how many were changed; on a refusal nothing is
/// changed and the error says why (entity and field named).
Result<std::size_t> setFieldOnAll(Scene& scene, const ComponentInfo& component, const FieldInfo& field,
                                  const FieldValue& value, const std::vector<Entity>& entities);
/// Adds the component (default value) to each entity that lacks it; refused
/// like setFieldOnAll (e.g. a box on a circle: one shape per body).
Result<std::size_t> addComponentToAll(Scene& scene, const ComponentInfo& component, const std::vector<Entity>& entities);
/// Removes it from each that has it; refused like setFieldOnAll.
Result<std::size_t> removeComponentFromAll(Scene& scene, const ComponentInfo& component,
                                           const std::vector<Entity>& entities);
/// An edit's answer for Editor::tryEdit: whether it changed anything, or
/// why it was refused.
inline Result<bool> changedAny(const Result<std::size_t>& count) {
    if (!count) return count.failure();
    return count.value() > 0;
}
/// The same for an edit that creates an entity, which lands in `out`.
inline Result<bool> createdInto(const Result<Entity>& made, Entity& out) {
    if (!made) return made.failure();
    out = made.value();
    return true;
}

/// Unique entity names for a burst of creations (paste, generated levels):
/// the names in use are gathered once, O(n), and each take() is O(1)
/// amortised because the next free number of each stem is remembered, so
/// pasting k bodies into an n-body scene costs O(n + k), not O(n k).
class NameAllocator {
public:
    explicit NameAllocator(const Registry& registry);
    /// Over a set of names in use that are not entities' (template names).
    explicit NameAllocator(std::unordered_set<std::string> used) : used_(std::move(used)) {}
    /// `base` if unused, else base_2, base_3, ... (the first free one); the
    /// name returned counts as used from then on.
    std::string take(const std::string& base);

private:
    std::unordered_set<std::string> used_;
    std::unordered_map<std::string, int> nextNumber_;  ///< stem -> first number not yet known to be used
};

/// `base` if no entity is called that, else base_2, base_3, ... (one name;
/// use a NameAllocator for many).
std::string uniqueName(const Registry& registry, const std::string& base);
/// Entity called `name`, or a null handle.
Entity findByName(const Registry& registry, std::string_view name);
/// Name, or "entity N" (N its place in the scene order).
std::string displayName(const Registry& registry, Entity e);
/// What the entity is, for the entity list and its filter: "spring",
/// "joint", "wall", "box", "circle", "polygon", "attractor", "boid", else
/// "point".
std::string_view entityKind(const Registry& registry, Entity e);

/// True when the entity is a body: has a position and is not a spring.
bool isBody(const Registry& registry, Entity e);

/// The topmost (last in scene order) entity under `world` (metres). Circles
/// and boxes by their shape; shapeless bodies within `pickRadius` metres of
/// their position; planes within `pickRadius` of their line; springs within
/// `pickRadius` of their segment.
Entity pick(const Scene& scene, Vec2 world, double pickRadius);

/// Entities whose position (bodies) or midpoint (springs) lies in the box.
std::vector<Entity> entitiesInRect(const Scene& scene, Vec2 cornerA, Vec2 cornerB);

/// Springs that have `e` as one of their ends.
std::vector<Entity> springsAttachedTo(const Registry& registry, Entity e);
/// Entities (springs, joints: any component with an entity reference) not
/// among `entities` that refer to one of them.
std::vector<Entity> attachedTo(const Registry& registry, const std::vector<Entity>& entities);

/// Destroys the entities and everything attached to them (a spring whose
/// end disappears would make the level invalid). A deleted emitter's
/// copies alive stay, renamed without their '#'. Returns how many went.
std::size_t destroyWithSprings(Scene& scene, const std::vector<Entity>& entities);

/// Copies `entities` (and their components) into `dst` with fresh unique
/// names, moved by `offset` metres. References among them (spring ends) are
/// rewired to the copies of their targets. A reference to an entity not
/// copied: see OutsideRefs. Returns the new entities.
enum class OutsideRefs : std::uint8_t {
    Keep,      ///< keeps pointing at it (dst is the same document); a copy whose end is not a body of dst goes
    Carry,     ///< kept unchecked (dst is the clipboard: the handles are the document's)
    Drop,      ///< the referring copy goes (dst is another document)
};
std::vector<Entity> cloneEntities(const Registry& src, const std::vector<Entity>& entities, Scene& dst, Vec2 offset,
                                  OutsideRefs outside = OutsideRefs::Keep);

/// Palette builders: each returns the new entity. Names are unique.
Entity addCircle(Scene& scene, Vec2 at, double radius = 0.5);
/// Convex hull of `points`, counter-clockwise, without repeated or
/// collinear points (fewer than 3 when they all lie on one line).
std::vector<Vec2> convexHull(std::vector<Vec2> points);
/// Vertices of a regular polygon about the origin: vertex 0 at `angle` rad,
/// `radius` metres from the centre.
std::vector<Vec2> regularPolygon(int sides, double radius, double angle);
/// A dynamic polygon body from world-space vertices (convex,
/// counter-clockwise), positioned at their centroid. Refused when
/// polygonProblem() refuses them.
Result<Entity> addPolygon(Scene& scene, const std::vector<Vec2>& worldVertices);
Entity addBox(Scene& scene, Vec2 at, double width = 1.0, double height = 1.0);
/// A wall through `through` with the given normal (normalised here).
Entity addPlane(Scene& scene, Vec2 through, Vec2 normal);
/// The synthetic level of `stepwise edit --bench-bodies N`: N circles
/// (0.25 m, 1 kg) in a box of three planes under gravity, jittered so they
/// do not stack in perfect columns (a scenes::CircleGrid). Named c0, c1, ...
/// directly: generating 100,000 bodies through the palette's one-at-a-time
/// naming would be quadratic.
Scene benchScene(int bodies);
/// A spring between two bodies (named here if they have no name: files
/// refer to them by name), rest length = current distance.
Entity addSpring(Scene& scene, Entity a, Entity b);
/// A spring from a body to a fixed world point.
Entity addAnchoredSpring(Scene& scene, Entity a, Vec2 anchor);
/// A joint of `type` from body `a` to body `b` (null: the world) at world
/// point `anchor` (for distance and rope: from a's centre to `anchor`).
/// Unnamed ends get names (files name them). Refused when the file would
/// refuse the joint (two static ends).
Result<Entity> addJoint(Scene& scene, const std::string& type, Entity a, Entity b, Vec2 anchor);
/// A static attractor of `mass` kg.
Entity addAttractor(Scene& scene, Vec2 at, double mass = 100.0);
/// A boid at `at` with velocity `velocity`.
Entity addBoid(Scene& scene, Vec2 at, Vec2 velocity);

/// Axis-aligned bounds of an entity's shape (or its point), metres; false
/// when it has no position (planes, springs).
bool entityBounds(const Registry& registry, Entity e, Vec2& lo, Vec2& hi);

} // namespace stepwise::editor
