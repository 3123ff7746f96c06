// The component table: every component and every field survives a save and
// load exactly, and the table has one row per component with sane fields.
// The test walks the table itself, so a new component is covered the day it
// is added.

#include "stepwise/component_table.hpp"
#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"

#include <gtest/gtest.h>

#include <set>

using namespace stepwise;

namespace {

/// Writes a distinctive, valid, non-default value into a field; `salt`
/// varies it per field so swapped fields would be caught.
void setDistinct(const FieldInfo& field, void* component, int salt, Entity target) {
    void* m = field.address(component);
    const double v = 0.125 + 0.0625 * salt;  // exact binary fractions, in (0, 1]
    switch (field.kind) {
    case FieldKind::Number: *static_cast<double*>(m) = field.range.contains(v * 7.3) ? v * 7.3 : v; break;
    case FieldKind::Integer: *static_cast<int*>(m) = int(field.range.min) + salt; break;
    // High bits set too, so a save that kept only 31 bits would be caught.
    case FieldKind::Bits: *static_cast<std::uint32_t*>(m) = 0x80000001u + std::uint32_t(salt); break;
    case FieldKind::OptionalNumber: *static_cast<std::optional<double>*>(m) = v * 3.1; break;
    case FieldKind::Vector: *static_cast<Vec2*>(m) = {0.1 * salt + 1.0 / 3.0, -2.0 / 7.0}; break;
    case FieldKind::OptionalVector: *static_cast<std::optional<Vec2>*>(m) = Vec2{1e-300, -9.87654321e29}; break;
    case FieldKind::Color: *static_cast<Rgb*>(m) = {0.453125, 1.0 / 3.0, 0.0}; break;
    case FieldKind::Bool: *static_cast<bool*>(m) = salt % 2 == 0; break;
    case FieldKind::VectorList:  // a convex, counter-clockwise quadrilateral off its origin
        *static_cast<std::vector<Vec2>*>(m) = {{0.1 * salt + 1.0 / 3.0, -2.0 / 7.0}, {2.0, -0.5}, {2.5, 1e-3}, {0.2, 1.0}};
        break;
    case FieldKind::IntegerList: *static_cast<std::vector<int>*>(m) = {salt + 1, salt + 4}; break;
    case FieldKind::ShapeList: {  // one of each kind, with every optional field set somewhere
        CompoundShape circle;
        circle.center = {0.1 * salt + 1.0 / 3.0, -2.0 / 7.0};
        circle.radius = 0.3;
        circle.density = 2.5;
        circle.sensor = true;
        CompoundShape box;
        box.kind = CompoundShape::Kind::Box;
        box.center = {1.0, 1.0 / 3.0};
        box.angle = 0.1;
        box.friction = 0.7;
        box.filter = Filter{2, 0x80000001u, -4};
        CompoundShape polygon;
        polygon.kind = CompoundShape::Kind::Polygon;
        polygon.vertices = {{0.1, -2.0 / 7.0}, {2.0, -0.5}, {2.5, 1e-3}, {0.2, 1.0}};
        polygon.restitution = 0.25;
        CompoundShape capsule;
        capsule.kind = CompoundShape::Kind::Capsule;
        capsule.a = {-1.0 / 3.0, 0.0};
        capsule.b = {0.5, 1e-3};
        *static_cast<std::vector<CompoundShape>*>(m) = {circle, box, polygon, capsule};
        break;
    }
    case FieldKind::String:
        // A field with a fixed set of values (a joint's type) gets one of them.
        *static_cast<std::string*>(m) = field.choices.empty()
                                            ? "label \"quoted\" ü " + std::to_string(salt)
                                            : std::string(field.choices[std::size_t(salt) % field.choices.size()]);
        break;
    case FieldKind::EntityRef: *static_cast<Entity*>(m) = target; break;
    }
}

/// Entity references are compared by the name of the entity they point at
/// (handles differ between two registries).
bool fieldEquals(const FieldInfo& field, const void* a, const void* b, const Registry& ra, const Registry& rb) {
    const void* ma = field.address(const_cast<void*>(a));
    const void* mb = field.address(const_cast<void*>(b));
    switch (field.kind) {
    case FieldKind::Number: return *static_cast<const double*>(ma) == *static_cast<const double*>(mb);
    case FieldKind::Integer: return *static_cast<const int*>(ma) == *static_cast<const int*>(mb);
    case FieldKind::Bits: return *static_cast<const std::uint32_t*>(ma) == *static_cast<const std::uint32_t*>(mb);
    case FieldKind::OptionalNumber:
        return *static_cast<const std::optional<double>*>(ma) == *static_cast<const std::optional<double>*>(mb);
    case FieldKind::Vector: return *static_cast<const Vec2*>(ma) == *static_cast<const Vec2*>(mb);
    case FieldKind::OptionalVector:
        return *static_cast<const std::optional<Vec2>*>(ma) == *static_cast<const std::optional<Vec2>*>(mb);
    case FieldKind::Color: return *static_cast<const Rgb*>(ma) == *static_cast<const Rgb*>(mb);
    case FieldKind::Bool: return *static_cast<const bool*>(ma) == *static_cast<const bool*>(mb);
    case FieldKind::VectorList:
        return *static_cast<const std::vector<Vec2>*>(ma) == *static_cast<const std::vector<Vec2>*>(mb);
    case FieldKind::IntegerList: return *static_cast<const std::vector<int>*>(ma) == *static_cast<const std::vector<int>*>(mb);
    case FieldKind::ShapeList:
        return *static_cast<const std::vector<CompoundShape>*>(ma) == *static_cast<const std::vector<CompoundShape>*>(mb);
    case FieldKind::String: return *static_cast<const std::string*>(ma) == *static_cast<const std::string*>(mb);
    case FieldKind::EntityRef: {
        const Entity ea = *static_cast<const Entity*>(ma), eb = *static_cast<const Entity*>(mb);
        if (ea.isNull() || eb.isNull()) return ea.isNull() && eb.isNull();
        const Name* na = ra.tryGet<Name>(ea);
        const Name* nb = rb.tryGet<Name>(eb);
        return na && nb && na->value == nb->value;
    }
    }
    return false;
}

} // namespace

