// Contact hard cases as sweeps: each case runs across its parameter (spin,
// load, crowd size) and the solver settings (substeps 1, 2, 4, 8 and the
// engine's choice), and asserts the physical answer at every value.

#include "generated_scenes.hpp"
#include "stepwise/components.hpp"
#include "stepwise/scene.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <sstream>
#include <string>
#include <vector>

using namespace stepwise;

namespace {

/// The engine's contact slop (collision/position_correction.hpp): the
/// overlap the contacts are allowed to keep, and the position pass's
/// tolerance on it.
constexpr double kSlop = 0.005, kSlopTolerance = 1e-6;
/// 0: the engine chooses (a level without `substeps`).
const std::vector<int> kSubsteps{0, 1, 2, 4, 8};

Scene world(Vec2 gravity, int substeps, int iterations = 0) {
    Scene s;
    s.world.gravity = gravity;
    s.world.substeps = substeps;
    s.world.solverIterations = iterations;
    return s;
}

Entity disc(Scene& s, Vec2 p, double r, double friction = 0.9, double spin = 0.0) {
    Registry& reg = s.registry;
    const Entity e = reg.create();
    reg.emplace<Position>(e, Position{p});
    reg.emplace<Velocity>(e, Velocity{});
    reg.emplace<Mass>(e, Mass{1.0});
    reg.emplace<Radius>(e, Radius{r});
    reg.emplace<Friction>(e, Friction{friction});
    reg.emplace<AngularVelocity>(e, AngularVelocity{spin});
    return e;
}

Entity crate(Scene& s, Vec2 p, double side, double mass = 1.0) {
    Registry& reg = s.registry;
    const Entity e = reg.create();
    reg.emplace<Position>(e, Position{p});
    reg.emplace<Velocity>(e, Velocity{});
    reg.emplace<Mass>(e, Mass{mass});
    reg.emplace<Box>(e, Box{side, side});
    reg.emplace<Friction>(e, Friction{0.6});
    return e;
}

/// A static box whose top face is at y = 0.
Entity floorBox(Scene& s, double width, double thickness, double friction = 0.9) {
    const Entity e = scenes::addStaticBox(s, {0.0, -0.5 * thickness}, width, thickness);
    s.registry.emplace<Friction>(e, Friction{friction});
    return e;
}

/// The plane y = 0, solid below.
Entity floorPlane(Scene& s) {
    Registry& reg = s.registry;
    const Entity e = reg.create();
    reg.emplace<Position>(e, Position{{0.0, 0.0}});
    reg.emplace<Static>(e, Static{true});
    reg.emplace<Plane>(e, Plane{});
    return e;
}

std::string label(int substeps) { return substeps == 0 ? "the engine's choice" : std::to_string(substeps); }

double spinOf(const World& w, const Scene& scene, Entity e) {
    Scene out = scene;
    w.writeBack(out);
    return out.registry.tryGet<AngularVelocity>(e)->value;
}

} // namespace

// A solid disc set down spinning on a rough floor slips until it rolls; the
// friction impulse about the contact point leaves the angular momentum
// about that point, I w0 = (I + m r^2) w, so it ends rolling at
// v = -w0 r / 3 whatever the spin.
TEST(HardContacts, SpinningDiscEndsRollingAtAThirdOfItsRimSpeed) {
    const double r = 0.5, mu = 0.9, g = 9.81;
    for (const double w0 : {-2.0, -8.0, -15.0, -20.0, -50.0, -100.0, -200.0}) {
        for (const int substeps : kSubsteps) {
            Scene s = world({0.0, -g}, substeps);
            floorBox(s, 2000.0, 1.0);
            const Entity d = disc(s, {0.0, r}, r, mu, w0);
            Result<World> w = World::build(s);
            ASSERT_TRUE(w) << w.error();
            // Slipping ends after |w0| r / (3 mu g) seconds; run twice that.
            const double slipTime = std::abs(w0) * r / (3.0 * mu * g);
            const int steps = int(std::ceil(2.0 * slipTime / s.world.dt)) + 30;
            const double startEnergy = 0.5 * (0.5 * r * r) * w0 * w0;
            for (int i = 0; i < steps; ++i) ASSERT_TRUE(w->step());
            const double v = w->bodyVelocity(0).x, spin = spinOf(*w, s, d);
            const double expected = -w0 * r / 3.0;
            SCOPED_TRACE("w0 " + std::to_string(w0) + " rad/s, substeps " + label(substeps));
            EXPECT_NEAR(v, expected, 0.01 * std::abs(expected));
            EXPECT_NEAR(-spin * r, v, 0.01 * std::abs(expected));  // rolling, not slipping
            const double energy = 0.5 * v * v + 0.5 * (0.5 * r * r) * spin * spin;
            EXPECT_LT(energy, startEnergy);  // friction only takes energy away
        }
    }
}

