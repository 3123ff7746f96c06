#pragma once
/// \file world.hpp
/// The simulation. A World is compiled from a Scene: the dynamic bodies'
/// state is packed into one state vector and each force system gets the
/// arrays it needs, so a scene with no springs never visits the spring
/// system and bodies without a shape cost the collision stages nothing.
/// `step()` runs a named pipeline of timed stages (Box2D's b2World_Step
/// shape); `writeBack()` copies the results into the Scene.

#include "stepwise/components.hpp"
#include "stepwise/entity.hpp"
#include "stepwise/result.hpp"
#include "stepwise/scene.hpp"
#include "stepwise/vec2.hpp"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace stepwise {

/// Wall time of one pipeline stage in the last step, milliseconds.
struct StageTime {
    std::string_view name;  ///< "forces", "integrate", "broad_phase", ...
    double milliseconds = 0.0;
};

/// What the last step did.
struct StepStats {
    std::uint64_t step = 0;            ///< steps taken since build
    std::vector<StageTime> stages;     ///< in pipeline order
    std::size_t contactCount = 0;
    /// Time of each active force system inside "forces" (addition): their
    /// sum is the "forces" stage. With gravity and drag only, semi-implicit
    /// Euler fuses them into its update and their time is in "integrate".
    std::vector<StageTime> systems;
    int forceEvaluations = 0;          ///< force evaluations in the last step (addition)
    /// Internal steps accepted and rejected in the last step, over all its
    /// substeps: dopri5 chooses them for world.tolerance; a fixed-step
    /// integrator takes one per substep and rejects none.
    int internalSteps = 0;
    int rejectedSteps = 0;
};

/// Energy and momentum of the dynamic bodies, joules and kg*m/s.
struct EnergyReport {
    double kinetic = 0.0;
    double gravity = 0.0;     ///< potential of uniform gravity, zero at y = 0
    double springs = 0.0;     ///< 1/2 k (len - rest)^2 summed
    double attractors = 0.0;  ///< -G m_i m_a / sqrt(r^2 + eps^2) summed over pairs
    Vec2 momentum;
    double potential() const { return gravity + springs + attractors; }
    double total() const { return kinetic + potential(); }
};

/// One contact of the last step, for the debugging views.
struct ContactRecord {
    Entity a, b;               ///< b is a plane or static body when one side is
    Vec2 point;                ///< world point, metres
    Vec2 normal;               ///< unit, from a to b
    double depth = 0.0;        ///< penetration, metres (negative: speculative gap)
    double normalImpulse = 0.0;   ///< N*s
    double tangentImpulse = 0.0;  ///< N*s
};

/// A body entering (`begin`) or leaving a sensor's shape in the last step.
struct SensorEvent {
    Entity sensor;  ///< the entity whose shape is a sensor
    Entity body;    ///< the entity that entered or left it
    bool begin = true;
    friend bool operator==(const SensorEvent&, const SensorEvent&) = default;
};

/// A copy an emitter added (`added`) or removed at the start of the last
/// step, by the copy's name ("doll#3").
struct EmitterEvent {
    Entity emitter;
    std::string copy;
    bool added = true;
    friend bool operator==(const EmitterEvent&, const EmitterEvent&) = default;
};

/// One joint at the end of the last step, for the debugging views.
struct JointRecord {
    Entity joint;              ///< the joint's entity
    Entity a, b;               ///< its ends; b null = the world
    Vec2 anchorA, anchorB;     ///< world anchor points, metres
    double separation = 0.0;   ///< |anchorB - anchorA|, metres (the error of a hinge or weld)
    Vec2 force;                ///< reaction force on b, newtons (a feels -force), over the last substep
    double torque = 0.0;       ///< reaction torque on b, N*m (motor and limits included)
    double angle = 0.0;        ///< b's angle relative to a minus the reference angle, rad
};

/// A joint that broke: after step `step` its constraint force exceeded its
/// `max_force`, and it left the run (docs/joints.md, "Breaking").
struct JointBreak {
    Entity joint;              ///< the joint's entity
    Entity a, b;               ///< its ends; b null = the world
    std::uint64_t step = 0;    ///< StepStats::step of the step after which it broke
    double force = 0.0;        ///< |constraint force| over that step's last substep, newtons
    double maxForce = 0.0;     ///< its max_force, newtons
    friend bool operator==(const JointBreak&, const JointBreak&) = default;
};

/// A stiffness warning: a spring whose dt*sqrt(k/m) is past the chosen
/// integrator's stability limit.
struct StiffnessHint {
    Entity spring;
    std::string springName;   ///< entity name, or "entity N"
    double hOmega = 0.0;      ///< dt*sqrt(k/m_reduced) per substep
    double limit = 0.0;       ///< the integrator's stable h*omega
    double largestStableDt = 0.0;  ///< seconds per step (whole step, substeps included)
    std::string integrator;   ///< the integrator whose limit it is (addition)
    std::string message() const;
};

