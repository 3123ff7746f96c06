// The simulation controller (editor/app/simulation): play, step back,
// reset, time scale and the frame budget.

#include "editor_fixture.hpp"

using namespace stepwise;
using namespace stepwise::editor;
using namespace stepwise::editor_test;
using stepwise::test::readFile;

TEST(Simulation, ResetReturnsToTheEditedSceneAndStepBackIsExact) {
    Fixture f("spring_chain.json");
    // An edit before playing is part of the level.
    ASSERT_TRUE(f.ed.applyEdit("gravity", [](Scene& s) {
        s.world.gravity.y = -5.0;
        return true;
    }));
    const std::string edited = textOf(f.ed.doc.scene);
    f.ed.stepForward();
    ASSERT_EQ(f.ed.sim.state(), SimState::Paused) << f.ed.sim.message();
    const std::string afterOne = textOf(f.ed.doc.scene);
    EXPECT_NE(afterOne, edited);
    f.ed.stepForward();
    f.ed.stepForward();
    f.ed.stepBack();
    f.ed.stepBack();
    EXPECT_EQ(textOf(f.ed.doc.scene), afterOne);
    f.ed.stepBack();
    EXPECT_EQ(textOf(f.ed.doc.scene), edited);
    // Play, then edit while paused: the edit applies to the state ...
    f.ed.togglePlay();
    for (int i = 0; i < 10; ++i) f.ed.update(1.0 / 60.0);
    EXPECT_EQ(f.ed.sim.steps(), 10u);
    f.ed.togglePlay();
    ASSERT_TRUE(f.ed.applyEdit("mass", [&](Scene& s) {
        s.registry.tryGet<Mass>(f.named("link3"))->value = 9.0;
        return true;
    }));
    f.ed.stepForward();
    // ... and reset discards it with the simulated state.
    f.ed.resetSimulation();
    EXPECT_EQ(f.ed.sim.state(), SimState::Editing);
    EXPECT_EQ(textOf(f.ed.doc.scene), edited);
    // The edit from before Play is still undoable.
    ASSERT_TRUE(f.ed.undo());
    EXPECT_EQ(f.ed.doc.scene.world.gravity.y, -9.81);
}

TEST(Simulation, SteppingThroughTheEditorMatchesTheWorld) {
    Fixture f("orbit.json");
    Result<World> w = World::build(f.ed.doc.scene);
    ASSERT_TRUE(w) << w.error();
    for (int i = 0; i < 30; ++i) ASSERT_TRUE(w->step());
    Scene expected = f.ed.doc.scene;
    w->writeBack(expected);
    // A step back restores the World's saved state in place, so stepping
    // on gives the same bits (with contacts too: test_editor_state).
    for (int i = 0; i < 20; ++i) f.ed.stepForward();
    for (int i = 0; i < 5; ++i) f.ed.stepBack();
    for (int i = 0; i < 15; ++i) f.ed.stepForward();
    EXPECT_EQ(textOf(f.ed.doc.scene), textOf(expected));
}

TEST(Simulation, AMouseSpringDragBuildsTheWorldOnceAndPullsTheBody) {
    Fixture f("spring_chain.json");  // link11, the free end, starts at (6, 0)
    f.ed.tool = Tool::Select;
    f.ed.togglePlay();
    f.ed.update(1.0 / 60.0);
    const std::uint64_t buildsBefore = f.ed.sim.worldBuilds();
    const Entity link = findByName(f.ed.doc.scene.registry, "link11");
    const Vec2 grab = f.ed.doc.scene.registry.tryGet<Position>(link)->value;
    f.ed.handleViewportEvent(f.mouse(InputEvent::Type::MouseDown, grab));
    ASSERT_TRUE(f.ed.sim.mouseSpring);
    // The cursor moves every frame; the anchor follows without a rebuild.
    const Vec2 target{6.0, 3.0};
    for (int i = 1; i <= 60; ++i) {
        f.ed.handleViewportEvent(f.mouse(InputEvent::Type::MouseMove, grab + (target - grab) * std::min(1.0, i / 20.0)));
        f.ed.update(1.0 / 60.0);
    }
    EXPECT_EQ(f.ed.sim.worldBuilds(), buildsBefore + 1);  // once, when the drag began
    // Pulled up against gravity toward the cursor, from below y = 0.
    const Vec2 held = f.ed.doc.scene.registry.tryGet<Position>(link)->value;
    EXPECT_GT(held.y, 1.0) << held.x << ", " << held.y;
    f.ed.handleViewportEvent(f.mouse(InputEvent::Type::MouseUp, target));
    EXPECT_FALSE(f.ed.sim.mouseSpring);
    f.ed.update(1.0 / 60.0);
    EXPECT_EQ(f.ed.sim.worldBuilds(), buildsBefore + 2);  // released: rebuilt without it
}

// Moving bodies while paused goes to the live World in place, with no
// rebuild, and the run goes on exactly as from a World rebuilt from the
// edited scene (which carries the same warm start): the same bits after 20
// more steps, for a body on top of the pile, one inside it and one at the
// floor, each moved and given a velocity.
namespace {

/// Applies the same `edit` to both fixtures, has `rebuilt` build its World
/// again from its edited scene, steps both `steps` times, and expects the
/// same bytes from both and no World build on `inPlace` (one if `rebuilds`).
void expectRunsAsARebuild(Fixture& inPlace, Fixture& rebuilt, const std::string& label,
                          const std::function<bool(Scene&)>& edit, int steps, bool rebuilds = false) {
    const std::uint64_t builds = inPlace.ed.sim.worldBuilds();
    for (Fixture* f : {&inPlace, &rebuilt}) ASSERT_TRUE(f->ed.applyEdit(label, edit));
    rebuilt.ed.sim.sceneChanged();
    for (int i = 0; i < steps; ++i) {
        inPlace.ed.stepForward();
        rebuilt.ed.stepForward();
    }
    EXPECT_EQ(inPlace.ed.sim.worldBuilds(), rebuilds ? builds + 1 : builds);
    EXPECT_EQ(textOf(inPlace.ed.doc.scene), textOf(rebuilt.ed.doc.scene));
}

/// Plays `f` for `frames` frames of 1/60 s, then pauses it.
void playThenPause(Fixture& f, int frames) {
    f.ed.togglePlay();
    for (int i = 0; i < frames; ++i) f.ed.update(1.0 / 60.0);
    f.ed.togglePlay();
}

/// A body contacts and forces move: a position, neither static nor kinematic.
bool isFreeBody(const Registry& reg, Entity e) {
    return reg.has<Position>(e) && !(reg.has<Static>(e) && reg.tryGet<Static>(e)->value) &&
           !(reg.has<Kinematic>(e) && reg.tryGet<Kinematic>(e)->value);
}

} // namespace

TEST(Simulation, AMoveWhilePausedGoesToTheWorldInPlaceAndRunsAsARebuild) {
    for (const char* name : {"c1999", "c1000", "c0"}) {
        SCOPED_TRACE(name);
        Fixture inPlace("pile.json"), rebuilt("pile.json");
        Entity body;
        for (Fixture* f : {&inPlace, &rebuilt}) {
            f->ed.togglePlay();
            for (int i = 0; i < 30; ++i) f->ed.update(1.0 / 60.0);
            f->ed.togglePlay();
            ASSERT_EQ(f->ed.sim.state(), SimState::Paused);
            body = findByName(f->ed.doc.scene.registry, name);
            ASSERT_TRUE(f->ed.doc.scene.registry.alive(body));
        }
        const std::uint64_t builds = inPlace.ed.sim.worldBuilds();
        for (Fixture* f : {&inPlace, &rebuilt}) {
            ASSERT_TRUE(f->ed.applyEdit("move", [&](Scene& s) {
                s.registry.tryGet<Position>(body)->value.y += 0.75;
                s.registry.emplace<Velocity>(body, Velocity{{1.5, -0.5}});
                return true;
            }));
        }
        rebuilt.ed.sim.sceneChanged();  // the other path: rebuild from the edited scene
        for (int i = 0; i < 20; ++i) {
            inPlace.ed.stepForward();
            rebuilt.ed.stepForward();
        }
        EXPECT_EQ(inPlace.ed.sim.worldBuilds(), builds) << "moved in place, never rebuilt";
        EXPECT_GT(rebuilt.ed.sim.worldBuilds(), builds);
        EXPECT_EQ(textOf(inPlace.ed.doc.scene), textOf(rebuilt.ed.doc.scene));
    }
}

// A body of a sleeping pyramid moved in place wakes its island, as the
// rebuild does, and the two runs agree bit for bit.
TEST(Simulation, AMoveInPlaceWakesTheSleepingIslandAsARebuildDoes) {
    Fixture inPlace("pyramid.json"), rebuilt("pyramid.json");
    Entity top;
    for (Fixture* f : {&inPlace, &rebuilt}) {
        f->ed.togglePlay();
        for (int i = 0; i < 900 && (!f->ed.sim.world() || f->ed.sim.world()->sleepingBodyCount() == 0); ++i)
            f->ed.update(1.0 / 60.0);
        f->ed.togglePlay();
        ASSERT_GT(f->ed.sim.world()->sleepingBodyCount(), 0u) << "the pyramid falls asleep";
        const Registry& reg = f->ed.doc.scene.registry;
        double highest = -1e300;
        for (Entity e : reg.entities())
            if (reg.has<Box>(e) && reg.tryGet<Position>(e)->value.y > highest && !(reg.has<Static>(e) && reg.tryGet<Static>(e)->value)) {
                highest = reg.tryGet<Position>(e)->value.y;
                top = e;
            }
    }
    expectRunsAsARebuild(inPlace, rebuilt, "move", [&](Scene& s) {
        s.registry.tryGet<Position>(top)->value.x += 0.3;
        return true;
    }, 20);
    const World& w = *inPlace.ed.sim.world();
    for (std::size_t b = 0; b < w.bodyCount(); ++b)
        if (w.bodyEntity(b) == top) EXPECT_FALSE(w.asleep(b)) << "the moved box's island woke";
}