// A ball or a box resting on a thin static box or a plane under a steady
// load of any size: the contacts may give way by the slop, never more, and
// the floor is never crossed.
TEST(HardContacts, StrongSteadyLoadNeverSinksPastTheSlop) {
    const double r = 0.5;
    for (const bool plane : {false, true}) {
        for (const bool box : {false, true}) {
            for (const double g : {10.0, 100.0, 1e3, 2e4, 1e5, 1e6}) {
                for (const int substeps : kSubsteps) {
                    Scene s = world({0.0, -g}, substeps);
                    if (plane) floorPlane(s);
                    else floorBox(s, 4.0, 0.02);
                    if (box) crate(s, {0.0, r}, 2.0 * r);
                    else disc(s, {0.0, r}, r);
                    Result<World> w = World::build(s);
                    ASSERT_TRUE(w) << w.error();
                    double deepest = 0.0;
                    for (int i = 0; i < 120; ++i) {
                        ASSERT_TRUE(w->step());
                        deepest = std::max(deepest, r - w->bodyPosition(0).y);
                    }
                    EXPECT_LE(deepest, kSlop + kSlopTolerance) << (box ? "box" : "ball") << " on "
                                                      << (plane ? "a plane" : "a 2 cm box") << ", g " << g
                                                      << ", substeps " << label(substeps);
                }
            }
        }
    }
}

// A stack of five on a thin static box, at loads its own contacts carry:
// the bottom box holds on the floor at any settings. (Past them, at 100
// m/s^2 with one substep and one iteration, the soft contacts between the
// boxes give way by load / (m omega^2), 4 cm each, and the stack topples.)
TEST(HardContacts, StackStaysOnAThinBoxAtAnySettings) {
    for (const double g : {9.81, 20.0, 30.0}) {
        for (const int substeps : kSubsteps) {
            for (const int iterations : {1, 2, 8}) {
                Scene s = world({0.0, -g}, substeps, iterations);
                floorBox(s, 4.0, 0.02);
                for (int k = 0; k < 5; ++k) crate(s, {0.0, 0.5 + k}, 1.0);
                Result<World> w = World::build(s);
                ASSERT_TRUE(w) << w.error();
                double deepest = 0.0;
                for (int i = 0; i < 120; ++i) {
                    ASSERT_TRUE(w->step());
                    deepest = std::max(deepest, 0.5 - w->bodyPosition(0).y);
                }
                EXPECT_LE(deepest, kSlop + kSlopTolerance)
                    << "g " << g << ", substeps " << label(substeps) << ", iterations " << iterations;
            }
        }
    }
}

// A pile given too few substeps overlaps deeply between its bodies (which
// validate warns about), but its bottom row still sits on the floor.
TEST(HardContacts, DeepPileAtAnySettingsKeepsItsBottomOnTheFloor) {
    for (const int substeps : {1, 2}) {
        for (const int iterations : {1, 2, 8}) {
            Scene s = scenes::circlesInBox(400);
            s.world.substeps = substeps;
            s.world.solverIterations = iterations;
            s.world.sleep = false;
            Result<World> w = World::build(s);
            ASSERT_TRUE(w) << w.error();
            for (int i = 0; i < 240; ++i) ASSERT_TRUE(w->step());
            // circlesInBox's floor is a static box whose top is at y = 0.
            double deepest = 0.0;
            for (std::size_t b = 0; b < w->bodyCount(); ++b) deepest = std::max(deepest, 0.25 - w->bodyPosition(b).y);
            EXPECT_LE(deepest, kSlop + kSlopTolerance) << "substeps " << substeps << ", iterations " << iterations;
        }
    }
}

namespace {
/// Steps `w` `steps` times: the fastest any body moved at the end of a
/// step; infinity when a step fails.
double fastestOver(World& w, int steps) {
    double fastest = 0.0;
    for (int i = 0; i < steps; ++i) {
        if (!w.step()) return std::numeric_limits<double>::infinity();
        for (std::size_t b = 0; b < w.bodyCount(); ++b) fastest = std::max(fastest, length(w.bodyVelocity(b)));
    }
    return fastest;
}
} // namespace

