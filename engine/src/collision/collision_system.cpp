#include "collision/collision_system.hpp"
#include "collision/static_sweep.hpp"

#include "stepwise/components.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>

namespace stepwise::collision {

namespace {
/// Contacts within this distance count as touching; also the base of the
/// speculative margin. Metres (Box2D's b2_linearSlop).
constexpr double kLinearSlop = 0.005;
constexpr double kSpeculativeBase = 4.0 * kLinearSlop;
/// How far past the momentum and forces that can reach one contact its
/// warm start may be (warmStartBound): the loader's factor for its own bound.
constexpr double kWarmStartMargin = 4.0;

double msSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}
} // namespace

double momentOfInertia(const Shape& shape, double mass) {
    switch (shape.kind) {
    case ShapeKind::Circle: return 0.5 * mass * shape.radius * shape.radius;
    case ShapeKind::Box: {
        const double w = 2.0 * shape.halfExtents.x, h = 2.0 * shape.halfExtents.y;
        return mass * (w * w + h * h) / 12.0;
    }
    case ShapeKind::Plane:
    case ShapeKind::ChainSegment: return 0.0;  // no area; only on static and kinematic bodies
    case ShapeKind::Capsule:
        return mass * capsuleMassProperties(2.0 * length(shape.halfExtents), shape.radius).inertiaPerMass;
    case ShapeKind::Polygon: {
        // Fan of triangles (0, vi, vi+1) about the centre of mass (the
        // origin of the outline): each has area cross(vi, vi+1)/2 and polar
        // second moment area/6 (vi.vi + vi.vi+1 + vi+1.vi+1); I = m J / A.
        const ConvexPolygon& p = *shape.polygon;
        if (p.cornerRadius > 0.0) {
            // Rounded: the polygon, its edge strips and corner sectors.
            const std::vector<Vec2> outline(p.vertices, p.vertices + p.count);
            const PolygonMassProperties props = polygonMassProperties(outline, p.cornerRadius);
            return mass * props.secondMoment / props.area;
        }
        double area = 0.0, polar = 0.0;
        for (int i = 0; i < p.count; ++i) {
            const Vec2 a = p.vertices[i], b = p.vertices[(i + 1) % p.count];
            const double triangle = 0.5 * cross(a, b);
            area += triangle;
            polar += triangle / 6.0 * (dot(a, a) + dot(a, b) + dot(b, b));
        }
        return mass * polar / area;
    }
    }
    return 0.0;
}

Vec2 CollisionSystem::centreOfMass(std::size_t i, std::span<const Vec2> x) const {
    const Collider& c = colliders_[i];
    const Vec2 p = c.body >= 0 ? x[std::size_t(c.body)] : c.staticPosition;
    // Bodies whose centre of mass is their position take it as it is, bit
    // for bit (no + 0 that would turn -0 into +0).
    if (c.centreOfMass.x == 0.0 && c.centreOfMass.y == 0.0) return p;
    return p + rotate(Rot::fromAngle(angles_[i]), c.centreOfMass);
}

namespace {

/// Farthest point of a shape from its own centre (the collider's centre of
/// mass for a body's one shape), metres; planes and shapeless colliders 0.
double shapeReach(const Shape& s) {
    switch (s.kind) {
    case ShapeKind::Circle: return s.radius;
    case ShapeKind::Polygon: return s.polygon->radius + s.polygon->cornerRadius;
    case ShapeKind::Capsule: return length(s.halfExtents) + s.radius;
    case ShapeKind::ChainSegment: return std::max(length(s.segment->p1), length(s.segment->p2));
    default: return length(s.halfExtents);
    }
}

} // namespace

void CollisionSystem::add(const Collider& c, double angle, double angularVelocity, const Filter& filter) {
    const std::uint32_t index = std::uint32_t(colliders_.size());
    colliders_.push_back(c);
    if (c.shape.kind == ShapeKind::Polygon) {
        polygons_.push_back(*c.shape.polygon);
        colliders_.back().shape.polygon = &polygons_.back();
    }
    if (c.shape.kind == ShapeKind::ChainSegment) {
        segments_.push_back(*c.shape.segment);
        colliders_.back().shape.segment = &segments_.back();
    }
    if (c.hub >= 0) {
        // A shape of a compound body: everything that moves is its hub's.
        const std::size_t hub = std::size_t(c.hub);
        filtered_ = filtered_ || !(filter == Filter{});
        filters_.push_back(filter);
        collidableKnown_ = false;
        anyKinematic_ = anyKinematic_ || c.kinematic;
        anySensor_ = anySensor_ || c.sensor;
        colliderAsleep_.push_back(0);
        shapesOfHubs_.push_back(index);
        awakeShapesOfHubs_.push_back(index);
        angles_.push_back(angles_[hub]);
        angularVelocities_.push_back(angularVelocities_[hub]);
        invMass_.push_back(invMass_[hub]);
        colliders_.back().inertia = 0.0;
        colliders_.back().mass = 0.0;
        invInertia_.push_back(0.0);
        // Reach about the body's centre of mass: the shape's own plus how
        // far its centre sits from the body's.
        maxExtent_.push_back(shapeReach(c.shape) + length(c.centreOfMass - colliders_[hub].centreOfMass));
        finite_.push_back(index);
        solverIndex_.push_back(solverIndex_[hub]);
        return;
    }
    // A kinematic body moves like a dynamic one (a solver body, turned by
    // its spin) with zero inverse mass and inertia.
    const bool dynamic = c.body >= 0 && (c.mass > 0.0 || c.kinematic);
    filtered_ = filtered_ || !(filter == Filter{});
    filters_.push_back(filter);
    collidableKnown_ = false;
    anyKinematic_ = anyKinematic_ || c.kinematic;
    anySensor_ = anySensor_ || c.sensor;
    colliderAsleep_.push_back(0);
    if (dynamic) awakeSolverColliders_.push_back(index);
    angles_.push_back(angle);
    angularVelocities_.push_back(dynamic ? angularVelocity : 0.0);
    invMass_.push_back(dynamic && !c.kinematic ? 1.0 / c.mass : 0.0);
    const double inertia = !dynamic || c.kinematic ? 0.0
                           : c.solverOnly         ? c.inertia
                                                  : momentOfInertia(c.shape, c.mass);
    colliders_.back().inertia = inertia;
    invInertia_.push_back(inertia > 0.0 ? 1.0 / inertia : 0.0);
    maxExtent_.push_back(c.solverOnly ? 0.0 : shapeReach(c.shape));
    if (dynamic && (c.centreOfMass.x != 0.0 || c.centreOfMass.y != 0.0)) offsetBodies_.push_back(index);
    if (c.solverOnly) {
        // in the solver only: no broad phase, no narrow phase
    } else if (c.shape.kind == ShapeKind::Plane) {
        planes_.push_back(index);
    } else {
        finite_.push_back(index);
    }
    // SolverBody 0 is the shared static body.
    if (bodies_.empty()) bodies_.push_back(SolverBody{});
    if (dynamic) {
        solverIndex_.push_back(std::uint32_t(bodies_.size()));
        SolverBody b;
        b.invMass = invMass_.back();
        b.invInertia = invInertia_.back();
        bodies_.push_back(b);
    } else {
        solverIndex_.push_back(0);
    }
}

void CollisionSystem::setMass(std::size_t i, double mass, double inertia) {
    Collider& c = colliders_[i];
    const bool dynamic = c.body >= 0 && (mass > 0.0 || c.kinematic);
    c.mass = mass;
    invMass_[i] = dynamic && !c.kinematic ? 1.0 / mass : 0.0;
    c.inertia = !dynamic || c.kinematic ? 0.0 : c.solverOnly ? inertia : momentOfInertia(c.shape, mass);
    invInertia_[i] = c.inertia > 0.0 ? 1.0 / c.inertia : 0.0;
    if (const std::uint32_t s = solverIndex_[i]; s != 0) {
        bodies_[s].invMass = invMass_[i];
        bodies_[s].invInertia = invInertia_[i];
    }
    for (std::size_t j = i + 1; j < colliders_.size() && colliders_[j].hub == std::int32_t(i); ++j) invMass_[j] = invMass_[i];
}

void CollisionSystem::reshape(std::size_t i, const Collider& fresh, const Filter& filter) {
    Collider& c = colliders_[i];
    const ConvexPolygon* kept = c.shape.kind == ShapeKind::Polygon ? c.shape.polygon : nullptr;
    c.shape = fresh.shape;
    if (fresh.shape.kind == ShapeKind::Polygon) {
        // The outline lives here: over the old one when there was one.
        if (kept) {
            *const_cast<ConvexPolygon*>(kept) = *fresh.shape.polygon;
            c.shape.polygon = kept;
        } else {
            polygons_.push_back(*fresh.shape.polygon);
            c.shape.polygon = &polygons_.back();
        }
    }
    c.friction = fresh.friction;
    c.restitution = fresh.restitution;
    filters_[i] = filter;
    filtered_ = filtered_ || !(filter == Filter{});
    collidableKnown_ = false;
    maxExtent_[i] = shapeReach(c.shape);
    // The sweep's test of a fast body reads the smallest reach it noted
    // when it first ran (one shape: compound bodies are not reshaped).
    if (staticSweepReady_ && c.body >= 0 && !c.solverOnly) minReach_[i] = smallestReach(c.shape);
    setMass(i, c.mass, c.inertia);  // the inertia of the new shape
}

std::uint32_t CollisionSystem::addAll(std::span<const ColliderAdd> list) {
    const std::uint32_t base = std::uint32_t(colliders_.size());
    for (const ColliderAdd& a : list) {
        Collider c = a.collider;
        if (c.hub >= 0) c.hub += std::int32_t(base);
        add(c, a.angle, a.angularVelocity, a.filter);
        if (c.hub >= 0)
            maxExtent_[std::size_t(c.hub)] = std::max(maxExtent_[std::size_t(c.hub)], maxExtent_.back());
    }
    return base;
}

std::unique_ptr<CollisionSystem> CollisionSystem::changed(std::span<const std::uint8_t> dropCollider,
                                                          std::span<const std::uint8_t> dropJoint,
                                                          std::span<const std::int32_t> bodyMap,
                                                          std::span<const ColliderAdd> added,
                                                          std::span<const JointAdd> addedJoints,
                                                          std::span<const std::uint32_t> sceneIndex) const {
    auto next = std::make_unique<CollisionSystem>();
    CollisionSystem& n = *next;
    n.settings_ = settings_;
    n.jointSettings_ = jointSettings_;
    n.autoBroadPhase_ = autoBroadPhase_;
    n.broadPhase_.setKind(broadPhase_.kind());
    n.positionCorrection_ = positionCorrection_;
    n.bodyAsleep_ = bodyAsleep_;
    n.wakeBody_ = wakeBody_;
    const std::size_t oldCount = colliders_.size();
    std::vector<std::int32_t> colliderMap(oldCount, -1);
    // Room for all of them at once: a joint is a large struct, and growing
    // a dozen arrays one push at a time would copy each many times.
    const std::size_t most = oldCount + added.size();
    for (auto* v : {&n.angles_, &n.angularVelocities_, &n.invMass_, &n.invInertia_, &n.maxExtent_}) v->reserve(most);
    n.colliders_.reserve(most);
    n.filters_.reserve(most);
    n.colliderAsleep_.reserve(most);
    n.solverIndex_.reserve(most);
    n.bodies_.reserve(most + 1);
    n.finite_.reserve(most);
    n.awakeSolverColliders_.reserve(most);
    n.joints_.reserve(joints_.size() + addedJoints.size());
    n.noCollide_.reserve(noCollide_.size() + addedJoints.size());
    const auto keep = [&](std::size_t c) {
        Collider copy = colliders_[c];
        if (copy.body >= 0) copy.body = bodyMap[std::size_t(copy.body)];
        if (copy.hub >= 0) copy.hub = colliderMap[std::size_t(copy.hub)];  // kept before its shapes
        colliderMap[c] = std::int32_t(n.colliders_.size());
        n.add(copy, angles_[c], angularVelocities_[c], filters_[c]);
        n.maxExtent_.back() = maxExtent_[c];  // a hub's reach is its shapes'
    };
    // Shapes (and compound bodies' hubs) in their order with the new ones
    // merged in by scene order, then the bodies in the solver only because
    // a joint holds them: World::build's order.
    std::vector<std::int32_t> placed(added.size(), -1);  // each add's collider
    std::size_t nextAdd = 0;
    const auto sceneOf = [&](Entity e) {
        return e.index < sceneIndex.size() ? sceneIndex[e.index] : std::numeric_limits<std::uint32_t>::max();
    };
    const auto addEntity = [&] {  // the colliders of the next added entity
        const Entity e = added[nextAdd].collider.entity;
        for (; nextAdd < added.size() && added[nextAdd].collider.entity == e; ++nextAdd) {
            Collider c = added[nextAdd].collider;
            if (c.hub >= 0) c.hub = placed[std::size_t(c.hub)];  // listed before its shapes
            placed[nextAdd] = std::int32_t(n.colliders_.size());
            n.add(c, added[nextAdd].angle, added[nextAdd].angularVelocity, added[nextAdd].filter);
            if (c.hub >= 0)
                n.maxExtent_[std::size_t(c.hub)] = std::max(n.maxExtent_[std::size_t(c.hub)], n.maxExtent_.back());
        }
    };
    const auto jointOnly = [&](std::size_t c) { return colliders_[c].solverOnly && !isHub(c); };
    for (std::size_t c = 0; c < oldCount; ++c) {
        if (dropCollider[c] || jointOnly(c)) continue;
        while (nextAdd < added.size() && sceneOf(added[nextAdd].collider.entity) < sceneOf(colliders_[c].entity))
            addEntity();
        keep(c);
    }
    while (nextAdd < added.size()) addEntity();
    for (std::size_t c = 0; c < oldCount; ++c)
        if (!dropCollider[c] && jointOnly(c)) keep(c);
    // The joints in scene order too.
    bool anyBroken = false;
    std::size_t nextJoint = 0;
    for (std::size_t k = 0; k < joints_.size(); ++k) {
        if (dropJoint[k]) continue;
        for (; nextJoint < addedJoints.size() && sceneOf(addedJoints[nextJoint].joint.entity) < sceneOf(joints_[k].entity);
             ++nextJoint)
            n.addJointOf(addedJoints[nextJoint], placed);
        anyBroken = anyBroken || joints_[k].broken;
        n.addKeptJoint(joints_[k], colliderMap);
    }
    for (; nextJoint < addedJoints.size(); ++nextJoint) n.addJointOf(addedJoints[nextJoint], placed);
    if (anyBroken) n.jointsBroke();
    n.setWarmStartCache(keptCache(warmStartCache(), colliderMap));
    return next;
}

void CollisionSystem::addKeptJoints(std::span<const joints::JointConstraint> old, std::span<const std::uint8_t> dropJoint,
                                    std::span<const std::int32_t> colliderMap) {
    bool anyBroken = false;
    for (std::size_t k = 0; k < old.size(); ++k) {
        if (dropJoint[k]) continue;
        anyBroken = anyBroken || old[k].broken;
        addKeptJoint(old[k], colliderMap);
    }
    if (anyBroken) jointsBroke();
}

void CollisionSystem::addKeptJoint(joints::JointConstraint j, std::span<const std::int32_t> colliderMap) {
    for (joints::JointEnd* end : {&j.a, &j.b}) {
        if (end->collider < 0) continue;
        end->collider = colliderMap[std::size_t(end->collider)];
        end->solverBody = solverBodyOf(std::size_t(end->collider));
    }
    std::int32_t filter[2] = {-1, -1};
    if (j.noCollideKey != 0) {
        filter[0] = colliderMap[std::size_t(j.noCollideKey >> 32)];
        filter[1] = colliderMap[std::size_t(j.noCollideKey & 0xFFFFFFFFu)];
    }
    j.noCollideKey = 0;
    addJoint(j, filter[0], filter[1], filter[0] < 0 || filter[1] < 0);
}

std::vector<CachedImpulse> CollisionSystem::keptCache(std::vector<CachedImpulse> all,
                                                      std::span<const std::int32_t> colliderMap) {
    // The map keeps the colliders' order, so the cache stays sorted as it was.
    std::size_t out = 0;
    for (const CachedImpulse& c : all) {
        const std::int32_t a = colliderMap[c.colliderA()], b = colliderMap[c.colliderB()];
        if (a < 0 || b < 0) continue;
        all[out++] = {CachedImpulse::makeKey(std::uint32_t(a), std::uint32_t(b), c.feature()), c.normal, c.tangent};
    }
    all.resize(out);
    return all;
}