// An edit beyond a body's pose, mass and shape (here its drag) rebuilds
// the World.
TEST(Simulation, AnEditBeyondPoseMassAndShapeRebuildsTheWorld) {
    Fixture f("pile.json");
    f.ed.togglePlay();
    f.ed.update(1.0 / 60.0);
    f.ed.togglePlay();
    const std::uint64_t builds = f.ed.sim.worldBuilds();
    const Entity body = findByName(f.ed.doc.scene.registry, "c10");
    ASSERT_TRUE(f.ed.applyEdit("drag", [&](Scene& s) {
        s.registry.emplace<Drag>(body, Drag{0.5});
        return true;
    }));
    f.ed.stepForward();
    EXPECT_EQ(f.ed.sim.worldBuilds(), builds + 1);
}

// A new mass goes to the live World in place and the run goes on exactly
// as from a World rebuilt from the edited scene: circles, boxes of a
// sleeping pyramid, compound bodies, jointed ragdoll bones, heavier and
// lighter. A mass that changes the engine's choice of settings (a 1000:1
// pile in a level that leaves the settings to the engine) rebuilds, and
// still runs as the rebuild.
TEST(Simulation, AMassEditGoesInPlaceAndRunsAsARebuild) {
    struct Case {
        const char* level;
        const char* body;
        double factor;
        bool inPlace;
    };
    const Case cases[] = {{"pile.json", "c1999", 3.0, true},    {"pile.json", "c0", 0.25, true},
                          {"pyramid.json", "", 2.0, true},      {"tumbler.json", "", 0.5, true},
                          {"ragdoll.json", "", 4.0, true},      {"kinematic.json", "ball 3", 1.5, true},
                          {"kinematic.json", "ball 3", 1000.0, false}};
    for (const Case& c : cases) {
        SCOPED_TRACE(std::string(c.level) + " " + c.body + " x" + std::to_string(c.factor));
        Fixture inPlace(c.level), rebuilt(c.level);
        for (Fixture* f : {&inPlace, &rebuilt}) {
            playThenPause(*f, 60);
            ASSERT_EQ(f->ed.sim.state(), SimState::Paused);
        }
        // The named body, else the last dynamic body with a shape.
        const Registry& reg = inPlace.ed.doc.scene.registry;
        Entity body = *c.body ? findByName(reg, c.body) : Entity{};
        if (!*c.body)
            for (Entity e : reg.entities())
                if ((reg.has<Box>(e) || reg.has<Radius>(e) || reg.has<Polygon>(e) || reg.has<Capsule>(e) ||
                     reg.has<Shapes>(e)) &&
                    isFreeBody(reg, e))
                    body = e;
        ASSERT_TRUE(reg.alive(body));
        expectRunsAsARebuild(inPlace, rebuilt, "mass", [&](Scene& s) {
            const Mass* m = s.registry.tryGet<Mass>(body);
            const double before = m ? m->value
                                    : s.registry.has<Shapes>(body)
                                        ? compoundMassProperties(*s.registry.tryGet<Shapes>(body), std::nullopt).mass
                                        : 1.0;
            s.registry.emplace<Mass>(body, Mass{before * c.factor});
            return true;
        }, 30, !c.inPlace);
    }
}

// The engine's choice of settings reads the whole scene, so edits in
// place leave it to one check before the next step. A mass dragged through
// many values while paused (a slider edits once a frame) rebuilds nothing
// on the way, even through values that would change the choice; the value
// left at the step decides: 1.5 times the ball's mass keeps the World, a
// thousand times rebuilds it once. Either way the run is a rebuild's.
TEST(Simulation, EditsInPlaceSettleTheEnginesChoiceOnceBeforeTheNextStep) {
    for (const double last : {1.5, 1000.0}) {
        SCOPED_TRACE(last);
        Fixture inPlace("kinematic.json"), rebuilt("kinematic.json");
        for (Fixture* f : {&inPlace, &rebuilt}) playThenPause(*f, 60);
        const Entity ball = inPlace.named("ball 3");
        const double m0 = inPlace.ed.doc.scene.registry.tryGet<Mass>(ball)->value;
        const std::uint64_t builds = inPlace.ed.sim.worldBuilds();
        for (const double factor : {2.0, 1000.0, 300.0, 0.5, 1000.0, last})
            for (Fixture* f : {&inPlace, &rebuilt})
                ASSERT_TRUE(f->ed.applyEdit("mass", [&](Scene& s) {
                    s.registry.tryGet<Mass>(ball)->value = m0 * factor;
                    return true;
                }));
        EXPECT_EQ(inPlace.ed.sim.worldBuilds(), builds) << "no edit rebuilt";
        rebuilt.ed.sim.sceneChanged();
        for (int i = 0; i < 30; ++i) {
            inPlace.ed.stepForward();
            rebuilt.ed.stepForward();
        }
        EXPECT_EQ(inPlace.ed.sim.worldBuilds(), builds + (last > 100.0 ? 1 : 0));
        EXPECT_EQ(textOf(inPlace.ed.doc.scene), textOf(rebuilt.ed.doc.scene));
    }
}

// A turn (the rotate tool: an angle, often with a new position) and a
// spin go to the live World in place too, and the run goes on as from a
// rebuilt World: boxes of a pyramid, a compound body, a ragdoll's capsule
// bones (turned about their position, off their centre of mass).
TEST(Simulation, ATurnGoesInPlaceAndRunsAsARebuild) {
    struct Case {
        const char* level;
        double turn, spin, shift;
    };
    const Case cases[] = {{"pyramid.json", 0.3, 0.0, 0.0},  {"pyramid.json", -0.2, 2.0, 0.25},
                          {"tumbler.json", 0.5, -1.0, 0.0}, {"ragdoll.json", 1.0, 0.5, 0.1},
                          {"polygons.json", -0.7, 3.0, -0.2}};
    for (const Case& c : cases) {
        SCOPED_TRACE(std::string(c.level) + " turn " + std::to_string(c.turn));
        Fixture inPlace(c.level), rebuilt(c.level);
        for (Fixture* f : {&inPlace, &rebuilt}) playThenPause(*f, 45);
        const Registry& reg = inPlace.ed.doc.scene.registry;
        Entity body;
        for (Entity e : reg.entities())
            if ((reg.has<Box>(e) || reg.has<Polygon>(e) || reg.has<Capsule>(e) || reg.has<Shapes>(e)) &&
                isFreeBody(reg, e))
                body = e;
        ASSERT_TRUE(reg.alive(body));
        expectRunsAsARebuild(inPlace, rebuilt, "rotate", [&](Scene& s) {
            const double angle = s.registry.has<Angle>(body) ? s.registry.tryGet<Angle>(body)->value : 0.0;
            s.registry.emplace<Angle>(body, Angle{angle + c.turn});
            if (c.spin != 0.0) s.registry.emplace<AngularVelocity>(body, AngularVelocity{c.spin});
            s.registry.tryGet<Position>(body)->value.x += c.shift;
            return true;
        }, 30);
    }
}

// A new shape, friction, restitution or filter goes to the live World in
// place and the run goes on as from a rebuilt World: a circle shrunk and
// grown in a pile, a box of a pyramid widened, a capsule thickened, a
// filter changed, a bone made bouncy. An outline whose centroid moves (a
// polygon's) rebuilds, and still runs as the rebuild.
TEST(Simulation, AShapeEditGoesInPlaceAndRunsAsARebuild) {
    struct Case {
        const char* what;
        const char* level;
        const char* body;  // "" = the level's last dynamic body with this shape
        std::function<void(Registry&, Entity)> edit;
        bool inPlace;
    };
    const Case cases[] = {
        {"smaller circle", "pile.json", "c1000", [](Registry& r, Entity e) { r.tryGet<Radius>(e)->value *= 0.8; }, true},
        {"larger circle", "pile.json", "c1899", [](Registry& r, Entity e) { r.tryGet<Radius>(e)->value *= 1.3; }, true},
        {"friction", "pile.json", "c10", [](Registry& r, Entity e) { r.emplace<Friction>(e, Friction{0.05}); }, true},
        {"wider box", "pyramid.json", "", [](Registry& r, Entity e) { r.tryGet<Box>(e)->width *= 1.1; }, true},
        {"thicker capsule", "capsules.json", "ramp capsule 0",
         [](Registry& r, Entity e) { r.tryGet<Capsule>(e)->radius *= 1.25; }, true},
        {"filter", "filters.json", "ghost ball 0", [](Registry& r, Entity e) { r.emplace<Filter>(e, Filter{}); }, true},
        {"bouncy", "ragdoll.json", "head", [](Registry& r, Entity e) { r.emplace<Restitution>(e, Restitution{0.8}); }, true},
        {"polygon outline", "polygons.json", "slider",
         [](Registry& r, Entity e) { r.tryGet<Polygon>(e)->vertices[2].x = 0.35; }, false},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.what);
        Fixture inPlace(c.level), rebuilt(c.level);
        for (Fixture* f : {&inPlace, &rebuilt}) playThenPause(*f, 45);
        const Registry& reg = inPlace.ed.doc.scene.registry;
        Entity body = *c.body ? findByName(reg, c.body) : Entity{};
        if (!*c.body)
            for (Entity e : reg.entities())
                if (reg.has<Box>(e) && isFreeBody(reg, e)) body = e;
        ASSERT_TRUE(reg.alive(body));
        expectRunsAsARebuild(inPlace, rebuilt, c.what, [&](Scene& s) {
            c.edit(s.registry, body);
            return true;
        }, 45, !c.inPlace);
    }
}