// Bodies started on top of each other push apart by their positions: no
// body is flung. The soft contacts push out at up to 3 m/s each (Box2D's
// cap), and once the crowd has opened into a pack of shallower overlaps,
// its pushes add up along a few neighbours: measured at most 4.2 m/s
// (1,000 bodies at 4 substeps). While a body at the crowd's rim kept the
// pushes its crowded neighbours gave it, 300 reached 11.6 m/s; moved by
// velocity, not by position only, 100 bodies reach 116 m/s.
TEST(HardContacts, CrowdStartedAtOnePointSeparatesAtABoundedSpeed) {
    for (const int n : {2, 10, 64, 100, 300, 1000}) {
        for (const int substeps : {0, 1, 4}) {
            Scene s = world({0.0, 0.0}, substeps);
            s.world.sleep = false;
            for (int i = 0; i < n; ++i) disc(s, {0.0, 0.0}, 0.25, 0.2);
            Result<World> w = World::build(s);
            ASSERT_TRUE(w) << w.error();
            const double fastest = fastestOver(*w, 180);
            double spread = 0.0;
            for (std::size_t b = 0; b < w->bodyCount(); ++b) spread = std::max(spread, length(w->bodyPosition(b)));
            SCOPED_TRACE(std::to_string(n) + " bodies, substeps " + label(substeps));
            EXPECT_LE(fastest, 5.0);
            // n discs of radius 0.25 need a disc of radius 0.25 sqrt(n / 0.9)
            // to lie apart; in 3 s they have spread over half of it at least.
            if (n >= 10) {
                EXPECT_GT(spread, 0.5 * 0.25 * std::sqrt(n / 0.9));
            }
        }
    }
}

// The same at 8 iterations, for discs, boxes and capsules: measured at
// most 6.1 m/s (300 capsules at 4 substeps). A body just outside the crowd
// kept the pushes its crowded neighbours gave it (their own velocities go
// back), and the passes, run to convergence, summed them along chains of
// such bodies: 300 capsules reached 15.6 m/s at 4 substeps, 300 boxes 11.5.
TEST(HardContacts, CrowdsOfEveryShapeSeparateAtABoundedSpeedAtEightIterations) {
    enum class Kind { Disc, Box, Capsule };
    for (const Kind kind : {Kind::Disc, Kind::Box, Kind::Capsule}) {
        for (const int n : {10, 100, 300}) {
            for (const int substeps : {1, 4, 8}) {
                Scene s = world({0.0, 0.0}, substeps, 8);
                s.world.sleep = false;
                for (int i = 0; i < n; ++i) {
                    if (kind == Kind::Disc) {
                        disc(s, {0.0, 0.0}, 0.25, 0.2);
                    } else if (kind == Kind::Box) {
                        crate(s, {0.0, 0.0}, 0.5);
                    } else {
                        const Entity e = crate(s, {0.0, 0.0}, 0.5);
                        s.registry.remove<Box>(e);
                        s.registry.emplace<Capsule>(e, Capsule{{-0.2, 0.0}, {0.2, 0.0}, 0.15});
                    }
                }
                Result<World> w = World::build(s);
                ASSERT_TRUE(w) << w.error();
                const double fastest = fastestOver(*w, 180);
                const char* names[] = {"discs", "boxes", "capsules"};
                EXPECT_LE(fastest, 7.0) << n << " " << names[int(kind)] << ", substeps " << substeps
                                        << ", 8 iterations";
            }
        }
    }
}

namespace {
/// A chain of `links` boxes (0.5 x 0.1 m, `linkMass` kg) hinged end to end
/// and started among `discs` discs (radius 0.25 m, 1 kg), all at the origin.
/// `pinned`: the chain starts from a static post 2.5 m to the left, so that
/// only its last links are in the crowd and its joints lead out of it.
Scene chainInACrowd(int links, double linkMass, int discs, int substeps, int iterations, bool pinned = false,
                    Vec2 gravity = {0.0, 0.0}) {
    Scene s = world(gravity, substeps, iterations);
    s.world.sleep = false;
    for (int i = 0; i < discs; ++i) disc(s, {0.0, 0.0}, 0.25, 0.2);
    std::vector<Entity> chain;
    const double first = pinned ? -2.5 + 0.25 : 0.0;
    for (int i = 0; i < links; ++i) {
        const Entity e = crate(s, {first + 0.5 * (pinned ? i : 0.5 * i), 0.0}, 0.5, linkMass);
        s.registry.tryGet<Box>(e)->height = 0.1;
        chain.push_back(e);
    }
    const double half = pinned ? 0.25 : 0.125;
    for (int i = 1; i < links; ++i)
        scenes::addHinge(s.registry, chain[std::size_t(i)], chain[std::size_t(i - 1)], {-half, 0.0}, {half, 0.0});
    if (pinned) {
        const Entity post = scenes::addStaticBox(s, {-2.5, 0.0}, 0.1, 0.1);
        scenes::addHinge(s.registry, chain[0], post, {-half, 0.0}, {0.0, 0.0});
    }
    return s;
}
} // namespace

