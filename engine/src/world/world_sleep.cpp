// The World's side of sleeping (world/islands.hpp): what a step does with
// the islands, and which islands an edit wakes.

#include "world/world_collisions.hpp"
#include "world/rest_balance.hpp"
#include "world/world_impl.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <span>
#include <utility>
#include <vector>

namespace stepwise {

void WorldImpl::sleepChanged() {
    if (!sleep.changed) return;
    sleep.changed = false;
    if (collision) collision->refreshSleeping(detail::asVec2(xs(), bodyEntity.size()));
}

void WorldImpl::islandEdges(std::vector<std::pair<std::uint32_t, std::uint32_t>>& edges) const {
    for (const detail::SpringData& s : model.springs)
        if (s.b != detail::kNoBody) edges.emplace_back(s.a, s.b);
    if (collision) collision->bodyEdges(edges);
}

void WorldImpl::updateSleep(const double* startX, const double* startV) {
    if (!sleep.enabled) return;
    double* px = xs();
    double* pv = vs();
    // Asleep through the step: integrated with the rest (the integrators
    // run over whole arrays) but not solved; put back exactly.
    for (const std::uint32_t b : sleep.sleeping) {
        px[2 * b] = startX[2 * b];
        px[2 * b + 1] = startX[2 * b + 1];
        pv[2 * b] = startV[2 * b];
        pv[2 * b + 1] = startV[2 * b + 1];
    }
    const std::size_t n = bodyEntity.size();
    std::vector<double>& speed = sleepSpeed;
    speed.resize(n);
    for (std::size_t b = 0; b < n; ++b) {
        if (sleep.island[b] >= 0) continue;
        double w = 0.0;
        if (colliderOfBody[b] >= 0) w = collision->angularVelocity(std::size_t(colliderOfBody[b]));
        speed[b] = std::sqrt(pv[2 * b] * pv[2 * b] + pv[2 * b + 1] * pv[2 * b + 1]) + sleep.extent[b] * std::abs(w);
    }
    std::vector<double>& angle = sleepAngle;
    angle.assign(n, 0.0);
    for (std::size_t b = 0; b < n; ++b)
        if (colliderOfBody[b] >= 0) angle[b] = collision->angle(std::size_t(colliderOfBody[b]));
    const auto fieldAccel = [&](std::size_t b) {
        const Vec2 g = model.fieldAt(px[2 * b], px[2 * b + 1], std::uint32_t(b), px);
        return std::hypot(g.x, g.y);
    };
    if (!sleep.advanceTimers(speed, px, pv, angle, settings.dt, fieldAccel)) return;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
    islandEdges(edges);
    // An island falls asleep as it is: velocities and spins (all under
    // sleep_velocity) are kept, frozen, so a wake resumes it exactly where
    // it paused, and a saved file shows the state it paused in.
    // What holds each body up: its touching contacts with the static world
    // and whether a joint or a spring ties it there. Asked only on the steps
    // some island is ready to sleep.
    std::vector<collision::Support> supports;
    std::vector<std::uint8_t> held(n, 0);
    if (collision) collision->staticSupports(supports, held);
    for (const detail::SpringData& s : model.springs)
        if (s.b == detail::kNoBody) held[s.a] = 1;
    std::stable_sort(supports.begin(), supports.end(),
              [](const collision::Support& a, const collision::Support& b) { return a.body < b.body; });
    std::vector<collision::Support> islandSupports;
    const auto couldRest = [&](std::span<const std::uint32_t> bodies) {
        islandSupports.clear();
        Vec2 pull{};
        for (const std::uint32_t b : bodies) {
            if (held[b]) return true;  // a joint or spring may hold any pull: the velocity rule decides
            pull += model.mass[b] * model.fieldAt(px[2 * b], px[2 * b + 1], b, px);
            const auto first = std::lower_bound(supports.begin(), supports.end(), b,
                                                [](const collision::Support& s, std::uint32_t body) { return s.body < body; });
            for (auto it = first; it != supports.end() && it->body == b; ++it) islandSupports.push_back(*it);
        }
        return detail::couldRest(islandSupports, pull, bodies.size() == 1);
    };
    if (sleep.fallAsleep(edges, couldRest).empty()) return;
    sleepChanged();
}

namespace {

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool sameBits(Vec2 a, Vec2 b) { return sameBits(a.x, b.x) && sameBits(a.y, b.y); }

/// Everything of a collider an edit can change (its motion aside).
bool sameCollider(const collision::Collider& a, const collision::Collider& b) {
    if (a.shape.kind != b.shape.kind || !sameBits(a.shape.radius, b.shape.radius) ||
        !sameBits(a.shape.halfExtents, b.shape.halfExtents) || !sameBits(a.shape.normal, b.shape.normal) ||
        !sameBits(a.shape.offset, b.shape.offset) ||
        (a.body < 0 && !sameBits(a.staticPosition, b.staticPosition)) ||  // a body's is where it was built
        !sameBits(a.mass, b.mass) || !sameBits(a.restitution, b.restitution) || !sameBits(a.friction, b.friction) ||
        a.solverOnly != b.solverOnly || !sameBits(a.inertia, b.inertia) || !sameBits(a.centreOfMass, b.centreOfMass))
        return false;
    if (a.shape.polygon && b.shape.polygon) {
        const collision::ConvexPolygon &p = *a.shape.polygon, &q = *b.shape.polygon;
        if (p.count != q.count || !sameBits(p.cornerRadius, q.cornerRadius)) return false;
        for (int i = 0; i < p.count; ++i)
            if (!sameBits(p.vertices[i], q.vertices[i])) return false;
    }
    if ((a.shape.segment == nullptr) != (b.shape.segment == nullptr)) return false;
    if (a.shape.segment) {
        const collision::ChainSegment &p = *a.shape.segment, &q = *b.shape.segment;
        if (!sameBits(p.p1, q.p1) || !sameBits(p.p2, q.p2) || !sameBits(p.ghost1, q.ghost1) ||
            !sameBits(p.ghost2, q.ghost2) || p.open1 != q.open1 || p.open2 != q.open2 || p.index != q.index)
            return false;
    }
    return true;
}

bool sameJoint(const joints::JointConstraint& a, const joints::JointConstraint& b) {
    const auto sameEnd = [](const joints::JointEnd& p, const joints::JointEnd& q) {
        return sameBits(p.fixedCentre, q.fixedCentre) && sameBits(p.fixedAngle, q.fixedAngle) && sameBits(p.local, q.local);
    };
    return a.kind == b.kind && a.entityA == b.entityA && a.entityB == b.entityB && sameEnd(a.a, b.a) &&
           sameEnd(a.b, b.b) && sameBits(a.localAxis, b.localAxis) && sameBits(a.referenceAngle, b.referenceAngle) &&
           a.hasLower == b.hasLower && a.hasUpper == b.hasUpper && sameBits(a.lower, b.lower) &&
           sameBits(a.upper, b.upper) && a.motor == b.motor && sameBits(a.motorSpeed, b.motorSpeed) &&
           sameBits(a.maxMotor, b.maxMotor) && sameBits(a.length, b.length) && sameBits(a.stiffnessHz, b.stiffnessHz) &&
           sameBits(a.dampingRatio, b.dampingRatio) && sameBits(a.springHz, b.springHz) &&
           sameBits(a.springDampingRatio, b.springDampingRatio) && sameBits(a.maxForce, b.maxForce);
}

/// The settings that change how bodies move (time and the dopri5 step are
/// state, not settings).
/// A value per live entity, looked up through the handle: a table indexed
/// by the entity's slot that checks the generation, so a lookup is one
/// array read (no hashing) and a handle to a destroyed entity finds nothing.
class EntitySlots {
public:
    static constexpr std::uint32_t kNone = ~std::uint32_t(0);
    void set(Entity e, std::uint32_t value) {
        if (e.isNull()) return;
        if (e.index >= slots_.size()) slots_.resize(std::size_t(e.index) + 1, {0, kNone});
        slots_[e.index] = {e.generation, value};
    }
    std::uint32_t find(Entity e) const {
        if (e.isNull() || e.index >= slots_.size() || slots_[e.index].first != e.generation) return kNone;
        return slots_[e.index].second;
    }

private:
    std::vector<std::pair<std::uint32_t, std::uint32_t>> slots_;  // (generation, value)
};

bool sameMotionSettings(WorldSettings a, WorldSettings b) {
    a.time = b.time;
    a.adaptiveStep = b.adaptiveStep;
    return a == b;
}

} // namespace

void WorldImpl::wakeForChangedSettings() {
    if (sleep.anyAsleep() && !sameMotionSettings(settings, sleptUnder)) {
        sleep.wakeAll();
        sleepChanged();
    }
    sleptUnder = settings;
}

void WorldImpl::wakeEdited(const WorldImpl& before) {
    // Settings: judged at the next step (wakeForChangedSettings).
    sleptUnder = before.sleptUnder;
    if (!sleep.anyAsleep()) return;
    EntitySlots bodyOf, oldBodyOf;
    for (std::size_t b = 0; b < bodyEntity.size(); ++b) bodyOf.set(bodyEntity[b], std::uint32_t(b));
    for (std::size_t b = 0; b < before.bodyEntity.size(); ++b) oldBodyOf.set(before.bodyEntity[b], std::uint32_t(b));
    const auto wakeEntity = [&](Entity e) {
        if (const std::uint32_t b = bodyOf.find(e); b != EntitySlots::kNone) sleep.wake(b);
    };
    // Bodies: state and parameters, bit for bit (an untouched body was
    // written back from the old World and reads back the same).
    const double *px = xs(), *pv = vs(), *ox = before.xs(), *ov = before.vs();
    for (std::size_t b = 0; b < bodyEntity.size(); ++b) {
        if (sleep.island[b] < 0) continue;
        const std::uint32_t o = oldBodyOf.find(bodyEntity[b]);
        const bool same = o != EntitySlots::kNone && sameBits(px[2 * b], ox[2 * o]) &&
                          sameBits(px[2 * b + 1], ox[2 * o + 1]) && sameBits(pv[2 * b], ov[2 * o]) &&
                          sameBits(pv[2 * b + 1], ov[2 * o + 1]) && sameBits(model.mass[b], before.model.mass[o]) &&
                          sameBits(model.dragOn ? model.dragB[b] : 0.0, before.model.dragOn ? before.model.dragB[o] : 0.0);
        if (!same) sleep.wake(std::uint32_t(b));
    }
    // Shapes: a changed, added or removed static shape wakes everything (it
    // may hold up any island); a changed body's shape, angle or spin wakes
    // its island; a removed shape wakes what it touched (its cached contacts).
    if (collision || before.collision) {
        // An entity's colliders are consecutive (a compound body's hub, then
        // its shapes): the slots hold each entity's first, and a shape is
        // found by its part among them.
        EntitySlots oldFirst, newCollider;
        const auto oldColliderOf = [&](const collision::Collider& col) {
            std::uint32_t o = oldFirst.find(col.entity);
            if (o == EntitySlots::kNone) return o;
            // A chain's segments follow its first in order (after its hub on
            // a kinematic body).
            if (col.shape.segment) {
                if (before.collision->collider(o).part == collision::Collider::kHubPart) ++o;
                o += col.shape.segment->index;
            }
            for (; o < before.collision->colliderCount() && before.collision->collider(o).entity == col.entity; ++o)
                if (before.collision->collider(o).part == col.part) return o;
            return EntitySlots::kNone;
        };
        std::size_t staticCount = 0, oldStaticCount = 0;
        if (before.collision)
            for (std::size_t c = 0; c < before.collision->colliderCount(); ++c) {
                if (oldFirst.find(before.collision->collider(c).entity) == EntitySlots::kNone)
                    oldFirst.set(before.collision->collider(c).entity, std::uint32_t(c));
                oldStaticCount += before.collision->collider(c).body < 0 ? 1 : 0;
            }
        bool staticEdited = false;
        if (collision)
            for (std::size_t c = 0; c < collision->colliderCount(); ++c) {
                const collision::Collider& col = collision->collider(c);
                newCollider.set(col.entity, std::uint32_t(c));
                const std::uint32_t o = oldColliderOf(col);
                const bool same = o != EntitySlots::kNone && sameCollider(col, before.collision->collider(o)) &&
                                  sameBits(collision->angle(c), before.collision->angle(o)) &&
                                  sameBits(collision->angularVelocity(c), before.collision->angularVelocity(o));
                if (col.body < 0) {
                    ++staticCount;
                    staticEdited = staticEdited || !same;
                } else if (!same) {
                    sleep.wake(std::uint32_t(col.body));
                }
            }
        if (staticEdited || staticCount != oldStaticCount) sleep.wakeAll();
        if (before.collision) {
            const std::vector<Entity>& oldColliders = before.layout->colliders;
            for (const CachedImpulse& e : before.collision->warmStartCache()) {
                const Entity a = oldColliders[e.colliderA()], b = oldColliders[e.colliderB()];
                if (newCollider.find(a) == EntitySlots::kNone) wakeEntity(b);
                if (newCollider.find(b) == EntitySlots::kNone) wakeEntity(a);
            }
        }
        // Joints: changed, added or removed ones wake both ends.
        EntitySlots oldJoint, kept;
        const std::span<const joints::JointConstraint> oldJoints =
            before.collision ? before.collision->jointConstraints() : std::span<const joints::JointConstraint>{};
        for (std::size_t j = 0; j < oldJoints.size(); ++j) oldJoint.set(oldJoints[j].entity, std::uint32_t(j));
        if (collision)
            for (const joints::JointConstraint& j : collision->jointConstraints()) {
                const std::uint32_t o = oldJoint.find(j.entity);
                if (o != EntitySlots::kNone) kept.set(j.entity, 1);
                if (o == EntitySlots::kNone || !sameJoint(j, oldJoints[o])) {
                    wakeEntity(j.entityA);
                    wakeEntity(j.entityB);
                }
            }
        for (const joints::JointConstraint& j : oldJoints)
            if (kept.find(j.entity) == EntitySlots::kNone) {
                wakeEntity(j.entityA);
                wakeEntity(j.entityB);
            }
    }
    // Springs: the same, by entity.
    EntitySlots oldSpring, springKept;
    for (std::size_t i = 0; i < before.model.springs.size(); ++i)
        oldSpring.set(before.model.springs[i].entity, std::uint32_t(i));
    const auto endEntity = [](const WorldImpl& w, std::uint32_t body) {
        return body == detail::kNoBody ? Entity{} : w.bodyEntity[body];
    };
    for (const detail::SpringData& s : model.springs) {
        const std::uint32_t i = oldSpring.find(s.entity);
        bool same = i != EntitySlots::kNone;
        if (same) {
            const detail::SpringData& o = before.model.springs[i];
            springKept.set(s.entity, 1);
            same = endEntity(*this, s.a) == endEntity(before, o.a) && endEntity(*this, s.b) == endEntity(before, o.b) &&
                   sameBits(s.k, o.k) && sameBits(s.c, o.c) && sameBits(s.rest, o.rest) && sameBits(s.fx, o.fx) &&
                   sameBits(s.fy, o.fy);
        }
        if (!same) {
            sleep.wake(s.a);
            if (s.b != detail::kNoBody) sleep.wake(s.b);
        }
    }
    for (const detail::SpringData& o : before.model.springs)
        if (springKept.find(o.entity) == EntitySlots::kNone) {
            wakeEntity(endEntity(before, o.a));
            wakeEntity(endEntity(before, o.b));
        }
    sleepChanged();
}

bool World::asleep(std::size_t body) const { return impl_->sleep.island.at(body) >= 0; }
std::size_t World::sleepingBodyCount() const { return impl_->sleep.sleeping.size(); }
std::vector<Entity> World::sleepingBodies() const {
    std::vector<Entity> out;
    out.reserve(impl_->sleep.sleeping.size());
    for (const std::uint32_t b : impl_->sleep.sleeping) out.push_back(impl_->bodyEntity[b]);
    return out;
}

bool World::wakeIfSettingsChanged() {
    WorldImpl& w = *impl_;
    const std::size_t before = w.sleep.sleeping.size();
    w.wakeForChangedSettings();
    return w.sleep.sleeping.size() != before;
}

bool World::wake(Entity entity) {
    WorldImpl& w = *impl_;
    const auto it = std::find(w.bodyEntity.begin(), w.bodyEntity.end(), entity);
    if (it == w.bodyEntity.end()) return false;
    const bool woke = w.sleep.wake(std::uint32_t(it - w.bodyEntity.begin()));
    w.sleepChanged();
    return woke;
}

} // namespace stepwise