TEST(ComponentTable, NamesAreUniqueAndFindable) {
    std::set<std::string_view> names;
    for (const ComponentInfo& info : componentTable()) {
        EXPECT_TRUE(names.insert(info.name).second) << info.name;
        EXPECT_EQ(findComponent(info.name), &info);
        EXPECT_FALSE(info.fields.empty()) << info.name;
        if (info.inlineValue) {
            EXPECT_EQ(info.fields.size(), 1u) << info.name;
        }
        for (const FieldInfo& f : info.fields) EXPECT_EQ(f.key.empty(), info.inlineValue) << info.name;
    }
    EXPECT_EQ(findComponent("velocty"), nullptr);
    // The scene format's required components (docs/format.md) are all present.
    for (const char* required : {"name", "type", "position", "velocity", "mass", "static", "radius", "box", "angle",
                                 "angular_velocity", "color", "restitution", "friction", "drag", "plane", "attractor",
                                 "spring", "boid", "polygon"})
        EXPECT_NE(findComponent(required), nullptr) << required;
}

TEST(ComponentTable, DidYouMeanFindsCloseNames) {
    const auto names = componentNames();
    EXPECT_EQ(closestName("velocty", names), std::optional<std::string_view>("velocity"));
    EXPECT_EQ(closestName("positon", names), std::optional<std::string_view>("position"));
    EXPECT_EQ(closestName("zzzzzzzzzzzz", names), std::nullopt);
}

/// Every component, with every field set to a non-default value, reads back
/// identical after save -> load, and a second save gives the same bytes.
class ComponentRoundTrip : public ::testing::TestWithParam<std::string> {};

TEST_P(ComponentRoundTrip, EveryFieldSurvivesSaveAndLoad) {
    const ComponentInfo* info = findComponent(GetParam());
    ASSERT_NE(info, nullptr);

    Scene scene;
    Registry& r = scene.registry;
    // A spring needs two named bodies; other components go on a body.
    const Entity target = r.create();
    r.emplace<Name>(target, Name{"target"});
    r.emplace<Position>(target, Position{{3.0, 4.0}});
    const Entity host = r.create();
    if (info->name != "name") r.emplace<Name>(host, Name{"host"});
    for (std::string_view needed : info->requires_) findComponent(needed)->emplaceDefault(r, host);
    void* component = info->emplaceDefault(r, host);
    int salt = 1;
    for (const FieldInfo& f : info->fields) setDistinct(f, component, salt++, target);
    if (info->name == "spring") {
        auto* s = static_cast<Spring*>(component);
        s->a = target;
        s->b = Entity{};  // anchored: b and anchor are exclusive
    }
    if (info->name == "joint") {
        auto* j = static_cast<Joint*>(component);
        j->a = target;
        j->b = Entity{};   // the world
        j->anchor.reset(); // input only: the loader turns it into the locals
    }
    if (info->name == "template") {
        // A template body is a dynamic body with a shape.
        r.emplace<Position>(host, Position{{-1.0, 2.0}});
        r.emplace<Radius>(host, Radius{0.25});
    }
    if (info->name == "emitter") {
        // It copies an existing template; no copies alive (they would be
        // entities of their own).
        auto* em = static_cast<Emitter*>(component);
        em->alive = 0;
        em->copies.clear();
        r.emplace<Template>(target, Template{em->templateName});
        r.emplace<Radius>(target, Radius{0.25});
    }
    if (info->name == "boid") static_cast<Boid*>(component)->separationRadius = 0.5;
    if (info->name == "plane") static_cast<Plane*>(component)->normal = {0.6, 0.8};  // unit already
    if (info->name == "chain") r.emplace<Static>(host, Static{true});  // chains are only on static bodies

    const std::string text = sceneToJsonText(scene);
    Result<Scene> loaded = parseScene(text, "roundtrip.json");
    ASSERT_TRUE(loaded) << loaded.error() << "\n" << text;
    const Entity loadedHost = loaded->registry.entities().at(1);
    const void* back = info->getConst(loaded->registry, loadedHost);
    ASSERT_NE(back, nullptr) << info->name << " missing after load\n" << text;
    for (const FieldInfo& f : info->fields)
        EXPECT_TRUE(fieldEquals(f, component, back, r, loaded->registry)) << info->name << "." << f.key << "\n" << text;
    EXPECT_EQ(sceneToJsonText(*loaded), text);
}

INSTANTIATE_TEST_SUITE_P(AllComponents, ComponentRoundTrip, ::testing::ValuesIn([] {
                             std::vector<std::string> names;
                             for (std::string_view n : componentNames()) names.emplace_back(n);
                             return names;
                         }()),
                         [](const auto& param) { return param.param; });