// A hinged chain started inside a crowd separates with it at a bounded
// speed, whatever its links weigh against the crowd's bodies. Its links
// join the crowd (their push is a position change) and its joints within
// the crowd give back what the biased passes added. Measured at most
// 3.0 m/s (two 1 kg links, 8 substeps, 8 iterations). Before, a link
// touching the crowd kept its pushes and passed them on through its
// joints, and the joints' impulses carried the crowd's push into the
// next substep's warm start: the same scenes through `stepwise run` gave
// 51 m/s (two 0.1 kg links at 8 x 8) and 28 m/s (ten 1 kg links).
TEST(HardContacts, AHingedChainStartedInACrowdSeparatesAtABoundedSpeed) {
    for (const double linkMass : {0.1, 1.0, 10.0}) {
        for (const int links : {2, 10}) {
            for (const auto& [substeps, iterations] : {std::pair{0, 0}, {1, 0}, {4, 2}, {4, 8}, {8, 8}}) {
                Result<World> w = World::build(chainInACrowd(links, linkMass, 100, substeps, iterations));
                ASSERT_TRUE(w) << w.error();
                const double fastest = fastestOver(*w, 180);
                EXPECT_LE(fastest, 5.0) << links << " links of " << linkMass << " kg among 100 discs, substeps "
                                        << label(substeps) << ", iterations " << label(iterations);
            }
        }
    }
}

// The same chain pinned to a post 2.5 m from the crowd, so that only its
// last links are in it and its joints lead out of it: the joints from the
// crowd to the links outside give back what they passed on. Without
// gravity, measured at most 5.8 m/s (0.1 kg links at 4 x 8); before, 41 m/s
// for 1 kg links at 4 x 8, and 759 m/s for 0.1 kg at 8 x 8. Under gravity
// above a floor 1 m below, for links of 1 and 10 kg: at most 10.1 m/s
// (1 kg at 8 x 8; the discs fall 1 m and the chain whips onto the floor);
// before, 204 m/s, and 92 m/s for 10 kg links at 8 x 8, where the links
// kept their joints' answer as if they carried the discs' weight out of
// the crowd. (Links a tenth of a disc's mass do carry it, and keep their
// answer: 23 m/s at 8 x 8, against 76 before.)
TEST(HardContacts, AChainPinnedOutsideACrowdSeparatesFromItAtABoundedSpeed) {
    for (const double g : {0.0, -9.81}) {
        for (const double linkMass : {0.1, 1.0, 10.0}) {
            if (g != 0.0 && linkMass < 1.0) continue;
            for (const auto& [substeps, iterations] : {std::pair{0, 0}, {1, 0}, {4, 2}, {4, 8}, {8, 8}}) {
                Scene scene = chainInACrowd(10, linkMass, 100, substeps, iterations, true, {0.0, g});
                if (g != 0.0) scenes::addStaticBox(scene, {0.0, -1.5}, 20.0, 1.0);
                Result<World> w = World::build(scene);
                ASSERT_TRUE(w) << w.error();
                const double fastest = fastestOver(*w, 180);
                EXPECT_LE(fastest, g == 0.0 ? 7.0 : 12.0)
                    << "links of " << linkMass << " kg, gravity " << g << ", substeps " << label(substeps)
                    << ", iterations " << label(iterations);
            }
        }
    }
}

// Two ragdolls (levels/filters.json: ten limbs each on nine hinges, with
// limits), the second moved down into the first by `overlap` metres (at
// 1.5 m they coincide), fall apart onto the floor at under 20 m/s: a fall
// from the top of the scene (5.5 m) gives 10.4 m/s, and a limb swinging
// about its joint whips faster. Measured at most 17.8 m/s (0.75 m, 8 x 8).
// Before, the crowd's push went out along the limbs' joints: the same
// scenes through `stepwise run` reached 530 m/s (1.5 m, 8 x 8), and at
// 0.75 m and 8 x 8 the run diverged at step 54 (an upper arm spinning at
// 1.7e9 rad/s).
TEST(HardContacts, RagdollsStartedInsideEachOtherFallApartAtABoundedSpeed) {
    Result<Scene> level = loadSceneFile(std::string(STEPWISE_SOURCE_DIR) + "/levels/filters.json");
    ASSERT_TRUE(level) << level.error();
    for (const double overlap : {0.0, 0.3, 0.75, 1.2, 1.5}) {
        for (const auto& [substeps, iterations] : {std::pair{0, 0}, {1, 0}, {4, 8}, {8, 8}}) {
            Scene scene = *level;
            scene.world.substeps = substeps;
            scene.world.solverIterations = iterations;
            for (const Entity e : scene.registry.entities()) {
                const Name* name = scene.registry.tryGet<Name>(e);
                Position* p = scene.registry.tryGet<Position>(e);
                if (name && p && name->value.rfind("B ", 0) == 0) p->value.y -= overlap;
            }
            Result<World> w = World::build(scene);
            ASSERT_TRUE(w) << w.error();
            const double fastest = fastestOver(*w, 300);
            EXPECT_LE(fastest, 20.0) << "overlap " << overlap << " m, substeps " << label(substeps)
                                    << ", iterations " << label(iterations);
        }
    }
}