// A kinematic body's new velocity (a platform sped up while paused) goes
// in place and holds: each substep sets a kinematic body's velocity again,
// from the edited value, as a rebuilt World's would.
TEST(Simulation, AKinematicBodysNewVelocityGoesInPlaceAndHolds) {
    for (const char* level : {"kinematic.json", "conveyor.json"}) {
        SCOPED_TRACE(level);
        Fixture inPlace(level), rebuilt(level);
        for (Fixture* f : {&inPlace, &rebuilt}) playThenPause(*f, 20);
        const Registry& reg = inPlace.ed.doc.scene.registry;
        Entity platform;
        for (Entity e : reg.entities())
            if (reg.has<Kinematic>(e) && reg.tryGet<Kinematic>(e)->value && reg.has<Velocity>(e)) platform = e;
        ASSERT_TRUE(reg.alive(platform));
        expectRunsAsARebuild(inPlace, rebuilt, "speed up", [&](Scene& s) {
            s.registry.tryGet<Velocity>(platform)->value.x += 0.75;
            return true;
        }, 30);
    }
}

// Moves in place of bodies whose centre of mass is off their position
// (polygons, compound bodies, capsule bones) run as a rebuild too.
TEST(Simulation, AMoveOfAnOffCentreBodyGoesInPlaceAndRunsAsARebuild) {
    for (const char* level : {"polygons.json", "tumbler.json", "terrain.json", "capsules.json"}) {
        SCOPED_TRACE(level);
        Fixture inPlace(level), rebuilt(level);
        for (Fixture* f : {&inPlace, &rebuilt}) playThenPause(*f, 30);
        const Registry& reg = inPlace.ed.doc.scene.registry;
        std::vector<Entity> moved;
        for (Entity e : reg.entities())
            if ((reg.has<Polygon>(e) || reg.has<Shapes>(e) || reg.has<Capsule>(e)) && isFreeBody(reg, e))
                moved.push_back(e);
        ASSERT_FALSE(moved.empty());
        expectRunsAsARebuild(inPlace, rebuilt, "move", [&](Scene& s) {
            for (Entity e : moved) {
                s.registry.tryGet<Position>(e)->value += Vec2{0.05, 0.4};
                s.registry.emplace<Velocity>(e, Velocity{{0.5, 1.0}});
            }
            return true;
        }, 30);
    }
}

namespace {

/// Where a new body can go in a level: above everything in it, over the
/// middle of its dynamic bodies.
Vec2 dropPoint(const Registry& reg) {
    double top = -1e300, sum = 0.0;
    int count = 0;
    for (Entity e : reg.entities()) {
        const Position* p = reg.tryGet<Position>(e);
        if (!p || !isFreeBody(reg, e)) continue;
        top = std::max(top, p->value.y);
        sum += p->value.x;
        ++count;
    }
    return {count ? sum / count : 0.0, top + 2.0};
}

/// Adds, at `at`, one body of each shape kind (a ball with a filter, a
/// turned box, a spinning triangle, a capsule, a compound body) and a pair of boxes
/// hinged together, each with a velocity: what the editor's tools and a
/// paste add.
void addOneOfEach(Scene& s, Vec2 at) {
    Registry& reg = s.registry;
    const auto body = [&](const std::string& name, Vec2 offset, Vec2 velocity) {
        const Entity e = reg.create();
        reg.emplace<Name>(e, Name{name});
        reg.emplace<Position>(e, Position{at + offset});
        reg.emplace<Velocity>(e, Velocity{velocity});
        reg.emplace<Mass>(e, Mass{1.5});
        return e;
    };
    reg.emplace<Radius>(body("new ball", {-2.0, 0.0}, {0.5, -1.0}), Radius{0.3});
    reg.emplace<Filter>(reg.entities().back(), Filter{2, 0xFFFFFFFFu, 0});
    const Entity box = body("new box", {-1.0, 0.5}, {0.0, -2.0});
    reg.emplace<Box>(box, Box{0.6, 0.4});
    reg.emplace<Angle>(box, Angle{0.4});
    const Entity triangle = body("new triangle", {0.0, 0.0}, {-0.5, 0.0});
    reg.emplace<Polygon>(triangle, Polygon{});
    reg.emplace<AngularVelocity>(triangle, AngularVelocity{3.0});
    reg.emplace<Capsule>(body("new capsule", {1.0, 0.5}, {0.0, 1.0}), Capsule{{-0.3, 0.0}, {0.3, 0.0}, 0.15});
    Shapes compound;
    compound.items.resize(2);
    compound.items[0].center = {-0.3, 0.0};
    compound.items[0].radius = 0.2;
    compound.items[1].kind = CompoundShape::Kind::Box;
    compound.items[1].center = {0.3, 0.0};
    compound.items[1].width = compound.items[1].height = 0.4;
    reg.emplace<Shapes>(body("new compound", {2.0, 0.0}, {0.0, 0.0}), std::move(compound));
    const Entity left = body("new link a", {-1.0, 2.0}, {0.0, 0.0});
    const Entity right = body("new link b", {0.0, 2.0}, {1.0, 0.0});
    for (Entity e : {left, right}) reg.emplace<Box>(e, Box{0.8, 0.2});
    const Entity hinge = reg.create();
    reg.emplace<Name>(hinge, Name{"new hinge"});
    Joint joint;
    joint.type = "hinge";
    joint.a = left;
    joint.b = right;
    joint.localA = {0.5, 0.0};
    joint.localB = {-0.5, 0.0};
    reg.emplace<Joint>(hinge, std::move(joint));
}

} // namespace

// Bodies added while paused (one of each shape kind, a hinged pair) go to
// the live World in place, and the run goes on exactly as from a World
// rebuilt from the edited scene: in a pile, a sleeping pyramid (the new
// bodies land on it), ragdolls, compound bodies and filtered shapes.
TEST(Simulation, AddedBodiesGoInPlaceAndRunAsARebuild) {
    // default.json has springs (a pendulum, a crane's cable) and a plane.
    for (const char* level : {"pile.json", "pyramid.json", "ragdoll.json", "tumbler.json", "filters.json", "default.json"}) {
        SCOPED_TRACE(level);
        Fixture inPlace(level), rebuilt(level);
        for (Fixture* f : {&inPlace, &rebuilt}) playThenPause(*f, 60);
        const Vec2 at = dropPoint(inPlace.ed.doc.scene.registry);
        expectRunsAsARebuild(inPlace, rebuilt, "add", [&](Scene& s) {
            addOneOfEach(s, at);
            return true;
        }, 60);
        const World& w = *inPlace.ed.sim.world();
        const Entity ball = findByName(inPlace.ed.doc.scene.registry, "new ball");
        bool found = false;
        for (std::size_t b = 0; b < w.bodyCount(); ++b) found = found || w.bodyEntity(b) == ball;
        EXPECT_TRUE(found) << "the new ball is a body of the World";
        // The new bodies fell: gravity and contacts act on them.
        EXPECT_LT(inPlace.ed.doc.scene.registry.tryGet<Position>(ball)->value.y, at.y - 0.5);
    }
}