/// One contact point's accumulated impulses in the solver's own indexing,
/// kept from one step to the next for the warm start (ContactImpulse is the
/// same entry keyed by entities, as files hold it).
struct CachedImpulse {
    std::uint64_t key = 0;  ///< (colliderA << 40) | (colliderB << 16) | feature id
    double normal = 0.0, tangent = 0.0;  ///< N*s
    static std::uint64_t makeKey(std::uint32_t a, std::uint32_t b, std::uint32_t feature) {
        return (std::uint64_t(a) << 40) | (std::uint64_t(b) << 16) | (feature & 0xFFFF);
    }
    std::uint32_t colliderA() const { return std::uint32_t(key >> 40); }
    std::uint32_t colliderB() const { return std::uint32_t((key >> 16) & 0xFFFFFF); }
    std::uint32_t feature() const { return std::uint32_t(key & 0xFFFF); }
    friend bool operator<(const CachedImpulse& l, const CachedImpulse& r) { return l.key < r.key; }
    friend bool operator==(const CachedImpulse&, const CachedImpulse&) = default;
};

/// Which entity each array of a WorldState belongs to. One per build,
/// shared by every snapshot taken from that build.
struct WorldLayout {
    std::vector<Entity> bodies;      ///< dynamic bodies, in state-vector order
    std::vector<Entity> spinBodies;  ///< dynamic bodies without a shape that turn
    std::vector<Entity> colliders;   ///< every shape, in collider order
    /// per collider: which shape of its entity's `shapes` it is (0 for a
    /// single shape; 0xFFFFFFFF for a compound body's hub, which has none)
    std::vector<std::uint32_t> colliderParts;
    std::vector<std::uint8_t> colliderMoves;  ///< per collider: 1 when it is a dynamic body's
    std::vector<Entity> joints;      ///< every joint's entity, in solver (scene) order
    /// With emitters: the run's registry when the layout was made (the
    /// copies alive with their components, under the handles writeBack
    /// gives them in a scene) and each emitter's component with its run
    /// state. Null and empty without emitters.
    std::shared_ptr<const Registry> registry;
    std::vector<std::pair<Entity, Emitter>> emitters;
    /// With emitters: which run the layout belongs to (one per build, kept
    /// by restoreState's rebuild); 0 without.
    std::uint64_t run = 0;
    friend bool operator==(const WorldLayout& a, const WorldLayout& b) {
        return a.bodies == b.bodies && a.spinBodies == b.spinBodies && a.colliders == b.colliders &&
               a.colliderMoves == b.colliderMoves && a.joints == b.joints && a.emitters == b.emitters;
    }
};

/// Everything a step reads that an earlier step wrote: a World restored
/// from a snapshot steps bit for bit as the World that took it did. The
/// editor's step-back history is made of these. Add any new state carried
/// between steps (sleep timers, ...) here and in
/// saveState/restoreState, and its entity-keyed form to SolverState.
struct WorldState {
    std::shared_ptr<const WorldLayout> layout;
    double time = 0.0;            ///< seconds
    double adaptiveStep = 0.0;    ///< dopri5's proposed internal step, s (world.adaptive_step)
    std::uint64_t steps = 0;      ///< StepStats::step
    std::vector<double> x, v;     ///< bodies, interleaved (x0, y0, x1, ...): metres, m/s
    std::vector<double> spinAngle;             ///< spinBodies, rad
    std::vector<double> colliderAngle, colliderSpin;  ///< colliders, rad and rad/s
    std::vector<CachedImpulse> contacts;       ///< the warm-start cache
    std::vector<JointImpulse> joints;          ///< every joint's accumulated impulses, in layout.joints order
    /// Joints broken so far, in the order they broke; writeBack removes
    /// their entities from the scene.
    std::vector<JointBreak> breaks;
    std::vector<double> sleepTimer;            ///< bodies: seconds still (world.sleep_time)
    std::vector<std::int32_t> sleepIsland;     ///< bodies: -1 awake, else the sleeping island's first body
    std::vector<double> sleepAnchor;           ///< bodies: where the still window began (x, y m, angle rad, vx, vy m/s)
    std::vector<std::uint8_t> sleepAnchored;   ///< bodies: 1 while a still window runs
    /// Heap bytes held (the layout, shared, not counted).
    std::size_t bytes() const;
    /// The warm start keyed by entities (as World::solverState()).
    SolverState solverState() const;
    /// Writes the bodies' state and the time into `scene`, as
    /// World::writeBack did when the snapshot was taken.
    void writeBack(Scene& scene) const;
};