void CollisionSystem::addJointsOf(std::span<const JointAdd> addedJoints, std::uint32_t base, std::size_t addedCount) {
    std::vector<std::int32_t> placed(addedCount);
    for (std::size_t k = 0; k < addedCount; ++k) placed[k] = std::int32_t(base + k);
    for (const JointAdd& add : addedJoints) addJointOf(add, placed);
}

void CollisionSystem::addJointOf(const JointAdd& add, std::span<const std::int32_t> placed) {
    const auto at = [placed](std::int32_t k) { return k >= 0 ? placed[std::size_t(k)] : -1; };
    joints::JointConstraint j = add.joint;
    for (joints::JointEnd* end : {&j.a, &j.b}) {
        if (end->collider < 0) continue;
        end->collider = at(end->collider);
        end->solverBody = solverBodyOf(std::size_t(end->collider));
    }
    addJoint(j, at(add.filterA), at(add.filterB), add.collideConnected);
}

bool CollisionSystem::appendsAtEnd() const {
    // Such bodies come after every shape (build, changed(), removed() keep
    // that order), so the last collider is one if any is.
    return colliders_.empty() || !colliders_.back().solverOnly || isHub(colliders_.size() - 1);
}

void CollisionSystem::appended(std::span<const ColliderAdd> added, std::span<const JointAdd> addedJoints) {
    const std::uint32_t base = addAll(added);
    addJointsOf(addedJoints, base, added.size());
    forgetLastStep();
    setWarmStartCache(warmStartCache());
}

namespace {

/// Keeps the entries of `values` that `map` sends somewhere (>= 0), in order.
template <class T>
void keepMarked(std::vector<T>& values, std::span<const std::int32_t> map) {
    std::size_t out = 0;
    for (std::size_t i = 0; i < values.size(); ++i)
        if (map[i] >= 0) values[out++] = values[i];
    values.resize(out);
}

/// An ascending list of indices, the dropped taken out and the rest renumbered.
void renumber(std::vector<std::uint32_t>& list, std::span<const std::int32_t> map) {
    std::size_t out = 0;
    for (const std::uint32_t i : list)
        if (map[i] >= 0) list[out++] = std::uint32_t(map[i]);
    list.resize(out);
}

} // namespace

void CollisionSystem::removed(std::span<const std::uint8_t> dropCollider, std::span<const std::uint8_t> dropJoint,
                              std::span<const std::int32_t> bodyMap) {
    const std::size_t oldCount = colliders_.size();
    std::vector<std::int32_t> colliderMap(oldCount, -1);
    std::int32_t kept = 0;
    for (std::size_t c = 0; c < oldCount; ++c)
        if (!dropCollider[c]) colliderMap[c] = kept++;
    // Solver bodies in their order, the static one first, as add() numbers
    // them for the kept colliders.
    std::vector<std::int32_t> solverMap(bodies_.size(), -1);
    if (!bodies_.empty()) solverMap[0] = 0;
    std::int32_t solvers = bodies_.empty() ? 0 : 1;
    for (std::size_t c = 0; c < oldCount; ++c)
        if (colliderMap[c] >= 0 && colliders_[c].hub < 0 && solverIndex_[c] != 0) solverMap[solverIndex_[c]] = solvers++;
    for (std::size_t c = 0; c < oldCount; ++c) {
        if (colliderMap[c] < 0) continue;
        Collider& col = colliders_[c];
        if (col.body >= 0) col.body = bodyMap[std::size_t(col.body)];
        if (col.hub >= 0) col.hub = colliderMap[std::size_t(col.hub)];
        solverIndex_[c] = std::uint32_t(solverMap[solverIndex_[c]]);
    }
    keepMarked(colliders_, colliderMap);
    keepMarked(filters_, colliderMap);
    keepMarked(colliderAsleep_, colliderMap);
    keepMarked(angles_, colliderMap);
    keepMarked(angularVelocities_, colliderMap);
    keepMarked(invMass_, colliderMap);
    keepMarked(invInertia_, colliderMap);
    keepMarked(maxExtent_, colliderMap);
    keepMarked(solverIndex_, colliderMap);
    keepMarked(bodies_, solverMap);
    for (auto* list : {&finite_, &planes_, &offsetBodies_, &shapesOfHubs_, &awakeShapesOfHubs_, &awakeSolverColliders_})
        renumber(*list, colliderMap);
    filtered_ = anyKinematic_ = anySensor_ = collidableKnown_ = false;
    for (std::size_t c = 0; c < colliders_.size(); ++c) {
        filtered_ = filtered_ || !(filters_[c] == Filter{});
        anyKinematic_ = anyKinematic_ || colliders_[c].kinematic;
        anySensor_ = anySensor_ || colliders_[c].sensor;
    }
    // The outlines of the colliders gone stay in the deques (the kept ones'
    // addresses must not move); past half dead they are copied afresh.
    std::size_t livePolygons = 0, liveSegments = 0;
    for (const Collider& c : colliders_) {
        livePolygons += c.shape.kind == ShapeKind::Polygon ? 1 : 0;
        liveSegments += c.shape.kind == ShapeKind::ChainSegment ? 1 : 0;
    }
    if (polygons_.size() > 2 * livePolygons + 16) {
        std::deque<ConvexPolygon> fresh;
        for (Collider& c : colliders_)
            if (c.shape.kind == ShapeKind::Polygon) c.shape.polygon = &fresh.emplace_back(*c.shape.polygon);
        polygons_ = std::move(fresh);
    }
    if (segments_.size() > 2 * liveSegments + 16) {
        std::deque<ChainSegment> fresh;
        for (Collider& c : colliders_)
            if (c.shape.kind == ShapeKind::ChainSegment) c.shape.segment = &fresh.emplace_back(*c.shape.segment);
        segments_ = std::move(fresh);
    }
    // The joints kept, added again in order as changed() adds them.
    std::vector<joints::JointConstraint> oldJoints = std::move(joints_);
    joints_.clear();
    noCollide_.clear();
    breakable_.clear();
    addKeptJoints(oldJoints, dropJoint, colliderMap);
    std::vector<CachedImpulse> cache = keptCache(warmStartCache(), colliderMap);
    forgetLastStep();
    setWarmStartCache(std::move(cache));
}

void CollisionSystem::forgetLastStep() {
    constraints_.clear();
    details_.clear();
    keptConstraints_.clear();
    keptDetails_.clear();
    records_.clear();
    recordsPending_ = false;
    recordsFromKept_ = false;
    detected_ = false;
    turningFrame_ = true;
    staticSweepReady_ = false;
    previousCache_.clear();
    jointImpulsesBefore_.clear();
    jointRecords_.clear();
    sensorOverlaps_.clear();
    sensorEvents_.clear();
    lastH_ = 0.0;
    directJoints_.reset();
    jointOrderReady_ = false;
    jointBundlesReady_ = false;  // its joint indices may be stale
    const BroadPhaseKind kind = broadPhase_.kind();
    broadPhase_ = BroadPhase{};  // the sweep's order kept between steps starts again, as a new system's
    broadPhase_.setKind(kind);
    // Solver bodies keep the motion of their last step: an awake body's is
    // set afresh when the next step begins, and a sleeping one's is never
    // read (its joints report where it rests: poseResting).
}

void CollisionSystem::setWarmStartCache(std::vector<CachedImpulse> cache) {
    if (!std::is_sorted(cache.begin(), cache.end())) std::sort(cache.begin(), cache.end());
    cache_ = std::move(cache);
    cacheCursor_ = 0;
    sleepingCache_.clear();
    if (anySleeping_) splitCache();
}

std::vector<CachedImpulse> CollisionSystem::warmStartCache() const {
    if (sleepingCache_.empty()) return cache_;
    std::vector<CachedImpulse> all(cache_.size() + sleepingCache_.size());
    std::merge(cache_.begin(), cache_.end(), sleepingCache_.begin(), sleepingCache_.end(), all.begin());
    return all;
}

void CollisionSystem::splitCache() {
    std::vector<CachedImpulse> all = warmStartCache();
    cache_.clear();
    sleepingCache_.clear();
    for (const CachedImpulse& e : all)
        (colliderAsleep_[e.colliderA()] || colliderAsleep_[e.colliderB()] ? sleepingCache_ : cache_).push_back(e);
    cacheCursor_ = 0;
}

void CollisionSystem::refreshSleeping(std::span<const Vec2> x) {
    const std::size_t n = colliders_.size();
    anySleeping_ = false;
    for (std::size_t i = 0; i < n; ++i) {
        const std::int32_t body = colliders_[i].body;
        colliderAsleep_[i] = bodyAsleep_ && body >= 0 && (*bodyAsleep_)[std::size_t(body)] ? 1 : 0;
        anySleeping_ = anySleeping_ || colliderAsleep_[i];
    }
    syncShapes();
    awakeSolverColliders_.clear();
    for (std::size_t i = 0; i < n; ++i)
        if (solverIndex_[i] != 0 && !colliderAsleep_[i] && colliders_[i].hub < 0)
            awakeSolverColliders_.push_back(std::uint32_t(i));
    awakeShapesOfHubs_.clear();
    for (const std::uint32_t i : shapesOfHubs_)
        if (!colliderAsleep_[i]) awakeShapesOfHubs_.push_back(i);
    for (joints::JointConstraint& j : joints_)
        j.asleep = j.broken || (j.a.collider >= 0 && colliderAsleep_[std::size_t(j.a.collider)]) ||
                   (j.b.collider >= 0 && colliderAsleep_[std::size_t(j.b.collider)]);
    splitCache();

    // What detect() reads of a collider that does not move: its centre, its
    // rotation, no motion of its own.
    centres_.resize(n);
    rotScratch_.resize(n);
    endV_.resize(n);
    startV_.resize(n);
    spin_.resize(n);
    margins_.resize(n);
    shapeBoxes_.resize(n);
    awakeProxies_.clear();
    std::vector<Aabb> frozenBoxes;
    std::vector<std::uint32_t> frozenProxies;
    for (std::size_t k = 0; k < finite_.size() && anySleeping_; ++k) {
        const std::uint32_t i = finite_[k];
        if (colliders_[i].body >= 0 && !colliderAsleep_[i]) {
            awakeProxies_.push_back(std::uint32_t(k));
            continue;
        }
        // A sleeping body keeps its (small) velocity but does not move:
        // its margin and its pairs' speculative margins count no motion.
        centres_[i] = centreOfMass(i, x);
        rotScratch_[i] = Rot::fromAngle(angles_[i]);
        endV_[i] = startV_[i] = Vec2{};
        spin_[i] = 0.0;
        margins_[i] = kSpeculativeBase;
        Aabb box = shapeBoxes_[i] = computeAabb(colliders_[i].shape, centres_[i], rotScratch_[i]);
        box.lower -= Vec2{kSpeculativeBase, kSpeculativeBase};
        box.upper += Vec2{kSpeculativeBase, kSpeculativeBase};
        frozenBoxes.push_back(box);
        frozenProxies.push_back(std::uint32_t(k));
    }
    if (anySleeping_) frozen_.build(frozenBoxes, frozenProxies);
    else frozen_.clear();

    // The sleeping islands' contacts stay listed (the contacts view, the
    // count, break-on-contact): recomputed once here from the frozen shapes
    // and their kept impulses, then kept at the front of records_.
    if (recordsPending_) makeRecords();
    std::vector<ContactRecord> awakeRecords;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> awakePairs;
    for (std::size_t r = sleepingRecordCount_; r < records_.size(); ++r)
        if (!colliderAsleep_[recordPairs_[r].first] && !colliderAsleep_[recordPairs_[r].second]) {
            awakeRecords.push_back(records_[r]);
            awakePairs.push_back(recordPairs_[r]);
        }
    records_.clear();
    recordPairs_.clear();
    for (std::size_t k = 0; k < sleepingCache_.size();) {
        const std::uint32_t a = sleepingCache_[k].colliderA(), b = sleepingCache_[k].colliderB();
        std::size_t end = k;
        while (end < sleepingCache_.size() && sleepingCache_[end].colliderA() == a && sleepingCache_[end].colliderB() == b)
            ++end;
        const bool planeA = colliders_[a].shape.kind == ShapeKind::Plane;
        const Manifold m = collide(colliders_[a].shape, planeA ? Vec2{} : centreOfMass(a, x),
                                   planeA ? Rot{} : Rot::fromAngle(angles_[a]), colliders_[b].shape,
                                   centreOfMass(b, x), Rot::fromAngle(angles_[b]), 2.0 * kSpeculativeBase);
        for (int p = 0; p < m.pointCount; ++p) {
            double normal = 0.0, tangent = 0.0;
            for (std::size_t e = k; e < end; ++e)
                if ((sleepingCache_[e].key & 0xFFFF) == (m.points[p].id & 0xFFFF)) {
                    normal = sleepingCache_[e].normal;
                    tangent = sleepingCache_[e].tangent;
                    break;
                }
            if (m.points[p].separation > kLinearSlop && normal == 0.0) continue;
            ContactRecord r;
            r.a = colliders_[a].entity;
            r.b = colliders_[b].entity;
            r.point = m.points[p].point;
            r.normal = m.normal;
            if (solverIndex_[a] == 0 && solverIndex_[b] != 0) {
                std::swap(r.a, r.b);
                r.normal = -r.normal;
            }
            r.depth = -m.points[p].separation;
            r.normalImpulse = normal;
            r.tangentImpulse = tangent;
            records_.push_back(r);
            recordPairs_.emplace_back(a, b);
        }
        k = end;
    }
    sleepingRecordCount_ = records_.size();
    records_.insert(records_.end(), awakeRecords.begin(), awakeRecords.end());
    recordPairs_.insert(recordPairs_.end(), awakePairs.begin(), awakePairs.end());
}

void CollisionSystem::bodyEdges(std::vector<std::pair<std::uint32_t, std::uint32_t>>& out) const {
    // Only contacts that touch (a point within the slop, or one that carried
    // load) join islands. A speculative point across a gap does not: a trio
    // of circles rolling along the floor at 1 cm/s, 13 mm from a settled
    // pile, would otherwise keep all 2,000 bodies of the pile awake (the
    // trio never sleeps: it rolls, see islands.hpp); apart, the pile sleeps
    // and the trio wakes it when it comes within reach (sleepingBroadPhase).
    for (std::size_t k = 0; k < details_.size(); ++k) {
        const ContactDetail& d = details_[k];
        const ContactConstraint& c = constraints_[k];
        bool touching = false;
        for (int i = 0; i < c.pointCount; ++i)
            touching = touching || d.separation[i] < kLinearSlop || c.points[i].normalImpulse > 0.0;
        if (!touching) continue;
        // A kinematic body joins no island (as in Box2D): a platform would
        // otherwise tie every pile it touches into one.
        if (anyKinematic_ && (colliders_[d.colliderA].kinematic || colliders_[d.colliderB].kinematic)) continue;
        const std::int32_t a = colliders_[d.colliderA].body, b = colliders_[d.colliderB].body;
        if (a >= 0 && b >= 0) out.emplace_back(std::uint32_t(a), std::uint32_t(b));
    }
    for (const joints::JointConstraint& j : joints_) {
        if (j.broken || j.a.collider < 0 || j.b.collider < 0) continue;
        if (anyKinematic_ &&
            (colliders_[std::size_t(j.a.collider)].kinematic || colliders_[std::size_t(j.b.collider)].kinematic))
            continue;
        const std::int32_t a = colliders_[std::size_t(j.a.collider)].body, b = colliders_[std::size_t(j.b.collider)].body;
        if (a >= 0 && b >= 0) out.emplace_back(std::uint32_t(a), std::uint32_t(b));
    }
}