// Static shapes added or deleted go in place as well, and wake every
// island (what held a sleeping pile up may be gone): a shelf and a chain
// added into a pile and above a sleeping pyramid, the pyramid's ground
// deleted under it, the pile's floor deleted.
TEST(Simulation, StaticShapesAddedOrDeletedGoInPlaceAndRunAsARebuild) {
    struct Case {
        const char* what;
        const char* level;
        int frames;
        std::function<void(Scene&, Vec2)> edit;
    };
    const auto shelf = [](Scene& s, Vec2 at) {
        const Entity e = s.registry.create();
        s.registry.emplace<Name>(e, Name{"shelf"});
        s.registry.emplace<Position>(e, Position{at});
        s.registry.emplace<Static>(e, Static{true});
        s.registry.emplace<Box>(e, Box{6.0, 0.3});
        s.registry.emplace<Angle>(e, Angle{0.1});
        const Entity ball = s.registry.create();
        s.registry.emplace<Position>(ball, Position{at + Vec2{0.0, 1.0}});
        s.registry.emplace<Radius>(ball, Radius{0.3});
    };
    const auto chain = [](Scene& s, Vec2 at) {
        const Entity e = s.registry.create();
        s.registry.emplace<Position>(e, Position{at});
        s.registry.emplace<Static>(e, Static{true});
        Chain c;
        c.points = {{-3.0, 1.0}, {-1.0, 0.0}, {1.0, 0.0}, {3.0, 1.0}};
        c.loop = false;
        s.registry.emplace<Chain>(e, std::move(c));
    };
    const auto lowestStatic = [](Scene& s, Vec2) {
        Entity lowest;
        double y = 1e300;
        for (Entity e : s.registry.entities())
            if (s.registry.has<Static>(e) && s.registry.tryGet<Static>(e)->value && s.registry.has<Box>(e) &&
                s.registry.tryGet<Position>(e)->value.y < y) {
                y = s.registry.tryGet<Position>(e)->value.y;
                lowest = e;
            }
        (void)s.registry.destroy(lowest);
    };
    const Case cases[] = {{"shelf in a pile", "pile.json", 30, shelf},
                          {"chain over a sleeping pyramid", "pyramid.json", 600, chain},
                          {"the pyramid's ground", "pyramid.json", 600, lowestStatic},
                          {"the pile's floor", "pile.json", 30, lowestStatic}};
    for (const Case& c : cases) {
        SCOPED_TRACE(c.what);
        Fixture inPlace(c.level), rebuilt(c.level);
        for (Fixture* f : {&inPlace, &rebuilt}) playThenPause(*f, c.frames);
        if (c.frames > 100) ASSERT_GT(inPlace.ed.sim.world()->sleepingBodyCount(), 0u) << "the pyramid sleeps";
        const Vec2 at = dropPoint(inPlace.ed.doc.scene.registry);
        expectRunsAsARebuild(inPlace, rebuilt, c.what, [&](Scene& s) {
            c.edit(s, at);
            return true;
        }, 45);
        EXPECT_EQ(inPlace.ed.sim.world()->sleepingBodyCount(), rebuilt.ed.sim.world()->sleepingBodyCount());
    }
}

// The editor's own Duplicate and Paste add in place: a ragdoll (bones and
// joints) duplicated, a pyramid's boxes copied and pasted.
TEST(Simulation, DuplicateAndPasteAddInPlaceAndRunAsARebuild) {
    for (const char* level : {"ragdoll.json", "pyramid.json"}) {
        SCOPED_TRACE(level);
        Fixture inPlace(level), rebuilt(level);
        for (Fixture* f : {&inPlace, &rebuilt}) playThenPause(*f, 30);
        std::vector<Entity> bodies;
        const Registry& reg = inPlace.ed.doc.scene.registry;
        for (Entity e : reg.entities())
            if (isFreeBody(reg, e) && bodies.size() < 12) bodies.push_back(e);
        const std::uint64_t builds = inPlace.ed.sim.worldBuilds();
        const std::size_t before = reg.size();
        for (Fixture* f : {&inPlace, &rebuilt}) {
            f->ed.select(bodies);
            if (level == std::string("ragdoll.json")) {
                ASSERT_TRUE(f->ed.duplicateSelection());
            } else {
                f->ed.copySelection();
                ASSERT_TRUE(f->ed.paste());
            }
        }
        EXPECT_GE(inPlace.ed.doc.scene.registry.size(), before + bodies.size());
        rebuilt.ed.sim.sceneChanged();
        for (int i = 0; i < 60; ++i) {
            inPlace.ed.stepForward();
            rebuilt.ed.stepForward();
        }
        EXPECT_EQ(inPlace.ed.sim.worldBuilds(), builds) << "added in place, never rebuilt";
        EXPECT_TRUE(textOf(inPlace.ed.doc.scene) == textOf(rebuilt.ed.doc.scene));
    }
}

// Deleting bodies (with the joints on them) while paused goes in place as
// well: a circle inside the pile, a box of a sleeping pyramid (its island
// wakes and the boxes above it fall), a whole ragdoll, one joint of it.
TEST(Simulation, DeletedBodiesLeaveInPlaceAndRunAsARebuild) {
    struct Case {
        const char* level;
        std::function<std::vector<Entity>(const Registry&)> pick;
    };
    const auto named = [](const char* name) {
        return [name](const Registry& reg) { return std::vector<Entity>{findByName(reg, name)}; };
    };
    // The dynamic box nearest the middle of the level's lowest row.
    const auto lowBox = [](const Registry& reg) {
        Entity best;
        double lowest = 1e300;
        for (Entity e : reg.entities())
            if (reg.has<Box>(e) && isFreeBody(reg, e) && reg.tryGet<Position>(e)->value.y < lowest - 1e-3) {
                lowest = reg.tryGet<Position>(e)->value.y;
                best = e;
            }
        return std::vector<Entity>{best};
    };
    // Every dynamic body (the ragdoll's bones; its joints go with them).
    const auto everyBody = [](const Registry& reg) {
        std::vector<Entity> out;
        for (Entity e : reg.entities())
            if (isFreeBody(reg, e)) out.push_back(e);
        return out;
    };
    const auto firstJoint = [](const Registry& reg) {
        for (Entity e : reg.entities())
            if (reg.has<Joint>(e)) return std::vector<Entity>{e};
        return std::vector<Entity>{};
    };
    const Case cases[] = {{"pile.json", named("c1000")},
                          {"pile.json", named("c0")},
                          {"pyramid.json", lowBox},
                          {"ragdoll.json", everyBody},
                          {"ragdoll.json", firstJoint},
                          // A crate among springs; the bob, whose spring goes with it.
                          {"default.json", named("crate 3")},
                          {"default.json", named("bob")}};
    for (const Case& c : cases) {
        Fixture inPlace(c.level), rebuilt(c.level);
        for (Fixture* f : {&inPlace, &rebuilt}) playThenPause(*f, c.level == std::string("pyramid.json") ? 600 : 60);
        const std::vector<Entity> doomed = c.pick(inPlace.ed.doc.scene.registry);
        SCOPED_TRACE(std::string(c.level) + ", " + std::to_string(doomed.size()) + " deleted");
        ASSERT_FALSE(doomed.empty());
        for (Entity e : doomed) ASSERT_TRUE(inPlace.ed.doc.scene.registry.alive(e));
        const std::uint64_t builds = inPlace.ed.sim.worldBuilds();
        for (Fixture* f : {&inPlace, &rebuilt}) {
            f->ed.select(doomed);
            ASSERT_TRUE(f->ed.deleteSelection());
        }
        rebuilt.ed.sim.sceneChanged();
        for (int i = 0; i < 60; ++i) {
            inPlace.ed.stepForward();
            rebuilt.ed.stepForward();
        }
        EXPECT_EQ(inPlace.ed.sim.worldBuilds(), builds) << "deleted in place, never rebuilt";
        EXPECT_EQ(textOf(inPlace.ed.doc.scene), textOf(rebuilt.ed.doc.scene));
    }
}

// Step back after an edit made in place returns the scene as the steps
// after the edit left it (the new body there, the new mass kept), and
// stepping on again repeats them bit for bit; stepping back past the edit
// returns the state from before it.
TEST(Simulation, StepBackAfterAnEditInPlaceRestoresTheEditedScene) {
    struct Case {
        const char* what;
        std::function<void(Scene&, Vec2)> edit;
    };
    const Case cases[] = {
        {"add", [](Scene& s, Vec2 at) { addOneOfEach(s, at); }},
        {"delete", [](Scene& s, Vec2) { (void)s.registry.destroy(findByName(s.registry, "c1000")); }},
        {"mass", [](Scene& s, Vec2) { s.registry.emplace<Mass>(findByName(s.registry, "c1899"), Mass{3.0}); }},
        {"radius", [](Scene& s, Vec2) { s.registry.tryGet<Radius>(findByName(s.registry, "c1500"))->value = 0.4; }},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.what);
        Fixture f("pile.json");
        playThenPause(f, 30);
        const std::string before = textOf(f.ed.doc.scene);
        const Vec2 at = dropPoint(f.ed.doc.scene.registry);
        const std::uint64_t builds = f.ed.sim.worldBuilds();
        ASSERT_TRUE(f.ed.applyEdit(c.what, [&](Scene& s) {
            c.edit(s, at);
            return true;
        }));
        std::vector<std::string> pass;
        for (int i = 0; i < 6; ++i) {
            f.ed.stepForward();
            pass.push_back(textOf(f.ed.doc.scene));
        }
        EXPECT_EQ(f.ed.sim.worldBuilds(), builds) << "the edit went in place";
        for (int i = 0; i < 3; ++i) f.ed.stepBack();
        // (Compared as booleans: a level's text is too long to print.)
        EXPECT_TRUE(textOf(f.ed.doc.scene) == pass[2]);
        for (int i = 3; i < 6; ++i) {
            f.ed.stepForward();
            EXPECT_TRUE(textOf(f.ed.doc.scene) == pass[std::size_t(i)]) << "step " << i + 1 << " after the edit";
        }
        for (int i = 0; i < 6; ++i) f.ed.stepBack();
        EXPECT_EQ(f.ed.sim.steps(), 30u);
        EXPECT_TRUE(textOf(f.ed.doc.scene) != before) << "back to the step the edit was made at, with the edit";
        f.ed.stepBack();
        EXPECT_EQ(f.ed.sim.steps(), 29u);
    }
}