/// The contacts' stiffness when no rule needs more, Hz (Box2D v3's is 30;
/// 60 gives 4x less overlap in a 25-deep circle pile at the same cost).
inline constexpr double kContactHertz = 60.0;
/// The gravity kContactHertz serves, m/s^2: a stronger load may stiffen the
/// contacts by up to sqrt(g / kReferenceGravity) (ContactSettingsChoice).
inline constexpr double kReferenceGravity = 10.0;
/// sqrt(g / kReferenceGravity), at least 1: how much faster a scene under
/// `gravity` (m/s^2) runs than the same scene at the reference. A pile
/// under g is the reference pile sped up by this factor: the same
/// overlaps with contacts this much stiffer (and pushing out this much
/// faster, collision::SolverSettings::pushCap), every speed this much
/// higher. So a strong load may stiffen the contacts by up to it
/// (ContactSettingsChoice::contactHertz).
double loadSpeedup(double gravity);

/// What the engine runs when a level gives no `substeps` (and no
/// `solver_iterations`), decided from the scene's structure (its bodies,
/// shapes, masses, joints and gravity) and, for stacks and impacts, from the
/// level as authored (where its boxes stand, its velocities and which bodies
/// touch). A run that saved its state records the choice, so a resumed run
/// runs what the long run chose.
/// The fewest substeps (1, 2, 4, 8, ...; the joint rules up to 16, the
/// contact rules up to kMaxContactSubsteps) that hold:
///  * the pile: the deepest the N dynamic shapes can pile (a heap k deep,
///    k (k + 1) / 2 >= N, no wider than floor(W / d) bodies on ground W
///    wide, or ceil(N / floor(W / d)) full rows), its deepest overlap under
///    1% of a diameter (expectedPileOverlap, mass ratio included);
///  * the load: the contact under the bottom body, under 1% of a diameter
///    and 10% of the thinnest static support's thickness (strong gravity);
///  * the joint loops: joints that close a loop among moving bodies (a
///    grid, a closed linkage) are solved by Gauss-Seidel at their loop
///    stiffness (the world's joint_hz, else 60 Hz), which must stay within
///    kLoopJointHertzFraction of the substep rate (trees of joints are
///    solved exactly at any substep count and add no rule);
///  * the jointed supports: a body heavier than kJointSupportRatio s^2 times
///    the lightest body of a joint group hung from the world (a crate on a
///    bridge's planks) needs s substeps;
///  * the impacts: a moving body (its velocity and spin as the level gives
///    them) drives what it strikes at up to (1 + e) M / (M + m) of its
///    speed; that body's travel per substep stays under kImpactTravel of
///    its size (8 substeps at most).
/// Contacts stiffen with the substep rate up to 60 Hz (kContactHertz): past
/// 4 substeps, or 8 for a deep column, more substeps stop helping. Under a
/// load stronger than kReferenceGravity, a contact rule that cannot hold at
/// 60 Hz (a tall stack, a strong load) raises the stiffness to what holds
/// it, by up to sqrt(g / kReferenceGravity) (contactHertz), and takes the
/// substeps that carry it, up to kMaxContactSubsteps.
/// docs/collisions.md "Substeps when the level gives none".
struct ContactSettingsChoice {
    int substeps = 1;
    int iterations = 8;        ///< 8 at 1 substep, else 2
    int stackDepth = 0;        ///< bodies in the deepest column the scene can pile up
    double diameter = 0.0;     ///< metres, the median dynamic shape's size
    /// m/s^2, the steady load: |world.gravity|, plus the pull of static
    /// attractors and dynamic ones with a shape and the force of springs
    /// and slider and hinge motors per unit mass, where the sum is
    /// strongest on a body resting with another
    double gravity = 0.0;
    bool attractorLoad = false;  ///< the load includes attractors' pull
    bool springLoad = false;     ///< the load includes springs' force
    bool motorLoad = false;      ///< the load includes slider or hinge motors' force
    double massRatio = 1.0;    ///< heaviest / lightest dynamic shape that can pile
    double support = 0.0;      ///< m, thinnest static support along gravity (0: none)
    int columnHeight = 0;      ///< flat-faced bodies in the fullest column as placed
    int stackHeight = 0;       ///< of them, the most that touch one on another
    double columnWidth = 0.0;  ///< m, the median flat-faced body's size
    int pileSubsteps = 1;      ///< what each rule alone needs (the pile's and the column's)
    int loadSubsteps = 1;
    /// rad/s: a bound on the fastest spring mode, max(omega, damping rate),
    /// by Gershgorin's theorem on M^-1/2 K M^-1/2 (0: no springs, or an
    /// implicit or adaptive integrator, which need no rule).
    double springRate = 0.0;
    int springSubsteps = 1;    ///< the fewest with h * springRate <= 1
    /// The impact that asks the most (impactSubsteps): the striker's speed
    /// (its fastest point, m/s), the size (m) of the body it strikes, the
    /// striker's mass over that body's (infinite for a kinematic striker),
    /// and the speed (m/s) the struck body is driven at.
    double impactSpeed = 0.0;
    double impactSize = 0.0;
    double impactMassRatio = 1.0;
    double impactDriven = 0.0;
    int impactSubsteps = 1;    ///< the fewest in 1, 2, 4, 8 with driven * h <= kImpactTravel * size
    /// Joints that close a loop among dynamic bodies, counting only rigid
    /// ones (not a weld or distance joint with its own stiffness), and the
    /// stiffness the Gauss-Seidel passes solve them at, Hz.
    int jointLoops = 0;
    double jointLoopHertz = 0.0;
    int jointLoopSubsteps = 1; ///< the fewest with jointLoopHertz <= kLoopJointHertzFraction / h
    /// The heaviest body that can pile over the lightest body of a joint
    /// group hung from the world (a bridge's plank), as a mass ratio (0: no
    /// such pair), and the fewest substeps with that ratio at most
    /// kJointSupportRatio s^2.
    double jointSupportRatio = 0.0;
    int jointSupportSubsteps = 1;
    /// Contact stiffness cap as a fraction of the substep rate: 0.25, or
    /// 0.125 (with one colour order) when stackHeight > kDeepColumn under
    /// gravity (SolverSettings::hertzFraction); the rules above use the
    /// same cap.
    double hertzFraction = 0.25;
    /// The contacts' stiffness, Hz: kContactHertz, or under a load past
    /// kReferenceGravity what the pile, column and load rules need when they
    /// fail there (at most kContactHertz sqrt(g / kReferenceGravity)); the
    /// solver caps it at hertzFraction of the substep rate
    /// (SolverSettings::contactHertz).
    double contactHertz = kContactHertz;
    /// "pile 12 deep ...": what made the choice.
    std::string reason() const;
};
/// Systems a World leaves out of its scene (the editor's switches). The
/// scene keeps its components; the World compiles as if they were absent:
/// no gravity, no drag, no springs, no attractors, no boids, or no contacts
/// (joints still hold).
struct SystemSwitches {
    bool gravity = true, drag = true, springs = true, attractors = true, boids = true, collisions = true;
    /// Switches off a system by name ("gravity", "drag", "springs",
    /// "attractors", "boids", "collisions"); false for any other name.
    bool disable(std::string_view system);
};
ContactSettingsChoice chooseContactSettings(const Scene& scene, const SystemSwitches& switches = {});
/// A column of flat-faced bodies taller than this gets Box2D v3.1's contacts:
/// stiffness capped at an eighth of the substep rate instead of a quarter,
/// and every solver pass in one colour order instead of alternating.
/// Measured with Box2D's pyramid layout at 4 substeps and 1 iteration: with
/// a quarter and alternation, 10 rows come to rest, 14 keep 7e-5 J moving
/// after 5 s, 20 rows 0.55 J and 60 rows slide 112 mm; with both changes,
/// 14 to 60 rows end within 7 mm. Shallower stacks keep the stiffer,
/// alternating contacts: 4 times less overlap, and they settle and sleep
/// sooner (docs/collisions.md, "Deep columns").
inline constexpr int kDeepColumn = 12;
/// The impact rule's bound: a struck body moves at most this fraction of
/// its size per substep. Measured on Box2D's smash (a 512 kg box at 40 m/s
/// into 0.4 m bricks of 0.16 kg): 0.83 of a brick per substep (2 substeps)
/// ends with 382 mm of overlap, 0.42 (4 substeps) with 0.88 mm.
inline constexpr double kImpactTravel = 0.5;
/// Joints in a loop are solved by Gauss-Seidel with their position error
/// corrected at a stiffness of jointLoopHertz; the soft step holds that
/// stiffness only up to this fraction of the substep rate when a substep
/// has few iterations. Measured on Box2D's 100 x 100 hinge grid at 60 Hz:
/// at half the substep rate (1 substep and 8 iterations, or 2 substeps
/// and 2) the grid swings open by up to 1.2 m or diverges; at a quarter
/// (4 substeps, 1 or 2 iterations) it opens at most 0.31 m and settles.
inline constexpr double kLoopJointHertzFraction = 0.25;
/// A body resting on a joint group hung from the world (a crate on a
/// bridge) presses one light body that the joints hold up: each pass of
/// the contact moves that body as if it were free, the joints take the move
/// back, and the crate sinks and springs back, gaining energy until it
/// falls through. The substeps that hold it grow with the mass ratio.
/// Measured with Box2D-like planks (2 kg, 1 m, hinged between two piers)
/// under a 1.2 m crate dropped from 2.6 m, at the chosen iterations: 1
/// substep holds 2.5:1 and bounces 0.66 m at 5:1, falls through at 10:1;
/// 2 hold 10:1 and drop 25:1; 4 hold 50:1 and drop 100:1; 8 hold 100:1 and
/// drop 250:1. So s substeps hold a ratio up to 3 s^2.
inline constexpr double kJointSupportRatio = 3.0;
/// The most substeps the impact rule asks for: past it a level must give
/// its own (the rule's warning names the number).
inline constexpr int kImpactMaxSubsteps = 8;
/// The most substeps the contact rules (pile, column, load) ask for: the
/// most a level may give (kMaxLevelSubsteps), so the engine never names a
/// count it could have taken itself. They double from 1 and stop here. Only
/// a load past kReferenceGravity gets past 16: the stiffness it needs, at
/// most kContactHertz sqrt(g / kReferenceGravity), is carried by
/// contactHertz / (hertzFraction / dt) substeps (at 60 steps a second, 64
/// at 1000 m/s^2, 128 at 10^4, 1000 past 4 10^4 for a deep column). Capped
/// at 16, ten boxes flew apart from 7000 m/s^2 and twenty from 3000: their
/// overlaps grew past what the contacts hold.
inline constexpr int kMaxContactSubsteps = 1000;
/// Expected deepest resting overlap (metres) in a pile `depth` bodies deep
/// under `gravity` (m/s^2) with substeps of `h` seconds: the soft contact
/// compresses by load / (m_n omega^2), omega = 2 pi min(contactHertz, f / h)
/// with f the contacts' cap (ContactSettingsChoice::hertzFraction),
/// with a factor measured on the 30-row pile (docs/collisions.md, "Substeps
/// when the level gives none"). The lowest
/// contact between bodies carries (depth - 1) heavy bodies on a light one:
/// load (depth - 1) M g over m_n = m M / (m + M), i.e. (depth - 1)(1 + R)
/// m_n g with R = M / m (2 (depth - 1) for equal bodies).
double expectedPileOverlap(int depth, double gravity, double h, double massRatio = 1.0, double hertzFraction = 0.25,
                           double contactHertz = kContactHertz);
