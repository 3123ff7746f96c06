#pragma once
// The collision stages of a step: broad phase, narrow phase (with
// speculative margins for continuous collision), impact propagation, and the
// soft contact solve in each substep. The World owns the translational state
// of dynamic bodies (one state vector for the integrators); this system owns
// the rotational state of the bodies that have shapes, since only contacts
// create torque.

#include "collision/broad_phase.hpp"
#include "collision/contact_bundles.hpp"
#include "collision/contact_solver.hpp"
#include "collision/frozen_boxes.hpp"
#include "collision/narrow_phase.hpp"
#include "collision/position_correction.hpp"
#include "collision/static_support.hpp"
#include "joints/direct_joints.hpp"
#include "joints/joint_bundles.hpp"
#include "joints/joint_solver.hpp"
#include "joints/tree_contacts.hpp"

#include "stepwise/components.hpp"
#include "stepwise/entity.hpp"
#include "stepwise/world.hpp"

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <utility>
#include <span>
#include <vector>

namespace stepwise::collision {

/// One shape in the world.
struct Collider {
    Shape shape;
    std::int32_t body = -1;      ///< index in the World's state vector; -1 = static or plane
    /// A shape of a moving compound body: the collider that holds the
    /// body's rotation, spin, mass and solver body (its hub); -1 otherwise.
    /// Such a shape has no mass of its own and shares everything but its
    /// geometry, material, filter and sensor flag with the hub.
    std::int32_t hub = -1;
    /// Which shape of its entity's `shapes` list this is (0 for a
    /// single-shape body); kHubPart for a hub.
    std::uint32_t part = 0;
    static constexpr std::uint32_t kHubPart = 0xFFFFFFFFu;
    Vec2 staticPosition;         ///< centre of a static shape, metres
    double mass = 0.0;           ///< kg; 0 for static
    double restitution = 0.0;
    double friction = 0.2;
    Entity entity;
    /// A body with no shape that is in the solver only because a joint
    /// holds it, or the hub of a compound body: it turns and takes impulses
    /// but never collides itself.
    bool solverOnly = false;
    /// A kinematic body: in the state vector (`body` >= 0) and moving, with
    /// zero inverse mass and inertia, so contacts push others but never it.
    bool kinematic = false;
    /// A sensor: overlaps are detected and reported, never solved.
    bool sensor = false;
    /// Moment of inertia about the centre, kg m^2: given for solverOnly
    /// bodies, set by add() from the shape for the others.
    double inertia = 0.0;
    /// Centre of mass relative to the body's position, in the body frame,
    /// metres: non-zero for a polygon whose centroid is not its position.
    /// A compound body's shape: its own centre (of its outline) there.
    /// The state vector then holds the position (the file's value, so saves
    /// round-trip exactly) and the velocity of the centre of mass; contacts
    /// work about the centre of mass and turning the body moves its position.
    Vec2 centreOfMass;
};

/// Solid-shape moment of inertia about the centre, kg m^2.
double momentOfInertia(const Shape& shape, double mass);

using stepwise::CachedImpulse;  // world.hpp: snapshots hold the cache as it is

struct CollisionTimings {
    double broadPhaseMs = 0.0, narrowPhaseMs = 0.0, solveMs = 0.0;
};

class CollisionSystem {
public:
    /// Adds a collider with its initial orientation (rad) and spin (rad/s),
    /// and the filter of which colliders it meets (shouldCollide).
    void add(const Collider& collider, double angle, double angularVelocity, const Filter& filter = {});
    bool empty() const { return colliders_.empty(); }
    /// Sets the farthest reach of a compound body's hub from its centre of
    /// mass (its shapes' reach), metres: what sleeping and margins use.
    void setMaxExtent(std::size_t i, double extent) { maxExtent_[i] = extent; }
    /// Whether collider i is a compound body's hub.
    bool isHub(std::size_t i) const { return colliders_[i].part == Collider::kHubPart; }
    std::size_t colliderCount() const { return colliders_.size(); }
    const Collider& collider(std::size_t i) const { return colliders_[i]; }
    double angle(std::size_t i) const { return angles_[i]; }
    double angularVelocity(std::size_t i) const { return angularVelocities_[i]; }

    SolverSettings& settings() { return settings_; }