// Undo of an add or a delete made in place, with no step between, goes
// back to the run as it was: the steps that follow are those of a run
// never edited, bit for bit.
TEST(Simulation, UndoOfAnAddOrDeleteInPlaceRunsAsIfNeverEdited) {
    for (const bool add : {true, false}) {
        SCOPED_TRACE(add ? "add" : "delete");
        Fixture edited("pile.json"), untouched("pile.json");
        for (Fixture* f : {&edited, &untouched}) playThenPause(*f, 30);
        const Vec2 at = dropPoint(edited.ed.doc.scene.registry);
        ASSERT_TRUE(edited.ed.applyEdit(add ? "add" : "delete", [&](Scene& s) {
            if (add) addOneOfEach(s, at);
            else (void)s.registry.destroy(findByName(s.registry, "c1000"));
            return true;
        }));
        ASSERT_TRUE(edited.ed.undo());
        for (int i = 0; i < 30; ++i) {
            edited.ed.stepForward();
            untouched.ed.stepForward();
        }
        EXPECT_TRUE(textOf(edited.ed.doc.scene) == textOf(untouched.ed.doc.scene));
    }
}

// Undo and redo of edits taken in place (with steps between, so the run
// goes on from where it is) go in place too, and run as a rebuild: a move,
// a mass, a radius, an add and a delete, each undone then redone. Undoing
// a delete brings the body back at its place in the scene's order, not
// last: in place too, between the kept bodies.
TEST(Simulation, UndoAndRedoOfEditsInPlaceGoInPlaceAndRunAsARebuild) {
    struct Case {
        const char* what;
        std::function<void(Scene&, Vec2)> edit;
    };
    const Case cases[] = {
        {"move", [](Scene& s, Vec2) { s.registry.tryGet<Position>(findByName(s.registry, "c1899"))->value.y += 1.0; }},
        {"mass", [](Scene& s, Vec2) { s.registry.emplace<Mass>(findByName(s.registry, "c1899"), Mass{3.0}); }},
        {"radius", [](Scene& s, Vec2) { s.registry.tryGet<Radius>(findByName(s.registry, "c1500"))->value = 0.4; }},
        {"add", [](Scene& s, Vec2 at) { addOneOfEach(s, at); }},
        {"delete", [](Scene& s, Vec2) { (void)s.registry.destroy(findByName(s.registry, "c1000")); }},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.what);
        Fixture inPlace("pile.json"), rebuilt("pile.json");
        for (Fixture* f : {&inPlace, &rebuilt}) playThenPause(*f, 30);
        const Vec2 at = dropPoint(inPlace.ed.doc.scene.registry);
        for (Fixture* f : {&inPlace, &rebuilt}) {
            ASSERT_TRUE(f->ed.applyEdit(c.what, [&](Scene& s) {
                c.edit(s, at);
                return true;
            }));
            for (int i = 0; i < 5; ++i) f->ed.stepForward();
        }
        const std::uint64_t builds = inPlace.ed.sim.worldBuilds();
        for (const bool undo : {true, false}) {
            for (Fixture* f : {&inPlace, &rebuilt}) ASSERT_TRUE(undo ? f->ed.undo() : f->ed.redo());
            rebuilt.ed.sim.sceneChanged();
            for (int i = 0; i < 15; ++i) {
                inPlace.ed.stepForward();
                rebuilt.ed.stepForward();
            }
            EXPECT_EQ(inPlace.ed.sim.worldBuilds(), builds) << (undo ? "undo" : "redo") << " went in place";
            EXPECT_TRUE(textOf(inPlace.ed.doc.scene) == textOf(rebuilt.ed.doc.scene)) << (undo ? "undo" : "redo");
        }
    }
}

// While editing, the panels' World takes adds, deletes and their undos in
// place or rebuilt, in any order, and ends as a World built from the
// scene: a box added, three circles deleted, both undone, then redone.
TEST(Simulation, TheEditingWorldFollowsAddsDeletesAndTheirUndos) {
    Fixture f("pile.json");
    const auto frame = [&f] { ASSERT_NE(f.ed.sim.editingWorld(f.ed.doc.scene), nullptr) << f.ed.sim.editingWorldError(); };
    frame();
    ASSERT_TRUE(f.ed.applyEdit("add", [](Scene& s) {
        const Entity e = s.registry.create();
        s.registry.emplace<Position>(e, Position{{-2.0, 20.0}});
        s.registry.emplace<Box>(e, Box{1.0, 1.0});
        return true;
    }));
    frame();
    f.ed.select({findByName(f.ed.doc.scene.registry, "c100"), findByName(f.ed.doc.scene.registry, "c101"),
                 findByName(f.ed.doc.scene.registry, "c102")});
    ASSERT_TRUE(f.ed.deleteSelection());
    frame();
    for (const bool undo : {true, true, false, false}) {
        ASSERT_TRUE(undo ? f.ed.undo() : f.ed.redo());
        frame();
        Result<World> built = World::build(f.ed.doc.scene);
        ASSERT_TRUE(built) << built.error();
        const World& live = *f.ed.sim.editingWorld(f.ed.doc.scene);
        ASSERT_EQ(live.bodyCount(), built->bodyCount());
        for (std::size_t b = 0; b < built->bodyCount(); ++b) EXPECT_EQ(live.bodyEntity(b), built->bodyEntity(b));
    }
}

// Step back past an edit restores a scene without it: the undo history
// past the restored step goes with it, else an undo would restore a body
// the scene does not have (a stranger's script: a ball added, moved,
// stepped back past, undone). Stepping back over an undo clears it all (a
// redo would add the ball a second time); stepping back between edits
// keeps it.
TEST(Simulation, StepBackPastAnEditDropsTheUndoHistoryPastTheStep) {
    const auto addBall = [](Editor& ed) {
        return ed.applyEdit("add ball", [](Scene& s) {
            const Entity e = s.registry.create();
            s.registry.emplace<Name>(e, Name{"late ball"});
            s.registry.emplace<Position>(e, Position{{0.0, 8.0}});
            s.registry.emplace<Radius>(e, Radius{0.3});
            return true;
        });
    };
    const auto moveBall = [](Editor& ed) {
        return ed.applyEdit("move ball", [](Scene& s) {
            s.registry.tryGet<Position>(findByName(s.registry, "late ball"))->value.x += 1.0;
            return true;
        });
    };
    {
        Fixture f("ragdoll.json");
        for (int i = 0; i < 2; ++i) f.ed.stepForward();
        ASSERT_TRUE(addBall(f.ed));
        ASSERT_TRUE(moveBall(f.ed));
        ASSERT_EQ(f.ed.commands.size(), 2u);
        f.ed.stepBack();  // to the state before step 2: before both edits
        EXPECT_TRUE(findByName(f.ed.doc.scene.registry, "late ball").isNull());
        EXPECT_EQ(f.ed.commands.size(), 0u);
        EXPECT_NE(f.ed.status.find("the undo history past that step is cleared (2 edits)"), std::string::npos)
            << f.ed.status;
        EXPECT_FALSE(f.ed.undo());
        for (int i = 0; i < 3; ++i) f.ed.stepForward();
        EXPECT_TRUE(f.ed.sim.message().empty()) << f.ed.sim.message();
    }
    // One step, the ball added, `steps` more.
    const auto ballInARun = [&](Fixture& f, int steps) {
        f.ed.stepForward();
        const bool added = addBall(f.ed);
        for (int i = 0; i < steps; ++i) f.ed.stepForward();
        return added;
    };
    {
        Fixture f("ragdoll.json");
        ASSERT_TRUE(ballInARun(f, 3));
        ASSERT_TRUE(f.ed.undo());
        EXPECT_TRUE(findByName(f.ed.doc.scene.registry, "late ball").isNull());
        f.ed.stepBack();  // to a step the ball took
        EXPECT_FALSE(findByName(f.ed.doc.scene.registry, "late ball").isNull());
        EXPECT_EQ(f.ed.commands.size(), 0u);
        EXPECT_FALSE(f.ed.redo());
        EXPECT_FALSE(f.ed.undo());
        for (int i = 0; i < 3; ++i) f.ed.stepForward();
        EXPECT_TRUE(f.ed.sim.message().empty()) << f.ed.sim.message();
    }
    {
        Fixture f("ragdoll.json");
        ASSERT_TRUE(ballInARun(f, 5));
        f.ed.stepBack();
        f.ed.stepBack();
        EXPECT_EQ(f.ed.commands.size(), 1u) << "no edit was stepped back past";
        ASSERT_TRUE(f.ed.undo());
        EXPECT_TRUE(findByName(f.ed.doc.scene.registry, "late ball").isNull());
    }
}