// The same crowd under gravity above a floor: no body is pushed higher
// than the crowd's unfolded radius (plus a body) above where it started, at
// the engine's iterations and at 8.
TEST(HardContacts, CrowdStartedAtOnePointAboveAFloorIsNotThrownUp) {
    for (const int n : {10, 64, 100, 300}) {
        for (const auto& [substeps, iterations] : {std::pair{0, 0}, {1, 0}, {4, 0}, {4, 8}, {8, 8}}) {
            Scene s = world({0.0, -9.81}, substeps, iterations);
            floorBox(s, 400.0, 1.0);
            for (int i = 0; i < n; ++i) disc(s, {0.0, 5.0}, 0.25, 0.2);
            Result<World> w = World::build(s);
            ASSERT_TRUE(w) << w.error();
            double highest = 0.0;
            for (int i = 0; i < 240; ++i) {
                ASSERT_TRUE(w->step());
                for (std::size_t b = 0; b < w->bodyCount(); ++b)
                    highest = std::max(highest, w->bodyPosition(b).y);
            }
            EXPECT_LT(highest, 5.0 + 0.25 * std::sqrt(n / 0.9) + 0.5)
                << n << " bodies, substeps " << label(substeps) << ", iterations " << label(iterations);
        }
    }
}

// Box2D's pyramid layout (unit boxes, friction 0.6, rows offset by half a
// box, sleep off), swept from 8 to 48 rows at Box2D v3's settings (4
// substeps, 1 iteration) and at the engine's choice: after 5 s the top box
// is within 1 cm of where it was placed sideways and the pyramid is still.
// At a quarter of the substep rate with alternating passes, 20 rows kept
// 0.55 J moving and 60 rows slid 112 mm (docs/collisions.md, "Deep
// columns").
TEST(HardContacts, PyramidsOfEveryHeightStandAtBox2DsSettingsAndTheDefaults) {
    for (const int rows : {8, 14, 20, 32, 48})
        for (const int substeps : {4, 0}) {
            Scene s = world({0.0, -10.0}, substeps, substeps ? 1 : 0);
            s.world.sleep = false;
            floorBox(s, 4.0 * rows, 2.0, 0.6);
            for (int r = 0; r < rows; ++r)
                for (int c = 0; c < rows - r; ++c) crate(s, {-0.5 * (rows - 1) + c + 0.5 * r, 0.5 + r}, 1.0);
            Result<World> w = World::build(s);
            ASSERT_TRUE(w) << w.error();
            const std::size_t topBody = w->bodyCount() - 1;
            const double startX = w->bodyPosition(topBody).x;
            for (int step = 0; step < 300; ++step) ASSERT_TRUE(w->step().ok()) << rows << " rows";
            const std::string label = std::to_string(rows) + " rows at " +
                                      (substeps ? "4 substeps, 1 iteration" : "the defaults") + " (" +
                                      std::to_string(w->settings().substeps) + "x" +
                                      std::to_string(w->settings().solverIterations) + ")";
            EXPECT_LT(std::abs(w->bodyPosition(topBody).x - startX), 0.01) << label;
            EXPECT_LT(w->energy().kinetic, 0.1) << label;
        }
}

// A column of unit boxes at the engine's settings: its layers compress in
// series, and the top sinks by less than 1 cm in all (the choice counts the
// column: 4 substeps for 10 boxes, where a heap of 10 would need 1). Past
// about 12 boxes the 60 Hz contacts themselves are the limit (20 boxes:
// 2.8 cm at 4 substeps and more).
TEST(HardContacts, StackOfUpToTenBoxesSinksUnderOneCentimetreAtTheDefaults) {
    for (const int n : {2, 3, 5, 8, 10}) {
        Scene s = world({0.0, -9.81}, 0);
        floorBox(s, 40.0, 1.0);
        for (int k = 0; k < n; ++k) crate(s, {0.0, 0.5 + k}, 1.0);
        Result<World> w = World::build(s);
        ASSERT_TRUE(w) << w.error();
        for (int i = 0; i < 300; ++i) ASSERT_TRUE(w->step());
        const double sink = (n - 0.5) - w->bodyPosition(std::size_t(n - 1)).y;
        EXPECT_GT(sink, 0.0) << n << " boxes";  // the contacts do carry the load
        EXPECT_LT(sink, 0.01) << n << " boxes, " << w->settings().substeps << " substeps";
    }
}