    /// Adds a joint (ends already mapped to solver bodies and colliders).
    /// `filterA`/`filterB`: the colliders of its two ends (-1 for none); unless
    /// `collideConnected`, contacts between them are dropped.
    void addJoint(const joints::JointConstraint& joint, std::int32_t filterA, std::int32_t filterB,
                  bool collideConnected);
    /// A collider to add in place (CollisionSystem::changed).
    struct ColliderAdd {
        Collider collider;
        double angle = 0.0, angularVelocity = 0.0;
        Filter filter;
    };
    /// Adds a list of colliders in order (an entity's, or an emission's);
    /// a compound shape's `hub` is its hub's place in the list, and the hub
    /// reaches as far as its farthest shape. Returns the first one's index.
    std::uint32_t addAll(std::span<const ColliderAdd> list);
    /// A joint to add in place: its ends' `collider` and the filters are
    /// indices into the ColliderAdd list (-1: a fixed end, or none).
    struct JointAdd {
        joints::JointConstraint joint;
        std::int32_t filterA = -1, filterB = -1;
        bool collideConnected = false;
    };
    /// Bodies came and went (an emitter's copies, an undone delete): the
    /// system with the colliders `dropCollider` marks and the joints
    /// `dropJoint` marks taken out, the rest in their order with their
    /// state-vector bodies mapped by `bodyMap` (old index -> new), and
    /// `added` and `addedJoints` merged in by their entities' places in the
    /// scene order (`sceneIndex`, by entity slot), all shapes before the
    /// solver-only bodies, where World::build puts them: the very arrays a
    /// build of the scene as it now is would make. `added` lists each
    /// entity's colliders together, in scene order. Every kept collider's rotation and spin,
    /// every kept joint's impulses and state and every warm-start entry
    /// between kept colliders stay as they are; the removed bodies' entries
    /// go. The settings, the broad-phase choice and the sleep source carry
    /// over; the caller refreshes the sleeping set.
    std::unique_ptr<CollisionSystem> changed(std::span<const std::uint8_t> dropCollider,
                                             std::span<const std::uint8_t> dropJoint,
                                             std::span<const std::int32_t> bodyMap, std::span<const ColliderAdd> added,
                                             std::span<const JointAdd> addedJoints,
                                             std::span<const std::uint32_t> sceneIndex) const;
    /// Whether appended() may take an addition: no collider is in the solver
    /// only because a joint holds it (a build puts those after every shape,
    /// so new shapes would go before them).
    bool appendsAtEnd() const;
    /// Bodies came and none went: `added` and `addedJoints` appended to this
    /// system in place, with what changed() would leave (the same arrays,
    /// warm start and joint state; no last step's contacts; solver bodies
    /// as add() makes them), without copying what stays. Only when
    /// appendsAtEnd().
    void appended(std::span<const ColliderAdd> added, std::span<const JointAdd> addedJoints);
    /// Bodies went: the colliders `dropCollider` marks and the joints
    /// `dropJoint` marks taken out of this system in place, the rest moved
    /// up in their order with their state-vector bodies mapped by `bodyMap`,
    /// leaving what changed() with nothing added would (the same arrays,
    /// warm start and joint state; no last step's contacts), without
    /// making every array again. Then appended() may add, when
    /// appendsAtEnd().
    void removed(std::span<const std::uint8_t> dropCollider, std::span<const std::uint8_t> dropJoint,
                 std::span<const std::int32_t> bodyMap);
    /// Polygon outlines and chain segments held, those of colliders gone
    /// included (removed() frees them once they are half).
    std::size_t outlinesHeld() const { return polygons_.size() + segments_.size(); }
    /// Solver body of a collider (0 = static), for mapping joint ends.
    std::uint32_t solverBodyOf(std::size_t collider) const { return solverIndex_[collider]; }
    bool hasJoints() const { return !joints_.empty(); }
    /// Whether any collider has a shape (a system may hold only joints).
    bool hasShapes() const { return !finite_.empty() || !planes_.empty(); }
    joints::JointSettings& jointSettings() { return jointSettings_; }
    const joints::DirectJoints& directJoints() const { return directJoints_; }
    /// The joints in solver (scene) order; their accumulated impulses are
    /// the joints' warm start, saved and restored with the contacts' cache.
    std::span<const joints::JointConstraint> jointConstraints() const { return joints_; }
    std::span<joints::JointConstraint> jointConstraints() { return joints_; }
    /// Joints of the last step, for the debugging views.
    std::span<const JointRecord> jointRecords() const { return jointRecords_; }
    /// After a successful step: every unbroken, awake joint with a max_force
    /// whose constraint force over the last substep (|jointForce|) exceeds
    /// it breaks: it leaves the solver, its groups, its island edges and the
    /// no-collide list, and its impulses go to zero (so a saved state lists
    /// none for it). Appends (joint index, force in N) of each to `out`.
    /// Only joints with a max_force are visited.
    void breakJoints(std::vector<std::pair<std::uint32_t, double>>& out);
    bool hasBreakableJoints() const { return !breakable_.empty(); }
    /// Sets which joints are broken (a restored snapshot's): the others are
    /// whole again. `broken` holds joint entities.
    void setBrokenJoints(std::span<const Entity> broken);
    const SolverSettings& settings() const { return settings_; }
    /// Fixes the broad-phase strategy (tests, benchmarks); by default it is
    /// chosen per step from the number of shapes.
    void setBroadPhase(BroadPhaseKind kind) {
        autoBroadPhase_ = false;
        broadPhase_.setKind(kind);
    }
    const BroadPhase& broadPhase() const { return broadPhase_; }
    /// Off: boxes are fattened in the mean-velocity frame only, never in
    /// the frame that turns with the bodies (tests compare the two).
    void setTurningFrame(bool on) { turningFrame_ = on; }