void CollisionSystem::staticSupports(std::vector<Support>& out, std::vector<std::uint8_t>& held) const {
    const auto fixed = [&](std::uint32_t c) { return colliders_[c].body < 0 || colliders_[c].kinematic; };
    for (std::size_t k = 0; k < details_.size(); ++k) {
        const ContactDetail& d = details_[k];
        const ContactConstraint& c = constraints_[k];
        const bool fixedA = fixed(d.colliderA), fixedB = fixed(d.colliderB);
        if (fixedA == fixedB) continue;
        bool touching = false;
        for (int i = 0; i < c.pointCount; ++i)
            touching = touching || d.separation[i] < kLinearSlop || c.points[i].normalImpulse > 0.0;
        if (!touching) continue;
        // The normal runs from A to B: it pushes B along it and A against it.
        Support s;
        s.body = std::uint32_t(colliders_[fixedA ? d.colliderB : d.colliderA].body);
        s.normal = fixedA ? c.normal : -c.normal;
        s.friction = c.friction;
        s.points = c.pointCount;
        for (int i = 0; i < c.pointCount; ++i) {
            const ContactPoint& p = c.points[i];
            s.along[i] = fixedA ? p.rnB : -p.rnA;
            s.up[i] = fixedA ? p.dnB : -p.dnA;
        }
        out.push_back(s);
    }
    for (const joints::JointConstraint& j : joints_) {
        if (j.broken) continue;
        const bool worldA = j.a.collider < 0 || fixed(std::uint32_t(j.a.collider));
        const bool worldB = j.b.collider < 0 || fixed(std::uint32_t(j.b.collider));
        if (worldA && !worldB) held[std::size_t(colliders_[std::size_t(j.b.collider)].body)] = 1;
        if (worldB && !worldA) held[std::size_t(colliders_[std::size_t(j.a.collider)].body)] = 1;
    }
}

bool CollisionSystem::sleepingBroadPhase(std::span<const Rot> rots, Vec2 ref0, Vec2 ref1) {
    awakeBoxes_.resize(awakeProxies_.size());
    awakeCores_.resize(awakeProxies_.size());
    awakeMovable_.assign(awakeProxies_.size(), 1);
    for (std::size_t j = 0; j < awakeProxies_.size(); ++j) {
        const std::uint32_t i = finite_[awakeProxies_[j]];
        Aabb box = shapeBoxes_[i] = computeAabb(colliders_[i].shape, centres_[i], rots[i]);
        awakeCores_[j] = (box.upper.x - box.lower.x) * (box.upper.y - box.lower.y);
        const Vec2 fat{margins_[i], margins_[i]};
        box.lower -= fat;
        box.upper += fat;
        awakeBoxes_[j] = box;
    }
    if (autoBroadPhase_)
        broadPhase_.setKind(awakeProxies_.size() > 512 ? BroadPhaseKind::UniformGrid : BroadPhaseKind::SweepAndPrune);
    broadPhase_.findPairs(awakeBoxes_, awakeMovable_, awakePairs_, awakeCores_);
    // awakeProxies_ ascends, so the mapped pairs keep (a, b) order.
    pairs_.clear();
    for (const ProxyPair& p : awakePairs_) pairs_.push_back({awakeProxies_[p.a], awakeProxies_[p.b]});
    // In the full broad phase a frozen shape's margin holds its drift from
    // the reference motion, dt |ref|; here the awake box carries it.
    const double refDrift = dt_ * std::max(length(ref0), length(ref1));
    const std::size_t awakeAwake = pairs_.size();
    for (std::size_t j = 0; j < awakeProxies_.size(); ++j) {
        Aabb box = awakeBoxes_[j];
        box.lower -= Vec2{refDrift, refDrift};
        box.upper += Vec2{refDrift, refDrift};
        const std::uint32_t k = awakeProxies_[j];
        frozen_.query(box, [&](std::uint32_t f) { pairs_.push_back({std::min(k, f), std::max(k, f)}); });
    }
    if (pairs_.size() != awakeAwake) std::sort(pairs_.begin(), pairs_.end());
    crowdBodies_.clear();
    const std::span<const std::uint8_t> crowded = broadPhase_.crowded();
    for (std::size_t j = 0; j < crowded.size(); ++j)
        if (crowded[j]) crowdBodies_.push_back(solverIndex_[finite_[awakeProxies_[j]]]);

    // An awake shape with a manifold against a sleeping one wakes its island.
    std::vector<std::uint32_t> woken;
    for (const ProxyPair& pair : pairs_) {
        const std::uint32_t a = finite_[pair.a], b = finite_[pair.b];
        if (!colliderAsleep_[a] && !colliderAsleep_[b]) continue;
        if (colliders_[a].sensor || colliders_[b].sensor) continue;  // a sensor wakes nothing
        if (!collides(a, b)) continue;
        if (!noCollide_.empty() && joinedNotColliding(a, b)) continue;
        const double closing = closingSpeed(a, b);
        // Within reach this step: the gap the two can close in dt (the
        // speeds at both ends of the step, forces included, and the spin)
        // plus the slop. Farther, the awake shape cannot touch the sleeping
        // one before the next step looks again; a wider margin would let a
        // body resting or rolling a few millimetres away keep waking a pile.
        const Manifold m = collide(colliders_[a].shape, centres_[a], rots[a], colliders_[b].shape, centres_[b], rots[b],
                                   kLinearSlop + dt_ * closing + spin_[a] + spin_[b]);
        if (m.pointCount > 0) woken.push_back(std::uint32_t(colliders_[colliderAsleep_[a] ? a : b].body));
    }
    if (woken.empty()) return true;
    for (const std::uint32_t body : woken) wakeBody_(body);
    return false;
}

bool CollisionSystem::nothingCanCollide() {
    if (collidableKnown_) return nothingCollides_;
    collidableKnown_ = true;
    nothingCollides_ = false;
    // Sensors sense what their filter lets through, and with no filter
    // every pair may collide.
    if (anySensor_ || !filtered_) return false;
    // The distinct filters of the shapes in the broad phase and the planes,
    // and whether each is held by two or more: a level has a handful.
    constexpr std::size_t kFewFilters = 16;
    std::vector<std::pair<Filter, std::size_t>> distinct;
    for (const std::vector<std::uint32_t>* list : {&finite_, &planes_})
        for (const std::uint32_t c : *list) {
            const Filter& f = filters_[c];
            const auto same = std::find_if(distinct.begin(), distinct.end(), [&](const auto& d) { return d.first == f; });
            if (same != distinct.end()) {
                ++same->second;
            } else if (distinct.size() == kFewFilters) {
                return false;  // many kinds of shape: not worth finding out
            } else {
                distinct.emplace_back(f, 1);
            }
        }
    for (std::size_t i = 0; i < distinct.size(); ++i)
        for (std::size_t j = i; j < distinct.size(); ++j)
            if ((j != i || distinct[i].second > 1) && shouldCollide(distinct[i].first, distinct[j].first)) return false;
    nothingCollides_ = true;
    return true;
}

bool CollisionSystem::joinedNotColliding(std::uint32_t a, std::uint32_t b) const {
    // Joints name a body's first collider: a moving compound body's hub; a
    // static compound body's first shape, which its others follow in order;
    // a chain's first segment, which its others follow in order.
    const auto first = [&](std::uint32_t c) {
        const Collider& col = colliders_[c];
        if (col.hub >= 0) return std::uint32_t(col.hub);
        return col.shape.kind == ShapeKind::ChainSegment ? c - col.shape.segment->index : c - col.part;
    };
    const std::uint32_t fa = first(a), fb = first(b);
    const std::uint64_t key = (std::uint64_t(std::min(fa, fb)) << 32) | std::max(fa, fb);
    return std::binary_search(noCollide_.begin(), noCollide_.end(), key);
}

void CollisionSystem::addJoint(const joints::JointConstraint& joint, std::int32_t filterA, std::int32_t filterB,
                               bool collideConnected) {
    if (bodies_.empty()) bodies_.push_back(SolverBody{});
    joints::JointConstraint& j = joints_.emplace_back(joint);
    directJoints_.reset();
    jointOrderReady_ = false;
    jointBundlesReady_ = false;  // its joint indices may be stale
    if (j.maxForce > 0.0) breakable_.push_back(std::uint32_t(joints_.size() - 1));
    if (!collideConnected && filterA >= 0 && filterB >= 0) {
        const auto lo = std::uint64_t(std::min(filterA, filterB)), hi = std::uint64_t(std::max(filterA, filterB));
        const std::uint64_t key = (lo << 32) | hi;
        j.noCollideKey = key;
        noCollide_.insert(std::lower_bound(noCollide_.begin(), noCollide_.end(), key), key);
    }
}

void CollisionSystem::breakJoints(std::vector<std::pair<std::uint32_t, double>>& out) {
    // The joints past their max_force, most past it (force / max_force) first.
    breakCandidates_.clear();
    for (const std::uint32_t k : breakable_) {
        const joints::JointConstraint& j = joints_[k];
        if (j.asleep) continue;  // broken already, or asleep: nothing pulls harder than before
        const double force = length(joints::jointForce(j, lastH_));
        // Not (force <= maxForce): a non-finite force breaks the joint too.
        if (!(force > j.maxForce)) continue;
        breakCandidates_.push_back({k, force, std::isfinite(force) ? force / j.maxForce : std::numeric_limits<double>::infinity()});
    }
    if (breakCandidates_.empty()) return;
    std::stable_sort(breakCandidates_.begin(), breakCandidates_.end(),
                     [](const BreakCandidate& a, const BreakCandidate& b) { return a.excess > b.excess; });
    // One break per step in each piece that joints hold together: the
    // forces of a step were all found with every joint whole, and the first
    // to fail unloads the rest. A 300 kg crate landing on a chain of pins
    // pulled 14 kN through every one of them in the step it landed, and all
    // fourteen broke at once, where the weak middle pin alone gives way and
    // the halves swing free.
    std::vector<std::uint32_t> piece(bodies_.size());
    std::iota(piece.begin(), piece.end(), 0u);
    const auto find = [&](std::uint32_t b) {
        while (piece[b] != b) b = piece[b] = piece[piece[b]];
        return b;
    };
    for (const joints::JointConstraint& j : joints_)
        if (!j.broken && j.a.solverBody != 0 && j.b.solverBody != 0)
            piece[find(j.a.solverBody)] = find(j.b.solverBody);
    std::vector<std::uint8_t> pieceBroke(bodies_.size(), 0);
    for (const BreakCandidate& candidate : breakCandidates_) {
        joints::JointConstraint& j = joints_[candidate.joint];
        const std::uint32_t root = find(j.a.solverBody != 0 ? j.a.solverBody : j.b.solverBody);
        if (pieceBroke[root]) continue;
        pieceBroke[root] = 1;
        j.broken = true;
        j.asleep = true;
        // All +0: the joint carries nothing, so a save lists no entry for it
        // and a restore of a later state has nothing to warm.
        joints::setImpulses(j, JointImpulse{j.entity});
        out.emplace_back(candidate.joint, candidate.force);
    }
    // In joint order, as the step's breaks are reported.
    std::sort(out.begin(), out.end());
    jointsBroke();
}

void CollisionSystem::setBrokenJoints(std::span<const Entity> broken) {
    bool changed = false;
    for (joints::JointConstraint& j : joints_) {
        const bool b = std::find(broken.begin(), broken.end(), j.entity) != broken.end();
        if (b == j.broken) continue;
        changed = true;
        j.broken = b;
        // Whole again: awake until the sleep state (set after this) says otherwise.
        j.asleep = b;
    }
    if (changed) jointsBroke();
}

void CollisionSystem::jointsBroke() {
    // The no-collide list as the joints still whole would build it (a
    // sorted multiset: two joints may keep the same pair apart), so the
    // broken joint's bodies collide from the next step on, as in a world
    // built from the scene without it.
    noCollide_.clear();
    for (const joints::JointConstraint& j : joints_)
        if (!j.broken && j.noCollideKey != 0) noCollide_.push_back(j.noCollideKey);
    std::sort(noCollide_.begin(), noCollide_.end());
    directJoints_.reset();
    jointOrderReady_ = false;
    jointBundlesReady_ = false;  // its joint indices may be stale
}

void CollisionSystem::addManifold(std::uint32_t a, std::uint32_t b, const Manifold& m,
                                  std::span<const Vec2> centres) {
    if (m.pointCount == 0) return;
    // Built in place (detect() reserved room for every manifold): a copy of
    // both would double the bytes written per manifold.
    ContactConstraint& c = constraints_.emplace_back();
    ContactDetail& detail = details_.emplace_back();
    detail.colliderA = a;
    detail.colliderB = b;
    detail.restitution = std::max(colliders_[a].restitution, colliders_[b].restitution);
    c.bodyA = solverIndex_[a];
    c.bodyB = solverIndex_[b];
    // A kinematic side counts as static (Box2D's rule: zero inverse mass).
    // (The flag is read first: a collider's kinematic bit is on another
    // cache line than what the narrow phase has read of it.)
    c.touchesStatic = c.bodyA == 0 || c.bodyB == 0 || (anyKinematic_ && (colliders_[a].kinematic || colliders_[b].kinematic));
    // A circle turns under its contact point only about its own centre: not
    // a compound body's circle, which turns about the body's.
    c.roundA = colliders_[a].shape.kind == ShapeKind::Circle && colliders_[a].hub < 0;
    c.roundB = colliders_[b].shape.kind == ShapeKind::Circle && colliders_[b].hub < 0;
    // Lever arms from the body's centre of mass: a compound shape's hub's.
    const Vec2 centreA = colliders_[a].hub >= 0 ? centres[std::size_t(colliders_[a].hub)] : centres[a];
    const Vec2 centreB = colliders_[b].hub >= 0 ? centres[std::size_t(colliders_[b].hub)] : centres[b];
    c.normal = m.normal;
    c.friction = std::sqrt(colliders_[a].friction * colliders_[b].friction);
    c.pointCount = m.pointCount;
    for (int i = 0; i < m.pointCount; ++i) {
        ContactPoint& p = c.points[i];
        detail.point[i] = m.points[i].point;
        detail.separation[i] = m.points[i].separation;
        detail.id[i] = m.points[i].id;
        // Planes have no centre: their anchor is the point itself, which is
        // fine because a plane never moves or turns.
        const Vec2 anchorA = colliders_[a].shape.kind == ShapeKind::Plane ? Vec2{} : detail.point[i] - centreA;
        const Vec2 anchorB = colliders_[b].shape.kind == ShapeKind::Plane ? Vec2{} : detail.point[i] - centreB;
        p.rnA = cross(anchorA, m.normal);
        p.rnB = cross(anchorB, m.normal);
        p.dnA = dot(anchorA, m.normal);
        p.dnB = dot(anchorB, m.normal);
    }
    contactPairs_.add(c);
    // Noted here, where the separations are at hand, rather than by a pass
    // over every contact (addDeepOverlapsToCrowd).
    if (!c.touchesStatic) {
        double deepest = m.points[0].separation;
        if (m.pointCount == 2) deepest = std::min(deepest, m.points[1].separation);
        if (deepest < -0.25 * std::min(maxExtent_[a], maxExtent_[b]))
            deepContacts_.push_back(std::uint32_t(constraints_.size() - 1));
    }
    if (settings_.warmStart && !cache_.empty()) {
        // The cache is sorted by key, and pairs arrive sorted by (a, b), so
        // the search for this pair starts where the last pair's ended (a
        // plane's pairs, out of that order, search from the start): one
        // short search per manifold instead of a full one per point.
        const std::uint64_t pairKey = (std::uint64_t(a) << 40) | (std::uint64_t(b) << 16);
        const auto from = cacheCursor_ < cache_.size() && cache_[cacheCursor_].key <= pairKey
                              ? cache_.begin() + std::ptrdiff_t(cacheCursor_)
                              : cache_.begin();
        // Usually a few entries on: step there, and search only past that.
        auto it = from;
        for (int step = 0; step < 8 && it != cache_.end() && it->key < pairKey; ++step) ++it;
        if (it != cache_.end() && it->key < pairKey) it = std::lower_bound(it, cache_.end(), CachedImpulse{pairKey, 0, 0});
        cacheCursor_ = std::size_t(it - cache_.begin());
        bool found[2] = {false, false};  // the first entry of a key counts, as lower_bound finds it
        for (; it != cache_.end() && (it->key >> 16) == (pairKey >> 16); ++it) {
            for (int i = 0; i < m.pointCount; ++i) {
                if (found[i] || (it->key & 0xFFFF) != (detail.id[i] & 0xFFFF)) continue;
                found[i] = true;
                c.points[i].normalImpulse = it->normal;
                c.points[i].tangentImpulse = it->tangent;
            }
        }
    }
}

