// Table-driven scene edits (editor/app/scene_edit): the inspector's and the
// World panel's edit paths, checked with the loader's own words.

#include "editor_fixture.hpp"

#include <map>

#include "stepwise/world_fields.hpp"

#include "app/collision_pairs.hpp"

using namespace stepwise;
using namespace stepwise::editor;
using namespace stepwise::editor_test;
using stepwise::test::readFile;

TEST(Inspector, MultiSelectionEditAppliesToAllAndIsOneUndoStep) {
    Fixture f("spring_chain.json");
    const ComponentInfo* mass = findComponent("mass");
    ASSERT_NE(mass, nullptr);
    const std::vector<Entity> sel{f.named("link0"), f.named("link1"), f.named("link4")};
    f.ed.select(sel);
    const std::string before = textOf(f.ed.doc.scene);
    const std::uint64_t key = f.ed.newMergeKey();
    // A slider drag: three values, one command.
    for (double v : {0.5, 0.7, 2.5})
        ASSERT_TRUE(f.ed.tryEdit("edit mass", [&](Scene& s) {
            return changedAny(setFieldOnAll(s, *mass, mass->fields[0], v, f.ed.selection));
        }, key).value());
    f.ed.endEdit();
    for (Entity e : sel) EXPECT_EQ(f.ed.doc.scene.registry.tryGet<Mass>(e)->value, 2.5);
    EXPECT_NE(f.ed.doc.scene.registry.tryGet<Mass>(f.named("link2"))->value, 2.5);
    ASSERT_TRUE(f.ed.undo());
    EXPECT_EQ(textOf(f.ed.doc.scene), before);
    // Out of range: refused, nothing changes.
    const Result<std::size_t> refused = setFieldOnAll(f.ed.doc.scene, *mass, mass->fields[0], -1.0, sel);
    ASSERT_FALSE(refused);
    EXPECT_NE(refused.error().find("mass"), std::string::npos) << refused.error();
    // Add and remove a component on the whole selection.
    const ComponentInfo* drag = findComponent("restitution");
    ASSERT_NE(drag, nullptr);
    ASSERT_TRUE(f.ed.tryEdit("add", [&](Scene& s) { return changedAny(addComponentToAll(s, *drag, sel)); }).value());
    for (Entity e : sel) EXPECT_TRUE(drag->has(f.ed.doc.scene.registry, e));
    ASSERT_TRUE(
        f.ed.tryEdit("remove", [&](Scene& s) { return changedAny(removeComponentFromAll(s, *drag, sel)); }).value());
    for (Entity e : sel) EXPECT_FALSE(drag->has(f.ed.doc.scene.registry, e));
}

TEST(Inspector, CopyEntityIsTableDrivenAndExact) {
    Result<Scene> s = loadSceneFile(kLevels / "render_showcase.json");
    ASSERT_TRUE(s) << s.error();
    // Copy every entity into a fresh scene with the same world: same bytes.
    Scene copy;
    copy.version = s->version;
    copy.world = s->world;
    copy.view = s->view;
    for (Entity e : s->registry.entities()) copyComponents(s->registry, e, copy.registry, copy.registry.create());
    EXPECT_EQ(textOf(copy), textOf(*s));
}

TEST(PolygonTool, ConvexHullIsCounterClockwiseWithoutCollinearPoints) {
    const std::vector<Vec2> hull = convexHull({{0, 0}, {1, 0}, {2, 0}, {2, 2}, {1, 1}, {0, 2}, {0, 0}, {1, 2}});
    ASSERT_EQ(hull.size(), 4u);
    EXPECT_EQ(polygonProblem(hull), std::nullopt);
    EXPECT_EQ(convexHull({{0, 0}, {1, 1}, {2, 2}}).size(), 2u);
}