    /// Records the step-start state. Detection for the whole step runs in
    /// the first solveSubstep, once the forces of the step are known: margins
    /// cover the motion of `dt`, so contacts exist before fast bodies reach a
    /// surface.
    void beginStep(std::span<const Vec2> x, std::span<const Vec2> v, double dt, int substeps);
    /// Contact solve for one substep of length h. On entry `x`, `v` hold the
    /// integrator's unconstrained end-of-substep state; on exit, the
    /// constrained one (positions move by h times the contact velocity change).
    /// The first call of a step also runs the broad and narrow phases.
    void solveSubstep(std::span<Vec2> x, std::span<Vec2> v, double h);
    /// Stores impulses for warm starting and the joint records; the contact
    /// records are made when first asked for (contacts()).
    void endStep();

    std::span<const ContactRecord> contacts() const {
        if (recordsPending_) makeRecords();
        return records_;
    }
    /// Sensor events of the last step and the overlaps at its end.
    std::span<const SensorEvent> sensorEvents() const { return sensorEvents_; }
    std::vector<std::pair<Entity, Entity>> sensorOverlaps() const;
    bool hasSensors() const { return anySensor_; }
    /// Sets the overlaps from the positions `x` without events: at build,
    /// and after a restore (what is inside then was inside before).
    void initSensors(std::span<const Vec2> x);
    /// Forgets the last step's contacts (a restore replaced that step); the
    /// sleeping islands' contacts stay listed.
    void clearContactRecords() {
        recordsPending_ = false;
        records_.resize(sleepingRecordCount_);
        recordPairs_.resize(sleepingRecordCount_);
    }
    /// How many records contacts() holds, without making them.
    std::size_t contactPointCount() const;
    /// Broad-phase pairs and narrow-phase manifolds of the last detection.
    std::size_t candidatePairCount() const { return pairs_.size(); }
    std::size_t manifoldCount() const { return constraints_.size(); }
    /// The last detection's broad-phase pairs, as collider indices.
    std::vector<std::pair<std::uint32_t, std::uint32_t>> candidateColliderPairs() const;
    /// Whether the finite colliders a and b, all awake, could come within
    /// the slop of each other in the last detection's step, by their shapes'
    /// boxes and their motion relative to each other (velocity linear in
    /// time, spin all round). The broad phase pairs every two for which it
    /// holds, in whichever frame it grew its boxes (tests check it).
    bool canTouch(std::size_t a, std::size_t b) const;
    const CollisionTimings& timings() const { return timings_; }
    /// The last step's contacts in colours (counts, order), for tests and benchmarks.
    const ColouredContacts& colouredContacts() const { return coloured_; }
    const joints::JointBundles& jointBundles() const { return jointBundles_; }
    /// The impact passes' scratch: their statistics, and the reference mode
    /// (every contact in every pass) tests compare against.
    ImpactScratch& impactScratch() { return impactScratch_; }

    /// Sets the rotational state: undoes a step's change (after a
    /// divergence), or resumes from a snapshot.
    /// Centre of mass of collider i in the world (its position plus the
    /// rotated offset), metres, at the given body positions.
    Vec2 centreOfMass(std::size_t i, std::span<const Vec2> x) const;

    /// Turns collider i (a body's own, or a compound body's hub, whose
    /// shapes follow) to `angle` with spin `angularVelocity`.
    void setRotation(std::size_t i, double angle, double angularVelocity) {
        angles_[i] = angle;
        angularVelocities_[i] = angularVelocity;
        syncShapes();
    }
    /// Undoes a step's rotational change (after a divergence).
    void restoreRotation(std::span<const double> angles, std::span<const double> angularVelocities) {
        angles_.assign(angles.begin(), angles.end());
        angularVelocities_.assign(angularVelocities.begin(), angularVelocities.end());
        syncShapes();
    }
    /// Undoes what the last beginStep..endStep did to the carried solver
    /// state (after a divergence): the warm-start cache and the joints'
    /// impulses go back to what they were, so the failed step's (perhaps
    /// non-finite) impulses never warm a later step.
    void undoSolverState();
    std::span<const double> angles() const { return angles_; }
    std::span<const double> angularVelocities() const { return angularVelocities_; }

    /// The warm-start cache the next step starts from (sorted by key): with
    /// the bodies' state, all a step reads that an earlier step wrote. The
    /// sleeping islands' entries are kept aside while they sleep and merged
    /// in here.
    std::vector<CachedImpulse> warmStartCache() const;
    /// Replaces it (resume from a snapshot or a file); sorted here. Set the
    /// sleeping bodies first (refreshSleeping): the entries are split by them.
    void setWarmStartCache(std::vector<CachedImpulse> cache);