// A body at rest near a static wall gets a speculative margin for no motion,
// so it has no contact with the wall when the step begins. Struck within the
// step by a heavy ball, it leaves at up to twice the striker's speed, far
// past that margin: it must still stop at the wall (a thin box, a one-sided
// chain segment, a plane), never pass it or end deeper than the slop, and
// nor may the striker. Swept over the striker's speed and the substeps.
TEST(HardContacts, ABodyStruckWithinAStepNeverPassesAStaticWall) {
    constexpr double r = 0.25, wall = 1.0;  // the wall's face at x = 1, solid beyond
    for (const char* kind : {"thin box", "chain", "plane"}) {
        for (const double speed : {20.0, 50.0, 100.0, 200.0, 400.0}) {
            for (const int substeps : kSubsteps) {
                Scene s = world({0.0, 0.0}, substeps);
                const std::string what = std::string(kind) + " at " + std::to_string(int(speed)) + " m/s, substeps " +
                                         label(substeps);
                if (std::string(kind) == "thin box") {
                    scenes::addStaticBox(s, {wall + 0.01, 0.0}, 0.02, 10.0);
                } else if (std::string(kind) == "chain") {
                    const Entity e = s.registry.create();
                    s.registry.emplace<Position>(e, Position{{wall, 0.0}});
                    s.registry.emplace<Static>(e, Static{true});
                    // Downward, so the side bodies meet (its right) faces -x.
                    s.registry.emplace<Chain>(e, Chain{{{0.0, 5.0}, {0.0, -5.0}}, false});
                } else {
                    const Entity e = floorPlane(s);
                    s.registry.tryGet<Plane>(e)->normal = {-1.0, 0.0};
                    s.registry.tryGet<Plane>(e)->offset = -wall;
                }
                // The target 0.5 m from the wall, the striker half a step's
                // travel behind it: they meet within the first step.
                disc(s, {wall - r - 0.5, 0.0}, r, 0.0);
                const Entity striker = disc(s, {wall - 3.0 * r - 0.5 - 0.5 * speed / 60.0, 0.0}, r, 0.0);
                s.registry.tryGet<Mass>(striker)->value = 10.0;
                s.registry.tryGet<Velocity>(striker)->value = {speed, 0.0};
                Result<World> w = World::build(s);
                ASSERT_TRUE(w) << w.error();
                double deepest = -1.0;
                for (int i = 0; i < 40; ++i) {
                    ASSERT_TRUE(w->step()) << what;
                    for (const std::size_t body : {0u, 1u}) deepest = std::max(deepest, w->bodyPosition(body).x + r - wall);
                }
                EXPECT_LE(deepest, kSlop + kSlopTolerance) << what << ": a ball went " << deepest << " m into the wall";
                EXPECT_LT(w->bodyPosition(0).x, wall) << what << ": the target passed the wall";
            }
        }
    }
}

namespace {

/// Box2D's spinner made small: a drum of radius 8 m (a 120-point chain loop,
/// solid outside), a 14 m bar turned at `spin` rad/s about the drum's
/// centre by an unlimited motor (at 14 rad/s its tip runs at 98 m/s, as
/// Box2D's spinner's at 100), and `count` discs and squares
/// filling the drum from the bottom, 0.45 m apart (0.5 m shapes: they start
/// overlapping, as Box2D's do).
std::string drumLevel(int count, int substeps, double spin) {
    constexpr double pi = 3.14159265358979323846;
    std::ostringstream s;
    s.precision(17);
    s << R"({"world": {"gravity": {"x": 0, "y": -10})";
    if (substeps > 0) s << R"(, "substeps": )" << substeps;
    s << R"(}, "entities": [{"name": "drum", "position": {"x": 0, "y": 0}, "static": true, "friction": 0.1, "chain": {"loop": true, "points": [)";
    for (int i = 0; i < 120; ++i) {
        const double a = -2.0 * pi * i / 120.0;
        s << (i ? ", " : "") << R"({"x": )" << 8.0 * std::cos(a) << R"(, "y": )" << 8.0 * std::sin(a) << "}";
    }
    s << R"(]}}, {"name": "bar", "position": {"x": 0, "y": 0}, "mass": 20, "friction": 0,
        "polygon": {"vertices": [{"x": -0.2, "y": -7}, {"x": 0.2, "y": -7}, {"x": 0.2, "y": 7}, {"x": -0.2, "y": 7}], "radius": 0.1}},
        {"name": "motor", "joint": {"type": "hinge", "a": "bar", "anchor": {"x": 0, "y": 0}, "motor_speed": )" << spin << R"(, "max_motor_torque": 1e10}})";
    int made = 0;
    for (double y = -7.2; made < count && y < 7.0; y += 0.45)
        for (double x = -7.2; made < count && x < 7.2; x += 0.45) {
            if (std::hypot(x, y) > 7.3 || std::abs(x) < 0.5) continue;  // inside, clear of the bar
            s << R"(, {"name": "b)" << made << R"(", "position": {"x": )" << x << R"(, "y": )" << y
              << R"(}, "mass": 0.1, "friction": 0.1, "restitution": 0.1, )"
              << (made % 2 ? R"("radius": 0.25})" : R"("box": {"width": 0.5, "height": 0.5}})");
            ++made;
        }
    s << "]}";
    return s.str();
}

} // namespace