/// Expected overlap (m) of the contact under the bottom body of a pile
/// `depth` deep on static ground: load ((depth - 1) R + 1) m g over m_n = m.
double expectedSupportOverlap(int depth, double gravity, double h, double massRatio = 1.0,
                              double hertzFraction = 0.25, double contactHertz = kContactHertz);
/// world.restitution_threshold when the level gives none: four times the
/// speed gravity adds in one substep (m/s), so resting contacts never bounce
/// and, with zero gravity, every approach does.
double derivedRestitutionThreshold(double gravity, double h);
/// A warning before playing: the level's own substeps let its deepest pile
/// sink into itself by more than 2% of a diameter.
struct PileHint {
    int stackDepth = 0;
    double expectedOverlap = 0.0;  ///< metres
    double diameter = 0.0;         ///< metres
    int substeps = 1;              ///< the level's
    int substepsNeeded = 1;        ///< the fewest that keep it under 2% (kMaxContactSubsteps at most; 0: none does)
    double overlapAtMost = 0.0;    ///< metres, at kMaxContactSubsteps when none keeps it under 2%
    std::string message() const;
};

/// A warning before playing: under a load stronger than kReferenceGravity
/// the contact rules ask for stiffer contacts (ContactSettingsChoice::
/// contactHertz) than the running substeps carry (hertzFraction of the
/// substep rate), so a stack or pile sinks into itself past the rules'
/// bounds, and a tall one can collapse. Said of the level's own substeps,
/// and of the engine's when even kMaxContactSubsteps fall short; never of
/// a scene whose bodies cannot rest on one another (static contacts turn
/// rigid before the slop at any stiffness).
struct ContactStiffnessHint {
    double gravity = 0.0;       ///< m/s^2
    double hertzNeeded = 0.0;   ///< Hz, what the rules ask for
    double hertzCarried = 0.0;  ///< Hz, what the running substeps carry
    int substeps = 1;           ///< running
    int substepsNeeded = 0;     ///< the fewest that carry it (0: more than a level can give)
    std::string message() const;
};