// A stranger's session: 60 actions drawn from adds, deletes, duplicates,
// moves, masses, radii, undos, redos, steps and steps back, in an order
// from a fixed seed. After each, the run with edits in place and one that
// rebuilds its World after every action hold the same bytes.
TEST(Simulation, ARandomSessionOfEditsInPlaceRunsAsRebuilds) {
    // default.json: a plane, springs (deleting the bob takes its spring).
    for (const char* level : {"pile.json", "default.json"}) {
        SCOPED_TRACE(level);
        Fixture inPlace(level), rebuilt(level);
        for (Fixture* f : {&inPlace, &rebuilt}) playThenPause(*f, 20);
        std::uint64_t state = 12345;
        const auto next = [&state](std::uint64_t n) {
            state = state * 6364136223846793005ull + 1442695040888963407ull;
            return (state >> 33) % n;
        };
        const auto someBody = [](const Registry& reg, std::uint64_t pick) {
            std::vector<Entity> free;
            for (Entity e : reg.entities())
                if (isFreeBody(reg, e) && reg.has<Radius>(e)) free.push_back(e);
            return free.empty() ? Entity{} : free[pick % free.size()];
        };
        int added = 0;
        for (int action = 0; action < 60; ++action) {
            const std::uint64_t kind = next(10), pick = next(1u << 20);
            const Entity body = someBody(inPlace.ed.doc.scene.registry, pick);
            SCOPED_TRACE("action " + std::to_string(action) + " kind " + std::to_string(kind));
            for (Fixture* f : {&inPlace, &rebuilt}) {
                Editor& ed = f->ed;
                switch (kind) {
                case 0:
                    (void)ed.applyEdit("add", [&](Scene& s) {
                        const Entity e = s.registry.create();
                        s.registry.emplace<Name>(e, Name{"added " + std::to_string(added)});
                        s.registry.emplace<Position>(e, Position{{-10.0 + double(pick % 20), 24.0}});
                        if (pick % 2) s.registry.emplace<Radius>(e, Radius{0.3});
                        else s.registry.emplace<Box>(e, Box{0.5, 0.4});
                        return true;
                    });
                    break;
                case 1:
                    ed.select({body});
                    (void)ed.deleteSelection();
                    break;
                case 2:
                    ed.select({body});
                    (void)ed.duplicateSelection();
                    break;
                case 3:
                    (void)ed.applyEdit("move", [&](Scene& s) {
                        s.registry.tryGet<Position>(body)->value.y += 0.5;
                        return true;
                    });
                    break;
                case 4:
                    (void)ed.applyEdit("mass", [&](Scene& s) {
                        s.registry.emplace<Mass>(body, Mass{0.5 + double(pick % 4)});
                        return true;
                    });
                    break;
                case 5:
                    (void)ed.applyEdit("radius", [&](Scene& s) {
                        s.registry.tryGet<Radius>(body)->value = 0.2 + 0.02 * double(pick % 5);
                        return true;
                    });
                    break;
                case 6: (void)ed.undo(); break;
                case 7: (void)ed.redo(); break;
                case 8:
                    for (int i = 0; i < 3; ++i) ed.stepForward();
                    break;
                default: ed.stepBack(); break;
                }
            }
            added += kind == 0 ? 1 : 0;
            rebuilt.ed.sim.sceneChanged();
            inPlace.ed.stepForward();
            rebuilt.ed.stepForward();
            ASSERT_TRUE(textOf(inPlace.ed.doc.scene) == textOf(rebuilt.ed.doc.scene));
        }
        EXPECT_LT(inPlace.ed.sim.worldBuilds(), rebuilt.ed.sim.worldBuilds() / 2) << "most actions went in place";
    }
}

// What the World does not take in place rebuilds, and still runs as the
// rebuild: a static wall, a spring, a body spinning near the speed limit,
// a body joined to one already there, a heavy body that changes the
// engine's choice of settings.
TEST(Simulation, AddsTheWorldCannotTakeInPlaceRebuild) {
    struct Case {
        const char* what;
        const char* level;
        std::function<void(Scene&, Vec2)> add;
    };
    const auto ball = [](Scene& s, Vec2 at, double mass) {
        const Entity e = s.registry.create();
        s.registry.emplace<Position>(e, Position{at});
        s.registry.emplace<Radius>(e, Radius{0.3});
        s.registry.emplace<Mass>(e, Mass{mass});
        return e;
    };
    const Case cases[] = {
        {"spring", "pile.json",
         [&](Scene& s, Vec2 at) {
             const Entity e = ball(s, at, 1.0);
             const Entity spring = s.registry.create();
             Spring sp;
             sp.a = e;
             sp.anchor = at + Vec2{0.0, 1.0};
             sp.k = 50.0;
             s.registry.emplace<Spring>(spring, std::move(sp));
         }},
        // A spin near the speed limit a build checks (it falls clear of
        // the pile in these steps).
        {"spin", "pile.json",
         [&](Scene& s, Vec2 at) { s.registry.emplace<AngularVelocity>(ball(s, at, 1.0), AngularVelocity{2e9}); }},
        {"joint to an old body", "ragdoll.json",
         [&](Scene& s, Vec2 at) {
             Entity old;
             for (Entity e : s.registry.entities())
                 if (isFreeBody(s.registry, e)) old = e;
             const Entity e = ball(s, at, 1.0);
             const Entity j = s.registry.create();
             Joint joint;
             joint.type = "distance";
             joint.a = e;
             joint.b = old;
             joint.length = 3.0;
             s.registry.emplace<Joint>(j, std::move(joint));
         }},
        {"heavy", "kinematic.json", [&](Scene& s, Vec2 at) { ball(s, at, 1000.0); }},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.what);
        Fixture inPlace(c.level), rebuilt(c.level);
        for (Fixture* f : {&inPlace, &rebuilt}) playThenPause(*f, 30);
        const Vec2 at = dropPoint(inPlace.ed.doc.scene.registry);
        expectRunsAsARebuild(inPlace, rebuilt, "add", [&](Scene& s) {
            c.add(s, at);
            return true;
        }, 30, true);
    }
}

TEST(Simulation, DisabledSystemIsLeftOutOfTheWorld) {
    Fixture f("spring_chain.json");
    f.ed.sim.disabledSystems.insert("springs");
    f.ed.stepForward();
    ASSERT_NE(f.ed.sim.world(), nullptr) << f.ed.sim.message();
    const auto active = f.ed.sim.world()->activeSystems();
    EXPECT_EQ(std::find(active.begin(), active.end(), "springs"), active.end());
    EXPECT_NE(std::find(active.begin(), active.end(), "gravity"), active.end());
    // The document keeps its springs.
    EXPECT_GT(f.ed.doc.scene.registry.count<Spring>(), 0u);
}

TEST(Simulation, DivergencePausesAndNamesEntityAndQuantity) {
    Fixture f("orbit.json");
    ASSERT_TRUE(f.ed.applyEdit("blow up", [&](Scene& s) {
        // A spring far too stiff for the level's explicit step (h omega
        // about 130) on the planet (first body): its swing grows about
        // 1e4-fold a step and passes the fastest speed a level holds within
        // a few steps, though its first step is one a run holds (a pull
        // past that the build refuses, below).
        const Entity planet = findByName(s.registry, "planet");
        const Vec2 at = s.registry.tryGet<Position>(planet)->value;
        const double mass = s.registry.has<Mass>(planet) ? s.registry.tryGet<Mass>(planet)->value : 1.0;
        const Entity spring = s.registry.create();
        s.registry.emplace<Spring>(spring, Spring{planet, Entity{}, at + Vec2{1.0, 0.0}, 1e9 * mass, 0.0, 0.0});
        return true;
    }));
    f.ed.togglePlay();
    for (int i = 0; i < 5 && f.ed.sim.state() == SimState::Playing; ++i) f.ed.update(1.0 / 60.0);
    EXPECT_EQ(f.ed.sim.state(), SimState::Paused);
    EXPECT_TRUE(f.ed.sim.diverged());
    EXPECT_NE(f.ed.sim.message().find("planet"), std::string::npos) << f.ed.sim.message();
    EXPECT_NE(f.ed.sim.message().find("became"), std::string::npos) << f.ed.sim.message();
}

TEST(Simulation, APullNoStepCanTakeIsRefusedNamingTheBody) {
    Fixture f("orbit.json");
    ASSERT_TRUE(f.ed.applyEdit("blow up", [&](Scene& s) {
        s.world.G = 1e30;  // the most a level holds
        return true;
    }));
    f.ed.togglePlay();
    f.ed.update(1.0 / 60.0);
    EXPECT_EQ(f.ed.sim.steps(), 0u);
    EXPECT_NE(f.ed.sim.message().find("cannot simulate: entity 1 (\"planet\"): the attractors pull it at"),
              std::string::npos)
        << f.ed.sim.message();
    EXPECT_TRUE(f.ed.sim.cannotSimulate());
    // Undone, the level builds again and the refusal is over.
    ASSERT_TRUE(f.ed.undo());
    f.ed.stepForward();
    EXPECT_EQ(f.ed.sim.steps(), 1u) << f.ed.sim.message();
    EXPECT_FALSE(f.ed.sim.cannotSimulate());
}

TEST(Simulation, TimeScaleSetsStepsPerFrame) {
    Fixture f("orbit.json");  // dt = 1/240
    // A clock that never moves: every step fits the frame's budget however
    // slow this machine is right now (with the wall clock, a busy machine
    // got fewer steps).
    f.ed.sim.clockMs = [] { return 0.0; };
    f.ed.sim.timeScale = 0.5;
    f.ed.togglePlay();
    for (int i = 0; i < 10; ++i) f.ed.update(1.0 / 60.0);
    EXPECT_EQ(f.ed.sim.steps(), 20u);  // 10 frames * (1/60 * 0.5) / (1/240)
    EXPECT_FALSE(f.ed.sim.behind());
}

TEST(Simulation, StepsPastTheFrameBudgetAreDropped) {
    Fixture f("orbit.json");  // dt = 1/240: a 1/60 s frame is due 4 steps
    // A fake clock 3 ms later at every read (advance reads it once at the
    // frame's start and once before each step): with the 8 ms budget the
    // frame takes its first step (always), a second at 6 ms spent, and stops
    // at 9 ms with 2 of its 4 steps dropped.
    double now = 0.0;
    f.ed.sim.clockMs = [&] { return now += 3.0; };
    f.ed.sim.physicsBudgetMs = 8.0;
    f.ed.togglePlay();
    f.ed.update(1.0 / 60.0);
    EXPECT_EQ(f.ed.sim.steps(), 2u);
    EXPECT_TRUE(f.ed.sim.behind());
}