// The bar drives the crowd round the drum at tens of m/s, presses it into
// the one-sided chain and strikes bodies within a step: none may end a step
// outside the drum. Swept over the crowd's size, the bar's speed and the
// substeps.
TEST(HardContacts, ACrowdDrivenRoundADrumStaysInsideIt) {
    for (const int count : {60, 300, 700})
        for (const double spin : {4.0, 14.0})
        for (const int substeps : kSubsteps) {
            const std::string what = std::to_string(count) + " bodies, bar at " + std::to_string(int(spin)) +
                                     " rad/s, substeps " + label(substeps);
            Result<Scene> scene = parseScene(drumLevel(count, substeps, spin), "drum.json");
            ASSERT_TRUE(scene) << scene.error();
            Result<World> w = World::build(*scene);
            ASSERT_TRUE(w) << w.error();
            ASSERT_EQ(w->bodyCount(), std::size_t(count) + 1);
            double farthest = 0.0;
            for (int step = 0; step < 100; ++step) {
                ASSERT_TRUE(w->step()) << what;
                for (std::size_t b = 0; b < w->bodyCount(); ++b) farthest = std::max(farthest, length(w->bodyPosition(b)));
            }
            EXPECT_LT(farthest, 8.0) << what << ": a body's centre left the drum";
        }
}

namespace {

/// A shape a tumbling body can have, and the static surface it lands on.
enum class Tumbler { Plank, Capsule, RoundedHexagon, Dumbbell };
enum class Ground { Plane, ThinBox, Chain };

const char* nameOf(Tumbler t) {
    switch (t) {
    case Tumbler::Plank: return "plank";
    case Tumbler::Capsule: return "capsule";
    case Tumbler::RoundedHexagon: return "rounded hexagon";
    case Tumbler::Dumbbell: return "dumbbell";
    }
    return "";
}
const char* nameOf(Ground g) {
    switch (g) {
    case Ground::Plane: return "a plane";
    case Ground::ThinBox: return "a 2 cm box";
    case Ground::Chain: return "a chain";
    }
    return "";
}

constexpr double kPi = 3.14159265358979323846;

/// The hexagon's corners (circumradius 0.5 m), rounded by 0.05 m.
std::vector<Vec2> hexagon() {
    std::vector<Vec2> v;
    for (int k = 0; k < 6; ++k) v.push_back({0.5 * std::cos(kPi * k / 3.0), 0.5 * std::sin(kPi * k / 3.0)});
    return v;
}

Entity tumbler(Scene& s, Tumbler kind, Vec2 p, double spin) {
    Registry& reg = s.registry;
    const Entity e = reg.create();
    reg.emplace<Position>(e, Position{p});
    reg.emplace<Velocity>(e, Velocity{{0.0, -20.0}});
    reg.emplace<AngularVelocity>(e, AngularVelocity{spin});
    reg.emplace<Mass>(e, Mass{1.0});
    reg.emplace<Friction>(e, Friction{0.6});
    switch (kind) {
    case Tumbler::Plank: reg.emplace<Box>(e, Box{1.0, 0.3}); break;
    case Tumbler::Capsule: reg.emplace<Capsule>(e, Capsule{{-0.5, 0.0}, {0.5, 0.0}, 0.1}); break;
    case Tumbler::RoundedHexagon: reg.emplace<Polygon>(e, Polygon{hexagon(), 0.05}); break;
    case Tumbler::Dumbbell: {
        CompoundShape left, right;
        left.center = {-0.4, 0.0};
        right.center = {0.4, 0.0};
        left.radius = right.radius = 0.15;
        reg.emplace<Shapes>(e, Shapes{{left, right}});
        break;
    }
    }
    return e;
}

/// How far the body's outline reaches below y = 0 (0 when above): its
/// lowest point from its pose, worked out here, not by the engine.
double depthBelowZero(const Scene& out, Entity e, Tumbler kind) {
    const Vec2 p = out.registry.tryGet<Position>(e)->value;
    const Angle* angle = out.registry.tryGet<Angle>(e);
    const double a = angle ? angle->value : 0.0, c = std::cos(a), s = std::sin(a);
    double lowest = 0.0;
    switch (kind) {
    case Tumbler::Plank: lowest = p.y - 0.5 * std::abs(s) - 0.15 * std::abs(c); break;
    case Tumbler::Capsule: lowest = p.y - 0.5 * std::abs(s) - 0.1; break;
    case Tumbler::RoundedHexagon:
        lowest = std::numeric_limits<double>::infinity();
        for (const Vec2 v : hexagon()) lowest = std::min(lowest, p.y + s * v.x + c * v.y - 0.05);
        break;
    case Tumbler::Dumbbell: lowest = p.y - 0.4 * std::abs(s) - 0.15; break;
    }
    return std::max(0.0, -lowest);
}

/// Builds `scene` and steps it `steps` times: the deepest any of `bodies`
/// reached below y = 0 at the end of a step (depthBelowZero); infinity
/// when a step fails.
double deepestBelowZero(const Scene& scene, std::span<const Entity> bodies, Tumbler kind, int steps) {
    Result<World> w = World::build(scene);
    if (!w) return std::numeric_limits<double>::infinity();
    double deepest = 0.0;
    Scene out = scene;
    for (int i = 0; i < steps; ++i) {
        if (!w->step()) return std::numeric_limits<double>::infinity();
        w->writeBack(out);
        for (const Entity e : bodies) deepest = std::max(deepest, depthBelowZero(out, e, kind));
    }
    return deepest;
}

} // namespace

