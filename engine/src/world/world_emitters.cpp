// Emitters (docs/format.md, "Templates and emitters"): copies of a
// template added and removed while the World runs, in place. A copy's
// bodies are appended to every array (state vector, force model, sleep,
// colliders, joints, springs) and a removed copy's are taken out with the
// survivors keeping their order, so the arrays are always those World::build
// would make of the scene as it now is (its copies last, in the order they
// appeared): a run saved and loaded steps on bit for bit as the run that
// saved it. Nothing is rebuilt from the scene; every other body's state and
// warm start stay as they are.

#include "world/world_impl.hpp"
#include "world/world_collisions.hpp"

#include "templates.hpp"

#include "stepwise/component_table.hpp"
#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_set>

namespace stepwise {

using detail::kNoBody;

namespace {

/// An emitter makes at most this many copies in one step; the rest wait for
/// the next step (an interval far below dt would otherwise loop for long).
constexpr int kMaxEmissionsPerStep = 1000;

bool hasShape(const Registry& reg, Entity e) {
    return reg.has<Radius>(e) || reg.has<Box>(e) || reg.has<Polygon>(e) || reg.has<Capsule>(e) || reg.has<Shapes>(e);
}

/// The template's entities in scene order: those with its `template` value
/// and the joints and springs among them.
std::vector<Entity> templateMembers(const Registry& reg, const std::string& name) {
    std::vector<Entity> out;
    for (const Entity e : reg.entities())
        if (const std::string* t = detail::templateOf(reg, e); t && *t == name) out.push_back(e);
    return out;
}

/// The member a copy is placed by: the first with a position.
Entity anchorOf(const Registry& reg, const std::vector<Entity>& members) {
    for (const Entity e : members)
        if (reg.has<Position>(e)) return e;
    return {};
}

std::string copyName(const std::string& base, const Registry& reg, Entity member, Entity anchor, std::size_t k) {
    if (member == anchor) return base;
    const Name* name = reg.tryGet<Name>(member);
    return base + "/" + (name && !name->value.empty() ? name->value : std::to_string(k));
}

} // namespace

std::optional<Error> compileEmitters(const Scene& scene, WorldImpl& w) {
    const Registry& reg = scene.registry;
    if (reg.count<Emitter>() == 0) return std::nullopt;
    w.registry = std::make_shared<Registry>(reg);
    // A copy is every entity named TEMPLATE#N or TEMPLATE#N/..., in scene
    // order: the bodies and joints it was made with (made in that order),
    // whatever has become of the template since (a body added to it or
    // deleted from it, or from the copy, while the copy is alive).
    std::unordered_map<std::string, std::vector<Entity>> copyParts;
    for (const Entity e : reg.entities())
        if (const Name* n = reg.tryGet<Name>(e); n && n->value.find('#') != std::string::npos)
            copyParts[n->value.substr(0, n->value.find('/'))].push_back(e);
    const std::vector<Entity>& order = reg.entities();
    for (std::size_t i = 0; i < order.size(); ++i) {
        const Entity e = order[i];
        const Emitter* em = reg.tryGet<Emitter>(e);
        if (!em) continue;
        const Name* name = reg.tryGet<Name>(e);
        const std::string label = detail::entityLabel(i, name ? &name->value : nullptr);
        EmitterRun run;
        run.entity = e;
        run.params = *em;
        if (!run.params.next) run.params.next = scene.world.time;
        run.body = w.bodyOfSlot[e.index];
        if (const Position* p = reg.tryGet<Position>(e)) run.position = p->value;
        run.members = templateMembers(reg, em->templateName);
        if (anchorOf(reg, run.members).isNull())
            return Error{label + ": emitter: no body has \"template\": \"" + em->templateName + "\""};
        // The loader refuses these; a scene made in code or in the editor
        // reaches here unchecked. A copy's bodies join the contact solver as
        // shapes, after the level's own, as a build orders them.
        for (const Entity m : run.members) {
            if (reg.has<Joint>(m) || reg.has<Spring>(m)) continue;
            const bool fixed = (reg.has<Static>(m) && reg.tryGet<Static>(m)->value) ||
                               (reg.has<Kinematic>(m) && reg.tryGet<Kinematic>(m)->value);
            if (fixed || !hasShape(reg, m) || reg.has<Attractor>(m) || reg.has<Boid>(m) || reg.has<Emitter>(m)) {
                const auto at = std::find(order.begin(), order.end(), m);
                const Name* mn = reg.tryGet<Name>(m);
                return Error{detail::entityLabel(std::size_t(at - order.begin()), mn ? &mn->value : nullptr) +
                             ": template \"" + em->templateName +
                             "\": a template entity is a dynamic body with a shape (radius, box, polygon, capsule or shapes)"};
            }
        }
        run.key = detail::emitterKey(reg, e, i);
        for (const int k : copyNumbers(*em)) {
            const std::string base = em->templateName + "#" + std::to_string(k);
            const auto it = copyParts.find(base);
            if (it == copyParts.end())
                return Error{label + ": emitter: copy \"" + base + "\" is alive in its run state but not in the scene"};
            run.copies.push_back(it->second);
            run.numbers.push_back(k);
        }
        w.emitters.push_back(std::move(run));
    }
    return std::nullopt;
}

long long WorldImpl::nextCopyNumber(const std::string& templateName) const {
    // One past every number the template's emitters have given (each gave
    // its `emitted`, and while the emitters stay the same their numbers are
    // 1 up to the sum) and every copy alive (an emitter of the template
    // deleted takes its count out of the sum): the same from the scene a
    // save writes as from the running World, so a resume numbers as the
    // long run does.
    long long given = 0, alive = 0;
    for (const EmitterRun& em : emitters) {
        if (em.params.templateName != templateName) continue;
        given += em.params.emitted;
        if (!em.numbers.empty()) alive = std::max<long long>(alive, em.numbers.back());
    }
    return std::max(given, alive) + 1;
}

void WorldImpl::runEmitters() {
    if (emitters.empty()) return;
    emitterEvents.clear();
    // Due at the first step that starts within half a step of the time, so
    // an interval that is a whole number of steps emits every that many
    // steps, whatever the rounding of the summed time.
    const double now = settings.time + 0.5 * settings.dt;
    bool due = false;
    for (const EmitterRun& em : emitters) {
        const Emitter& p = em.params;
        due = due || now >= *p.next || (p.lifetime && p.alive > 0 && now >= *p.oldest + *p.lifetime);
    }
    if (!due) return;
    // Snapshots hold the registry their layout was made with: while one
    // does (anything but this World and its own layout), change a copy.
    if (layout.use_count() > 1 || registry.use_count() > 2) registry = std::make_shared<Registry>(*registry);
    Registry& reg = *registry;
    std::vector<Entity> removed, added;
    for (EmitterRun& em : emitters) {
        Emitter& p = em.params;
        bool changed = false;  // a copy came or went: its list of copies alive is written again
        const auto removeOldest = [&] {
            changed = true;
            // The copy's name is its first entity's up to the '/' (the
            // anchor's, unless the designer deleted that one).
            if (const Name* name = reg.tryGet<Name>(em.copies.front().front()))
                emitterEvents.push_back({em.entity, name->value.substr(0, name->value.find('/')), false});
            for (const Entity e : em.copies.front()) {
                const auto it = std::find(added.begin(), added.end(), e);
                if (it != added.end()) added.erase(it);
                else removed.push_back(e);
                reg.destroy(e);
            }
            em.copies.pop_front();
            em.numbers.pop_front();
            --p.alive;
            // Copies appear `interval` apart, and the times were summed the
            // same way: the next oldest appeared at exactly this time.
            if (p.alive > 0) p.oldest = *p.oldest + p.interval;
            else p.oldest.reset();
        };
        while (p.lifetime && p.alive > 0 && now >= *p.oldest + *p.lifetime) removeOldest();
        const Entity anchor = anchorOf(reg, em.members);
        // A run never writes a time or a count a level cannot hold: past
        // them the emitter stops.
        const auto canEmit = [&] {
            return *p.next + p.interval <= kMaxMagnitude && p.emitted < std::numeric_limits<int>::max() &&
                   nextCopyNumber(p.templateName) <= std::numeric_limits<int>::max();
        };
        for (int made = 0; now >= *p.next && made < kMaxEmissionsPerStep && canEmit(); ++made) {
            if (p.alive >= p.count) removeOldest();
            const int number = int(nextCopyNumber(p.templateName));
            ++p.emitted;
            const std::string base = p.templateName + "#" + std::to_string(number);
            const Vec2 at = em.body != kNoBody ? Vec2{xs()[2 * em.body], xs()[2 * em.body + 1]} : em.position;
            const Vec2 offset = at - reg.tryGet<Position>(anchor)->value;
            const double turn = detail::emitterTurn(settings.seed, em.key, number, p.spread);
            const double c = std::cos(turn), s = std::sin(turn);
            const Vec2 velocity{c * p.velocity.x - s * p.velocity.y, s * p.velocity.x + c * p.velocity.y};
            std::unordered_map<Entity, Entity> copyOf;
            std::vector<Entity> copy;
            for (std::size_t k = 0; k < em.members.size(); ++k) {
                const Entity member = em.members[k];
                const std::string name = copyName(base, reg, member, anchor, k);
                // Through a scratch registry: copying within one registry
                // could move the source while its pool grows.
                Registry scratch;
                const Entity t = scratch.create();
                copyComponents(reg, member, scratch, t);
                const Entity e = reg.create();
                copyComponents(scratch, t, reg, e);
                reg.remove<Template>(e);
                reg.emplace<Name>(e, Name{name});
                if (Position* pos = reg.tryGet<Position>(e)) {
                    pos->value += offset;
                    reg.emplace<Velocity>(e, Velocity{velocity});
                }
                if (Spring* sp = reg.tryGet<Spring>(e); sp && sp->anchor) *sp->anchor += offset;
                if (Joint* j = reg.tryGet<Joint>(e); j && j->b.isNull()) j->localB += offset;
                copyOf.emplace(member, e);
                copy.push_back(e);
            }
            for (const Entity e : copy)
                forEachEntityRefMutable(reg, e, [&](const ComponentInfo&, const FieldInfo&, Entity& ref) {
                    if (const auto it = copyOf.find(ref); it != copyOf.end()) ref = it->second;
                });
            added.insert(added.end(), copy.begin(), copy.end());
            emitterEvents.push_back({em.entity, base, true});
            em.copies.push_back(std::move(copy));
            em.numbers.push_back(number);
            changed = true;
            if (p.alive == 0) p.oldest = *p.next;
            ++p.alive;
            p.next = *p.next + p.interval;
        }
        if (changed)
            p.copies = detail::storedCopyNumbers(std::vector<int>(em.numbers.begin(), em.numbers.end()), p.emitted);
    }
    changeBodies(reg, removed, added);
}

void WorldImpl::renumberEmitters(const Registry& reg) {
    const std::vector<Entity>& order = reg.entities();
    std::vector<std::uint32_t> sceneIndex(reg.slotCount(), 0);
    for (std::size_t i = 0; i < order.size(); ++i) sceneIndex[order[i].index] = std::uint32_t(i);
    for (EmitterRun& run : emitters) {
        run.key = detail::emitterKey(reg, run.entity, sceneIndex[run.entity.index]);
        run.body = bodyIndexOf(run.entity);
    }
}

void WorldImpl::changeBodies(const Registry& reg, std::span<const Entity> removed, std::span<const Entity> added) {
    // Flags by entity slot: a removed entity's slot may be reused by an
    // added one, which is told apart by its generation. An undone add
    // takes its slot out of the registry's table with it, so the removed
    // count too (this World's own bodies are within bodyOfSlot).
    std::size_t slots = std::max(reg.slotCount(), bodyOfSlot.size());
    for (const Entity e : removed) slots = std::max(slots, std::size_t(e.index) + 1);
    std::vector<Entity> goneAt(removed.empty() ? 0 : slots);
    for (const Entity e : removed) goneAt[e.index] = e;
    const auto isGone = [&goneAt](Entity e) { return e.index < goneAt.size() && goneAt[e.index] == e; };
    const std::size_t oldN = bodyEntity.size();
    // A removed body's island wakes: what touched it moves on without it.
    if (!removed.empty())
        for (std::size_t b = 0; b < oldN; ++b)
            if (sleep.island[b] >= 0 && isGone(bodyEntity[b])) sleep.wake(std::uint32_t(b));
    std::vector<std::int32_t> bodyMap(oldN, -1);
    std::size_t n = 0;
    for (std::size_t b = 0; b < oldN; ++b)
        if (!isGone(bodyEntity[b])) bodyMap[b] = std::int32_t(n++);
    const auto compact = [&](auto& values, std::size_t stride) {
        if (values.empty() || n == oldN) return;  // nothing gone: every value stays where it is
        std::size_t out = 0;
        for (std::size_t b = 0; b < oldN; ++b) {
            if (bodyMap[b] < 0) continue;
            for (std::size_t k = 0; k < stride; ++k) values[out * stride + k] = values[b * stride + k];
            ++out;
        }
        values.resize(out * stride);
    };
    const auto remap = [&](std::uint32_t& body) {
        if (body != kNoBody) body = std::uint32_t(bodyMap[body]);
    };
    detail::AlignedDoubles nextX(x[current].begin(), x[current].end()), nextV(v[current].begin(), v[current].end());
    // Every array with a value (or `stride` values) per body.
    const auto eachBodyArray = [&](auto&& f) {
        f(nextX, 2);
        f(nextV, 2);
        f(bodyEntity, 1);
        f(bodyName, 1);
        f(model.mass, 1);
        f(model.invMass, 1);
        f(isKinematic, 1);
        f(sleep.timer, 1);
        f(sleep.anchor, detail::kAnchorStride);
        f(sleep.anchored, 1);
        f(sleep.island, 1);
        f(sleep.asleep, 1);
        f(sleep.extent, 1);
        f(sleep.restless, 1);
    };
    eachBodyArray(compact);
    for (std::int32_t& label : sleep.island)
        if (label >= 0) label = bodyMap[std::size_t(label)];
    for (std::uint32_t& b : kinematicBody) remap(b);
    for (std::uint32_t& b : spinBody) remap(b);
    for (std::uint32_t& b : model.boids.body) remap(b);
    for (detail::AttractorData& a : model.attractors) remap(a.body);
    {
        std::size_t out = 0;
        for (std::size_t s = 0; s < model.springs.size(); ++s) {
            detail::SpringData d = model.springs[s];
            if (isGone(d.entity) || (d.a != kNoBody && bodyMap[d.a] < 0) || (d.b != kNoBody && bodyMap[d.b] < 0))
                continue;
            remap(d.a);
            remap(d.b);
            model.springs[out] = d;
            springName[out] = springName[s];
            ++out;
        }
        model.springs.resize(out);
        springName.resize(out);
    }

    // Where each entity stands in the scene order (messages name it so).
    std::vector<std::uint32_t> sceneIndex(slots, 0);
    for (std::size_t i = 0; i < reg.entities().size(); ++i) sceneIndex[reg.entities()[i].index] = std::uint32_t(i);

    // The new bodies, at the end in scene order (a static entity is shapes
    // only, as World::build has it).
    const std::size_t keptBodies = n;
    bool staticChanged = false;
    for (const Entity e : added) {
        const Position* p = reg.tryGet<Position>(e);
        if (!p || reg.has<Joint>(e) || reg.has<Spring>(e)) continue;
        if (const Static* st = reg.tryGet<Static>(e); st && st->value) {
            staticChanged = true;
            continue;
        }
        const Velocity* vel = reg.tryGet<Velocity>(e);
        const Shapes* compound = reg.tryGet<Shapes>(e);
        const double mass = reg.has<Mass>(e) ? reg.tryGet<Mass>(e)->value
                            : compound     ? compoundMassProperties(*compound, std::nullopt).mass
                                           : 1.0;
        bodyEntity.push_back(e);
        const Name* name = reg.tryGet<Name>(e);
        bodyName.push_back(name ? name->value : std::string());
        nextX.push_back(p->value.x);
        nextX.push_back(p->value.y);
        nextV.push_back(vel ? vel->value.x : 0.0);
        nextV.push_back(vel ? vel->value.y : 0.0);
        model.mass.push_back(mass);
        model.invMass.push_back(1.0 / mass);
        if (!isKinematic.empty()) isKinematic.push_back(0);
        sleep.timer.push_back(0.0);
        sleep.anchor.insert(sleep.anchor.end(), detail::kAnchorStride, 0.0);
        sleep.anchored.push_back(0);
        sleep.island.push_back(-1);
        sleep.asleep.push_back(0);
        sleep.extent.push_back(0.0);
        sleep.restless.push_back(0);
    }
    n = bodyEntity.size();
    // Bodies brought back where they stood (an undone delete) take their
    // places in the scene order, as a build lists them. The kept keep their
    // order, and so do the new, so only a merge of the two moves anything.
    const auto sceneOfBody = [&](std::size_t b) { return sceneIndex[bodyEntity[b].index]; };
    if (keptBodies > 0 && n > keptBodies && sceneOfBody(keptBodies) < sceneOfBody(keptBodies - 1)) {
        std::vector<std::uint32_t> from(n);  // from[k]: the body that goes k-th
        for (std::size_t b = 0; b < n; ++b) from[b] = std::uint32_t(b);
        std::stable_sort(from.begin(), from.end(),
                         [&](std::uint32_t a, std::uint32_t b) { return sceneOfBody(a) < sceneOfBody(b); });
        std::vector<std::int32_t> to(n);
        for (std::size_t k = 0; k < n; ++k) to[from[k]] = std::int32_t(k);
        eachBodyArray([&](auto& values, std::size_t stride) {
            if (values.empty()) return;
            const auto was = values;
            for (std::size_t k = 0; k < n; ++k)
                for (std::size_t i = 0; i < stride; ++i) values[k * stride + i] = was[from[k] * stride + i];
        });
        for (std::int32_t& b : bodyMap)
            if (b >= 0) b = to[std::size_t(b)];
        for (std::int32_t& label : sleep.island)
            if (label >= 0) label = to[std::size_t(label)];
        const auto moved = [&](std::uint32_t& body) {
            if (body != kNoBody) body = std::uint32_t(to[body]);
        };
        for (std::uint32_t& b : kinematicBody) moved(b);
        for (std::uint32_t& b : spinBody) moved(b);
        for (std::uint32_t& b : model.boids.body) moved(b);
        for (detail::AttractorData& a : model.attractors) moved(a.body);
        for (detail::SpringData& d : model.springs) {
            moved(d.a);
            moved(d.b);
        }
    }
    model.n = n;
    bodyOfSlot.assign(slots, kNoBody);
    for (std::size_t b = 0; b < n; ++b) bodyOfSlot[bodyEntity[b].index] = std::uint32_t(b);
    const auto bodyOf = [this](Entity e) { return e.index < bodyOfSlot.size() ? bodyOfSlot[e.index] : kNoBody; };
    bodySceneIndex.resize(n);
    for (std::size_t b = 0; b < n; ++b) bodySceneIndex[b] = sceneIndex[bodyEntity[b].index];
    // The kept springs' places moved with the removed entities; an unnamed
    // one is called by its place.
    for (std::size_t s = 0; s < model.springs.size(); ++s) {
        detail::SpringData& d = model.springs[s];
        d.sceneIndex = sceneIndex[d.entity.index];
        const Name* name = reg.tryGet<Name>(d.entity);
        if (!name || name->value.empty()) springName[s] = "entity " + std::to_string(d.sceneIndex);
    }

    // Forces: gravity pulls once there is a body; drag as World::build sets it.
    model.gravityOn = n > 0 && (model.gx != 0.0 || model.gy != 0.0);
    if (switches.drag) {
        model.dragOn = false;
        model.dragB.assign(n, 0.0);
        for (std::size_t b = 0; b < n; ++b)
            if (const Drag* d = reg.tryGet<Drag>(bodyEntity[b]); d && d->value > 0.0) {
                model.dragB[b] = d->value;
                model.dragOn = true;
            }
        model.dragRate.resize(model.dragOn ? n : 0);
        if (model.dragOn)
            for (std::size_t b = 0; b < n; ++b) model.dragRate[b] = model.dragB[b] * model.invMass[b];
        else model.dragB.clear();
    }
    if (switches.springs)
        for (const Entity e : added) {
            const Spring* s = reg.tryGet<Spring>(e);
            if (!s) continue;
            detail::SpringData d;
            d.a = bodyOf(s->a);
            Vec2 pa = reg.tryGet<Position>(s->a)->value, pb;
            if (!s->b.isNull()) {
                d.b = bodyOf(s->b);
                pb = reg.tryGet<Position>(s->b)->value;
            } else {
                pb = s->anchor.value_or(Vec2{});
            }
            d.fx = pb.x;
            d.fy = pb.y;
            d.k = s->k;
            d.c = s->damping;
            d.rest = s->restLength ? *s->restLength : length(pa - pb);
            d.sceneIndex = sceneIndex[e.index];
            d.entity = e;
            model.springs.push_back(d);
            const Name* name = reg.tryGet<Name>(e);
            springName.push_back(name && !name->value.empty() ? name->value : "entity " + std::to_string(d.sceneIndex));
        }

    // Shapes and joints.
    if (collision) {
        const std::size_t oldColliders = collision->colliderCount();
        std::vector<collision::CollisionSystem::ColliderAdd> adds;
        std::vector<collision::CollisionSystem::JointAdd> jointAdds;
        detail::ShapeStorage storage;  // add() copies the outlines; they stay put until then
        std::unordered_map<std::uint32_t, std::int32_t> addOf;  // entity index -> its first place in `adds`
        if (switches.collisions)
            for (const Entity e : added) {
                const std::size_t first = adds.size();
                detail::collidersFor(reg, e, bodyOf, kNoBody, storage, adds);
                if (adds.size() > first) addOf.emplace(e.index, std::int32_t(first));
            }
        for (const Entity e : added) {
            const Joint* stored = reg.tryGet<Joint>(e);
            if (!stored) continue;
            Joint joint = *stored;
            completeJoint(reg, joint);
            collision::CollisionSystem::JointAdd add;
            joints::JointConstraint& j = add.joint;
            j.entity = e;
            j.entityA = joint.a;
            j.entityB = joint.b;
            detail::fillJointParams(joint, j);
            std::int32_t filter[2] = {-1, -1};
            const Entity ends[2] = {joint.a, joint.b};
            joints::JointEnd* out[2] = {&j.a, &j.b};
            for (int k = 0; k < 2; ++k) {
                joints::JointEnd& je = *out[k];
                je.local = k == 0 ? joint.localA : joint.localB;
                if (ends[k].isNull()) continue;  // the world
                const Angle* an = reg.tryGet<Angle>(ends[k]);
                je.fixedCentre = reg.tryGet<Position>(ends[k])->value;
                je.fixedAngle = an ? an->value : 0.0;
                auto it = addOf.find(ends[k].index);
                if (it == addOf.end()) {
                    // Contacts switched off: the body joins the solver only.
                    collision::CollisionSystem::ColliderAdd only;
                    only.collider.body = std::int32_t(bodyOf(ends[k]));
                    only.collider.mass = reg.has<Mass>(ends[k]) ? reg.tryGet<Mass>(ends[k])->value : 1.0;
                    only.collider.entity = ends[k];
                    only.collider.solverOnly = true;
                    only.collider.inertia = 0.5 * only.collider.mass * detail::kShapelessRadius * detail::kShapelessRadius;
                    only.angle = je.fixedAngle;
                    it = addOf.emplace(ends[k].index, std::int32_t(adds.size())).first;
                    adds.push_back(only);
                }
                filter[k] = it->second;
                je.collider = it->second;
                je.local = je.local - adds[std::size_t(it->second)].collider.centreOfMass;
            }
            add.filterA = filter[0];
            add.filterB = filter[1];
            add.collideConnected = joint.collideConnected;
            jointAdds.push_back(add);
        }
        // In place: the gone taken out, then the new appended (only the new
        // colliders are looked at when nothing went). New entities that are
        // not the scene's last (an undone delete) go between kept ones, and
        // with bodies held in the solver only by a joint (a build puts them
        // after every shape) new shapes go before them: a new system.
        const std::vector<Entity>& order = reg.entities();
        const bool atEnd = added.size() <= order.size() &&
                           std::equal(added.begin(), added.end(), order.end() - std::ptrdiff_t(added.size()));
        const bool appends = atEnd && collision->appendsAtEnd();
        std::size_t firstNew = oldColliders;
        if (!removed.empty()) {
            std::vector<std::uint8_t> dropCollider(oldColliders, 0);
            for (std::size_t c = 0; c < oldColliders; ++c) {
                dropCollider[c] = isGone(collision->collider(c).entity) ? 1 : 0;
                staticChanged = staticChanged || (dropCollider[c] && collision->collider(c).body < 0);
            }
            const std::span<const joints::JointConstraint> oldJoints = collision->jointConstraints();
            std::vector<std::uint8_t> dropJoint(oldJoints.size(), 0);
            for (std::size_t k = 0; k < oldJoints.size(); ++k) dropJoint[k] = isGone(oldJoints[k].entity) ? 1 : 0;
            if ((adds.empty() && jointAdds.empty()) || appends) {
                collision->removed(dropCollider, dropJoint, bodyMap);
            } else {
                collision = collision->changed(dropCollider, dropJoint, bodyMap, adds, jointAdds, sceneIndex);
                collision->setSleepSource(&sleep.asleep, [impl = this](std::uint32_t body) { impl->sleep.wake(body); });
                adds.clear();
                jointAdds.clear();
            }
            firstNew = 0;
        }
        if (!adds.empty() || !jointAdds.empty()) {
            if (appends) {
                collision->appended(adds, jointAdds);
            } else {
                // Nothing went (else the branch above took the adds): the
                // kept bodies' map is the merge's alone.
                std::vector<std::uint8_t> none(collision->colliderCount(), 0), noJoint(collision->jointConstraints().size(), 0);
                collision = collision->changed(none, noJoint, bodyMap, adds, jointAdds, sceneIndex);
                collision->setSleepSource(&sleep.asleep, [impl = this](std::uint32_t body) { impl->sleep.wake(body); });
                firstNew = 0;
            }
        }
        if (firstNew == 0) colliderOfBody.assign(n, -1);
        else colliderOfBody.resize(n, -1);
        for (std::size_t c = firstNew; c < collision->colliderCount(); ++c)
            if (const std::int32_t body = collision->collider(c).body; body >= 0) {
                // A compound body's hub stands for the body, as World::build has it.
                if (collision->collider(c).hub >= 0) continue;
                colliderOfBody[std::size_t(body)] = std::int32_t(c);
                sleep.extent[std::size_t(body)] = collision->collider(c).solverOnly && !collision->isHub(c)
                                                      ? detail::kShapelessRadius
                                                      : collision->maxExtent(c);
            }
    } else {
        colliderOfBody.assign(n, -1);
    }

    // The state, in buffer 0 as World::build leaves it.
    x[0] = std::move(nextX);
    v[0] = std::move(nextV);
    x[1].assign(2 * n, 0.0);
    v[1].assign(2 * n, 0.0);
    current = 0;
    if (settings.substeps > 1) {
        backupX.assign(2 * n, 0.0);
        backupV.assign(2 * n, 0.0);
    }
    stepStartKnown = false;
    // A static shape that came or went may have held up any island.
    if (staticChanged) sleep.wakeAll();
    sleep.refresh();
    sleep.changed = true;
    sleepChanged();
    if (collision && collision->hasSensors()) collision->initSensors(detail::asVec2(xs(), n));
    setIntegratorKind(kind);
    listActiveSystems();
    layout = makeLayout();
}

std::size_t World::emitterCount() const { return impl().emitters.size(); }

std::span<const EmitterEvent> World::emitterEvents() const { return impl().emitterEvents; }

const std::string* World::copyName(Entity e) const {
    const WorldImpl& w = impl();
    if (!w.registry || !w.registry->alive(e)) return nullptr;
    const Name* name = w.registry->tryGet<Name>(e);
    return name ? &name->value : nullptr;
}

std::size_t World::copiesAlive() const {
    std::size_t n = 0;
    for (const EmitterRun& e : impl().emitters) n += e.copies.size();
    return n;
}

} // namespace stepwise