void CollisionSystem::beginStep(std::span<const Vec2> x, std::span<const Vec2> v, double dt, int substeps) {
    // The last step's manifolds, whose records nobody has asked for yet, are
    // kept aside for contacts(): this step's detection refills the arrays
    // (and if it diverges, the records stay those of the last whole step).
    if (recordsPending_ && !recordsFromKept_) {
        keptConstraints_.swap(constraints_);
        keptDetails_.swap(details_);
        recordsFromKept_ = true;
    }
    dt_ = dt;
    substeps_ = substeps;
    substepsDone_ = 0;
    detected_ = false;
    jointBundlesReady_ = false;
    stepStartX_ = x;
    timings_ = {};
    syncShapes();
    const std::size_t n = colliders_.size();
    centres_.resize(n);
    stepStart_.resize(n);
    startV_.resize(n);
    stepStartAngle_.assign(angles_.begin(), angles_.end());
    for (std::size_t i = 0; i < n; ++i) {
        const Collider& c = colliders_[i];
        centres_[i] = centreOfMass(i, x);
        stepStart_[i] = centres_[i];
        startV_[i] = c.body >= 0 && !colliderAsleep_[i] ? v[std::size_t(c.body)] : Vec2{};  // asleep: not moving
    }
    jointImpulsesBefore_.resize(joints_.size());
    for (std::size_t k = 0; k < joints_.size(); ++k) jointImpulsesBefore_[k] = joints::impulsesOf(joints_[k]);
    // Solver bodies start the step where they are: no displacement yet.
    for (std::size_t i = 0; i < n; ++i) {
        const std::uint32_t s = solverIndex_[i];
        if (s == 0) continue;
        bodies_[s].dp = {};
        bodies_[s].dq = {};
    }
}

bool CollisionSystem::canTouch(std::size_t a, std::size_t b) const {
    // a's box swept by its motion relative to b (linear in time, as in
    // sweptGrowth), grown all round by both shapes' reach (the slop and their
    // spin), against b's box: the same whichever frame the broad phase grew
    // its boxes in. A hair under the boxes' growth, whose sums round
    // differently.
    const Vec2 r0 = startV_[a] - startV_[b], r1 = endV_[a] - endV_[b];
    const double around = (2.0 * kSpeculativeBase + spin_[a] + spin_[b]) * (1.0 - 1e-6);
    const double dt = dt_;
    const Aabb& boxA = shapeBoxes_[a];
    const Aabb& boxB = shapeBoxes_[b];
    const double lowX = boxA.lower.x - around + dt * std::min(0.0, std::min(r0.x, r1.x));
    const double highX = boxA.upper.x + around + dt * std::max(0.0, std::max(r0.x, r1.x));
    const double lowY = boxA.lower.y - around + dt * std::min(0.0, std::min(r0.y, r1.y));
    const double highY = boxA.upper.y + around + dt * std::max(0.0, std::max(r0.y, r1.y));
    return lowX <= boxB.upper.x && boxB.lower.x <= highX && lowY <= boxB.upper.y && boxB.lower.y <= highY;
}

std::vector<std::pair<std::uint32_t, std::uint32_t>> CollisionSystem::candidateColliderPairs() const {
    std::vector<std::pair<std::uint32_t, std::uint32_t>> out;
    out.reserve(pairs_.size());
    for (const ProxyPair& p : pairs_) out.emplace_back(finite_[p.a], finite_[p.b]);
    return out;
}

double CollisionSystem::closingSpeed(std::size_t a, std::size_t b) const {
    // Relative speed is convex in time under constant acceleration, so the
    // larger of the two ends bounds it over the step. sqrt is monotonic and
    // correctly rounded: the root of the larger square is the larger root.
    return std::sqrt(std::max(lengthSquared(startV_[a] - startV_[b]), lengthSquared(endV_[a] - endV_[b])));
}

namespace {
/// How far a box grows below (`low`) and above (`high`) its shape on each
/// axis over a step of dt, for a body whose velocity against the broad
/// phase's frame is w0 at the step's start and w1 at its end (`drift`: the
/// larger length); `around` grows it all round, and the lot is widened for
/// a turning frame.
inline void sweptGrowth(double dt, Vec2 w0, Vec2 w1, double drift, double around, double widen, Vec2& low,
                        Vec2& high) {
    // The velocity against the frame is linear in time over the step
    // (constant acceleration), so on each axis the displacement lies between
    // 0 and dt times the least and the greatest of w0 and w1: the box grows
    // that way only. The rest grows all round: `around` and what widening
    // adds to the symmetric margin (rotatingFrameMargins), (widen - 1) dt
    // drift, which covers the turn of the frame across the gap.
    const double all = around * widen + (widen - 1.0) * (dt * drift);
    low = {all + dt * std::max(0.0, -std::min(w0.x, w1.x)), all + dt * std::max(0.0, -std::min(w0.y, w1.y))};
    high = {all + dt * std::max(0.0, std::max(w0.x, w1.x)), all + dt * std::max(0.0, std::max(w0.y, w1.y))};
}
} // namespace

void CollisionSystem::rotatingFrameMargins(Vec2 ref0, Vec2 ref1, double meanFrameSum) {
    // A pile swept round a drum moves at tens of m/s in any translating
    // frame, though neighbours barely move against each other: in the mean
    // frame its boxes grow by most of a body each and every body pairs with
    // dozens. Fitted to the bodies' motion, a frame that also turns at
    // omega (least squares, about their centroid c) takes the circulation
    // out of the drifts. A pair's relative velocity is then at most its two
    // drifts plus |omega| |x_a - x_b|, and |x_a - x_b| is at most the gap g
    // plus both reaches e; so margins
    //   (slop + dt drift + dt |omega| e + spin) / (1 - dt |omega|)
    // add up to at least the pair's speculative margin whenever g is within
    // it, and every pair that can touch this step still has overlapping
    // boxes. Of the drift, only its way on each axis is needed (sweptGrowth);
    // the rest of the margin grows all round. The frame is kept only where
    // its growth adds up to less than the mean frame's.
    Vec2 centroid{};
    std::size_t moving = 0;
    for (std::size_t i = 0; i < colliders_.size(); ++i) {
        if (solverIndex_[i] == 0) continue;
        centroid += centres_[i];
        ++moving;
    }
    centroid = centroid / double(moving);
    double moment = 0.0, turn0 = 0.0, turn1 = 0.0;
    for (std::size_t i = 0; i < colliders_.size(); ++i) {
        if (solverIndex_[i] == 0) continue;
        const Vec2 r = centres_[i] - centroid;
        moment += lengthSquared(r);
        turn0 += cross(r, startV_[i] - ref0);
        turn1 += cross(r, endV_[i] - ref1);
    }
    if (!(moment > 0.0)) return;
    const double omega0 = turn0 / moment, omega1 = turn1 / moment;
    const double sweep = dt_ * std::max(std::abs(omega0), std::abs(omega1));
    // dt |omega| is the angle the frame turns in a step; as it nears one
    // radian the divisor 1 - dt |omega| grows without limit.
    if (!(sweep > 0.0 && sweep <= 0.25)) return;
    const double widen = 1.0 / (1.0 - sweep);
    rotatedLow_.resize(colliders_.size());
    rotatedHigh_.resize(colliders_.size());
    double sum = 0.0;
    for (std::size_t i = 0; i < colliders_.size(); ++i) {
        const Vec2 r = centres_[i] - centroid;
        const Vec2 u0 = ref0 + Vec2{-omega0 * r.y, omega0 * r.x}, u1 = ref1 + Vec2{-omega1 * r.y, omega1 * r.x};
        const Vec2 w0 = startV_[i] - u0, w1 = endV_[i] - u1;
        const double drift = std::sqrt(std::max(lengthSquared(w0), lengthSquared(w1)));
        sweptGrowth(dt_, w0, w1, drift, kSpeculativeBase + sweep * maxExtent_[i] + spin_[i], widen,
                    rotatedLow_[i], rotatedHigh_[i]);
        sum += (rotatedLow_[i].x + rotatedLow_[i].y) + (rotatedHigh_[i].x + rotatedHigh_[i].y);
    }
    if (sum < meanFrameSum) {
        growLow_.swap(rotatedLow_);
        growHigh_.swap(rotatedHigh_);
    }
}

void CollisionSystem::detect(std::span<const Vec2> firstSubstepV, double h) {
    const auto start = std::chrono::steady_clock::now();
    const std::size_t n = colliders_.size();
    const double dt = dt_;
    // While islands sleep, only the awake colliders are visited; the frozen
    // ones' motion, margins and rotations were set by refreshSleeping. With
    // none asleep every collider is visited, in the same order.
    const auto forEachActive = [&](auto&& visit) {
        if (anySleeping_) {
            for (const std::uint32_t i : awakeSolverColliders_) visit(std::size_t(i));
            for (const std::uint32_t i : awakeShapesOfHubs_) visit(std::size_t(i));
        } else {
            for (std::size_t i = 0; i < n; ++i) visit(i);
        }
    };
  for (;;) {  // once, or again after an awake shape woke a sleeping island
    // The motion within the step, not only at its start: the velocity after
    // the first substep's forces, extrapolated to the end of the step as a
    // constant acceleration (v0 + substeps (v1 - v0)). A body at rest pulled
    // by a stiff spring or strong gravity gets its speculative margin from
    // the force, so it cannot pass a thin wall in its first step. Relative
    // speed is convex in time under constant acceleration, so the larger of
    // the two ends bounds it over the whole step.
    endV_.resize(n);
    forEachActive([&](std::size_t i) {
        const Collider& c = colliders_[i];
        endV_[i] = c.body >= 0 ? startV_[i] + double(substeps_) * (firstSubstepV[std::size_t(c.body)] - startV_[i])
                               : Vec2{};
    });
    // Broad phase in a frame moving with the bodies' mean velocity (at both
    // ends of the step): what matters for contact is relative motion, so a
    // crowd moving together (or falling together) is fattened as if at rest
    // and costs what it costs at rest. Each box grows the way its body moves
    // in that frame, by as far (sweptGrowth); any pair that can touch this
    // step then has overlapping boxes (canTouch), since its relative motion
    // is the difference of the two motions in the frame.
    Vec2 ref0{}, ref1{};
    std::size_t moving = 0;
    forEachActive([&](std::size_t i) {
        if (solverIndex_[i] == 0) return;
        ref0 += startV_[i];
        ref1 += endV_[i];
        ++moving;
    });
    if (moving > 0) {
        ref0 = ref0 / double(moving);
        ref1 = ref1 / double(moving);
    }
    margins_.resize(n);
    spin_.resize(n);
    shapeBoxes_.resize(n);
    growLow_.resize(n);
    growHigh_.resize(n);
    double meanFrameSum = 0.0;
    forEachActive([&](std::size_t i) {
        // How far any point of the shape can swing about its centre (m).
        spin_[i] = dt * std::abs(angularVelocities_[i]) * maxExtent_[i];
        const Vec2 w0 = startV_[i] - ref0, w1 = endV_[i] - ref1;
        if (anySleeping_) {
            // sleepingBroadPhase grows boxes all round. sqrt is monotonic and
            // correctly rounded: the root of the larger square is the larger
            // root, one square root instead of two.
            const double drift = std::sqrt(std::max(lengthSquared(w0), lengthSquared(w1)));
            margins_[i] = kSpeculativeBase + dt * drift + spin_[i];
            return;
        }
        // The mean frame does not turn: no widening, so no drift's length.
        sweptGrowth(dt, w0, w1, 0.0, kSpeculativeBase + spin_[i], 1.0, growLow_[i], growHigh_[i]);
        meanFrameSum += (growLow_[i].x + growLow_[i].y) + (growHigh_[i].x + growHigh_[i].y);
    });
    if (turningFrame_ && !anySleeping_ && moving > 1) rotatingFrameMargins(ref0, ref1, meanFrameSum);

    // One sincos per collider per step, shared by the boxes and the narrow phase.
    std::vector<Rot>& rots = rotScratch_;
    rots.resize(n);
    // Circles and planes never read theirs (narrow phase, boxes): no sincos
    // for them.
    forEachActive([&](std::size_t i) {
        const ShapeKind kind = colliders_[i].shape.kind;
        rots[i] = kind == ShapeKind::Circle || kind == ShapeKind::Plane ? Rot{} : Rot::fromAngle(angles_[i]);
    });

    if (nothingCanCollide()) {
        // No pair could make a contact: no boxes, no pairs (and no crowd).
        pairs_.clear();
        crowdBodies_.clear();
    } else if (anySleeping_) {
        if (!sleepingBroadPhase(rots, ref0, ref1)) {
            refreshSleeping(stepStartX_);  // the woken island's shapes join the awake ones
            continue;
        }
    } else {
    boxes_.resize(finite_.size());
    cores_.resize(finite_.size());
    movable_.resize(finite_.size());
    for (std::size_t k = 0; k < finite_.size(); ++k) {
        const std::uint32_t i = finite_[k];
        Aabb box = shapeBoxes_[i] = computeAabb(colliders_[i].shape, centres_[i], rots[i]);
        cores_[k] = (box.upper.x - box.lower.x) * (box.upper.y - box.lower.y);
        box.lower -= growLow_[i];
        box.upper += growHigh_[i];
        boxes_[k] = box;
        movable_[k] = colliders_[i].body >= 0 ? 1 : 0;
    }
    // Strategy by size (docs/measured/collisions.md): per call, sweep and prune wins
    // on a few hundred bodies (pyramid: 5 vs 9 us) and the uniform grid on a
    // dense 2,000-circle pile (490 vs 580 us); over whole runs the two are
    // within noise, since pairs cost far less than the contact solve. Both
    // return the same sorted pairs, so the choice never changes a result.
    if (autoBroadPhase_)
        broadPhase_.setKind(finite_.size() > 512 ? BroadPhaseKind::UniformGrid : BroadPhaseKind::SweepAndPrune);
    broadPhase_.findPairs(boxes_, movable_, pairs_, cores_);
    crowdBodies_.clear();
    const std::span<const std::uint8_t> crowded = broadPhase_.crowded();
    for (std::size_t k = 0; k < crowded.size(); ++k)
        if (crowded[k] && solverIndex_[finite_[k]] != 0) crowdBodies_.push_back(solverIndex_[finite_[k]]);
    }
    break;
  }
    timings_.broadPhaseMs = msSince(start);

    const std::vector<Rot>& rots = rotScratch_;
    const auto narrowStart = std::chrono::steady_clock::now();
    constraints_.clear();
    details_.clear();
    contactPairs_.clear(bodies_.size());
    deepContacts_.clear();
    sensorCandidates_.clear();
    // At most one manifold a pair (and a plane against each movable shape):
    // reserving once avoids the copies and the doubled capacity of growth
    // (a crowd of 100,000 makes hundreds of thousands of manifolds).
    // Grown by half again when short: reserving the exact count let a pile
    // whose pair count creeps up reallocate (and fault in fresh pages for)
    // both arrays on most steps.
    const std::size_t most = pairs_.size() + planes_.size() * finite_.size();
    if (most > constraints_.capacity()) {
        const std::size_t room = std::max(most, constraints_.capacity() + constraints_.capacity() / 2);
        constraints_.reserve(room);
        details_.reserve(room);
    }
    cacheCursor_ = 0;
    // The speculative margin of a pair: how far its gap can close this
    // step, from the two bodies' relative velocity (at either end of the
    // step) and their spin.
    const auto pairMargin = [&](std::uint32_t a, std::uint32_t b) {
        const double closing = closingSpeed(a, b);
        return 2.0 * kSpeculativeBase + dt * closing + spin_[a] + spin_[b];
    };
    for (const ProxyPair& pair : pairs_) {
        const std::uint32_t a = finite_[pair.a], b = finite_[pair.b];
        if (colliderAsleep_[a] || colliderAsleep_[b]) continue;  // no manifold: it would have woken them
        // Shapes of one body never touch each other (nor sense each other).
        if (!shapesOfHubs_.empty() && sameBody(a, b)) continue;
        if (anySensor_ && sensedInstead(a, b)) continue;
        if (!collides(a, b)) continue;
        // Bodies joined with collide_connected false do not collide.
        if (!noCollide_.empty() && joinedNotColliding(a, b)) continue;
        const Shape& shapeA = colliders_[a].shape;
        const Shape& shapeB = colliders_[b].shape;
        if (shapeA.kind == ShapeKind::Circle && shapeB.kind == ShapeKind::Circle) {
            // Two circles: the margin only decides whether the pair is in
            // reach. Every margin is at least 2 kSpeculativeBase, and a sum of
            // non-negative terms never rounds below a smaller one, so a pair
            // within that reach is within its own: its two square roots
            // (pairMargin) are skipped. collideCircles' test, same bits.
            const double closest = shapeA.radius + shapeB.radius + 2.0 * kSpeculativeBase;
            const double margin = lengthSquared(centres_[b] - centres_[a]) <= closest * closest
                                      ? 2.0 * kSpeculativeBase
                                      : pairMargin(a, b);
            Manifold m = collideCircles(shapeA.radius, centres_[a], shapeB.radius, centres_[b], margin);
            if (m.pointCount == 1 && centres_[a] == centres_[b]) m.normal = coincidentNormal(a, b);
            addManifold(a, b, m, centres_);
            continue;
        }
        const double margin = pairMargin(a, b);
        // Each shape lies within its reach of its centre, so shapes whose
        // reach circles are farther apart than the margin cannot make a
        // point: most of a fast pile's pairs, whose boxes the motion
        // fattened (the spinner: four in five), are passed over without the
        // narrow phase. The slack covers the rounding of the three terms.
        // (A chain segment's separation is not measured from a centre.)
        if (shapeA.kind != ShapeKind::ChainSegment && shapeB.kind != ShapeKind::ChainSegment) {
            const double apart = length(centres_[b] - centres_[a]) - maxExtent_[a] - maxExtent_[b];
            if (apart - 1e-9 * (apart + 2.0 * (maxExtent_[a] + maxExtent_[b])) > margin) continue;
        }
        const Manifold m = collide(shapeA, centres_[a], rots[a], shapeB, centres_[b], rots[b], margin);
        addManifold(a, b, m, centres_);
    }
    // Planes against every movable finite shape: planes are few and infinite,
    // so they stay out of the broad phase.
    for (const std::uint32_t p : planes_) {
        for (std::size_t k = 0, count = anySleeping_ ? awakeProxies_.size() : finite_.size(); k < count; ++k) {
            const std::uint32_t b = finite_[anySleeping_ ? awakeProxies_[k] : k];
            if (colliders_[b].body < 0 || (anyKinematic_ && colliders_[b].kinematic)) continue;
            if (anySensor_ && sensedInstead(p, b)) continue;
            if (!collides(p, b)) continue;
            const Manifold m = collide(colliders_[p].shape, {}, {}, colliders_[b].shape, centres_[b], rots[b],
                                       pairMargin(p, b));
            addManifold(p, b, m, centres_);
        }
    }
    addDeepOverlapsToCrowd();
    if (!joints_.empty()) {
        joints::prepareJoints(joints_, bodies_, centres_, angles_);
        // The joints' geometric stiffness, from the last step's impulses at
        // this step's anchors: once a step (it changes slowly, and a pass
        // over every joint each substep costs as much as a Gauss-Seidel
        // pass). Before the contacts are prepared, so their masses and every
        // pass see the inertia the joints see: a contact's impulse is then
        // applied with the inertia it was computed with, whichever path
        // solves it (the SIMD bundles copy the inertias here).
        joints::stiffenRotation(joints_, bodies_, h, stiffened_, stiffenScratch_);
    }
    impactScratch_.startStep();
    // Contacts of loose bodies on an exactly solved group are solved with
    // the group (tree_contacts.hpp), not in the colours.
    bool treeContacts = false;
    if (!joints_.empty()) {
        directJoints_.ensureBuilt(joints_, bodies_);
        treeContacts = directJoints_.directJointCount() > 0 &&
                       treeContacts_.select(constraints_, directJoints_, bodies_, inCrowd_, heldOut_);
    }
    if (!treeContacts) treeContacts_.clear();
    // The colouring prepares the contacts (their masses, from the inertia
    // the joints' stiffening set above) and bounds their warm start.
    ColouredContacts::Preparation preparation{details_, std::nullopt};
    if (settings_.warmStart && !cache_.empty()) preparation.warmStartBound = warmStartBound(firstSubstepV);
    coloured_.build(constraints_, preparation, contactPairs_, bodies_, settings_.simd,
                    treeContacts ? std::span<const std::uint8_t>(heldOut_) : std::span<const std::uint8_t>{});
    timings_.narrowPhaseMs = msSince(narrowStart);
}