// A body that turns within a step meets the ground with parts its contacts
// from the step's start do not hold: a corner swinging down, the far side
// of a rounded end. Dropped at 20 m/s and spun up to 300 rad/s (5 rad a
// step at 60 Hz), planks, capsules, rounded polygons and compound bodies
// never end a step deeper in a plane, a thin box or a chain than the slop,
// at any substeps. Before the position pass looked at them again, a capsule
// spinning at 100 rad/s ended a step 89 mm inside a plane at 4 substeps,
// and a plank under 1000 m/s^2 at 20 rad/s 214 mm.
TEST(HardContacts, ATumblingBodyNeverEndsAStepDeeperInTheGroundThanTheSlop) {
    for (const Ground ground : {Ground::Plane, Ground::ThinBox, Ground::Chain}) {
        for (const Tumbler kind : {Tumbler::Plank, Tumbler::Capsule, Tumbler::RoundedHexagon, Tumbler::Dumbbell}) {
            for (const double g : {9.81, 1000.0}) {
                for (const double spin : {0.0, 20.0, 100.0, 300.0}) {
                    for (const int substeps : kSubsteps) {
                        Scene s = world({0.0, -g}, substeps);
                        if (ground == Ground::Plane) {
                            floorPlane(s);
                        } else if (ground == Ground::ThinBox) {
                            floorBox(s, 400.0, 0.02, 0.6);
                        } else {
                            const Entity e = s.registry.create();
                            s.registry.emplace<Position>(e, Position{{0.0, 0.0}});
                            s.registry.emplace<Static>(e, Static{true});
                            // Right to left, so its solid side is down; 1 m segments.
                            Chain chain{{}, false};
                            for (int x = 200; x >= -200; --x) chain.points.push_back({double(x), 0.0});
                            s.registry.emplace<Chain>(e, std::move(chain));
                        }
                        const Entity body = tumbler(s, kind, {0.0, 1.5}, spin);
                        const double deepest = deepestBelowZero(s, std::span(&body, 1), kind, 90);
                        EXPECT_LE(deepest, kSlop + kSlopTolerance)
                            << "a " << nameOf(kind) << " spun at " << spin << " rad/s onto " << nameOf(ground)
                            << ", g " << g << ", substeps " << label(substeps);
                    }
                }
            }
        }
    }
}

// Stacks under loads far past what their soft contacts between bodies can
// carry (1,000 to 100,000 m/s^2) collapse into each other, and their
// bodies tumble; none may end a step deeper in the plane they stand on than
// the slop, at any settings. Before the position pass looked again at
// bodies that turned or outran their contacts, a pair of boxes at 1e5
// m/s^2 put a corner 189 mm into the plane at one substep and one
// iteration, and ten at 1e4 m/s^2 went 100 mm in at the defaults.
TEST(HardContacts, ACollapsingStackNeverEndsAStepDeeperInThePlaneThanTheSlop) {
    for (const Tumbler kind : {Tumbler::Plank, Tumbler::Capsule}) {
        for (const int height : {2, 5, 10}) {
            for (const double g : {1e3, 1e4, 1e5}) {
                for (const int substeps : kSubsteps) {
                    // The engine's choice has no iterations to sweep.
                    for (const int iterations : substeps ? std::vector<int>{1, 8} : std::vector<int>{0}) {
                        Scene s = world({0.0, -g}, substeps, iterations);
                        floorPlane(s);
                        // Planks 0.3 m thick and capsules 0.2 m, each on the one below.
                        const double thickness = kind == Tumbler::Plank ? 0.3 : 0.2;
                        std::vector<Entity> bodies;
                        for (int k = 0; k < height; ++k) {
                            const Entity e = tumbler(s, kind, {0.0, thickness * (0.5 + k)}, 0.0);
                            s.registry.tryGet<Velocity>(e)->value = {};
                            bodies.push_back(e);
                        }
                        const double deepest = deepestBelowZero(s, bodies, kind, 60);
                        EXPECT_LE(deepest, kSlop + kSlopTolerance)
                            << height << " " << nameOf(kind) << "s at g " << g << ", substeps " << label(substeps)
                            << ", iterations " << (iterations ? std::to_string(iterations) : label(0));
                    }
                }
            }
        }
    }
}
