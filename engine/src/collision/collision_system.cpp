#include "collision/collision_system.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace stepwise::collision {

namespace {
/// Contacts within this distance count as touching; also the base of the
/// speculative margin. Metres (Box2D's b2_linearSlop).
constexpr double kLinearSlop = 0.005;
constexpr double kSpeculativeBase = 4.0 * kLinearSlop;

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
    case ShapeKind::Plane: return 0.0;
    case ShapeKind::Polygon: {
        // Fan of triangles (0, vi, vi+1) about the centre of mass (the
        // origin of the outline): each has area cross(vi, vi+1)/2 and polar
        // second moment area/6 (vi.vi + vi.vi+1 + vi+1.vi+1); I = m J / A.
        const ConvexPolygon& p = *shape.polygon;
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

void CollisionSystem::add(const Collider& c, double angle, double angularVelocity) {
    const std::uint32_t index = std::uint32_t(colliders_.size());
    colliders_.push_back(c);
    if (c.shape.kind == ShapeKind::Polygon) {
        polygons_.push_back(*c.shape.polygon);
        colliders_.back().shape.polygon = &polygons_.back();
    }
    const bool dynamic = c.body >= 0 && c.mass > 0.0;
    angles_.push_back(angle);
    angularVelocities_.push_back(dynamic ? angularVelocity : 0.0);
    invMass_.push_back(dynamic ? 1.0 / c.mass : 0.0);
    const double inertia = !dynamic ? 0.0 : c.solverOnly ? c.inertia : momentOfInertia(c.shape, c.mass);
    colliders_.back().inertia = inertia;
    invInertia_.push_back(inertia > 0.0 ? 1.0 / inertia : 0.0);
    maxExtent_.push_back(c.solverOnly                          ? 0.0
                         : c.shape.kind == ShapeKind::Circle    ? c.shape.radius
                         : c.shape.kind == ShapeKind::Polygon ? c.shape.polygon->radius
                                                              : length(c.shape.halfExtents));
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

void CollisionSystem::setWarmStartCache(std::vector<CachedImpulse> cache) {
    if (!std::is_sorted(cache.begin(), cache.end())) std::sort(cache.begin(), cache.end());
    cache_ = std::move(cache);
    cacheCursor_ = 0;
}

void CollisionSystem::addJoint(const joints::JointConstraint& joint, std::int32_t filterA, std::int32_t filterB,
                               bool collideConnected) {
    if (bodies_.empty()) bodies_.push_back(SolverBody{});
    joints_.push_back(joint);
    if (!collideConnected && filterA >= 0 && filterB >= 0) {
        const auto lo = std::uint64_t(std::min(filterA, filterB)), hi = std::uint64_t(std::max(filterA, filterB));
        const std::uint64_t key = (lo << 32) | hi;
        noCollide_.insert(std::lower_bound(noCollide_.begin(), noCollide_.end(), key), key);
    }
}

void CollisionSystem::addManifold(std::uint32_t a, std::uint32_t b, const Manifold& m,
                                  std::span<const Vec2> centres) {
    if (m.pointCount == 0) return;
    ContactConstraint c;
    ContactDetail detail;
    detail.colliderA = a;
    detail.colliderB = b;
    detail.restitution = std::max(colliders_[a].restitution, colliders_[b].restitution);
    c.bodyA = solverIndex_[a];
    c.bodyB = solverIndex_[b];
    c.touchesStatic = c.bodyA == 0 || c.bodyB == 0;
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
        const Vec2 anchorA = colliders_[a].shape.kind == ShapeKind::Plane ? Vec2{} : detail.point[i] - centres[a];
        const Vec2 anchorB = colliders_[b].shape.kind == ShapeKind::Plane ? Vec2{} : detail.point[i] - centres[b];
        p.rnA = cross(anchorA, m.normal);
        p.rnB = cross(anchorB, m.normal);
        p.dnA = dot(anchorA, m.normal);
        p.dnB = dot(anchorB, m.normal);
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
        auto it = std::lower_bound(from, cache_.end(), CachedImpulse{pairKey, 0, 0});
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
    details_.push_back(detail);
    constraints_.push_back(c);
}

void CollisionSystem::beginStep(std::span<const Vec2> x, std::span<const Vec2> v, double dt, int substeps) {
    dt_ = dt;
    substeps_ = substeps;
    const auto start = std::chrono::steady_clock::now();
    const std::size_t n = colliders_.size();
    centres_.resize(n);
    margins_.resize(n);
    stepStart_.resize(n);
    stepStartAngle_.assign(angles_.begin(), angles_.end());
    for (std::size_t i = 0; i < n; ++i) {
        const Collider& c = colliders_[i];
        centres_[i] = centreOfMass(i, x);
        stepStart_[i] = centres_[i];
        // Speculative margin: how far any point of the shape can travel this
        // step, so a contact exists before a fast body reaches a surface.
        const double speed = c.body >= 0 ? length(v[std::size_t(c.body)]) : 0.0;
        margins_[i] = kSpeculativeBase + dt * (speed + std::abs(angularVelocities_[i]) * maxExtent_[i]);
    }

    // One sincos per collider per step, shared by the boxes and the narrow phase.
    std::vector<Rot>& rots = rotScratch_;
    rots.resize(n);
    for (std::size_t i = 0; i < n; ++i) rots[i] = Rot::fromAngle(angles_[i]);

    boxes_.resize(finite_.size());
    movable_.resize(finite_.size());
    for (std::size_t k = 0; k < finite_.size(); ++k) {
        const std::uint32_t i = finite_[k];
        Aabb box = computeAabb(colliders_[i].shape, centres_[i], rots[i]);
        const Vec2 fat{margins_[i], margins_[i]};
        box.lower -= fat;
        box.upper += fat;
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
    broadPhase_.findPairs(boxes_, movable_, pairs_);
    timings_.broadPhaseMs = msSince(start);

    const auto narrowStart = std::chrono::steady_clock::now();
    constraints_.clear();
    details_.clear();
    cacheCursor_ = 0;
    for (const ProxyPair& pair : pairs_) {
        const std::uint32_t a = finite_[pair.a], b = finite_[pair.b];
        if (!noCollide_.empty()) {
            // Bodies joined with collide_connected false do not collide.
            const std::uint64_t key = (std::uint64_t(std::min(a, b)) << 32) | std::max(a, b);
            if (std::binary_search(noCollide_.begin(), noCollide_.end(), key)) continue;
        }
        const Manifold m = collide(colliders_[a].shape, centres_[a], rots[a], colliders_[b].shape, centres_[b],
                                   rots[b], margins_[a] + margins_[b]);
        addManifold(a, b, m, centres_);
    }
    // Planes against every movable finite shape: planes are few and infinite,
    // so they stay out of the broad phase.
    for (const std::uint32_t p : planes_) {
        for (const std::uint32_t b : finite_) {
            if (colliders_[b].body < 0) continue;
            const Manifold m = collide(colliders_[p].shape, {}, {}, colliders_[b].shape, centres_[b], rots[b],
                                       margins_[b]);
            addManifold(p, b, m, centres_);
        }
    }

    // Gather velocities into the solver bodies.
    for (std::size_t i = 0; i < n; ++i) {
        const std::uint32_t s = solverIndex_[i];
        if (s == 0) continue;
        bodies_[s].v = v[std::size_t(colliders_[i].body)];
        bodies_[s].w = angularVelocities_[i];
        bodies_[s].dp = {};
        bodies_[s].dq = {};
    }
    prepareContacts(constraints_, details_, bodies_);
    if (!joints_.empty()) joints::prepareJoints(joints_, bodies_, centres_, angles_);
    timings_.narrowPhaseMs = msSince(narrowStart);
    timings_.solveMs = 0.0;
}

void CollisionSystem::solveSubstep(std::span<Vec2> x, std::span<Vec2> v, double h) {
    const auto start = std::chrono::steady_clock::now();
    const std::size_t n = colliders_.size();
    unconstrainedV_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        const std::uint32_t s = solverIndex_[i];
        if (s == 0) continue;
        const std::size_t body = std::size_t(colliders_[i].body);
        bodies_[s].v = v[body];
        bodies_[s].w = angularVelocities_[i];
        unconstrainedV_[i] = v[body];
    }
    // Contact stiffness may not exceed a quarter of the substep rate, or the
    // soft constraint itself becomes unstable (Box2D v3.0's cap; v3.1
    // lowered it to an eighth). Contacts
    // with static bodies may be twice as stiff, but under the same cap:
    // above it a heavy box on light boxes never comes to rest (measured).
    const double hertz = std::min(settings_.contactHertz, 0.25 / h);
    const Softness soft = Softness::make(hertz, settings_.dampingRatio, h);
    const Softness staticSoft = Softness::make(std::min(2.0 * hertz, 0.25 / h), settings_.dampingRatio, h);

    // A row of n touching bodies needs up to n passes; 64 bounds the cost.
    // Joints: rigid ones are corrected at up to half the substep rate
    // (twice the contacts' cap, as Box2D v3), solved before the contacts.
    const bool jointed = !joints_.empty();
    const Softness jointSoft =
        Softness::make(std::min(jointSettings_.hertz, 0.5 / h), jointSettings_.dampingRatio, h);
    lastH_ = h;

    propagateImpacts(constraints_, details_, bodies_, h, settings_.restitutionThreshold, 64);
    if (settings_.warmStart) {
        if (jointed) joints::warmStartJoints(joints_, bodies_);
        warmStart(constraints_, bodies_);
    }
    bool reverse = false;
    for (int it = 0; it < settings_.iterations; ++it, reverse = !reverse) {
        if (jointed) joints::solveJoints(joints_, bodies_, h, jointSoft, true);
        solveContacts(constraints_, bodies_, h, soft, staticSoft, settings_.pushMaxVelocity, true, reverse);
    }

    offsetAngleBefore_.resize(offsetBodies_.size());
    for (std::size_t k = 0; k < offsetBodies_.size(); ++k) offsetAngleBefore_[k] = angles_[offsetBodies_[k]];
    // Positions: the integrator moved x with the unconstrained velocity; add
    // the contact velocity change over the substep. Angles integrate here
    // (only contacts make torque).
    for (std::size_t i = 0; i < n; ++i) {
        const std::uint32_t s = solverIndex_[i];
        if (s == 0) continue;
        SolverBody& b = bodies_[s];
        const std::size_t body = std::size_t(colliders_[i].body);
        x[body] += h * (b.v - unconstrainedV_[i]);
        angles_[i] += h * b.w;
        b.dp = x[body] - stepStart_[i];
        b.dq = Rot::fromAngle(angles_[i] - stepStartAngle_[i]);
    }
    // A body turning about a centre of mass off its position moves its
    // position: p = c - R(angle) offset, with the centre c moved as above.
    for (std::size_t k = 0; k < offsetBodies_.size(); ++k) {
        const std::uint32_t i = offsetBodies_[k];
        const Collider& c = colliders_[i];
        SolverBody& b = bodies_[solverIndex_[i]];
        const std::size_t body = std::size_t(c.body);
        x[body] -= rotate(Rot::fromAngle(angles_[i]), c.centreOfMass) -
                   rotate(Rot::fromAngle(offsetAngleBefore_[k]), c.centreOfMass);
        b.dp = centreOfMass(i, std::span<const Vec2>(x.data(), x.size())) - stepStart_[i];
    }
    for (int it = 0; it < settings_.relaxIterations; ++it, reverse = !reverse) {
        if (jointed) joints::solveJoints(joints_, bodies_, h, jointSoft, false);
        solveContacts(constraints_, bodies_, h, soft, staticSoft, settings_.pushMaxVelocity, false, reverse);
    }

    for (std::size_t i = 0; i < n; ++i) {
        const std::uint32_t s = solverIndex_[i];
        if (s == 0) continue;
        v[std::size_t(colliders_[i].body)] = bodies_[s].v;
        angularVelocities_[i] = bodies_[s].w;
    }
    timings_.solveMs += msSince(start);
}

void CollisionSystem::endStep() {
    cache_.clear();
    records_.clear();
    for (std::size_t k = 0; k < constraints_.size(); ++k) {
        const ContactConstraint& c = constraints_[k];
        const ContactDetail& d = details_[k];
        for (int i = 0; i < c.pointCount; ++i) {
            const ContactPoint& p = c.points[i];
            const std::uint64_t key = CachedImpulse::makeKey(d.colliderA, d.colliderB, d.id[i]);
            cache_.push_back({key, p.normalImpulse, p.tangentImpulse});
            // Speculative points that never carried load are not contacts.
            if (d.separation[i] > kLinearSlop && p.normalImpulse == 0.0 && d.restitutionImpulse[i] == 0.0) continue;
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
        }
    }
    jointRecords_.clear();
    for (const joints::JointConstraint& j : joints_) {
        JointRecord r;
        r.joint = j.entity;
        r.a = j.entityA;
        r.b = j.entityB;
        const joints::JointAnchors anchors = joints::jointAnchors(j, bodies_);
        r.anchorA = anchors.a;
        r.anchorB = anchors.b;
        r.separation = anchors.separation;
        r.force = joints::jointForce(j, lastH_);
        r.torque = joints::jointTorque(j, lastH_);
        r.angle = joints::jointAngle(j, bodies_);
        jointRecords_.push_back(r);
    }
    // Usually already in order (constraints follow the sorted pairs); the
    // check is cheaper than sorting sorted data.
    if (!std::is_sorted(cache_.begin(), cache_.end())) std::sort(cache_.begin(), cache_.end());
}

} // namespace stepwise::collision