/// A warning before playing: at the level's own substeps, a body struck by
/// the level's fastest mover (the impact rule of ContactSettingsChoice) moves
/// more than kImpactTravel of its size per substep.
struct ImpactHint {
    double speed = 0.0;     ///< m/s, the striker's fastest point
    double size = 0.0;      ///< m, the struck body's size
    double driven = 0.0;    ///< m/s, the speed the struck body is driven at
    double travel = 0.0;    ///< m it moves per substep at the level's substeps
    int substeps = 1;       ///< the level's
    int substepsNeeded = 1; ///< the fewest that keep it under kImpactTravel of its size
    std::string message() const;
};

/// A warning before playing: at the level's own substeps, its joints in
/// loops are corrected faster than kLoopJointHertzFraction of the substep
/// rate (the joint-loop rule of ContactSettingsChoice).
struct JointLoopHint {
    int loops = 0;           ///< joints that close a loop
    double hertz = 0.0;      ///< their stiffness, Hz
    int substeps = 1;        ///< the level's
    int substepsNeeded = 1;  ///< the fewest that keep hertz within the fraction
    std::string message() const;
};

/// A warning before a run whose given substeps are too few for the heaviest
/// body that can rest on a joint group hung from the world
/// (kJointSupportRatio: s substeps hold a mass ratio up to 3 s^2).
struct JointSupportHint {
    double ratio = 0.0;      ///< the heaviest such body over the lightest jointed one
    int substeps = 1;        ///< the level's
    int substepsNeeded = 1;  ///< the fewest that hold the ratio
    std::string message() const;
};