    // --- Sleeping (world/islands.hpp). The World owns the islands; this
    // system reads which bodies sleep and asks the World to wake an island.
    /// `bodyAsleep` (per state-vector body, 1 = asleep) stays owned by the
    /// caller and must outlive this system; `wake(body)` wakes its island.
    void setSleepSource(const std::vector<std::uint8_t>* bodyAsleep, std::function<void(std::uint32_t)> wake) {
        bodyAsleep_ = bodyAsleep;
        wakeBody_ = std::move(wake);
    }
    /// Takes the sleeping set again after it changed: awake lists, the frozen
    /// boxes (at positions `x`), the cache split, the sleeping contacts'
    /// records, the joints' flags.
    void refreshSleeping(std::span<const Vec2> x);
    /// Pairs of dynamic bodies (state-vector indices) joined by a manifold of
    /// the last step or by a joint: the island edges this system knows of.
    void bodyEdges(std::vector<std::pair<std::uint32_t, std::uint32_t>>& out) const;
    /// The last step's touching contacts between a dynamic body and a
    /// static or kinematic shape (as bodyEdges judges touching), and in
    /// `held` (one per body, set to 1) the bodies a joint ties to the world,
    /// a static or a kinematic body: what sleep asks before freezing an
    /// island (world/rest_balance.hpp).
    void staticSupports(std::vector<Support>& out, std::vector<std::uint8_t>& held) const;
    /// Gives collider i (a dynamic body's own, or a compound body's hub) a
    /// new mass, as add() would have: `inertia` is taken as given for a
    /// solver-only collider (a hub, a shapeless body), else computed from the
    /// shape; a hub's shapes follow it.
    void setMass(std::size_t i, double mass, double inertia);
    /// Gives collider i, a dynamic body's only shape, the shape, friction,
    /// restitution and filter of `fresh` (made as add() takes it, with the
    /// same centre of mass and sensor flag), and the inertia and reach that
    /// follow, as add() would have; its contacts' warm start stays.
    void reshape(std::size_t i, const Collider& fresh, const Filter& filter);
    /// Farthest point of collider i from its centre of mass, metres.
    double maxExtent(std::size_t i) const { return maxExtent_[i]; }

private:
    /// Copies each compound body's rotation and spin from its hub to its
    /// shapes, so every per-collider reader sees the body's.
    void syncShapes() {
        for (const std::uint32_t i : shapesOfHubs_) {
            const std::size_t hub = std::size_t(colliders_[i].hub);
            angles_[i] = angles_[hub];
            angularVelocities_[i] = angularVelocities_[hub];
        }
    }
    /// The collider whose pair a joint names: a compound shape's hub.
    std::uint32_t ownerOf(std::uint32_t i) const {
        return colliders_[i].hub >= 0 ? std::uint32_t(colliders_[i].hub) : i;
    }
    /// Whether two colliders are shapes of the same moving body.
    bool sameBody(std::uint32_t a, std::uint32_t b) const {
        return colliders_[a].body >= 0 && colliders_[a].body == colliders_[b].body;
    }
    /// After the step's last substep: positions out of overlap beyond the
    /// slop (position_correction.hpp), written back to `x` and the angles.
    void correctStepPositions(std::span<Vec2> x);
    /// Part of the position pass: a body that turned far this step (a
    /// tumbling box, a spinning capsule) can meet the static world with
    /// features its step-start contacts do not hold (a corner that swung
    /// down, the far side of a rounded end). Its static contacts are found
    /// again at its present pose and it is pushed out to the slop along
    /// them. Returns whether a body moved; `scratchReady`: the position
    /// pass has sized positionScratch_ this step.
    bool correctTurnedAgainstStatic(bool scratchReady);
    /// Where a shape is within the step, from its body's move so far.
    struct PresentPose {
        Vec2 centre;  ///< the body's centre of mass, metres
        Vec2 at;      ///< the shape's centre, metres
        Rot q;        ///< the shape's rotation
    };
    PresentPose presentPose(std::uint32_t shape, const SolverBody& body) const;
    /// How far collider i's body was foreseen to move this step when its
    /// contacts were found (its speculative reach, metres): a body that went
    /// farther may meet static shapes it has no contact with.
    double foreseenTravel(std::size_t i) const;
    /// Visits the shapes of solver collider i that push (not sensors): the
    /// collider itself, or a compound body's shapes (once the static sweep
    /// is prepared: hubShapes_).
    template <typename Visit>
    void forEachSolidShape(std::uint32_t i, Visit&& visit) const {
        if (!colliders_[i].solverOnly) {
            if (!colliders_[i].sensor) visit(i);
            return;
        }
        const auto first = std::lower_bound(hubShapes_.begin(), hubShapes_.end(), std::pair{i, 0u});
        for (auto it = first; it != hubShapes_.end() && it->first == i; ++it)
            if (!colliders_[it->second].sensor) visit(it->second);
    }
    /// After the position pass: bodies that moved farther this step than
    /// their speculative margins allowed, swept against the static shapes
    /// near their path and put back where their centroid would pass into
    /// one (static_sweep.hpp), written back to `x` and the angles.
    void sweepAgainstStatic(std::span<Vec2> x);
    /// The static shapes' boxes and each compound body's shapes, built when
    /// the sweep first needs them (static shapes never move).
    void prepareStaticSweep();
    /// Adds the bodies of deeply overlapping moving pairs to crowdBodies_.
    void addDeepOverlapsToCrowd();
    /// Adds to crowdBodies_ the jointed bodies touching it, transitively.
    void addJointedNeighboursToCrowd();
    /// Lists the joints within the crowd, and those from it to a moving
    /// body outside, and saves their impulses (after the warm start);
    /// restoreCrowdJoints puts the first back and takes back what the
    /// second gave (after the biased passes).
    void saveCrowdJoints();
    void restoreCrowdJoints();
    /// Whether solver body b takes no impulse: the static entry 0, and
    /// kinematic bodies.
    bool fixedBody(std::uint32_t b) const { return bodies_[b].invMass == 0.0 && bodies_[b].invInertia == 0.0; }
    /// Riders: moving bodies outside every exactly solved joint group that
    /// rest on such a group or on another rider (a crate on a bridge, a box
    /// on the crate). noteRiders lists their contacts and separations before
    /// the groups' projection moves them; carryRiders then moves each rider
    /// out by what the projection (or a carried neighbour) pushed into it.
    /// noteRiders returns false when no loose body touches a group.
    bool noteRiders();
    void carryRiders(std::span<Vec2> x);
    /// The move of a loose rider (body B of `c` when `pushB`, else A) out
    /// of its contact by `deficit` (m, at point `deepest`): false when it
    /// would not hold the rider against its load; else `move` (along the
    /// normal on entry) becomes the move to make.
    bool carryAgainstLoad(const ContactConstraint& c, int deepest, bool pushB, double deficit, Vec2& move) const;
    /// Moves the riders that static friction holds with their supports
    /// (carryRiders' first part).
    void followRiders();
    /// How far the projection (a group's body) or the carry (a rider) moved
    /// `support`'s side of point `point` of contact `c`.
    Vec2 supportMove(const ContactConstraint& c, int point, std::uint32_t support) const;
    std::vector<Vec2> followSum_;       // followRiders: per solver body, the weighted sum of its supports' moves
    std::vector<double> followWeight_;  // and of their weights (normal impulses, N*s)

