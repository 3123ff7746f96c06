#pragma once
/// \file scene.hpp
/// A level in memory: world settings, an optional camera and the entities.
/// This is the editing representation; the simulation compiles it into
/// packed arrays (world.hpp) and writes results back.

#include "stepwise/registry.hpp"
#include "stepwise/vec2.hpp"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace stepwise {

/// The `world` object of a level file, with the scene format's defaults
/// (docs/format.md).
struct WorldSettings {
    Vec2 gravity{0.0, -9.81};                ///< m/s^2, applied to every dynamic body
    double G = 1.0;                          ///< gravitational constant for attractors, N*m^2/kg^2
    std::string integrator = "semi_implicit_euler";
    double dt = 1.0 / 60.0;                  ///< seconds per step
    /// Each step is `substeps` steps of dt/substeps. 0: not given (a file
    /// without the key); World::build then chooses from the scene's
    /// structure (chooseContactSettings in world.hpp) or runs the choice a
    /// saved run recorded (SolverState::chosen), and a save writes no key.
    int substeps = 0;
    double time = 0.0;                       ///< simulated seconds so far
    /// Contact solver velocity iterations (addition). 0: not given; World::build
    /// uses 8, or its own choice when substeps is not given either.
    int solverIterations = 0;
    /// m/s: impacts slower than this do not bounce. Absent: derived from
    /// gravity and the substep (derivedRestitutionThreshold in world.hpp).
    std::optional<double> restitutionThreshold;
    /// Local error per internal step for the error-controlled integrator
    /// (dopri5): each component's error is held to tolerance * (1 + |value|).
    double tolerance = 1e-6;
    /// Barnes–Hut opening angle for attractors, 0..1: a cell of side s is
    /// taken as one mass beyond s/theta (+ its centre-of-mass offset); 0 sums
    /// every pair exactly. 0.5 keeps the force error near 1e-3 (bench
    /// accuracy, Barnes–Hut panel).
    double theta = 0.5;
    /// dopri5's proposed next internal step, s (addition): part of the
    /// state, so that a saved and reloaded run continues bit for bit. 0: none
    /// yet (the first step tries the whole frame).
    double adaptiveStep = 0.0;
    /// Sleeping (Box2D's islands): dynamic bodies connected by touching
    /// contacts, springs and joints sleep as a whole when every one of them
    /// stays under sleepVelocity for sleepTime seconds; asleep, they cost
    /// almost nothing until something touches or edits them (docs/collisions.md,
    /// "Sleeping").
    bool sleep = true;
    /// m/s: a body is "still" while |v| + r_max |omega| (the speed of its
    /// fastest point, r_max its farthest point from the centre of mass)
    /// stays under this. Box2D v3's b2_defaultSleepThreshold.
    double sleepVelocity = 0.05;
    double sleepTime = 0.5;  ///< s an island must stay still before it sleeps (Box2D's b2_timeToSleep)
    /// Softness of rigid joints in the soft step, Hz (Box2D v3's
    /// jointHertz): how fast a joint's position error is corrected. Absent:
    /// the engine's choice (docs/joints.md, "Softness"). Never stiffer than
    /// half the substep rate.
    std::optional<double> jointHz;
    /// Damping ratio of that correction (Box2D v3's jointDampingRatio).
    /// Absent: the engine's choice.
    std::optional<double> jointDampingRatio;
    /// Seed of every random choice in a run (the emitters' spread); 0 when
    /// not given.
    int seed = 0;

    friend bool operator==(const WorldSettings&, const WorldSettings&) = default;
};

/// The `view` object (an addition to the format): the camera a level opens
/// with. `zoom` is pixels per metre in an image 720 pixels tall; other image
/// heights scale it so the same region of the world is shown.
struct View {
    Vec2 center{0.0, 0.0};  ///< metres
    double zoom = 40.0;     ///< pixels per metre at 720 px image height

    friend bool operator==(const View&, const View&) = default;
};

/// The accumulated impulse of one contact point at the end of a step: the
/// solver's warm start for the next step. In memory the two colliders are
/// entity handles; in a file, names (or the entity's index in `entities`
/// when it has no name).
struct ContactImpulse {
    Entity a, b;                 ///< the pair in the solver's order (a's collider index < b's, planes first)
    std::uint32_t feature = 0;   ///< the manifold point's feature id (which vertex/edge pair touches)
    double normalImpulse = 0.0;  ///< accumulated along the normal, N*s
    double tangentImpulse = 0.0; ///< accumulated along the tangent, N*s
    /// Which shape of a compound body (`shapes`) each side is, by its index
    /// in the list; 0 for a single-shape body.
    std::uint32_t shapeA = 0, shapeB = 0;