TEST(Inspector, RefusesAtEditTimeWhatTheLoaderRefusesNamingEntityAndField) {
    Fixture f("default.json");
    const std::string before = textOf(f.ed.doc.scene);
    const Entity bob = f.named("bob");
    ASSERT_TRUE(f.ed.doc.scene.registry.has<Radius>(bob));
    // A second shape.
    Result<bool> refused =
        f.ed.tryEdit("add box", [&](Scene& s) { return changedAny(addComponentToAll(s, *findComponent("box"), {bob})); });
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error(), "\"bob\" box: an entity has at most one shape (radius, box, polygon, capsule, chain or plane), got 2");
    // A speed past the fastest a level holds.
    const ComponentInfo* velocity = findComponent("velocity");
    refused = f.ed.tryEdit("v", [&](Scene& s) {
        return changedAny(setFieldOnAll(s, *velocity, velocity->fields[0], Vec2{1e308, 0.0}, {bob}));
    });
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error(), "\"bob\" velocity: expected each axis in [-1e+09, 1e+09], got {\"x\": 1e+308, \"y\": 0}");
    // The same numbers are refused by the loader.
    EXPECT_FALSE(parseScene(R"({"entities": [{"position": {"x": 0, "y": 0}, "velocity": {"x": 1e308, "y": 0}}]})", "t.json"));
    // A duplicate name.
    refused = rename(f, bob, "floor");
    ASSERT_FALSE(refused);
    EXPECT_NE(refused.error().find("duplicate name \"floor\""), std::string::npos) << refused.error();
    // Removing the position of a body that has a velocity.
    refused = f.ed.tryEdit("rm", [&](Scene& s) {
        return changedAny(removeComponentFromAll(s, *findComponent("position"), {bob}));
    });
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error().rfind("\"bob\"", 0), 0u) << refused.error();
    EXPECT_NE(refused.error().find("needs \"position\""), std::string::npos) << refused.error();
    // Mass out of range names the entity and the field.
    const ComponentInfo* mass = findComponent("mass");
    refused = f.ed.tryEdit("m", [&](Scene& s) { return changedAny(setFieldOnAll(s, *mass, mass->fields[0], -1.0, {bob})); });
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error(), "\"bob\" mass: expected a number in [1e-30, 1e+30], got -1");  // the loader's words
    // Nothing of it reached the scene.
    EXPECT_EQ(textOf(f.ed.doc.scene), before);
}

TEST(WorldSettingsEdit, OutOfRangeRefusedWithTheLoadersWords) {
    // The same value, through a file and through the World panel's edit
    // path: the same message after "where" (/world/KEY in a file,
    // world.KEY in the editor), and the scene left as it was.
    struct Case {
        const char* key;
        const char* json;
        FieldValue value;
    };
    const Case cases[] = {
        {"solver_iterations", "5000", 5000},  // the UI allowed only 1..200 before the table
        {"substeps", "0", 0},
        {"dt", "-1", -1.0},
        {"theta", "1.5", 1.5},
        {"tolerance", "0", 0.0},
        {"restitution_threshold", "-2", std::optional<double>(-2.0)},
        {"integrator", "\"rk5\"", std::string("rk5")},
    };
    for (const Case& c : cases) {
        const std::string key = c.key;
        Result<Scene> loaded = parseScene(R"({"world": {")" + key + "\": " + c.json + R"(}, "entities": []})", "t.json");
        ASSERT_FALSE(loaded) << key;
        const std::string loaderPrefix = "t.json: error: /world/" + key + ": ";
        ASSERT_EQ(loaded.error().rfind(loaderPrefix, 0), 0u) << loaded.error();

        Fixture f("default.json");
        const WorldSettings before = f.ed.doc.scene.world;
        std::optional<Error> refused;
        EXPECT_FALSE(f.ed.applyEdit("world", [&](Scene& s) {
            refused = setWorldField(s, *findWorldField(key), c.value);
            return !refused;
        }));
        ASSERT_TRUE(refused) << key;
        const std::string editorPrefix = "world." + key + ": ";
        ASSERT_EQ(refused->message.rfind(editorPrefix, 0), 0u) << refused->message;
        EXPECT_EQ(refused->message.substr(editorPrefix.size()), loaded.error().substr(loaderPrefix.size())) << key;
        EXPECT_EQ(f.ed.doc.scene.world, before) << key;
    }
}