    void addManifold(std::uint32_t a, std::uint32_t b, const Manifold& m, std::span<const Vec2> centres);
    /// Broad phase while some bodies sleep: the awake boxes among themselves
    /// and against the frozen ones (static and sleeping), pairs sorted as
    /// the full broad phase sorts them. Returns false when it woke an
    /// island (an awake body has a manifold with a sleeping one): then the
    /// detection starts over with that island awake.
    bool sleepingBroadPhase(std::span<const Rot> rots, Vec2 ref0, Vec2 ref1);
    /// The larger of colliders a and b's relative speeds at the two ends of
    /// the step (m/s): how fast their gap can close within it.
    double closingSpeed(std::size_t a, std::size_t b) const;
    /// Replaces growLow_ and growHigh_ by the growth in a frame that turns
    /// with the bodies, when it adds up to less than meanFrameSum (all
    /// colliders awake).
    void rotatingFrameMargins(Vec2 ref0, Vec2 ref1, double meanFrameSum);
    /// Moves cache entries that touch a sleeping collider to sleepingCache_
    /// and the others back to cache_ (each stays sorted).
    void splitCache();
    /// Broad and narrow phase at the step-start positions; `firstSubstepV`
    /// is the unconstrained velocity after the first substep's forces.
    void detect(std::span<const Vec2> firstSubstepV, double h);
    /// The most normal impulse this step's first substep can need at one
    /// contact point (N*s), from the awake bodies' motion and forces at the
    /// step's start. The colouring bounds each contact's warm start by it
    /// (boundWarmStart).
    double warmStartBound(std::span<const Vec2> firstSubstepV) const;
    static Vec2 coincidentNormal(std::uint32_t a, std::uint32_t b);
    /// What a system made by changed() starts without, dropped in place:
    /// the last step's contacts and records, the sweep's lazily built static
    /// boxes and the broad phase's kept order.
    void forgetLastStep();
    /// Adds the joints of `old` that `dropJoint` does not mark, their ends
    /// renumbered by `colliderMap` (old collider -> kept, -1 gone).
    void addKeptJoints(std::span<const joints::JointConstraint> old, std::span<const std::uint8_t> dropJoint,
                       std::span<const std::int32_t> colliderMap);
    /// Adds a kept joint, its ends renumbered by `colliderMap`.
    void addKeptJoint(joints::JointConstraint j, std::span<const std::int32_t> colliderMap);
    /// Adds an added joint, its ends' places in the addition mapped to
    /// colliders by `placed` (index in the ColliderAdd list -> collider).
    void addJointOf(const JointAdd& add, std::span<const std::int32_t> placed);
    /// The warm-start entries between kept colliders, renumbered.
    static std::vector<CachedImpulse> keptCache(std::vector<CachedImpulse> all, std::span<const std::int32_t> colliderMap);
    /// Adds the joints of an addition whose colliders start at `base`.
    void addJointsOf(std::span<const JointAdd> addedJoints, std::uint32_t base, std::size_t addedCount);