// The warm start is last substep's impulse, applied before this substep's
// passes check it. An impulse far past what the step needs (a hand-edited
// solver_state) is not taken back by them: a soft contact removes only part
// of the excess per pass, and a body between two contacts hands it back and
// forth, so the rest leaves as motion and throws the bodies it warms. What a
// contact point can need in one substep is what passes through it: the
// momentum of every awake body coming at it (linear, spin at its contacts'
// lever arms, and what a kinematic body drives it at), a substep of every
// external force (gravity, springs, attractors, drag: the first substep's
// velocity change), the overlap push (pushMaxVelocity), and what the joints
// carried last step. A contact carries a share of that sum (the bottom of a
// stack holds the weight of the whole column, more than its two bodies), so
// kWarmStartMargin times it leaves a run's own impulses alone. A wedge, or
// a body squeezed between static and kinematic sides, can press a contact
// harder than the sum; there the bound replaces part of the warm start, the
// same way in a straight run and a resumed one, so a resume stays exact.
// Straight and resumed runs are bounded alike, so a saved state still
// resumes bit for bit; a run's own impulses are within the bound and
// already non-negative with friction within the cone (the solve clamps
// them so), so they keep their bits.
double CollisionSystem::warmStartBound(std::span<const Vec2> firstSubstepV) const {
    const std::vector<double>& reach = contactPairs_.reach;
    // The fastest point of a kinematic body that touches something: a body
    // it drives is pushed at up to that speed.
    double driven = 0.0;
    for (const std::uint32_t i : awakeSolverColliders_) {
        const std::uint32_t s = solverIndex_[i];
        if (bodies_[s].invMass == 0.0)
            driven = std::max(driven, length(startV_[i]) + std::abs(angularVelocities_[i]) * reach[s]);
    }
    double bound = 0.0;
    for (const std::uint32_t i : awakeSolverColliders_) {
        const std::uint32_t s = solverIndex_[i];
        const double invMass = bodies_[s].invMass;
        if (invMass == 0.0) continue;
        const Vec2 v0 = startV_[i];
        const Vec2 forced = firstSubstepV[std::size_t(colliders_[i].body)] - v0;
        bound += (length(v0) + std::abs(angularVelocities_[i]) * reach[s] + length(forced) + driven +
                  settings_.pushCap(settings_.contactHertz)) /
                 invMass;
    }
    // A joint presses its bodies with what its rows carry; the rows in N*s
    // (a hinge's torque reaches a contact through its point row).
    for (std::size_t k = 0; k < joints_.size() && k < jointImpulsesBefore_.size(); ++k) {
        const joints::JointConstraint& j = joints_[k];
        if (j.asleep || j.broken) continue;
        const JointImpulse& imp = jointImpulsesBefore_[k];
        switch (j.kind) {
        case joints::JointKind::Hinge:
        case joints::JointKind::Weld: bound += length(imp.linear); break;
        case joints::JointKind::Slider:
            bound += std::abs(imp.linear.x) + std::abs(imp.motor) + imp.lower + imp.upper;
            break;
        case joints::JointKind::Wheel:
            bound += std::abs(imp.linear.x) + std::abs(imp.axial) + imp.lower + imp.upper;
            break;
        case joints::JointKind::Distance: bound += std::abs(imp.axial) + imp.lower + imp.upper; break;
        case joints::JointKind::Rope: bound += imp.upper; break;
        }
    }
    return kWarmStartMargin * bound;
}

void CollisionSystem::addDeepOverlapsToCrowd() {
    // Two moving shapes overlapping by more than a quarter of the smaller
    // one's reach did not get there by the solver: they were placed so
    // (bodies started at one point, an edit, an emitter). Their push-out is
    // taken as a position change only, like a crowded cell's: summed over a
    // few dozen such contacts, pushes of up to pushMaxVelocity each would
    // fling a hundred balls started at one point out at over 100 m/s. (A
    // tenth would also catch bodies that an impact packs together, and
    // Box2D's smash scene would keep 0.3 m overlaps that never open.)
    inCrowd_.assign(bodies_.size(), 0);
    for (const std::uint32_t b : crowdBodies_) inCrowd_[b] = 1;
    for (const std::uint32_t k : deepContacts_) {
        const ContactConstraint& c = constraints_[k];
        for (const std::uint32_t b : {c.bodyA, c.bodyB}) {
            if (inCrowd_[b]) continue;
            inCrowd_[b] = 1;
            crowdBodies_.push_back(b);
        }
    }
    if (!crowdBodies_.empty() && !joints_.empty()) addJointedNeighboursToCrowd();
}

void CollisionSystem::addJointedNeighboursToCrowd() {
    // A jointed body touching the crowd joins it, and so, in turn, does a
    // jointed body touching that one. Outside, it keeps the crowd's pushes
    // and its joints pass them on along its chain: ten hinged boxes among
    // 100 discs started at one point reached 28 m/s at 8 substeps and 8
    // iterations. (Taking the push back from it alone, as from an unjointed
    // body, leaves its joints' answer in its neighbours.) Inside, the push
    // is a position change as for the rest of the crowd, and its joints
    // give back what they passed on (saveCrowdJoints).
    //
    // Except a support: a crowd body jointed out of the crowd (to a static
    // body too) touching a crowd body at least twice its mass that an
    // external force (gravity, say) acts on. It may carry that body's load
    // out of the crowd, which only the biased passes, run with velocities
    // kept, can do: the relax pass alone cannot hold a heavy body on light
    // ones. A crate that sank into a bridge's 2 kg planks, with the planks
    // it touched in the crowd, came within 0.15 m of the lowest plank at 8
    // times a plank's mass and fell through the bridge at 10 (16 relax
    // passes held it at 10, not at 25). A support
    // that joined here leaves the crowd again, and one the crowd rule put
    // in it keeps its joints' answer.
    //
    // Jointed here means jointed to another moving body: a body held only
    // to the static world (a motor-driven drum or spinner) passes no push
    // on, and stays out as before.
    jointedBody_.assign(bodies_.size(), 0);
    bool anyJointed = false;
    for (const joints::JointConstraint& j : joints_) {
        if (j.broken || fixedBody(j.a.solverBody) || fixedBody(j.b.solverBody)) continue;
        jointedBody_[j.a.solverBody] = jointedBody_[j.b.solverBody] = 1;
        anyJointed = true;
    }
    crowdSupport_.assign(bodies_.size(), 0);
    if (!anyJointed) return;  // a drum or spinner: nothing to join, and no pass over the contacts
    // The contacts touching a jointed body, by body, both ends listed.
    neighbourStart_.assign(bodies_.size() + 1, 0);
    const auto touchesJointed = [&](const ContactConstraint& c) {
        return jointedBody_[c.bodyA] || jointedBody_[c.bodyB];
    };
    for (const ContactConstraint& c : constraints_)
        if (touchesJointed(c)) {
            ++neighbourStart_[c.bodyA + 1];
            ++neighbourStart_[c.bodyB + 1];
        }
    for (std::size_t b = 0; b < bodies_.size(); ++b) neighbourStart_[b + 1] += neighbourStart_[b];
    neighbours_.resize(neighbourStart_.back());
    neighbourFill_.assign(neighbourStart_.begin(), neighbourStart_.end() - 1);
    for (std::uint32_t k = 0; k < constraints_.size(); ++k) {
        const ContactConstraint& c = constraints_[k];
        if (!touchesJointed(c)) continue;
        neighbours_[neighbourFill_[c.bodyA]++] = k;
        neighbours_[neighbourFill_[c.bodyB]++] = k;
    }
    const auto other = [&](std::uint32_t k, std::uint32_t b) {
        return constraints_[k].bodyA == b ? constraints_[k].bodyB : constraints_[k].bodyA;
    };
    const std::size_t seeded = crowdBodies_.size();
    for (std::size_t next = 0; next < crowdBodies_.size(); ++next) {
        const std::uint32_t b = crowdBodies_[next];
        for (std::uint32_t k = neighbourStart_[b]; k < neighbourStart_[b + 1]; ++k) {
            const std::uint32_t o = other(neighbours_[k], b);
            if (inCrowd_[o] || !jointedBody_[o] || bodies_[o].invMass == 0.0) continue;
            inCrowd_[o] = 1;
            crowdBodies_.push_back(o);
        }
    }
    // Loaded: contact k's other body is in the crowd, at least twice b's
    // mass, and an external force acts on it over the step (endV_ -
    // startV_), so its weight may rest on b. (Which way the force points
    // says little: a crate in a sagging bridge presses on one plank from
    // above and on the next from the side.) A lighter load the relax pass
    // carries: with supports under bodies of their own mass, 1 kg links
    // pinned to a post with their end among 1 kg discs above a floor were
    // flung at 17 m/s at 8 x 8, against 10 m/s as crowd members; the bridge
    // sags the same either way.
    constexpr double kHeavier = 2.0;  // by mass, than b
    const auto loaded = [&](std::uint32_t k, std::uint32_t b) {
        const ContactConstraint& c = constraints_[k];
        const ContactDetail& d = details_[k];
        const bool bIsA = c.bodyA == b;
        const std::uint32_t o = bIsA ? c.bodyB : c.bodyA;
        const std::uint32_t collider = bIsA ? d.colliderB : d.colliderA;
        return inCrowd_[o] && bodies_[o].invMass > 0.0 && kHeavier * bodies_[o].invMass <= bodies_[b].invMass &&
               lengthSquared(endV_[collider] - startV_[collider]) > 0.0;
    };
    for (bool left = true; left;) {
        crowdSupport_.assign(bodies_.size(), 0);
        for (const joints::JointConstraint& j : joints_) {
            if (j.broken) continue;
            if (!inCrowd_[j.b.solverBody]) crowdSupport_[j.a.solverBody] = 1;
            if (!inCrowd_[j.a.solverBody]) crowdSupport_[j.b.solverBody] = 1;
        }
        for (std::uint32_t b = 0; b < bodies_.size(); ++b) {
            if (!crowdSupport_[b]) continue;
            bool carries = false;
            if (inCrowd_[b])
                for (std::uint32_t k = neighbourStart_[b]; k < neighbourStart_[b + 1] && !carries; ++k)
                    carries = loaded(neighbours_[k], b);
            crowdSupport_[b] = carries;
        }
        // Leaving may make a support of a body jointed to the one that left.
        std::size_t kept = seeded;
        for (std::size_t k = seeded; k < crowdBodies_.size(); ++k) {
            const std::uint32_t b = crowdBodies_[k];
            if (crowdSupport_[b]) inCrowd_[b] = 0;
            else crowdBodies_[kept++] = b;
        }
        left = kept < crowdBodies_.size();
        crowdBodies_.resize(kept);
    }
}

void CollisionSystem::saveCrowdJoints() {
    // The joints within the crowd (every moving end in it, or fixed) hold
    // what the biased passes add to them, like the crowd's contacts: after
    // the passes their impulses go back to the warm start with the crowd's
    // velocities, else the next substep's warm start would apply the
    // push-out the crowd took as a position change. A joint from the crowd
    // to a moving body outside it also gives back what it passed on to that
    // body. (With neither, a chain pinned to a post with its end among 100
    // discs started at one point reached 41 m/s at 4 x 8.) A support's
    // joints keep their answer (addJointedNeighboursToCrowd).
    crowdJoints_.clear();
    crowdJointImpulses_.clear();
    crowdRimJoints_.clear();
    crowdRimImpulses_.clear();
    if (crowdBodies_.empty()) return;
    const auto member = [&](std::uint32_t b) { return inCrowd_[b] && !crowdSupport_[b]; };
    const auto outside = [&](std::uint32_t b) { return !inCrowd_[b] && bodies_[b].invMass > 0.0; };
    for (std::uint32_t k = 0; k < joints_.size(); ++k) {
        const joints::JointConstraint& j = joints_[k];
        if (j.asleep) continue;
        const std::uint32_t a = j.a.solverBody, b = j.b.solverBody;
        if ((member(a) || fixedBody(a)) && (member(b) || fixedBody(b)) && (member(a) || member(b)))
            crowdJoints_.push_back(k);
        else if ((member(a) && outside(b)) || (member(b) && outside(a)))
            crowdRimJoints_.push_back(k);
    }
    if (crowdJoints_.empty() && crowdRimJoints_.empty()) return;
    jointBundles_.storeImpulses(joints_);
    for (const std::uint32_t k : crowdJoints_) crowdJointImpulses_.push_back(joints::impulsesOf(joints_[k]));
    for (const std::uint32_t k : crowdRimJoints_) crowdRimImpulses_.push_back(joints::impulsesOf(joints_[k]));
}