TEST(WorldSettingsEdit, AcceptsWhatTheLoaderAccepts) {
    // 600 solver iterations load from a file, so the World panel, which
    // reads the same table, takes them too.
    Fixture f("default.json");
    std::optional<Error> refused;
    EXPECT_TRUE(f.ed.applyEdit("world", [&](Scene& s) {
        refused = setWorldField(s, *findWorldField("solver_iterations"), 600);
        return !refused;
    })) << refused->message;
    EXPECT_EQ(f.ed.doc.scene.world.solverIterations, 600);
    Result<Scene> again = parseScene(textOf(f.ed.doc.scene), "t.json");
    ASSERT_TRUE(again) << again.error();
    EXPECT_EQ(again->world.solverIterations, 600);
    // A value of the wrong type for the field is refused, not written.
    EXPECT_EQ(setWorldField(f.ed.doc.scene, *findWorldField("solver_iterations"), 7.0),
              Error{"world.solver_iterations: a value of the wrong type for this field"});
    EXPECT_EQ(f.ed.doc.scene.world.solverIterations, 600);
}

// The entity list called polygons and joints "point" (car.json: the
// terrain's thirteen polygons and the car's three joints), and its filter
// could not find them by what they are.
TEST(EntityList, EveryShapeAndLinkIsNamedForWhatItIs) {
    LevelOpen car("car.json");
    const Registry& reg = car.ed.doc.scene.registry;
    std::map<std::string, std::string> kinds;
    for (Entity e : reg.entities()) kinds[displayName(reg, e)] = std::string(entityKind(reg, e));
    EXPECT_EQ(kinds["slope up"], "polygon");
    EXPECT_EQ(kinds["rear axle"], "joint");
    EXPECT_EQ(kinds["roof weld"], "joint");
    EXPECT_EQ(kinds["rear wheel"], "circle");
    EXPECT_EQ(kinds["car"], "box");
    LevelOpen chain("spring_chain.json");
    const Registry& springs = chain.ed.doc.scene.registry;
    EXPECT_EQ(entityKind(springs, findByName(springs, "spring0")), "spring");
    EXPECT_EQ(entityKind(springs, findByName(springs, "link0")), "point");
}

TEST(Inspector, ExcludedPartnersFollowFiltersAndJointsOfTheSelectedBody) {
    {
        Fixture f("filters.json");
        const Scene& scene = f.ed.doc.scene;
        const auto names = [&](const std::vector<ExcludedPartner>& list) {
            std::map<std::string, std::string> out;
            for (const ExcludedPartner& p : list) out[displayName(scene.registry, p.body)] = p.reason;
            return out;
        };
        // A ragdoll's bones share a negative group: the torso meets none of
        // the other nine bones of its own ragdoll, and every bone of the other.
        const auto torso = names(excludedPartners(scene, f.named("A torso")));
        EXPECT_EQ(torso.size(), 9u);
        for (const auto& [name, reason] : torso) {
            EXPECT_EQ(name.substr(0, 2), "A ") << name;
            EXPECT_EQ(reason, "filter") << name;
        }
        // A ghost ball leaves the gate's category out of its mask.
        EXPECT_EQ(names(excludedPartners(scene, f.named("ghost ball 0"))),
                  (std::map<std::string, std::string>{{"gate", "filter"}}));
        EXPECT_TRUE(excludedPartners(scene, f.named("crate 0")).empty());
        // The gate is static: against the other static bodies nothing is
        // excluded, since those pairs never meet anyway.
        EXPECT_EQ(excludedPartners(scene, f.named("gate")).size(), 4u);
    }
    {
        // Without filters, a joint with collide_connected false excludes its pair.
        Fixture f("ragdoll.json");
        std::map<std::string, std::string> torso;
        for (const ExcludedPartner& p : excludedPartners(f.ed.doc.scene, f.named("torso")))
            torso[displayName(f.ed.doc.scene.registry, p.body)] = p.reason;
        EXPECT_EQ(torso, (std::map<std::string, std::string>{{"head", "joint neck"},
                                                             {"upper arm L", "joint shoulder L"},
                                                             {"upper arm R", "joint shoulder R"},
                                                             {"thigh L", "joint hip L"},
                                                             {"thigh R", "joint hip R"}}));
    }
}