    std::vector<Collider> colliders_;
    std::deque<ConvexPolygon> polygons_;  // the polygon shapes' outlines (addresses stay fixed)
    std::deque<ChainSegment> segments_;   // the chain segments (addresses stay fixed)
    std::vector<std::uint32_t> offsetBodies_;  // dynamic colliders whose centre of mass is off their position
    std::vector<double> offsetAngleBefore_;    // their angles at the start of the substep, rad
    std::vector<double> angles_, angularVelocities_;
    /// Shapes of moving compound bodies (hub >= 0), ascending; empty in a
    /// world without one, which then takes only the single-shape paths.
    std::vector<std::uint32_t> shapesOfHubs_;
    std::vector<std::uint32_t> awakeShapesOfHubs_;  // those whose body is awake
    std::vector<double> invMass_, invInertia_, maxExtent_;
    std::vector<std::uint32_t> finite_;  // colliders that are not planes (broad-phase proxies)
    std::vector<std::uint32_t> planes_;
    std::vector<std::uint32_t> solverIndex_;  // collider -> SolverBody (0 = static)

    SolverSettings settings_;
    BroadPhase broadPhase_;
    bool autoBroadPhase_ = true;
    bool turningFrame_ = true;
    std::vector<Aabb> boxes_;
    std::vector<double> cores_;  // per box: its area before the margin (m^2), for the grid's crowd test
    std::vector<std::uint8_t> movable_;
    std::vector<ProxyPair> pairs_;
    std::vector<Vec2> centres_, stepStart_;
    /// margins_: per collider, its box's growth all round in the mean frame
    /// (m), for the broad phase while islands sleep.
    std::vector<double> stepStartAngle_, margins_, spin_;
    /// Per collider, all awake: how far its box grows below and above its
    /// shape's on each axis (m), the motion's part only in its direction
    /// (sweptGrowth).
    std::vector<Vec2> growLow_, growHigh_;
    std::vector<Aabb> shapeBoxes_;  ///< per collider in the broad phase: its shape's box, no margin
    std::vector<Vec2> rotatedLow_, rotatedHigh_;  ///< rotatingFrameMargins' candidates
    std::vector<Vec2> startV_, endV_;  // per collider: velocity at step start, predicted at step end (m/s)
    bool detected_ = false;
    struct SavedVelocity {
        Vec2 v;
        double w = 0.0;
    };
    std::vector<std::uint32_t> crowdBodies_;  // solver bodies in a crowded grid cell this step
    std::vector<SavedVelocity> crowdSaved_;
    std::vector<SolverBody> bodies_;
    std::vector<ContactConstraint> constraints_;
    std::vector<ContactDetail> details_;  // parallel to constraints_
    ColouredContacts coloured_;           // constraints_ in colours and SIMD bundles
    /// Per contact: its deepest point's separation at the step's end, as
    /// the last relax pass measured it (solveSubstep); valid while
    /// endSeparationsMeasured_.
    std::vector<double> endSeparations_;
    bool endSeparationsMeasured_ = false;
    ContactPairs contactPairs_;           // constraints_' bodies and point counts, packed (the narrow phase)
    ImpactScratch impactScratch_;         // which constraints_ touch which body (propagateImpacts)
    std::vector<CachedImpulse> cache_;
    std::vector<CachedImpulse> previousCache_;     // the cache the last step started from (undoSolverState)
    std::vector<JointImpulse> jointImpulsesBefore_;  // the joints' impulses at the last beginStep
    std::size_t cacheCursor_ = 0;  // where the previous manifold's cache search ended
    std::vector<Vec2> unconstrainedV_;
    // Made from the last whole step's manifolds when first asked for
    // (makeRecords): those are constraints_ and details_ until the next step
    // begins, then keptConstraints_ and keptDetails_.
    mutable std::vector<ContactRecord> records_;
    mutable bool recordsPending_ = false;
    bool recordsFromKept_ = false;
    /// How many records the pending manifolds will make, counted by endStep
    /// as it reads them for the cache: every step's statistics ask, and a
    /// count of its own read every manifold from memory again.
    std::size_t pendingRecordCount_ = 0;
    std::vector<ContactConstraint> keptConstraints_;
    std::vector<ContactDetail> keptDetails_;
    void makeRecords() const;
    const std::vector<ContactConstraint>& recordedConstraints() const;
    const std::vector<ContactDetail>& recordedDetails() const;
    static bool isRecord(const ContactConstraint& c, const ContactDetail& d, int i);
    std::vector<Rot> rotScratch_;
    std::vector<joints::JointConstraint> joints_;
    joints::JointSettings jointSettings_;
    joints::DirectJoints directJoints_;  // the tree-shaped groups' exact solve
    joints::TreeContacts treeContacts_;  // contacts of loose bodies on those groups, solved with them
    std::vector<std::uint8_t> heldOut_;  // per contact: solved by treeContacts_, not in the colours
    std::vector<std::uint32_t> jointOrder_;  // the joint passes' order (colourJoints)
    bool jointOrderReady_ = false;           // false: a joint was added, broke or mended since it was made
    std::vector<std::uint32_t> jointColourEnds_;  // where each colour ends in jointOrder_ (colourJoints)
    joints::JointBundles jointBundles_;           // the joint passes: plain hinges in SIMD lanes, the rest one at a time
    bool jointBundlesReady_ = false;              // built this step
    std::vector<joints::DirectJoints::Move> jointMoves_;  // per solver body: its projection (directJoints_.project)
    std::vector<std::uint32_t> jointMoved_;
    struct RiderContact {
        std::uint32_t contact;
        /// Its bodies, copied: the carry's passes test their roles first, and
        /// read the 232-byte contact only where one has moved.
        std::uint32_t bodyA, bodyB;
        /// Each point's separation before the projection, metres. Between two
        /// loose bodies (`betweenLoose`), whose separation the projection
        /// does not change, it is measured only if one of them is carried
        /// (riderBefore): most of a pile's contacts never are.
        double before[2];
        bool betweenLoose;
    };
    /// What r.before[i] holds, or for a contact between loose bodies what it
    /// would: the separation at the positions the bodies had before any carry.
    double riderBefore(const RiderContact& r, const ContactConstraint& c, int i) const;
    std::vector<RiderContact> riderContacts_;  // noteRiders
    /// Per solver body, for carryRiders: kLoose, kInGroup (an end of an
    /// exactly solved joint) or kCarried (a rider moved this substep).
    enum CarryRole : std::uint8_t { kLoose, kInGroup, kCarried };
    std::vector<std::uint8_t> carryRole_;
    std::vector<Vec2> riderLoad_;  // per solver body: its velocity change from outside forces this step, m/s
    std::vector<Vec2> carried_;    // per solver body: what carryRiders moved it by, metres
    std::vector<Vec2> dpBeforeCarry_;  // per solver body: its dp when noteRiders ran
    std::vector<std::pair<std::uint32_t, double>> stiffened_;  // bodies whose inertia a joint raised this substep
    std::vector<double> stiffenScratch_;
    std::vector<std::uint64_t> noCollide_;  // sorted (min collider << 32 | max collider)
    /// Whether colliders a and b belong to bodies joined with
    /// collide_connected false (noCollide_).
    bool joinedNotColliding(std::uint32_t a, std::uint32_t b) const;
    /// Whether any collider has a filter other than the default: without
    /// one every pair passes and the test is skipped.
    bool filtered_ = false;
    /// Each collider's filter, kept apart from the colliders: only a level
    /// with filters reads it.
    std::vector<Filter> filters_;
    /// Whether the filters let no two shapes meet (Box2D's joint grid: its
    /// circles all exclude one another), and whether that is known for the
    /// colliders as they are (any add, reshape or removal makes it unknown).
    /// Such a scene builds no boxes and finds no pairs.
    bool nothingCanCollide();
    bool nothingCollides_ = false, collidableKnown_ = false;
    /// Sensors: whether there are any, the pairs the broad phase found for
    /// them this step (sensor collider << 32 | other), the overlapping ones
    /// at the end of the last step (sorted, same keys), and its events.
    bool anySensor_ = false;
    std::vector<std::uint64_t> sensorCandidates_;
    std::vector<std::uint64_t> sensorOverlaps_;
    std::vector<SensorEvent> sensorEvents_;
    /// When a or b is a sensor: keeps the pair for the end-of-step test and
    /// returns true (no manifold for it); otherwise false.
    bool sensedInstead(std::uint32_t a, std::uint32_t b);
    /// Whether sensor collider s and collider o overlap at the centres and
    /// rotations given.
    bool sensorOverlap(std::uint32_t s, std::uint32_t o, std::span<const Vec2> x) const;
    /// At the end of a step: overlaps of this step's candidates, plus those
    /// kept by sleeping bodies; events for the differences.
    void updateSensors(std::span<const Vec2> x);
    /// Whether any collider is kinematic: then pairs of two bodies that
    /// nothing moves (kinematic or static) are skipped.
    bool anyKinematic_ = false;
    /// Whether colliders a and b may meet: under their filters, and when at
    /// least one of them can be pushed.
    bool collides(std::uint32_t a, std::uint32_t b) const {
        if (anyKinematic_ && invMass_[a] == 0.0 && invMass_[b] == 0.0) return false;
        return !filtered_ || shouldCollide(filters_[a], filters_[b]);
    }
    std::vector<std::uint32_t> breakable_;  // joints with a max_force, ascending
    /// breakJoints' scratch: a joint past its max_force, its force (N) and
    /// how far past (force / max_force).
    struct BreakCandidate {
        std::uint32_t joint;
        double force, excess;
    };
    std::vector<BreakCandidate> breakCandidates_;
    /// Drops broken joints' records and their no-collide entries, and
    /// regroups the direct solve.
    void jointsBroke();
    std::vector<JointRecord> jointRecords_;
    std::vector<double> turns_;  // endStep: each solver body's turn in the step, rad
    double lastH_ = 0.0;
    // Sleeping: see refreshSleeping(). With nothing asleep these are the
    // full lists and every stage runs exactly as without sleeping.
    const std::vector<std::uint8_t>* bodyAsleep_ = nullptr;
    std::function<void(std::uint32_t)> wakeBody_;
    bool anySleeping_ = false;
    std::vector<std::uint8_t> colliderAsleep_;           // per collider
    std::vector<std::uint32_t> awakeSolverColliders_;    // colliders with a solver body, awake, ascending
    struct SolvedBody {
        std::uint32_t collider, solver, body;  // collider, SolverBody and state-vector indices
    };
    std::vector<SolvedBody> awakeSolved_;                // awakeSolverColliders_'s indices, set each step
    std::vector<std::uint32_t> awakeProxies_;            // finite_ indices of awake dynamic shapes, ascending
    FrozenBoxes frozen_;                                 // static and sleeping shapes' boxes
    FrozenBoxes staticBoxes_;                            // static shapes' boxes, for the sweep
    std::vector<Rot> staticRots_;  // per collider: a static shape's rotation, for the sweep (others unset)
    std::vector<std::pair<std::uint32_t, std::uint32_t>> hubShapes_;  // (hub, shape), sorted, for the sweep
    std::vector<double> minReach_;  // per collider: its smallest reach (static_sweep.hpp), for the sweep
    bool staticSweepReady_ = false;
    std::vector<Aabb> awakeBoxes_;
    std::vector<double> awakeCores_;
    std::vector<std::uint8_t> awakeMovable_;
    std::vector<ProxyPair> awakePairs_;
    std::vector<CachedImpulse> sleepingCache_;           // warm start of the sleeping islands' contacts
    std::size_t sleepingRecordCount_ = 0;                // records_ starts with the sleeping contacts
    mutable std::vector<std::pair<std::uint32_t, std::uint32_t>> recordPairs_;  // colliders of each record
    std::span<const Vec2> stepStartX_;                   // beginStep's positions (valid during the step)
    CollisionTimings timings_;
    double dt_ = 0.0;
    int substeps_ = 1;
    std::vector<std::uint8_t> inCrowd_;  // per solver body: in crowdBodies_
    std::vector<std::uint8_t> takeBack_;  // per solver body: its pushes across the crowd's edge go back
    std::vector<std::uint32_t> deepContacts_;  // this step's moving contacts deeper than a quarter reach
    std::vector<double> crowdImpulses_;  // the crowd contacts' impulses after the warm start, while a crowd is solved
    std::vector<std::uint32_t> crowdJoints_;  // the awake joints within the crowd, this substep
    std::vector<JointImpulse> crowdJointImpulses_;  // theirs after the warm start
    std::vector<std::uint32_t> crowdRimJoints_;  // the awake joints from the crowd to a moving body outside it
    std::vector<JointImpulse> crowdRimImpulses_;  // theirs after the warm start
    std::vector<std::uint8_t> crowdSupport_;  // per solver body: a crowd body carrying a heavy one out (addJointedNeighboursToCrowd)
    std::vector<std::uint8_t> jointedBody_;  // per solver body: jointed to another moving body (addJointedNeighboursToCrowd)
    std::vector<std::uint32_t> neighbourStart_, neighbourFill_, neighbours_;  // contacts of jointed bodies, by body
    int substepsDone_ = 0;  // of this step, counted by solveSubstep
    PositionCorrectionSettings positionCorrection_;
    PositionCorrectionScratch positionScratch_;
    struct TurnedStaticContact {
        std::uint32_t solver, moving, fixed;  // the body's solver index, its shape's collider, the static collider
    };
    std::vector<std::uint32_t> turnedBodies_;          // correctTurnedAgainstStatic's turned bodies (solver indices)
    std::vector<TurnedStaticContact> turnedContacts_;  // and the static shapes near them, grouped by body
    std::vector<PresentContact> presentContacts_;      // one body's static contacts at its present pose
};

} // namespace stepwise::collision