void CollisionSystem::restoreCrowdJoints() {
    jointBundles_.storeImpulses(joints_);
    for (std::size_t m = 0; m < crowdJoints_.size(); ++m) joints::setImpulses(joints_[crowdJoints_[m]], crowdJointImpulses_[m]);
    joints::takeBackJointImpulses(joints_, crowdRimJoints_, crowdRimImpulses_, bodies_);
    jointBundles_.loadImpulses(joints_);
}

Vec2 CollisionSystem::coincidentNormal(std::uint32_t a, std::uint32_t b) {
    // Two circles on the same centre have no line of centres. A direction
    // that varies with the pair (golden-angle steps) pushes a crowd started
    // at one point apart in every direction instead of along one line; it
    // depends only on the indices, so it is deterministic.
    const double goldenAngle = 2.399963229728653;  // rad, pi (3 - sqrt 5)
    const double angle = goldenAngle * double((std::uint64_t(a) * 7919u + std::uint64_t(b)) % 100003u);
    return {std::cos(angle), std::sin(angle)};
}

void CollisionSystem::solveSubstep(std::span<Vec2> x, std::span<Vec2> v, double h) {
    // Detection waits for the first substep's forces (see detect()).
    if (!detected_) {
        detect(v, h);
        detected_ = true;
        // The awake solver bodies' indices side by side, for the substeps'
        // loops (a Collider is over a hundred bytes; these are twelve).
        awakeSolved_.resize(awakeSolverColliders_.size());
        for (std::size_t k = 0; k < awakeSolverColliders_.size(); ++k) {
            const std::uint32_t i = awakeSolverColliders_[k];
            awakeSolved_[k] = {i, solverIndex_[i], std::uint32_t(colliders_[i].body)};
        }
    }
    const auto start = std::chrono::steady_clock::now();
    const std::size_t n = colliders_.size();
    unconstrainedV_.resize(n);
    for (const SolvedBody& sb : awakeSolved_) {
        bodies_[sb.solver].v = v[sb.body];
        bodies_[sb.solver].w = angularVelocities_[sb.collider];
        unconstrainedV_[sb.collider] = v[sb.body];
    }
    // Contact stiffness may not exceed a quarter of the substep rate, or the
    // soft constraint itself becomes unstable (Box2D v3.0's cap; v3.1
    // lowered it to an eighth, which a deep column gets: hertzFraction). Contacts
    // with static bodies may be twice as stiff, but under the same cap:
    // above it a heavy box on light boxes never comes to rest.
    const double hertz = std::min(settings_.contactHertz, settings_.hertzFraction / h);
    const double pushCap = settings_.pushCap(hertz);
    const Softness soft = Softness::make(hertz, settings_.dampingRatio, h);
    Softness staticSoft = Softness::make(std::min(2.0 * hertz, 0.25 / h), settings_.dampingRatio, h);
    // Contacts with the static world turn rigid before the slop
    // (Softness::rigidDepth): a soft one under a steady load settles at
    // load / (m omega^2), which at 1000 m/s^2 and one substep sinks a ball
    // 11 cm and crosses a thin box. Up to that depth they stay soft, since a
    // rigid floor keeps a pyramid of boxes from coming to rest; short of the
    // slop, so the position pass (a backstop) leaves resting bodies alone
    // (moving them every step would keep them from sleeping).
    staticSoft.rigidDepth = 0.8 * positionCorrection_.slop;

    // A row of n touching bodies needs up to n passes; 64 bounds the cost.
    // Joints: rigid ones are corrected at up to half the substep rate
    // (twice the contacts' cap, as Box2D v3), solved before the contacts;
    // the softness is the world's, else the engine's choice by how the
    // joint is solved (JointSettings).
    const bool jointed = !joints_.empty();
    if (jointed && !jointOrderReady_) {
        joints::colourJoints(joints_, bodies_.size(), jointOrder_, &jointColourEnds_);
        jointOrderReady_ = true;
        jointBundlesReady_ = false;
    }
    // Once a step, after prepareJoints (in detect) and any wake: the
    // bundles copy the step-start anchors and which joints sleep, and leave
    // out the joints an exactly solved tree takes.
    if (jointed && !jointBundlesReady_) {
        directJoints_.ensureBuilt(joints_, bodies_);
        jointBundles_.build(joints_, jointOrder_, jointColourEnds_, settings_.simd);
        jointBundlesReady_ = true;
    }
    const double jointCap = 0.5 / h;
    const Softness jointSoft = Softness::make(
        std::min(jointSettings_.hertz.value_or(joints::JointSettings::kLoopHertz), jointCap),
        jointSettings_.dampingRatio.value_or(joints::JointSettings::kLoopDampingRatio), h);
    const Softness directSoft = Softness::make(
        std::min(jointSettings_.hertz.value_or(jointCap), jointCap),
        jointSettings_.dampingRatio.value_or(joints::JointSettings::kTreeDampingRatio), h);
    lastH_ = h;
    // In a crowd every pair approaches every other: the passes would run to
    // the bound over hundreds of thousands of contacts (60% of a 2,000-body
    // crowd's step). Two passes there; the push-apart does the rest.
    propagateImpacts(constraints_, details_, bodies_, contactPairs_, h, settings_.restitutionThreshold,
                     crowdBodies_.empty() ? 64 : 2, impactScratch_);
    if (settings_.warmStart) {
        if (jointed) jointBundles_.warmStart(joints_, bodies_);
        coloured_.warmStart(constraints_, bodies_);
        treeContacts_.warmStart(constraints_, bodies_);
    }
    crowdSaved_.resize(crowdBodies_.size());
    for (std::size_t k = 0; k < crowdBodies_.size(); ++k)
        crowdSaved_[k] = {bodies_[crowdBodies_[k]].v, bodies_[crowdBodies_[k]].w};
    if (!crowdBodies_.empty()) coloured_.saveImpulses(constraints_, inCrowd_, crowdImpulses_);
    if (jointed) saveCrowdJoints();
    // Bodies in a crowd (many on top of each other, or started deep in one
    // another) take the biased passes' push as a position correction only
    // (split impulse): their velocities and their contacts' impulses go back
    // to what the warm start left (saved above), and the relax pass then
    // only stops approaches. Otherwise each contact's push (up to
    // pushMaxVelocity) adds up along the crowd and flings its edge out at
    // tens of m/s. Ordinary scenes have no crowd and are unchanged.
    bool reverse = false;
    if (jointed) directJoints_.factor(joints_, bodies_, directSoft, true);
    const bool alternate = !settings_.oneColourOrder;
    for (int it = 0; it < settings_.iterations; ++it, reverse = alternate && !reverse) {
        if (jointed) {
            jointBundles_.solve(joints_, bodies_, h, jointSoft, directSoft, true);
            directJoints_.solve(joints_, bodies_);
        }
        coloured_.solve(constraints_, bodies_, h, soft, staticSoft, pushCap, true, reverse);
        if (!treeContacts_.empty())
            treeContacts_.solve(constraints_, joints_, bodies_, directJoints_, h, soft, staticSoft,
                                pushCap, true, reverse);
    }

    offsetAngleBefore_.resize(offsetBodies_.size());
    for (std::size_t k = 0; k < offsetBodies_.size(); ++k) offsetAngleBefore_[k] = angles_[offsetBodies_[k]];
    // Positions: the integrator moved x with the unconstrained velocity; add
    // the contact velocity change over the substep. Angles integrate here
    // (only contacts make torque).
    for (const SolvedBody& sb : awakeSolved_) {
        const std::uint32_t i = sb.collider;
        SolverBody& b = bodies_[sb.solver];
        x[sb.body] += h * (b.v - unconstrainedV_[i]);
        angles_[i] += h * b.w;
        b.dp = x[sb.body] - stepStart_[i];
        b.dq = rotationBy(angles_[i] - stepStartAngle_[i]);
    }
    if (!crowdJoints_.empty() || !crowdRimJoints_.empty()) restoreCrowdJoints();
    for (std::size_t k = 0; k < crowdBodies_.size(); ++k) {
        bodies_[crowdBodies_[k]].v = crowdSaved_[k].v;
        bodies_[crowdBodies_[k]].w = crowdSaved_[k].w;
    }
    // The impulses the biased passes added to the crowd's contacts are the
    // push-out it took as motion only: left in, the relax pass would take
    // them back from velocities they were never applied to, pulling apart
    // bodies together (100 balls started at one point would reach 160 m/s
    // in their second step). The warm-started impulses, which the
    // velocities do carry, go back with the velocities.
    // A moving body outside the crowd took pushes from its crowded
    // neighbours in the biased passes, and the relax pass cannot take them
    // back (their contacts' impulses are restored): kept, they add up along
    // chains of such bodies, and at 8 iterations 300 capsules started at one
    // point reached 15.6 m/s. So what the passes gave across the crowd's
    // edge goes back from the outside body's velocity too, and the push
    // moved only positions on both sides. Not from a jointed body left
    // outside (a support, see addJointedNeighboursToCrowd): its joints
    // answered the push in the same passes, and with the push taken back
    // alone their answer stayed, lifting the planks under a crate the crowd
    // rule had caught sunk into one of them (it fell through the bridge
    // from 2.5 times a plank's mass).
    if (!crowdBodies_.empty()) {
        takeBack_.assign(bodies_.size(), 0);
        for (std::size_t b = 1; b < bodies_.size(); ++b) takeBack_[b] = !inCrowd_[b] && bodies_[b].invMass > 0.0;
        for (const joints::JointConstraint& j : joints_) takeBack_[j.a.solverBody] = takeBack_[j.b.solverBody] = 0;
        coloured_.restoreImpulses(constraints_, inCrowd_, crowdImpulses_, bodies_, takeBack_);
    }
    // A body turning about a centre of mass off its position moves its
    // position: p = c - R(angle) offset, with the centre c moved as above.
    for (std::size_t k = 0; k < offsetBodies_.size(); ++k) {
        const std::uint32_t i = offsetBodies_[k];
        if (colliderAsleep_[i]) continue;
        const Collider& c = colliders_[i];
        SolverBody& b = bodies_[solverIndex_[i]];
        const std::size_t body = std::size_t(c.body);
        x[body] -= rotate(Rot::fromAngle(angles_[i]), c.centreOfMass) -
                   rotate(Rot::fromAngle(offsetAngleBefore_[k]), c.centreOfMass);
        b.dp = centreOfMass(i, std::span<const Vec2>(x.data(), x.size())) - stepStart_[i];
    }
    if (jointed) directJoints_.factor(joints_, bodies_, directSoft, false);
    // The step's last relax pass measures each bundled contact's deepest
    // point for the position pass (correctStepPositions), which then need
    // not read the contacts: the positions are final here unless an exactly
    // solved joint group's projection (and the riders' carry) moves them.
    const bool measure = substepsDone_ + 1 == substeps_ && settings_.simd && settings_.relaxIterations > 0 &&
                         !(jointed && directJoints_.directJointCount() > 0);
    if (measure) endSeparations_.resize(constraints_.size());
    endSeparationsMeasured_ = measure;
    for (int it = 0; it < settings_.relaxIterations; ++it, reverse = alternate && !reverse) {
        if (jointed) {
            jointBundles_.solve(joints_, bodies_, h, jointSoft, directSoft, false);
            directJoints_.solve(joints_, bodies_);
        }
        const bool last = it + 1 == settings_.relaxIterations;
        coloured_.solve(constraints_, bodies_, h, soft, staticSoft, pushCap, false, reverse,
                        measure && last ? std::span<double>(endSeparations_) : std::span<double>{});
        if (!treeContacts_.empty())
            treeContacts_.solve(constraints_, joints_, bodies_, directJoints_, h, soft, staticSoft,
                                pushCap, false, reverse);
    }

    // Tree-shaped joint groups: their positions projected onto the joints
    // (direct_joints.hpp), which removes the drift a velocity solve leaves
    // (a chain's links turn by up to a tenth of a radian a substep with a
    // heavy end) without touching the velocities.
    if (jointed && directJoints_.directJointCount() > 0) {
        directJoints_.project(joints_, bodies_, jointMoves_, jointMoved_);
        const bool riders = !jointMoved_.empty() && noteRiders();
        if (!jointMoved_.empty())
            for (const SolvedBody& sb : awakeSolved_) {
                const joints::DirectJoints::Move& m = jointMoves_[sb.solver];
                if (m.dp == Vec2{} && m.dq == 0.0) continue;
                const std::uint32_t i = sb.collider;
                SolverBody& b = bodies_[sb.solver];
                const double before = angles_[i];
                x[sb.body] += m.dp;
                angles_[i] += m.dq;
                // A body turning about a centre of mass off its position moves its position.
                if (const Vec2 com = colliders_[i].centreOfMass; com != Vec2{})
                    x[sb.body] -= rotate(Rot::fromAngle(angles_[i]), com) - rotate(Rot::fromAngle(before), com);
                b.dp += m.dp;
                b.dq = rotationBy(angles_[i] - stepStartAngle_[i]);
            }
        if (riders) carryRiders(x);
    }
    for (const SolvedBody& sb : awakeSolved_) {
        v[sb.body] = bodies_[sb.solver].v;
        angularVelocities_[sb.collider] = bodies_[sb.solver].w;
    }
    if (++substepsDone_ == substeps_) {
        correctStepPositions(x);
        sweepAgainstStatic(x);
        syncShapes();
        if (anySensor_) updateSensors(x);
    }
    timings_.solveMs += msSince(start);
}

bool CollisionSystem::noteRiders() {
    // The projection moves a group's bodies onto its joints without
    // touching velocities, and the contacts never see the move: a plank
    // lifted back onto its pins rises into the crate resting on it, and
    // the crate's soft contact takes out a few per cent of that overlap a
    // substep. Under a steady load the group sags and is lifted back by the
    // same amount every substep, so a crate of half a plank's mass settled
    // 46 mm into the planks of a taut bridge, and heavier ones bounced on
    // it and tore its pins open (424 mm deep, the pins 138 mm open, at
    // twice a plank's mass).
    carryRole_.assign(bodies_.size(), kLoose);
    for (const joints::JointConstraint& j : joints_)
        if (j.direct) carryRole_[j.a.solverBody] = carryRole_[j.b.solverBody] = kInGroup;
    const auto loose = [&](std::uint32_t b) { return carryRole_[b] == kLoose && bodies_[b].invMass > 0.0; };
    riderContacts_.clear();
    bool touchesGroup = false;
    const std::vector<std::uint32_t>& pairBodies = contactPairs_.bodies;
    for (std::size_t k = 0; k < constraints_.size(); ++k) {
        const std::uint32_t bodyA = pairBodies[2 * k], bodyB = pairBodies[2 * k + 1];
        const bool looseA = loose(bodyA), looseB = loose(bodyB);
        if (!looseA && !looseB) continue;
        // A loose body against a static or kinematic one is no rider's
        // contact. Against a group's body it may be; against another
        // loose body it is listed too, for when one of them is carried.
        if (looseA != looseB) {
            if (carryRole_[looseA ? bodyB : bodyA] != kInGroup) continue;
            touchesGroup = true;
        }
        RiderContact& r = riderContacts_.emplace_back();
        r.contact = std::uint32_t(k);
        r.bodyA = bodyA;
        r.bodyB = bodyB;
        r.betweenLoose = looseA && looseB;
        if (r.betweenLoose) continue;
        const ContactConstraint& c = constraints_[k];
        for (int i = 0; i < c.pointCount; ++i)
            r.before[i] = currentSeparation(bodies_[c.bodyA], bodies_[c.bodyB], c, c.points[i]);
    }
    if (!touchesGroup) return false;
    // Carries only translate, so the loose bodies' step-so-far moves are all
    // that riderBefore needs to measure a contact between two of them later.
    dpBeforeCarry_.resize(bodies_.size());
    for (std::size_t b = 0; b < bodies_.size(); ++b) dpBeforeCarry_[b] = bodies_[b].dp;
    riderLoad_.assign(bodies_.size(), Vec2{});
    for (const SolvedBody& sb : awakeSolved_) riderLoad_[sb.solver] = endV_[sb.collider] - startV_[sb.collider];
    return true;
}