TEST(Simulation, ASlowFrameDropsTimeInsteadOfTakingMoreSteps) {
    Fixture f("orbit.json");  // dt = 1/240: a 1/60 s frame is due 4 steps
    // A clock that never moves (as in TimeScaleSetsStepsPerFrame): with
    // the wall clock, four steps under the sanitizers on a loaded machine
    // overran the 8 ms budget and the first check saw one step.
    f.ed.sim.clockMs = [] { return 0.0; };
    f.ed.togglePlay();
    f.ed.update(1.0 / 60.0);
    EXPECT_EQ(f.ed.sim.steps(), 4u);
    EXPECT_FALSE(f.ed.sim.behind());
    // A budget already spent after the first step (as on a frame where one
    // step takes longer than the budget): one step per frame, the rest of
    // the frame's time dropped, and the editor says it is behind.
    f.ed.sim.physicsBudgetMs = -1.0;
    for (int i = 0; i < 5; ++i) f.ed.update(1.0 / 60.0);
    EXPECT_EQ(f.ed.sim.steps(), 9u);
    EXPECT_TRUE(f.ed.sim.behind());
    // The dropped time is not owed later: back on budget, 4 per frame again.
    f.ed.sim.physicsBudgetMs = 1e9;
    f.ed.update(1.0 / 60.0);
    EXPECT_EQ(f.ed.sim.steps(), 13u);
    EXPECT_FALSE(f.ed.sim.behind());
}

TEST(Simulation, StepCounterIsClearedByResetNewAndOpen) {
    Fixture f("default.json");
    for (int i = 0; i < 5; ++i) f.ed.stepForward();
    ASSERT_EQ(f.ed.sim.steps(), 5u);
    f.ed.resetSimulation();
    EXPECT_EQ(f.ed.sim.steps(), 0u);
    for (int i = 0; i < 3; ++i) f.ed.stepForward();
    f.ed.newDocument();
    EXPECT_EQ(f.ed.sim.steps(), 0u);
    ASSERT_TRUE(f.ed.open(kLevels / "orbit.json"));
    for (int i = 0; i < 2; ++i) f.ed.stepForward();
    ASSERT_TRUE(f.ed.open(kLevels / "default.json"));
    EXPECT_EQ(f.ed.sim.steps(), 0u);
}

// A joint that breaks (max_force) is named in the status line when the step
// it broke in is taken, and leaves the running scene; stepping back before
// the break brings it back.
TEST(SimulationBreaks, AJointThatBreaksIsNamedInTheStatusAndLeavesTheScene) {
    LevelOpen f("breaking_bridge.json");
    Editor& ed = f.ed;
    const auto pinAlive = [&] {
        for (Entity e : ed.doc.scene.registry.entities())
            if (const Name* n = ed.doc.scene.registry.tryGet<Name>(e); n && n->value == "pin 6") return true;
        return false;
    };
    bool named = false;
    for (int i = 0; i < 30; ++i) {
        ed.stepForward();
        named = named || ed.status.find("joint \"pin 6\" broke at t = ") != std::string::npos;
    }
    EXPECT_TRUE(named) << ed.status;
    EXPECT_FALSE(pinAlive());
    for (int i = 0; i < 25; ++i) ed.stepBack();
    EXPECT_TRUE(pinAlive()) << "stepping back before the break brings the joint back";
}

TEST(Simulation, StepBackAcrossEmissionsIsExact) {
    // emitter_rain drops a doll every 30 steps: stepping back over the
    // steps where a copy appeared brings back the scene of that step, copies
    // and all, and stepping on again retraces the first pass byte for byte.
    Fixture f("emitter_rain.json");
    std::vector<std::string> pass;
    pass.push_back(textOf(f.ed.doc.scene));
    for (int i = 0; i < 70; ++i) {
        f.ed.stepForward();
        ASSERT_EQ(f.ed.sim.state(), SimState::Paused) << f.ed.sim.message();
        pass.push_back(textOf(f.ed.doc.scene));
    }
    EXPECT_NE(pass[70].find("\"doll#3\""), std::string::npos);
    EXPECT_EQ(pass[30].find("\"doll#2\""), std::string::npos);
    for (int i = 69; i >= 20; --i) {
        f.ed.stepBack();
        ASSERT_EQ(textOf(f.ed.doc.scene), pass[std::size_t(i)]) << "back to step " << i;
    }
    for (int i = 21; i <= 70; ++i) {
        f.ed.stepForward();
        ASSERT_EQ(textOf(f.ed.doc.scene), pass[std::size_t(i)]) << "on to step " << i;
    }
}

// Select all, copy, paste in a run with copies alive: the pasted template
// is a template of its own with its own emitter, which starts from
// nothing; the pasted copies are the designer's bodies (no '#' in their
// names); the run goes on with both emitters. (Pasted into the original
// template, the new parts were missing from the copies alive, and the run
// refused to go on.) One part duplicated joins its template.
TEST(Simulation, APastedTemplateAndEmitterRunBesideTheOriginal) {
    Fixture f("emitter_rain.json");
    for (int i = 0; i < 40; ++i) f.ed.stepForward();
    ASSERT_FALSE(f.named("doll#2/head").isNull());
    f.ed.selectAll();
    f.ed.copySelection();
    ASSERT_TRUE(f.ed.paste());
    const Registry& reg = f.ed.doc.scene.registry;
    int parts = 0, newParts = 0;
    for (const Entity e : f.ed.selection) {
        if (const Name* n = reg.tryGet<Name>(e)) EXPECT_EQ(n->value.find('#'), std::string::npos) << n->value;
        if (const Template* t = reg.tryGet<Template>(e)) newParts += t->value == "doll_2" ? 1 : 0;
        if (const Emitter* em = reg.tryGet<Emitter>(e)) {
            EXPECT_EQ(em->templateName, "doll_2");
            EXPECT_EQ(em->emitted, 0);
            EXPECT_EQ(em->alive, 0);
        }
    }
    for (const Entity e : reg.entities())
        if (const Template* t = reg.tryGet<Template>(e)) parts += t->value == "doll" ? 1 : 0;
    EXPECT_GT(newParts, 0);
    EXPECT_EQ(newParts, parts);
    for (int i = 0; i < 40; ++i) {
        f.ed.stepForward();
        ASSERT_TRUE(f.ed.sim.message().empty()) << f.ed.sim.message();
    }
    EXPECT_FALSE(f.named("doll_2#1/head_2").isNull()) << "the pasted emitter copies its own template";
    EXPECT_FALSE(f.named("doll#3/head").isNull()) << "the original goes on";
    f.ed.select({f.named("head")});
    ASSERT_TRUE(f.ed.duplicateSelection());
    EXPECT_EQ(reg.tryGet<Template>(f.ed.selection.front())->value, "doll");
}

// An emitter duplicated or pasted without its template is a second emitter
// of that template: the two share its copy numbers, so every copy has its
// own name, before and during a run, and the scene saves and loads.
// Deleting the first emitter keeps its copies alive as the designer's own
// bodies (their names lose the '#'); the other goes on numbering past every
// copy alive; undo gives the names back.
TEST(Simulation, AnEmitterCopiedWithoutItsTemplateSharesItsCopyNumbers) {
    for (const int steps : {0, 35}) {
        SCOPED_TRACE(std::to_string(steps) + " steps first");
        Fixture f("emitter_rain.json");
        for (int i = 0; i < steps; ++i) f.ed.stepForward();
        f.ed.select({f.named("hatch")});
        ASSERT_TRUE(f.ed.duplicateSelection()) << f.ed.status;
        const Entity second = f.ed.selection.front();
        EXPECT_EQ(f.ed.doc.scene.registry.tryGet<Emitter>(second)->templateName, "doll");
        for (int i = 0; i < 90; ++i) f.ed.stepForward();
        EXPECT_TRUE(f.ed.sim.message().empty()) << f.ed.sim.message();
        const Registry& reg = f.ed.doc.scene.registry;
        const Emitter first = *reg.tryGet<Emitter>(f.named("hatch"));
        const Emitter copyEmitter = *reg.tryGet<Emitter>(second);
        EXPECT_GT(copyEmitter.emitted, 0);
        std::set<std::string> names;
        for (const Entity e : reg.entities())
            if (const Name* n = reg.tryGet<Name>(e)) EXPECT_TRUE(names.insert(n->value).second) << n->value;
        for (const Emitter* em : {&first, &copyEmitter})
            for (const int k : copyNumbers(*em)) EXPECT_TRUE(names.contains("doll#" + std::to_string(k))) << k;
        const Result<Scene> reloaded = parseScene(textOf(f.ed.doc.scene), "after.json");
        ASSERT_TRUE(reloaded) << reloaded.error();
        // The second emitter's copies alive are listed (not its newest
        // numbers); a copy of it starts from nothing, with no list.
        ASSERT_FALSE(copyEmitter.copies.empty());
        f.ed.select({second});
        ASSERT_TRUE(f.ed.duplicateSelection()) << f.ed.status;
        const Entity third = f.ed.selection.front();
        EXPECT_EQ(reg.tryGet<Emitter>(third)->emitted, 0);
        EXPECT_TRUE(reg.tryGet<Emitter>(third)->copies.empty());
        for (int i = 0; i < 20; ++i) f.ed.stepForward();
        EXPECT_TRUE(f.ed.sim.message().empty()) << f.ed.sim.message();
        EXPECT_GT(f.ed.doc.scene.registry.tryGet<Emitter>(third)->emitted, 0);
        f.ed.select({third});
        ASSERT_TRUE(f.ed.deleteSelection()) << f.ed.status;

        const std::vector<int> orphaned = copyNumbers(*reg.tryGet<Emitter>(f.named("hatch")));
        ASSERT_FALSE(orphaned.empty());
        f.ed.select({f.named("hatch")});
        ASSERT_TRUE(f.ed.deleteSelection()) << f.ed.status;
        for (const int k : orphaned) {
            EXPECT_TRUE(f.named("doll#" + std::to_string(k)).isNull()) << k;
            EXPECT_FALSE(f.named("doll " + std::to_string(k)).isNull()) << k;
        }
        for (int i = 0; i < 60; ++i) f.ed.stepForward();
        EXPECT_TRUE(f.ed.sim.message().empty()) << f.ed.sim.message();
        const Result<Scene> afterDelete = parseScene(textOf(f.ed.doc.scene), "deleted.json");
        EXPECT_TRUE(afterDelete) << (afterDelete ? "" : afterDelete.error());
    }
}