    friend bool operator==(const ContactImpulse&, const ContactImpulse&) = default;
};

/// The accumulated impulses of one joint at the end of a step: its warm
/// start for the next step. Which fields a joint uses depends on its type;
/// the others stay +0 (a World zeroes any it is given for rows the joint
/// does not have, such as a motor impulse on a hinge without a motor).
struct JointImpulse {
    Entity joint;                ///< the joint's own entity
    /// hinge and weld: the point constraint, N*s; slider: (across the axis
    /// N*s, relative rotation N*m*s)
    Vec2 linear;
    double angular = 0.0;        ///< weld: relative rotation; hinge: its spring (spring_hz), N*m*s
    double axial = 0.0;          ///< distance: along the anchors' line; wheel: its axis spring, N*s
    double motor = 0.0;          ///< hinge N*m*s, slider N*s
    double lower = 0.0;          ///< hinge, slider: lower limit (>= 0)
    double upper = 0.0;          ///< hinge, slider: upper limit; rope: its pull (>= 0)

    friend bool operator==(const JointImpulse&, const JointImpulse&) = default;
};

/// One dynamic body's sleep state: how long it has been
/// still, where that began, and the island it sleeps in. Awake bodies with
/// no still window have no entry.
struct BodySleep {
    Entity body;
    double sleepTime = 0.0;  ///< seconds it has stayed under world.sleep_velocity
    /// Where its still window began (position m, angle rad): a body that
    /// drifts 0.1 sleep_velocity sleep_time from it starts again.
    std::optional<Vec2> stillAt;
    double stillAngle = 0.0;
    /// Asleep: the island's label, one of its bodies (the first in scene
    /// order); the island wakes as a whole. Null: awake.
    Entity island;
    /// Its velocity at the window's middle (m/s; until then, its latest):
    /// the acceleration that keeps a body awake is measured from it.
    /// Absent (a file that does not record it): the body's velocity.
    std::optional<Vec2> stillVelocity;

    friend bool operator==(const BodySleep&, const BodySleep&) = default;
};

/// What the solver carries from one step to the next beyond what the
/// entities hold (positions, velocities, angles, spins). A World built from
/// a scene with this state steps exactly as the World that wrote it: the
/// file's optional `solver_state` section (an addition to the format).
/// Per-body solver state (sleep timers, ...) goes here next to `contacts`,
/// keyed by entity the same way.
/// What the engine chose for a run, recorded by the run so that its resume
/// runs the same (`solver_state.chosen`): the substeps and solver iterations
/// of a level that leaves them out (a level that gives a setting keeps its
/// own), and the contacts' stiffness cap, which the engine always chooses
/// from the scene's structure (ContactSettingsChoice::hertzFraction).
struct ChosenSettings {
    int substeps = 1;
    int solverIterations = 8;
    /// Absent in a file written without it: chosen again on load.
    std::optional<double> contactHertzFraction;
    /// The contacts' stiffness, Hz, when the engine raised it above
    /// kContactHertz (ContactSettingsChoice::contactHertz); absent with a
    /// recorded contactHertzFraction: kContactHertz.
    std::optional<double> contactHertz;

    friend bool operator==(const ChosenSettings&, const ChosenSettings&) = default;
};

struct SolverState {
    std::vector<ContactImpulse> contacts;  ///< warm start, sorted by the solver's key
    std::vector<JointImpulse> joints;      ///< joints' warm start, in scene order
    std::vector<BodySleep> bodies;         ///< sleep timers and sleeping islands, in body (scene) order
    /// Set when the engine chose the substeps or iterations (the level left
    /// them out): World::build runs these instead of choosing again.
    std::optional<ChosenSettings> chosen;

    bool empty() const { return contacts.empty() && joints.empty() && bodies.empty() && !chosen; }
    friend bool operator==(const SolverState&, const SolverState&) = default;
};

struct Scene {
    int version = 1;
    WorldSettings world;
    std::optional<View> view;
    Registry registry;
    /// Present when the scene was saved from a running simulation (`stepwise
    /// run --out`, the editor's "Save simulation state"): World::build then
    /// resumes exactly. Absent in hand-written levels: the solver starts cold.
    std::optional<SolverState> solverState;
};

} // namespace stepwise