double CollisionSystem::riderBefore(const RiderContact& r, const ContactConstraint& c, int i) const {
    if (!r.betweenLoose) return r.before[i];
    SolverBody a = bodies_[r.bodyA], b = bodies_[r.bodyB];
    a.dp = dpBeforeCarry_[r.bodyA];
    b.dp = dpBeforeCarry_[r.bodyB];
    return currentSeparation(a, b, c, c.points[i]);
}

Vec2 CollisionSystem::supportMove(const ContactConstraint& c, int point, std::uint32_t support) const {
    if (carryRole_[support] != kInGroup) return carried_[support];
    const ContactPoint& p = c.points[point];
    const Vec2 t{c.normal.y, -c.normal.x};
    // The point's lever arm on the support: dot(r, n) = dn, cross(r, n) = dot(r, t) = rn.
    const Vec2 arm = support == c.bodyA ? p.dnA * c.normal + p.rnA * t : p.dnB * c.normal + p.rnB * t;
    const joints::DirectJoints::Move& m = jointMoves_[support];
    return m.dp + m.dq * Vec2{-arm.y, arm.x};
}

void CollisionSystem::followRiders() {
    // A rider that static friction holds on its support moves with the
    // points that hold it (their mean, weighted by the normal impulses),
    // when they move into it and against its load: as if the projection
    // had moved it with the support. Lifted out by the overlap alone, it
    // shifted along the support by each lift's sideways part, which its
    // velocity did not take back: a 20 kg crate on a taut bridge crept
    // 47 mm in 20 s at 4 substeps. Riders on riders follow in later passes.
    // The impulses as the passes left them, bundled or not (the bundles
    // hold theirs until the step ends), so both paths follow alike.
    coloured_.storeImpulses(constraints_);
    followSum_.assign(bodies_.size(), Vec2{});
    followWeight_.assign(bodies_.size(), 0.0);
    constexpr int kMaxPasses = 8;
    for (int pass = 0; pass < kMaxPasses; ++pass) {
        bool any = false;
        for (const RiderContact& r : riderContacts_) {
            const bool riderA = carryRole_[r.bodyA] == kLoose && !fixedBody(r.bodyA);
            const bool riderB = carryRole_[r.bodyB] == kLoose && !fixedBody(r.bodyB);
            if (riderA == riderB) continue;
            const std::uint32_t rider = riderA ? r.bodyA : r.bodyB, support = riderA ? r.bodyB : r.bodyA;
            if (carryRole_[support] == kLoose) continue;  // not moved (yet)
            const ContactConstraint& c = constraints_[r.contact];
            double weight = 0.0;
            bool sticks = true;
            Vec2 move;
            for (int i = 0; i < c.pointCount; ++i) {
                const ContactPoint& p = c.points[i];
                if (!(p.normalImpulse > 0.0)) continue;
                sticks = sticks && std::abs(p.tangentImpulse) < c.friction * p.normalImpulse;
                weight += p.normalImpulse;
                move += p.normalImpulse * supportMove(c, i, support);
            }
            if (!sticks || !(weight > 0.0)) continue;
            move = (1.0 / weight) * move;
            const Vec2 out = riderA ? -1.0 * c.normal : c.normal;  // the rider's way out of the contact
            if (!(dot(move, out) > 0.0) || !(dot(move, riderLoad_[rider]) < 0.0)) continue;
            followSum_[rider] += weight * move;
            followWeight_[rider] += weight;
        }
        for (const RiderContact& r : riderContacts_) {
            for (const std::uint32_t rider : {r.bodyA, r.bodyB}) {
                if (carryRole_[rider] != kLoose || !(followWeight_[rider] > 0.0)) continue;
                const Vec2 move = (1.0 / followWeight_[rider]) * followSum_[rider];
                bodies_[rider].dp += move;
                carried_[rider] += move;
                carryRole_[rider] = kCarried;
                any = true;
            }
        }
        if (!any) break;
    }
}

bool CollisionSystem::carryAgainstLoad(const ContactConstraint& c, int deepest, bool pushB, double deficit,
                                       Vec2& move) const {
    const Vec2 load = riderLoad_[pushB ? c.bodyB : c.bodyA];
    if (!(dot(move, load) < 0.0)) return false;
    // Where the support's point under the rider moved mostly into it, the
    // rider follows that point: it then keeps its place on the support, as
    // static friction holds it. Lifted along any fixed direction instead,
    // it shifts along a tilted plank by each lift and the load brings it
    // back straight down, a ratchet (a crate on the shipped bridge crept
    // 3 mm/s lifted straight up, and 5 cm in 20 s on a taut bridge lifted
    // along the plank's normal).
    const Vec2 follow = supportMove(c, deepest, pushB ? c.bodyA : c.bodyB);
    const double into = dot(follow, move) / deficit;  // how far the point moved into the rider
    if (into > 0.5 * length(follow)) {
        move = (deficit / into) * follow;
        return true;
    }
    // Else straight up against the load where the contact faces it within
    // 60 degrees, or along the normal.
    const Vec2 up = (-1.0 / length(load)) * load;
    const double facing = dot(up, move) / deficit;
    if (facing > 0.5) move = (deficit / facing) * up;
    return true;
}

void CollisionSystem::carryRiders(std::span<Vec2> x) {
    // Each rider moves out of a contact until it is no deeper than before
    // the projection (or than touching, had it a gap), when the body across
    // has moved (a group's body, or a rider carried already: a box on the
    // crate goes up with it) and the move holds the rider against its load
    // (a box a ragdoll lies on is not pushed into the floor). The groups do
    // not move back: their joints stay where the projection put them, as a
    // static support would. Only positions move, as in the projection.
    // Passes repeat while a rider moves, to a bound; a pile deeper than
    // that is left to its soft contacts.
    carried_.assign(bodies_.size(), Vec2{});
    constexpr int kMaxPasses = 8;
    followRiders();
    for (int pass = 0; pass < kMaxPasses; ++pass) {
        bool any = false;
        for (const RiderContact& r : riderContacts_) {
            const std::uint8_t roleA = carryRole_[r.bodyA], roleB = carryRole_[r.bodyB];
            // The side pushed: a rider (not a group's body) whose neighbour
            // across has moved.
            const bool pushA = roleA != kInGroup && roleB != kLoose;
            const bool pushB = roleB != kInGroup && roleA != kLoose;
            if (!pushA && !pushB) continue;
            const ContactConstraint& c = constraints_[r.contact];
            double deficit = 0.0;
            int deepest = 0;
            for (int i = 0; i < c.pointCount; ++i) {
                const double now = currentSeparation(bodies_[c.bodyA], bodies_[c.bodyB], c, c.points[i]);
                const double before = riderBefore(r, c, i);
                if (std::min(before, 0.0) - now > deficit) {
                    deficit = std::min(before, 0.0) - now;
                    deepest = i;
                }
            }
            if (!(deficit > 0.0)) continue;
            // The normal runs from A to B: B moves along it, A against it.
            // Two carried riders carried into each other (boxes lifted along
            // the two sides of a sagging bridge) share the move by inverse
            // mass; a loose body is carried only against its load.
            const double shareB = pushA && pushB ? bodies_[c.bodyB].invMass /
                                                       (bodies_[c.bodyA].invMass + bodies_[c.bodyB].invMass)
                                                 : (pushB ? 1.0 : 0.0);
            Vec2 moveA = (-(1.0 - shareB) * deficit) * c.normal, moveB = (shareB * deficit) * c.normal;
            if (!(pushA && pushB)) {
                Vec2& move = pushB ? moveB : moveA;
                if (!carryAgainstLoad(c, deepest, pushB, deficit, move)) continue;
            }
            for (const auto& [rider, move] : {std::pair{c.bodyA, moveA}, std::pair{c.bodyB, moveB}}) {
                if (move == Vec2{}) continue;
                bodies_[rider].dp += move;
                carried_[rider] += move;
                carryRole_[rider] = kCarried;
            }
            any = true;
        }
        if (!any) break;
    }
    for (const SolvedBody& sb : awakeSolved_)
        if (const Vec2 m = carried_[sb.solver]; m != Vec2{}) x[sb.body] += m;
}

void CollisionSystem::correctStepPositions(std::span<Vec2> x) {
    // What the last relax pass measured, and the contacts it did not
    // solve (the colours' overflow) measured here.
    std::span<const double> measured;
    if (endSeparationsMeasured_) {
        const std::span<const std::uint32_t> order = coloured_.order();
        for (const std::uint32_t k : order.subspan(order.size() - coloured_.overflowCount())) {
            const ContactConstraint& c = constraints_[k];
            endSeparations_[k] = deepestSeparation(bodies_[c.bodyA], bodies_[c.bodyB], c);
        }
        measured = endSeparations_;
    }
    const bool corrected =
        correctPositions(constraints_, bodies_, inCrowd_, positionCorrection_, positionScratch_, measured);
    const bool turned = correctTurnedAgainstStatic(corrected);
    if (!corrected && !turned) return;
    // Back from the centre of mass's move and the turn to the body's
    // position: p = c - R(angle) offset.
    for (const SolvedBody& sb : awakeSolved_) {
        if (!positionScratch_.moved[sb.solver]) continue;
        const std::uint32_t i = sb.collider;
        const SolverBody& b = bodies_[sb.solver];
        angles_[i] += positionScratch_.turned[sb.solver];
        const Collider& c = colliders_[i];
        if (c.centreOfMass.x == 0.0 && c.centreOfMass.y == 0.0) {
            x[sb.body] = stepStart_[i] + b.dp;
        } else {
            x[sb.body] = stepStart_[i] + b.dp - rotate(Rot::fromAngle(angles_[i]), c.centreOfMass);
        }
    }
}

namespace {
/// The radius that rounds a shape's outline: its ends, its corners or the
/// whole shape (metres; 0 for a box).
double roundingOf(const Shape& shape) {
    switch (shape.kind) {
    case ShapeKind::Circle:
    case ShapeKind::Capsule: return shape.radius;
    case ShapeKind::Polygon: return shape.polygon->cornerRadius;
    case ShapeKind::Box:
    case ShapeKind::Plane:
    case ShapeKind::ChainSegment: return 0.0;
    }
    return 0.0;
}
} // namespace

double CollisionSystem::foreseenTravel(std::size_t i) const {
    return 2.0 * kSpeculativeBase + dt_ * std::max(length(startV_[i]), length(endV_[i])) + spin_[i];
}

CollisionSystem::PresentPose CollisionSystem::presentPose(std::uint32_t shape, const SolverBody& body) const {
    // The body's centre of mass moved by dp; the shape turned with the body
    // by dq about it.
    const Vec2 startCentre = centres_[ownerOf(shape)];
    const Vec2 centre = startCentre + body.dp;
    const Rot q0 = rotScratch_[shape];
    return {centre, centre + rotate(body.dq, centres_[shape] - startCentre),
            Rot{body.dq.c * q0.c - body.dq.s * q0.s, body.dq.s * q0.c + body.dq.c * q0.s}};
}

bool CollisionSystem::correctTurnedAgainstStatic(bool scratchReady) {
    // The step-start contacts follow the points they were found at exactly
    // (currentSeparation). A body can meet the static world elsewhere only
    // if it turned by more than the slop at its reach while touching it (a
    // lone circle turns under its contact point and never does), or if it
    // went farther than the motion its contacts were found for (the solve
    // sped it up). Such a body's static neighbours are looked up afresh, as
    // the sweep does: a chain segment answers only within its own length,
    // so the segment a tumbling plank swings onto may have no contact yet.
    const double slop = positionCorrection_.slop;
    // The turn this step: the substeps' (in the angles) and the position
    // pass's (not yet written to them).
    const auto turnOf = [&](std::uint32_t owner, std::uint32_t solver) {
        return (angles_[owner] - stepStartAngle_[owner]) + (scratchReady ? positionScratch_.turned[solver] : 0.0);
    };
    turnedBodies_.clear();
    // The bodies from the packed pairs: most contacts join two moving
    // bodies, and the 232-byte contacts are not read for them.
    const std::vector<std::uint32_t>& pairBodies = contactPairs_.bodies;
    for (std::size_t k = 0; k < constraints_.size(); ++k) {
        const std::uint32_t bodyA = pairBodies[2 * k], bodyB = pairBodies[2 * k + 1];
        // One side truly static: a kinematic side moved this step too.
        if ((bodyA == 0) == (bodyB == 0)) continue;
        const ContactDetail& d = details_[k];
        const bool staticFirst = bodyA == 0;
        const std::uint32_t moving = staticFirst ? d.colliderB : d.colliderA;
        const Collider& shape = colliders_[moving];
        if (shape.shape.kind == ShapeKind::Circle && shape.hub < 0) continue;
        const std::uint32_t solver = staticFirst ? bodyB : bodyA;
        const double turn = turnOf(ownerOf(moving), solver);
        // A corner the contacts do not hold comes at most turn x reach
        // nearer; a rounded part's nearest point moves off its anchor, which
        // then lies r (1 - cos turn) short of it (kept under the position
        // pass's own tolerance, a micrometre).
        const bool cornerCanReach = std::abs(turn) * maxExtent_[moving] > slop;
        if (!cornerCanReach) {
            const double rounding = roundingOf(shape.shape), sinHalf = std::sin(0.5 * turn);
            if (!(rounding > 0.0 && rounding * 2.0 * sinHalf * sinHalf > 1e-7)) continue;
        }
        turnedBodies_.push_back(solver);
    }
    std::sort(turnedBodies_.begin(), turnedBodies_.end());
    if (!staticSweepReady_) prepareStaticSweep();
    turnedContacts_.clear();
    for (const SolvedBody& sb : awakeSolved_) {
        const std::uint32_t i = sb.collider;
        const Collider& owner = colliders_[i];
        if (owner.kinematic) continue;
        const SolverBody& b = bodies_[sb.solver];
        const double travel = length(b.dp) + std::abs(turnOf(i, sb.solver)) * maxExtent_[i];
        if (!(travel > foreseenTravel(i)) &&
            !std::binary_search(turnedBodies_.begin(), turnedBodies_.end(), sb.solver))
            continue;
        forEachSolidShape(i, [&](std::uint32_t shape) {
            const Collider& moving = colliders_[shape];
            const auto take = [&](std::uint32_t fixed) {
                const Collider& f = colliders_[fixed];
                if (f.sensor || !collides(shape, fixed) || (!noCollide_.empty() && joinedNotColliding(shape, fixed)))
                    return;
                turnedContacts_.push_back({sb.solver, shape, fixed});
            };
            for (const std::uint32_t p : planes_) take(p);
            if (staticBoxes_.empty()) return;
            const PresentPose pose = presentPose(shape, b);
            Aabb box = computeAabb(moving.shape, pose.at, pose.q);
            box.lower -= Vec2{slop, slop};
            box.upper += Vec2{slop, slop};
            staticBoxes_.query(box, take);
        });
    }
    if (turnedContacts_.empty()) return false;
    // Each body's are together: the bodies were visited once each.
    bool moved = false;
    for (std::size_t begin = 0; begin < turnedContacts_.size();) {
        const std::uint32_t solver = turnedContacts_[begin].solver;
        std::size_t end = begin;
        while (end < turnedContacts_.size() && turnedContacts_[end].solver == solver) ++end;
        SolverBody& body = bodies_[solver];
        double turned = 0.0;
        for (int pass = 0; pass < positionCorrection_.maxPasses; ++pass) {
            presentContacts_.clear();
            for (std::size_t t = begin; t < end; ++t) {
                const std::uint32_t moving = turnedContacts_[t].moving, fixed = turnedContacts_[t].fixed;
                const PresentPose pose = presentPose(moving, body);
                // Planes are placed by their normal and offset alone (as detect() calls them).
                const bool plane = colliders_[fixed].shape.kind == ShapeKind::Plane;
                // The narrow phase's least margin: a clipped manifold can
                // lose its deep point when its other one lies beyond a zero
                // margin (the points past the slop are all that act).
                const Manifold m = collide(colliders_[fixed].shape, plane ? Vec2{} : centres_[fixed],
                                           plane ? Rot{} : staticRots_[fixed], colliders_[moving].shape, pose.at,
                                           pose.q, 2.0 * kSpeculativeBase);
                for (int i = 0; i < m.pointCount; ++i)
                    presentContacts_.push_back({m.normal, m.points[i].point - pose.centre, m.points[i].separation});
            }
            bool deep = false;
            for (const PresentContact& p : presentContacts_) deep = deep || p.separation < -slop;
            if (!deep) break;
            // Before the first move: the scratch the write-back reads.
            if (!scratchReady) {
                positionScratch_.turned.assign(bodies_.size(), 0.0);
                positionScratch_.moved.assign(bodies_.size(), 0);
                scratchReady = true;
            }
            positionScratch_.moved[solver] = 1;
            moved = true;
            if (!(pushOutOfStatic(body, presentContacts_, positionCorrection_, turned) < -1e-6)) break;
        }
        if (turned != 0.0) positionScratch_.turned[solver] += turned;
        begin = end;
    }
    return moved;
}