/// A warning after a resume: saved contact impulses larger than any run of
/// this scene can write were dropped (World::setSolverState), so the run
/// starts those contacts cold and is not an exact resume.
struct DroppedImpulses {
    std::size_t count = 0;
    double largest = 0.0;  ///< N*s, the largest dropped
    double bound = 0.0;    ///< N*s, the most a run can write here
    std::string message() const;
};

class WorldImpl;

class World {
public:
    /// Compiles `scene` into a world. Fails (with a message naming the entity
    /// and component) when the scene asks for something the engine cannot
    /// simulate.
    static Result<World> build(const Scene& scene, const SystemSwitches& switches = {});

    World(World&&) noexcept;
    World& operator=(World&&) noexcept;
    ~World();

    /// Advances one step of settings().dt (split into settings().substeps).
    /// On a non-finite value, stops and returns a message naming the step,
    /// the entity and the quantity ("step 42: entity 3 (\"ball\"): velocity.x
    /// became inf"); the world is then left as it was before that step.
    Result<void> step();

    /// Copies positions, velocities, angles and time into `scene`, whose
    /// entities must be the ones the world was built from, and destroys the
    /// entities of joints that broke (jointBreaks()).
    void writeBack(Scene& scene) const;

    /// The solver's carried state keyed by entities (what a file's
    /// `solver_state` holds). writeBack + this = everything a resume needs.
    SolverState solverState() const;
    /// Sets the carried solver state. Entries whose entities are not
    /// colliders of this world are skipped (an edit removed them), so it
    /// never fails. World::build applies a scene's solverState with this.
    void setSolverState(const SolverState& state);

    /// Snapshot of the whole evolving state (cheap: a few array copies).
    WorldState saveState() const;
    /// Restores a snapshot taken from this World or from one built from a
    /// scene with the same entities, shapes and systems (the same layout).
    /// Fails, changing nothing, when the layout differs, except for a
    /// snapshot of this run taken while its emitters had other copies
    /// alive: then the World is rebuilt from the snapshot's own scene (the
    /// only time an emitter's copies cost a build).
    Result<void> restoreState(const WorldState& state);

    /// Recompiles `scene` (an edited version of the scene this World runs)
    /// into this World in place: positions, parameters and components come
    /// from the scene; the warm start of every contact whose two entities
    /// still collide, and the step count, are kept. On failure the World is
    /// unchanged. The editor edits its one live World this way.
    Result<void> reload(const Scene& scene, const SystemSwitches& switches = {});