// A copy alive is whatever bears its name: a part deleted from it, or a
// part added to its template, leaves the run going (it refused to step
// on). An add or delete cannot be undone or redone once the run has added
// entities since (the emitter's copies): the undo would put back the
// entity table of its time and drop them. It is refused, saying why.
TEST(Simulation, EditsToALiveCopyOrItsTemplateLeaveTheRunGoing) {
    Fixture f("emitter_rain.json");
    f.ed.select({f.named("arm right")});
    ASSERT_TRUE(f.ed.deleteSelection());
    ASSERT_TRUE(f.ed.undo());
    for (int i = 0; i < 40; ++i) f.ed.stepForward();
    ASSERT_FALSE(f.named("doll#2/head").isNull());
    const std::string before = textOf(f.ed.doc.scene);
    EXPECT_FALSE(f.ed.redo());
    EXPECT_TRUE(f.ed.statusRefused);
    EXPECT_EQ(f.ed.status.rfind("redo refused: the run added or removed entities", 0), 0u) << f.ed.status;
    EXPECT_EQ(textOf(f.ed.doc.scene), before);
    f.ed.select({f.named("doll#2/head")});
    ASSERT_TRUE(f.ed.deleteSelection());
    ASSERT_TRUE(f.ed.applyEdit("one more part", [](Scene& s) {
        const Entity e = s.registry.create();
        s.registry.emplace<Name>(e, Name{"hat"});
        s.registry.emplace<Position>(e, Position{{8.0, 7.2}});
        s.registry.emplace<Radius>(e, Radius{0.1});
        s.registry.emplace<Template>(e, Template{"doll"});
        return true;
    }));
    for (int i = 0; i < 400; ++i) {
        f.ed.stepForward();
        ASSERT_TRUE(f.ed.sim.message().empty()) << "step " << i << ": " << f.ed.sim.message();
    }
    // The two newest copies, made after the edit, carry the added part.
    const Emitter* emitter = f.ed.doc.scene.registry.tryGet<Emitter>(f.named("hatch"));
    ASSERT_NE(emitter, nullptr);
    EXPECT_EQ(emitter->emitted, 15);
    for (const int copy : {emitter->emitted - 1, emitter->emitted})
        EXPECT_FALSE(f.named("doll#" + std::to_string(copy) + "/hat").isNull())
            << "copies made since have the new part";
    EXPECT_TRUE(f.named("doll#2/arm left").isNull()) << "the edited copy was removed whole in its turn";
    EXPECT_TRUE(f.named("doll#2").isNull());
}

// In a level with emitters, bodies added and deleted while paused go in
// place too, and the run through the emissions and removals that follow
// is a rebuild's: a ball added, a static slide before the emitter deleted
// (an unnamed emitter's random turns are keyed by its place in the scene,
// which moves up), a shelf deleted and the delete undone (the shelf back
// where it stood), and a lone ball deleted. A copy deleted rebuilds, and
// runs the same.
TEST(Simulation, AddsAndDeletesInALevelWithEmittersGoInPlaceAndRunAsARebuild) {
    Fixture inPlace("emitter_rain.json"), rebuilt("emitter_rain.json");
    for (Fixture* f : {&inPlace, &rebuilt}) {
        ASSERT_TRUE(f->ed.applyEdit("unname", [&](Scene& s) {
            s.registry.tryGet<Name>(findByName(s.registry, "hatch"))->value.clear();
            return true;
        }));
        for (int i = 0; i < 50; ++i) f->ed.stepForward();
    }
    const auto addBall = [](Scene& s) {
        const Entity e = s.registry.create();
        s.registry.emplace<Name>(e, Name{"visitor"});
        s.registry.emplace<Position>(e, Position{{3.0, 4.0}});
        s.registry.emplace<Radius>(e, Radius{0.3});
        return true;
    };
    {
        SCOPED_TRACE("a ball added");
        expectRunsAsARebuild(inPlace, rebuilt, "add", addBall, 60);
    }
    {
        SCOPED_TRACE("the slide deleted");
        expectRunsAsARebuild(inPlace, rebuilt, "delete", [](Scene& s) {
            return s.registry.destroy(findByName(s.registry, "slide"));
        }, 60);
    }
    {
        // Undone before a step: once copies come or go, the slot table
        // the undo would restore is gone, and the editor refuses it.
        SCOPED_TRACE("the shelf deleted and the delete undone");
        expectRunsAsARebuild(inPlace, rebuilt, "delete", [](Scene& s) {
            return s.registry.destroy(findByName(s.registry, "shelf"));
        }, 0);
        const std::uint64_t builds = inPlace.ed.sim.worldBuilds();
        for (Fixture* f : {&inPlace, &rebuilt}) ASSERT_TRUE(f->ed.undo());
        rebuilt.ed.sim.sceneChanged();
        for (int i = 0; i < 60; ++i) {
            inPlace.ed.stepForward();
            rebuilt.ed.stepForward();
        }
        EXPECT_FALSE(inPlace.named("shelf").isNull());
        EXPECT_EQ(inPlace.ed.sim.worldBuilds(), builds);
        EXPECT_EQ(textOf(inPlace.ed.doc.scene), textOf(rebuilt.ed.doc.scene));
    }
    {
        SCOPED_TRACE("the ball deleted");
        expectRunsAsARebuild(inPlace, rebuilt, "delete", [](Scene& s) {
            return s.registry.destroy(findByName(s.registry, "visitor"));
        }, 60);
    }
    {
        SCOPED_TRACE("a copy deleted");
        Entity copy;
        for (const Entity e : inPlace.ed.doc.scene.registry.entities())
            if (const Name* n = inPlace.ed.doc.scene.registry.tryGet<Name>(e); n && n->value.rfind("doll#", 0) == 0) {
                copy = e;
                break;
            }
        ASSERT_FALSE(copy.isNull());
        // As the editor deletes (the copy's joints on it go with it).
        const std::string name = inPlace.ed.doc.scene.registry.tryGet<Name>(copy)->value;
        const std::uint64_t builds = inPlace.ed.sim.worldBuilds();
        for (Fixture* f : {&inPlace, &rebuilt}) {
            f->ed.select({f->named(name)});
            ASSERT_TRUE(f->ed.deleteSelection());
        }
        rebuilt.ed.sim.sceneChanged();
        for (int i = 0; i < 60; ++i) {
            inPlace.ed.stepForward();
            rebuilt.ed.stepForward();
        }
        EXPECT_TRUE(inPlace.named(name).isNull());
        EXPECT_EQ(inPlace.ed.sim.worldBuilds(), builds + 1) << inPlace.ed.sim.message();
        EXPECT_EQ(textOf(inPlace.ed.doc.scene), textOf(rebuilt.ed.doc.scene));
    }
}

TEST(Simulation, AnEditUndoneBetweenEmissionsLeavesTheRunExact) {
    // Paused after the second doll appeared: a copy's mass and the
    // emitter's interval are edited and undone; the run then goes on as if
    // nothing happened, through the next emissions.
    Fixture straight("emitter_rain.json");
    for (int i = 0; i < 100; ++i) straight.ed.stepForward();
    Fixture f("emitter_rain.json");
    for (int i = 0; i < 40; ++i) f.ed.stepForward();
    const std::string before = textOf(f.ed.doc.scene);
    ASSERT_FALSE(f.named("doll#2/head").isNull());
    ASSERT_TRUE(f.ed.applyEdit("mass", [&](Scene& s) {
        s.registry.tryGet<Mass>(f.named("doll#2/head"))->value = 9.0;
        return true;
    }));
    ASSERT_TRUE(f.ed.applyEdit("interval", [&](Scene& s) {
        s.registry.tryGet<Emitter>(f.named("hatch"))->interval = 0.25;
        return true;
    }));
    ASSERT_TRUE(f.ed.undo());
    ASSERT_TRUE(f.ed.undo());
    EXPECT_EQ(textOf(f.ed.doc.scene), before);
    for (int i = 40; i < 100; ++i) f.ed.stepForward();
    EXPECT_EQ(textOf(f.ed.doc.scene), textOf(straight.ed.doc.scene));
}