void CollisionSystem::prepareStaticSweep() {
    staticSweepReady_ = true;
    std::vector<Aabb> boxes;
    std::vector<std::uint32_t> proxies;
    staticRots_.assign(colliders_.size(), Rot{});
    for (const std::uint32_t i : finite_) {
        const Collider& c = colliders_[i];
        if (c.body >= 0 || c.sensor) continue;
        staticRots_[i] = Rot::fromAngle(angles_[i]);
        boxes.push_back(computeAabb(c.shape, centres_[i], staticRots_[i]));
        proxies.push_back(i);
    }
    for (const std::uint32_t p : planes_) staticRots_[p] = Rot::fromAngle(angles_[p]);
    staticBoxes_.build(boxes, proxies);
    hubShapes_.clear();
    for (const std::uint32_t i : shapesOfHubs_) hubShapes_.push_back({std::uint32_t(colliders_[i].hub), i});
    std::sort(hubShapes_.begin(), hubShapes_.end());
    // A body's smallest reach: its shape's, or a compound body's smallest
    // shape's (a shapeless body never reaches anything: infinite).
    minReach_.assign(colliders_.size(), std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < colliders_.size(); ++i)
        if (colliders_[i].body >= 0 && !colliders_[i].solverOnly) minReach_[i] = smallestReach(colliders_[i].shape);
    for (const auto& [hub, shape] : hubShapes_) minReach_[hub] = std::min(minReach_[hub], minReach_[shape]);
}

void CollisionSystem::sweepAgainstStatic(std::span<Vec2> x) {
    if (!staticSweepReady_) prepareStaticSweep();
    if (staticBoxes_.empty() && planes_.empty()) return;
    // Stopped the linear slop short of the surface, as Box2D's sweep: the
    // contact the next step finds then starts as a touching one.
    const double target = kLinearSlop;
    std::vector<SweptShape> shapes;
    std::vector<std::uint32_t> shapeColliders;
    for (const SolvedBody& sb : awakeSolved_) {
        const std::uint32_t i = sb.collider;
        const Collider& owner = colliders_[i];
        if (owner.kinematic) continue;
        SolverBody& b = bodies_[sb.solver];
        // A body that went farther than the motion its contacts were found
        // for, or farther than half its smallest reach (Box2D's "fast"
        // body): sliding fast along a curved wall, it meets segments ahead
        // whose contacts were not found (a chain segment answers only
        // within its own length).
        const double turn = angles_[i] - stepStartAngle_[i];
        const double travel = length(b.dp) + std::abs(turn) * maxExtent_[i];
        if (!(travel > foreseenTravel(i)) && !(travel > 0.5 * minReach_[i])) continue;
        shapes.clear();
        shapeColliders.clear();
        // Each shape about the body's centre (a compound body's hub).
        forEachSolidShape(i, [&](std::uint32_t j) {
            shapes.push_back({&colliders_[j].shape, j == i ? Vec2{} : colliders_[j].centreOfMass - owner.centreOfMass});
            shapeColliders.push_back(j);
        });
        if (shapes.empty()) continue;
        const BodySweep sweep{stepStart_[i], stepStart_[i] + b.dp, stepStartAngle_[i], angles_[i]};
        double fraction = 1.0;
        for (std::size_t k = 0; k < shapes.size(); ++k) {
            const SweptShape& shape = shapes[k];
            const std::uint32_t j = shapeColliders[k];
            const auto test = [&](std::uint32_t s) {
                const Collider& fixed = colliders_[s];
                if (fixed.sensor || !collides(j, s) || (!noCollide_.empty() && joinedNotColliding(j, s))) return;
                // A static shape's centre of mass (centres_: where its
                // outline is centred) and rotation, which never change.
                const PlacedShape placed{&fixed.shape, centres_[s], staticRots_[s]};
                fraction = std::min(fraction, sweepFraction(sweep, shape, placed, target));
            };
            for (const std::uint32_t p : planes_) test(p);
            if (staticBoxes_.empty()) continue;
            const Rot q0 = Rot::fromAngle(sweep.a0), q1 = Rot::fromAngle(sweep.a1);
            Aabb box = computeAabb(*shape.shape, sweep.c0 + rotate(q0, shape.offset), q0);
            const Aabb end = computeAabb(*shape.shape, sweep.c1 + rotate(q1, shape.offset), q1);
            box.lower = {std::min(box.lower.x, end.lower.x) - target, std::min(box.lower.y, end.lower.y) - target};
            box.upper = {std::max(box.upper.x, end.upper.x) + target, std::max(box.upper.y, end.upper.y) + target};
            staticBoxes_.query(box, test);
        }
        if (!(fraction < 1.0)) continue;
        const Vec2 centre = sweep.centreAt(fraction);
        angles_[i] = sweep.angleAt(fraction);
        b.dp = centre - stepStart_[i];
        b.dq = rotationBy(angles_[i] - stepStartAngle_[i]);
        x[sb.body] = owner.centreOfMass.x == 0.0 && owner.centreOfMass.y == 0.0
                         ? centre
                         : centre - rotate(Rot::fromAngle(angles_[i]), owner.centreOfMass);
    }
}

void CollisionSystem::undoSolverState() {
    joints::restoreInertia(bodies_, stiffened_);
    stiffened_.clear();
    cache_.swap(previousCache_);
    cacheCursor_ = 0;
    for (std::size_t k = 0; k < joints_.size() && k < jointImpulsesBefore_.size(); ++k)
        joints::setImpulses(joints_[k], jointImpulsesBefore_[k]);
}

bool CollisionSystem::isRecord(const ContactConstraint& c, const ContactDetail& d, int i) {
    // Speculative points that never carried load are not contacts.
    return !(d.separation[i] > kLinearSlop && c.points[i].normalImpulse == 0.0 && d.restitutionImpulse[i] == 0.0);
}

const std::vector<ContactConstraint>& CollisionSystem::recordedConstraints() const {
    return recordsFromKept_ ? keptConstraints_ : constraints_;
}

const std::vector<ContactDetail>& CollisionSystem::recordedDetails() const {
    return recordsFromKept_ ? keptDetails_ : details_;
}

void CollisionSystem::makeRecords() const {
    recordsPending_ = false;
    const std::vector<ContactConstraint>& constraints = recordedConstraints();
    const std::vector<ContactDetail>& details = recordedDetails();
    for (std::size_t k = 0; k < constraints.size(); ++k) {
        const ContactConstraint& c = constraints[k];
        const ContactDetail& d = details[k];
        for (int i = 0; i < c.pointCount; ++i) {
            if (!isRecord(c, d, i)) continue;
            const ContactPoint& p = c.points[i];
            ContactRecord r;
            r.a = colliders_[d.colliderA].entity;
            r.b = colliders_[d.colliderB].entity;
            r.point = d.point[i];
            r.normal = c.normal;
            // Records put the static side (a plane or static body) second,
            // as world.hpp promises, with the normal still pointing a -> b.
            if (c.bodyA == 0 && c.bodyB != 0) {
                std::swap(r.a, r.b);
                r.normal = -r.normal;
            }
            r.depth = -d.separation[i];
            r.normalImpulse = p.normalImpulse + d.restitutionImpulse[i];
            r.tangentImpulse = p.tangentImpulse;
            records_.push_back(r);
            recordPairs_.emplace_back(d.colliderA, d.colliderB);
        }
    }
}

std::size_t CollisionSystem::contactPointCount() const {
    return records_.size() + (recordsPending_ ? pendingRecordCount_ : 0);
}

void CollisionSystem::endStep() {
    // Back to the joints for what reads them after the step (breaking,
    // records, snapshots, the next step's warm start), also after a step cut
    // short, which undoSolverState then takes back.
    if (jointBundlesReady_) jointBundles_.storeImpulses(joints_);
    storeImpacts(constraints_, details_, impactScratch_);
    joints::restoreInertia(bodies_, stiffened_);
    stiffened_.clear();
    // The cache this step started from is kept (swapped, not copied) so a
    // divergence can put it back.
    previousCache_.swap(cache_);
    cache_.clear();
    coloured_.storeImpulses(constraints_);
    records_.resize(sleepingRecordCount_);  // the sleeping islands' contacts stay
    recordPairs_.resize(sleepingRecordCount_);
    // The awake contacts' records are made when asked for (contacts()): a
    // run that never looks at them does not pay for them.
    recordsPending_ = true;
    recordsFromKept_ = false;
    pendingRecordCount_ = 0;
    for (std::size_t k = 0; k < constraints_.size(); ++k) {
        const ContactConstraint& c = constraints_[k];
        const ContactDetail& d = details_[k];
        // A manifold's two points in the order of their keys: the clipped
        // points' feature ids come in either order, and one pair out of
        // order makes the whole cache take the sort below.
        const bool swapped = c.pointCount == 2 && (d.id[1] & 0xFFFF) < (d.id[0] & 0xFFFF);
        for (int k = 0; k < c.pointCount; ++k) {
            const int i = swapped ? 1 - k : k;
            const ContactPoint& p = c.points[i];
            const std::uint64_t key = CachedImpulse::makeKey(d.colliderA, d.colliderB, d.id[i]);
            cache_.push_back({key, p.normalImpulse, p.tangentImpulse});
            pendingRecordCount_ += isRecord(c, d, i) ? 1 : 0;
        }
    }
    jointRecords_.clear();
    // A sleeping joint's bodies have not moved since their island fell
    // asleep (or since the World was built): it reports where they rest,
    // which its last awake step, if it had one here, no longer says.
    if (anySleeping_) joints::poseResting(joints_, centres_, angles_);
    if (!joints_.empty()) {
        turns_.resize(bodies_.size());
        for (std::size_t s = 0; s < bodies_.size(); ++s) turns_[s] = std::atan2(bodies_[s].dq.s, bodies_[s].dq.c);
    }
    for (const joints::JointConstraint& j : joints_) {
        if (j.broken) continue;
        JointRecord r;
        r.joint = j.entity;
        r.a = j.entityA;
        r.b = j.entityB;
        const joints::JointAnchors anchors = j.asleep ? joints::restingAnchors(j) : joints::jointAnchors(j, bodies_);
        r.anchorA = anchors.a;
        r.anchorB = anchors.b;
        r.separation = anchors.separation;
        r.force = joints::jointForce(j, lastH_);
        r.torque = joints::jointTorque(j, lastH_);
        r.angle = j.asleep ? j.deltaAngle : joints::jointAngle(j, std::span<const double>(turns_));
        jointRecords_.push_back(r);
    }
    // Usually already in order (constraints follow the sorted pairs); the
    // check is cheaper than sorting sorted data.
    if (!std::is_sorted(cache_.begin(), cache_.end())) std::sort(cache_.begin(), cache_.end());
}

bool CollisionSystem::sensedInstead(std::uint32_t a, std::uint32_t b) {
    if (!colliders_[a].sensor && !colliders_[b].sensor) return false;
    // Tested at the step's end (updateSensors), never a contact. Sensors do
    // not sense each other (Box2D's rule); filters apply.
    if (colliders_[a].sensor != colliders_[b].sensor &&
        (!filtered_ || shouldCollide(filters_[a], filters_[b])))
        sensorCandidates_.push_back(colliders_[a].sensor ? (std::uint64_t(a) << 32) | b : (std::uint64_t(b) << 32) | a);
    return true;
}

bool CollisionSystem::sensorOverlap(std::uint32_t s, std::uint32_t o, std::span<const Vec2> x) const {
    const Collider& cs = colliders_[s];
    const Collider& co = colliders_[o];
    const bool planeS = cs.shape.kind == ShapeKind::Plane, planeO = co.shape.kind == ShapeKind::Plane;
    const Manifold m = collide(cs.shape, planeS ? Vec2{} : centreOfMass(s, x),
                               planeS ? Rot{} : Rot::fromAngle(angles_[s]), co.shape,
                               planeO ? Vec2{} : centreOfMass(o, x), planeO ? Rot{} : Rot::fromAngle(angles_[o]), 0.0);
    for (int i = 0; i < m.pointCount; ++i)
        if (m.points[i].separation < 0.0) return true;
    return false;
}

void CollisionSystem::updateSensors(std::span<const Vec2> x) {
    std::vector<std::uint64_t> now;
    now.reserve(sensorCandidates_.size());
    for (const std::uint64_t key : sensorCandidates_)
        if (sensorOverlap(std::uint32_t(key >> 32), std::uint32_t(key & 0xFFFFFFFFu), x)) now.push_back(key);
    // A sleeping body stays where it was, and so does its overlap: its
    // pairs are not looked at while it sleeps.
    for (const std::uint64_t key : sensorOverlaps_)
        if (colliderAsleep_[key >> 32] || colliderAsleep_[key & 0xFFFFFFFFu]) now.push_back(key);
    std::sort(now.begin(), now.end());
    now.erase(std::unique(now.begin(), now.end()), now.end());
    sensorEvents_.clear();
    const auto event = [&](std::uint64_t key, bool begin) {
        sensorEvents_.push_back({colliders_[key >> 32].entity, colliders_[key & 0xFFFFFFFFu].entity, begin});
    };
    // Both lists are sorted: one merge finds what began and what ended.
    std::size_t i = 0, j = 0;
    while (i < now.size() || j < sensorOverlaps_.size()) {
        if (j == sensorOverlaps_.size() || (i < now.size() && now[i] < sensorOverlaps_[j])) event(now[i++], true);
        else if (i == now.size() || sensorOverlaps_[j] < now[i]) event(sensorOverlaps_[j++], false);
        else ++i, ++j;
    }
    sensorOverlaps_.swap(now);
}

void CollisionSystem::initSensors(std::span<const Vec2> x) {
    sensorOverlaps_.clear();
    sensorEvents_.clear();
    if (!anySensor_) return;
    syncShapes();
    // Every sensor against every shape that could be inside it: sensors are
    // few, and this runs once per build or restore.
    const std::size_t n = colliders_.size();
    for (std::uint32_t s = 0; s < n; ++s) {
        if (!colliders_[s].sensor || colliders_[s].solverOnly) continue;
        for (std::uint32_t o = 0; o < n; ++o) {
            const Collider& other = colliders_[o];
            if (o == s || other.sensor || other.solverOnly || sameBody(s, o)) continue;
            // The pairs a step looks at: a plane meets only dynamic shapes,
            // and two shapes meet when at least one moves.
            const bool planeS = colliders_[s].shape.kind == ShapeKind::Plane, planeO = other.shape.kind == ShapeKind::Plane;
            if (planeS && planeO) continue;
            if (planeS || planeO) {
                const Collider& finite = planeS ? other : colliders_[s];
                if (finite.body < 0 || finite.kinematic) continue;
            } else if (colliders_[s].body < 0 && other.body < 0) {
                continue;
            }
            if (filtered_ && !shouldCollide(filters_[s], filters_[o])) continue;
            if (sensorOverlap(s, o, x)) sensorOverlaps_.push_back((std::uint64_t(s) << 32) | o);
        }
    }
}

std::vector<std::pair<Entity, Entity>> CollisionSystem::sensorOverlaps() const {
    std::vector<std::pair<Entity, Entity>> out;
    out.reserve(sensorOverlaps_.size());
    for (const std::uint64_t key : sensorOverlaps_)
        out.emplace_back(colliders_[key >> 32].entity, colliders_[key & 0xFFFFFFFFu].entity);
    return out;
}

} // namespace stepwise::collision