    const WorldSettings& settings() const;
    /// Where the running substeps and solver iterations came from.
    enum class SettingsSource {
        Given,     ///< the level gives both
        Chosen,    ///< chosen now from the scene's structure (chooseContactSettings)
        Recorded,  ///< the choice a run recorded in the file (solver_state.chosen)
    };
    SettingsSource settingsSource() const;
    /// The structural choice for this scene (also when the level gives the
    /// settings: pileHint() compares against it).
    const ContactSettingsChoice& settingsChoice() const;
    /// One line for `stepwise validate`: "substeps 4, solver_iterations 2
    /// (chosen: 20 jointed bodies (load 20:1); pile 12 deep)".
    std::string settingsSummary() const;
    /// Changes the integrator by name (one of integratorNames()).
    Result<void> setIntegrator(std::string_view name);
    /// Moves the fixed end of a spring whose second end is fixed (an
    /// `anchor`, or a static body), metres: the editor's mouse spring follows the
    /// cursor this way without rebuilding the world (which would also drop
    /// the contacts' warm start). Fails when `spring` is not such a spring.
    Result<void> setSpringAnchor(Entity spring, Vec2 anchor);
    /// Puts dynamic body `body` at `position` with `velocity` (metres, m/s),
    /// in place: its island wakes, every other body and every contact's warm
    /// start stay as they are. The editor's move tool drags a body this way
    /// without rebuilding the world. Fails when `body` is not a dynamic body
    /// of this world, or a value is not finite.
    Result<void> moveBody(Entity body, Vec2 position, Vec2 velocity);
    /// Gives dynamic body `body` the mass its entity has in `scene` (what
    /// this World was built from, with that one edit), in place: its inertia
    /// follows, its island wakes, and every other body and every contact's
    /// warm start stay as they are; the steps that follow are those of
    /// reload(scene). The engine's choice of settings is not
    /// checked here but once before the next step, however many edits
    /// came between (settleChoice). Fails, leaving the World as it was,
    /// when springs or attractors act (a lighter body could be pulled past
    /// what a step can take, which a build refuses), or when `body` is not
    /// a dynamic, non-kinematic body of this World: the caller then reloads.
    Result<void> setMass(const Scene& scene, Entity body);
    /// Gives dynamic body `body` the angle and angular velocity its entity
    /// has in `scene`, in place, as setMass gives a mass (its island wakes;
    /// the steps that follow are reload's, once settled). Fails, leaving the
    /// World as it was, when `body` is kinematic or not a dynamic body of
    /// this World, or when it has no turn of its own here (a shapeless body
    /// without both an angle and a spin).
    Result<void> turnBody(const Scene& scene, Entity body);
    /// Gives dynamic body `body` the shape, friction, restitution and filter
    /// its entity has in `scene`, in place (its inertia follows; its island
    /// wakes; the steps that follow are reload's, once settled). Fails,
    /// leaving the World as it was, for a compound body or a chain, an edit
    /// that moves the body's centre of mass (a polygon's outline, a
    /// capsule's ends off centre) or makes it a sensor or not, or a shape a
    /// build refuses.
    Result<void> reshapeBody(const Scene& scene, const SystemSwitches& switches, Entity body);
    /// Takes the entities of `removed` (no longer in `scene`) out of the
    /// World and adds those of `added` (entities of `scene`, at its end or,
    /// as an undone delete brings them back, where they stood), in place,
    /// each at its place in the scene order: the islands of removed bodies
    /// wake, every other body and every contact's warm start stay, and the
    /// steps that follow are those of reload(scene, switches), once
    /// settled. The editor adds and deletes bodies this way; a static shape
    /// that comes or goes wakes every island, and with emitters their run
    /// takes the edited scene as its own. Fails, leaving the World as it
    /// was, for anything but dynamic and static bodies with a shape and the
    /// joints among dynamic ones (added), for planes, kinematic bodies and
    /// what still holds a removed body (removed), for an emitter, a
    /// template body or an emitted copy, and when attractors or boids act:
    /// the caller then reloads.
    Result<void> changeEntities(const Scene& scene, const SystemSwitches& switches, std::span<const Entity> removed,
                                std::span<const Entity> added);
    /// After setMass, turnBody, reshapeBody or changeEntities: checks once
    /// that a reload from `scene` (every edit since the last step applied)
    /// would run the substeps, iterations and contact stiffness this World
    /// runs, and takes that reload's choice (its reasons) as its own. The
    /// choice reads the whole scene, so it is made once per step, not per
    /// edit; step() refuses until it is settled. Fails when the edits
    /// change the choice: the caller then reloads. Nothing to do (and no
    /// cost) when no such edit came since the last check.
    Result<void> settleChoice(const Scene& scene, const SystemSwitches& switches = {});
    double time() const;

    /// Systems this scene needs, in pipeline order: "gravity", "drag",
    /// "springs", "attractors", "boids", "collisions" ...
    std::vector<std::string_view> activeSystems() const;
    const StepStats& lastStats() const;
    EnergyReport energy() const;
    /// When energy() is not finite: the first term that is not, named by
    /// its entity and quantity ("entity 3 (\"ball\"): kinetic energy
    /// m*v^2/2 became inf J (mass 1e+308 kg, speed 10 m/s)"); "" when every
    /// body's and spring's term is finite (then only the attractors' sum is
    /// not).
    std::string nonFiniteEnergyTerm() const;
    /// Contacts of the last step (empty when the scene has no shapes).
    std::span<const ContactRecord> contacts() const;
    /// Bodies that entered or left a sensor in the last step, in the order
    /// of (sensor, body) collider pairs. A body overlapping a sensor when
    /// the world is built (or restored) is inside from the start: no event.
    std::span<const SensorEvent> sensorEvents() const;
    /// Every (sensor, body) pair overlapping at the end of the last step.
    std::vector<std::pair<Entity, Entity>> sensorOverlaps() const;
    /// Joints of the last step, in scene order: anchors, separation and
    /// reaction force and torque (empty when the scene has no joints). A
    /// joint that broke is listed for the step it broke in, not after.
    std::span<const JointRecord> joints() const;
    /// Every joint that broke since the World was built (or, after
    /// restoreState, as of that snapshot), in the order they broke; those
    /// of the last step have `step == lastStats().step`. A broken joint is
    /// out of the run, and writeBack removes its entity from the scene, so a
    /// saved file no longer holds it and its resume is exact.
    std::span<const JointBreak> jointBreaks() const;

    /// Springs past the integrator's stability limit at the current dt.
    std::vector<StiffnessHint> stiffnessHints() const;
    /// Set when the scene's deepest pile would sink more than 2% of a
    /// diameter at the running substeps (see PileHint).
    std::optional<PileHint> pileHint() const;
    /// Set when the running substeps carry less contact stiffness than a
    /// strong load needs (ContactStiffnessHint).
    std::optional<ContactStiffnessHint> contactStiffnessHint() const;
    /// An impact the level's own substeps cannot hold (ImpactHint); never
    /// about substeps the engine chose or a run recorded.
    std::optional<ImpactHint> impactHint() const;
    /// Joints in loops the level's own substeps cannot hold (JointLoopHint);
    /// never about substeps the engine chose or a run recorded.
    std::optional<JointLoopHint> jointLoopHint() const;
    /// Set when the level gives its substeps and they are fewer than a body
    /// resting on a hung joint group needs (JointSupportHint).
    std::optional<JointSupportHint> jointSupportHint() const;
    /// Set when the last setSolverState dropped impulses no run could write.
    std::optional<DroppedImpulses> droppedImpulses() const;

    /// Net force a unit-mass probe at `point` would feel from the scene's
    /// field forces: gravity and attractors, through the same code the step
    /// runs. Newtons (= m/s^2 for 1 kg). `velocity` is ignored: both field
    /// forces depend on position only, and the velocity-dependent forces
    /// (drag, spring damping, boids) act on bodies, not on a probe.
    Vec2 probeForce(Vec2 point, Vec2 velocity = {}) const;

    /// Sleeping (world.sleep; docs/collisions.md "Sleeping"): whether dynamic
    /// body `body` sleeps, how many do, and their entities.
    bool asleep(std::size_t body) const;
    std::size_t sleepingBodyCount() const;
    std::vector<Entity> sleepingBodies() const;
    /// Wakes the island of `entity` (a dynamic body); false when it was not
    /// asleep. An application that moves or pushes a body itself calls this;
    /// edits that go through reload() and the setters wake what they change.
    bool wake(Entity entity);
    /// A step under world settings other than those the sleeping islands
    /// were last stepped under wakes them all first; this does it now (the
    /// editor's "Save simulation state" after a settings edit, so that the
    /// file resumes as the session goes on). True if it woke something.
    bool wakeIfSettingsChanged();

    /// Emitters in the level, and the copies they have alive (docs/format.md,
    /// "Templates and emitters"): those copies' bodies are in the state
    /// vector after the level's own, in the order they appeared.
    std::size_t emitterCount() const;
    std::size_t copiesAlive() const;
    /// Copies added and removed at the start of the last step, in the order
    /// it made them (per emitter: removals, then additions).
    std::span<const EmitterEvent> emitterEvents() const;
    /// The name of `e` when it is one of the copies alive (a scene the
    /// World was built from does not hold them until writeBack); nullptr
    /// otherwise.
    const std::string* copyName(Entity e) const;

    /// Moving bodies (dynamic and kinematic), in the order of the state vector.
    std::size_t bodyCount() const;
    /// How many of them are kinematic.
    std::size_t kinematicCount() const;
    Entity bodyEntity(std::size_t body) const;
    Vec2 bodyPosition(std::size_t body) const;
    Vec2 bodyVelocity(std::size_t body) const;
    /// Applied force on each dynamic body at the current state, newtons:
    /// what the force systems (gravity, drag, springs, attractors, boids)
    /// give, without the contact and joint constraints. A crate resting on
    /// the floor shows m g here; netForces() shows what moves it.
    std::vector<Vec2> bodyForces() const;
    /// Net force on each dynamic body over the last step, newtons: the
    /// momentum change m (v - v_start) / dt, so the applied forces and the
    /// contact and joint impulses together (a crate resting on the floor
    /// shows about 0). Empty when no step was taken since the World was
    /// built, reloaded or restored, or when the last step failed.
    std::vector<Vec2> netForces() const;

    /// Per-stage timing on (default) or off. Off, a step reads no clock at
    /// all; the benchmarks use this to time the integrators alone. (Addition.)
    void setProfiling(bool on);

private:
    // Tests, benchmarks and the accuracy report reach the internals through
    // engine/src/world/world_internals.hpp, not through this class's API.
    friend struct WorldInternalAccess;
    WorldImpl& impl() { return *impl_; }
    const WorldImpl& impl() const { return *impl_; }

    explicit World(std::unique_ptr<WorldImpl> impl);
    /// restoreState of a snapshot from before the emitters added or removed
    /// copies: this World is rebuilt from the snapshot's scene, only then.
    Result<void> restoreOtherCopies(const WorldState& s);
    std::unique_ptr<WorldImpl> impl_;
};

/// What advance() did.
struct AdvanceResult {
    std::uint64_t taken = 0;        ///< steps completed
    std::optional<Error> divergence;  ///< World::step's error (ErrorKind::Diverged) when a step failed
    bool stopped = false;           ///< afterStep asked to stop
    bool ok() const { return !divergence; }
};

/// Per-step hooks of advance(). Either may be empty.
struct AdvanceHooks {
    /// Before step `next` (counted from 1); false: stop without taking it.
    std::function<bool(std::uint64_t next)> beforeStep;
    /// After step `taken` completed (counted from 1); false: stop there.
    std::function<bool(std::uint64_t taken)> afterStep;
};

/// The step loop: up to `steps` steps of `world`, with the hooks around
/// each. A divergence stops the loop with World::step's message and leaves
/// the world as before the failed step. `stepwise run`, `render`, `bench`,
/// the editor and the tests all step through this one function.
AdvanceResult advance(World& world, std::uint64_t steps, const AdvanceHooks& hooks = {});

} // namespace stepwise
