#include "collision/contact_bundles.hpp"

#include "collision/simd_lanes.hpp"

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstring>

namespace stepwise::collision {

namespace {

using namespace simd;

static_assert(kContactLanes % kLanes == 0, "a bundle is whole vectors of simd_lanes.hpp");

struct PassArgs {
    SolverBody* bodies;
    ContactBundle<1>* one;
    std::size_t oneCount;
    ContactBundle<2>* two;
    std::size_t twoCount;
    Softness soft, staticSoft;
    double invH, pushMaxVelocity;
    double* deepest;  ///< per contact, or null: see ColouredContacts::solve
};

// Each copy of the kernels in a namespace of its own, apart from PassArgs:
// argument-dependent lookup would otherwise see both.
namespace narrow {
#include "collision/contact_kernels.inl"
} // namespace narrow

} // namespace

#ifdef STEPWISE_SIMD_DISPATCH
#pragma GCC push_options
#pragma GCC target("avx512f,avx512dq")
namespace {
namespace wide {
#include "collision/contact_kernels.inl"

template <int Mode>
__attribute__((target("avx512f,avx512dq"))) void onAvx512Dq(const PassArgs& args) {
    colourPass<Mode, D8>(args);
}
} // namespace wide
} // namespace
#pragma GCC pop_options
#endif

namespace {

using PassKernel = void (*)(const PassArgs&);

/// Eight lanes in one register on AVX-512; four at a time elsewhere.
template <int Mode>
PassKernel passKernel() {
#ifdef STEPWISE_SIMD_DISPATCH
    static const bool dq = __builtin_cpu_supports("avx512dq");
    switch (detail::simdLevel()) {
        case detail::SimdLevel::Avx512:
            return dq ? wide::onAvx512Dq<Mode> : onAvx512<PassArgs, narrow::colourPass<Mode, D4>>;
        case detail::SimdLevel::Avx2: return onAvx2<PassArgs, narrow::colourPass<Mode, D4>>;
        default: break;
    }
#endif
    return onBaseline<PassArgs, narrow::colourPass<Mode, D4>>;
}

template <int Points>
void fillLane(ContactBundle<Points>& bundle, int lane, const ContactConstraint& c, std::uint32_t source,
              std::span<const SolverBody> bodies) {
    const SolverBody& a = bodies[c.bodyA];
    const SolverBody& b = bodies[c.bodyB];
    bundle.bodyA[lane] = c.bodyA;
    bundle.bodyB[lane] = c.bodyB;
    bundle.source[lane] = source;
    bundle.nx[lane] = c.normal.x;
    bundle.ny[lane] = c.normal.y;
    bundle.friction[lane] = c.friction;
    bundle.invInertiaA[lane] = a.invInertia;
    bundle.invInertiaB[lane] = b.invInertia;
    bundle.flags[lane] = (c.touchesStatic ? kTouchesStatic : 0) | (c.block ? kBlock : 0) | (c.roundA ? kRoundA : 0) |
                         (c.roundB ? kRoundB : 0);
    if constexpr (Points == 2) {
        bundle.k11[lane] = c.blockMass.k11;
        bundle.k12[lane] = c.blockMass.k12;
        bundle.k22[lane] = c.blockMass.k22;
    }
    for (int i = 0; i < Points; ++i) {
        const ContactPoint& p = c.points[i];
        PointLanes& q = bundle.points[i];
        q.rnA[lane] = p.rnA;
        q.rnB[lane] = p.rnB;
        q.dnA[lane] = p.dnA;
        q.dnB[lane] = p.dnB;
        q.adjustedSeparation[lane] = p.adjustedSeparation;
        q.normalMass[lane] = p.normalMass;
        q.tangentMass[lane] = p.tangentMass;
        q.normalImpulse[lane] = p.normalImpulse;
        q.tangentImpulse[lane] = p.tangentImpulse;
    }
}

/// ColouredContacts::Preparation's work on one contact.
void prepare(ContactConstraint& c, std::size_t k, const ColouredContacts::Preparation& preparation,
             std::span<const SolverBody> bodies) {
    prepareContact(c, preparation.details[k], bodies[c.bodyA], bodies[c.bodyB]);
    if (preparation.warmStartBound) boundWarmStart(c, *preparation.warmStartBound);
}

/// Bundles the contacts `order` (all with `Points` points) at the end of
/// `out`, preparing each; lanes left over stay unused (all zero: static
/// body 0 against itself).
template <int Points>
void bundle(std::vector<ContactBundle<Points>>& out, std::span<const std::uint32_t> order,
            std::span<ContactConstraint> contacts, const ColouredContacts::Preparation& preparation,
            std::span<const std::uint32_t> pairBodies, std::span<const SolverBody> bodies) {
    const std::size_t first = out.size(), count = (order.size() + kContactLanes - 1) / kContactLanes;
    out.resize(first + count);
    // fillLane sets every field of a used lane; only the last bundle can
    // have unused lanes, which must be all zero.
    if (count > 0) std::memset(static_cast<void*>(&out.back()), 0, sizeof(ContactBundle<Points>));
    // A colour's contacts are scattered through `contacts` (about 240 bytes
    // each), their details through `details` and their bodies through
    // `bodies`: the preparation and the copy wait on memory, not
    // arithmetic. Fetch the contacts and the separations of their details
    // a few lanes ahead, and the bodies a few lanes ahead too, named by the
    // packed pairs (reading them from a contact fetched only lanes before
    // waited on that contact).
    constexpr std::size_t kContactAhead = 8, kBodiesAhead = 4;
    for (std::size_t k = 0; k < order.size(); ++k) {
        if (k + kContactAhead < order.size()) {
            const std::size_t ahead = order[k + kContactAhead];
            const char* line = reinterpret_cast<const char*>(&contacts[ahead]);
            for (std::size_t at = 0; at < sizeof(ContactConstraint); at += 64) __builtin_prefetch(line + at);
            __builtin_prefetch(line + sizeof(ContactConstraint) - 1);  // the last line, when the contact straddles one more
            const ContactDetail& detail = preparation.details[ahead];
            __builtin_prefetch(&detail.separation[0]);
            __builtin_prefetch(&detail.separation[1]);
        }
        if (k + kBodiesAhead < order.size()) {
            // Both lines of each body: the inverse inertia sits on the
            // second (the iterations' fields fill the first).
            const std::size_t ahead = order[k + kBodiesAhead];
            const SolverBody& a = bodies[pairBodies[2 * ahead]];
            const SolverBody& b = bodies[pairBodies[2 * ahead + 1]];
            __builtin_prefetch(&a);
            __builtin_prefetch(&a.invInertia);
            __builtin_prefetch(&b);
            __builtin_prefetch(&b.invInertia);
        }
        ContactConstraint& c = contacts[order[k]];
        prepare(c, order[k], preparation, bodies);
        fillLane(out[first + k / kContactLanes], int(k % kContactLanes), c, order[k], bodies);
    }
    for (std::size_t k = order.size(); k < count * kContactLanes; ++k)
        out[first + k / kContactLanes].source[k % kContactLanes] = ~0u;
}

/// Visits each used lane's impulses as (bodyA, bodyB, normal, tangent).
template <int Points, typename Bundles, typename Visit>
void forEachLane(Bundles& bundles, Visit&& visit) {
    for (auto& b : bundles)
        for (int l = 0; l < kContactLanes; ++l) {
            if (b.source[l] == ~0u) continue;
            for (int i = 0; i < Points; ++i)
                visit(b.bodyA[l], b.bodyB[l], b.source[l], i, b.points[i].normalImpulse[l],
                      b.points[i].tangentImpulse[l]);
        }
}

template <int Points>
void storeLanes(std::span<const ContactBundle<Points>> bundles, std::span<ContactConstraint> contacts) {
    // The contacts are written in colour order, scattered through the
    // array: ask for the impulses' lines of the bundle two ahead.
    constexpr std::size_t kAhead = 2;
    for (std::size_t k = 0; k < bundles.size(); ++k) {
        if (k + kAhead < bundles.size())
            for (const std::uint32_t source : bundles[k + kAhead].source)
                if (source != ~0u)
                    for (int i = 0; i < Points; ++i) __builtin_prefetch(&contacts[source].points[i].normalImpulse, 1);
        const ContactBundle<Points>& b = bundles[k];
        for (int l = 0; l < kContactLanes; ++l) {
            if (b.source[l] == ~0u) continue;
            ContactConstraint& c = contacts[b.source[l]];
            for (int i = 0; i < Points; ++i) {
                c.points[i].normalImpulse = b.points[i].normalImpulse[l];
                c.points[i].tangentImpulse = b.points[i].tangentImpulse[l];
            }
        }
    }
}

} // namespace

void ColouredContacts::build(std::span<ContactConstraint> contacts, const Preparation& preparation,
                             const ContactPairs& pairs, std::span<const SolverBody> bodies, bool simd,
                             std::span<const std::uint8_t> heldOut) {
    simd_ = simd;
    const std::size_t n = contacts.size();
    colourMask_.assign(bodies.size(), 0u);
    colourOf_.resize(n);
    // Counts per (colour, point count); the overflow is colour kContactColours.
    std::uint32_t counts[kContactColours + 1][2] = {};
    constexpr std::uint32_t kAllColours = (1u << kContactColours) - 1u;
    // From the packed pairs, not the 232-byte contacts (ContactPairs).
    std::size_t held = 0;
    for (std::size_t k = 0; k < n; ++k) {
        if (!heldOut.empty() && heldOut[k]) {
            colourOf_[k] = kHeldOut;
            ++held;
            continue;
        }
        const std::uint32_t bodyA = pairs.bodies[2 * k], bodyB = pairs.bodies[2 * k + 1];
        const bool two = pairs.twoPoints[k] != 0;
        // Static body 0 is in no colour: any number of contacts of one colour
        // may touch it (it never moves, so they do not interact through it).
        const std::uint32_t used = (bodyA != 0 ? colourMask_[bodyA] : 0u) | (bodyB != 0 ? colourMask_[bodyB] : 0u);
        std::uint32_t free = ~used & kAllColours;
        if (two && used != 0) {
            // Two-point manifolds (boxes, polygons: stacks) take the first
            // colour above every colour their bodies already have, wrapping
            // only when none is left. The contacts come roughly bottom-up
            // (sorted pairs), so a forward pass then runs up a stack in one
            // sweep, as a one-at-a-time pass does; first-free colours
            // alternate layers (red-black) and carry the load up two layers
            // a colour pass. On a 20-row pyramid at 1 iteration, first-free
            // creeps 6.2 mm between t = 2 s and 10 s, this 0.08 mm.
            // Circles keep first-free: on tests/test_collision's 400-circle
            // pile this rule leaves 13.1 mm of overlap (first-free: under the
            // test's 12.5) and flings a 20,000-circle crowd at 6.3 m/s (over 5).
            const int above = 32 - std::countl_zero(used);  // one past the highest colour either body has
            const std::uint32_t higher = above >= 32 ? 0u : ~((1u << above) - 1u);
            if ((free & higher) != 0) free &= higher;
        }
        int colour = kContactColours;
        if (free != 0) {
            colour = std::countr_zero(free);
            if (bodyA != 0) colourMask_[bodyA] |= 1u << colour;
            if (bodyB != 0) colourMask_[bodyB] |= 1u << colour;
        }
        colourOf_[k] = std::uint8_t(colour);
        ++counts[colour][two ? 1 : 0];
    }
    colourCount_ = 0;
    for (int colour = 0; colour < kContactColours; ++colour)
        if (counts[colour][0] + counts[colour][1] > 0) colourCount_ = colour + 1;
    // Order: colour by colour, one-point contacts before two-point ones, each
    // in contact order; the overflow last. A stable counting sort.
    std::uint32_t start[kContactColours + 1][2];
    std::uint32_t at = 0;
    for (int colour = 0; colour <= kContactColours; ++colour) {
        for (int kind = 0; kind < 2; ++kind) {
            start[colour][kind] = at;
            at += counts[colour][kind];
        }
    }
    // Colours past colourCount_ are empty, so the overflow starts where colourCount_ would.
    colourStart_.resize(std::size_t(colourCount_) + 1);
    for (int colour = 0; colour < colourCount_; ++colour) colourStart_[std::size_t(colour)] = start[colour][0];
    colourStart_[std::size_t(colourCount_)] = start[kContactColours][0];
    order_.resize(n - held);
    {
        std::uint32_t cursor[kContactColours + 1][2];
        std::memcpy(cursor, start, sizeof cursor);
        for (std::size_t k = 0; k < n; ++k)
            if (colourOf_[k] != kHeldOut) order_[cursor[colourOf_[k]][pairs.twoPoints[k]]++] = std::uint32_t(k);
    }
    one_.clear();
    two_.clear();
    oneStart_.assign(std::size_t(colourCount_) + 1, 0u);
    twoStart_.assign(std::size_t(colourCount_) + 1, 0u);
    // Unbundled contacts are prepared in contact order; the bundles'
    // contacts as they are bundled. Each contact's preparation reads only
    // itself and its bodies, so the order changes no bit.
    if (!simd_) {
        for (std::size_t k = 0; k < n; ++k) prepare(contacts[k], k, preparation, bodies);
        return;
    }
    for (std::size_t k = 0; k < n; ++k)
        if (colourOf_[k] >= kContactColours) prepare(contacts[k], k, preparation, bodies);  // overflow, held out
    for (int colour = 0; colour < colourCount_; ++colour) {
        oneStart_[std::size_t(colour)] = std::uint32_t(one_.size());
        twoStart_[std::size_t(colour)] = std::uint32_t(two_.size());
        const std::span<const std::uint32_t> all(order_);
        bundle<1>(one_, all.subspan(start[colour][0], counts[colour][0]), contacts, preparation, pairs.bodies, bodies);
        bundle<2>(two_, all.subspan(start[colour][1], counts[colour][1]), contacts, preparation, pairs.bodies, bodies);
    }
    oneStart_[std::size_t(colourCount_)] = std::uint32_t(one_.size());
    twoStart_[std::size_t(colourCount_)] = std::uint32_t(two_.size());
}

void ColouredContacts::warmStart(std::span<ContactConstraint> contacts, std::span<SolverBody> bodies) {
    if (!simd_) {
        collision::warmStart(contacts, order_, bodies);
        return;
    }
    const PassKernel kernel = passKernel<0>();
    for (int colour = 0; colour < colourCount_; ++colour) {
        const std::size_t c = std::size_t(colour);
        PassArgs args{bodies.data(), one_.data() + oneStart_[c], oneStart_[c + 1] - oneStart_[c],
                      two_.data() + twoStart_[c], twoStart_[c + 1] - twoStart_[c], {}, {}, 0.0, 0.0, nullptr};
        kernel(args);
    }
    const std::span<const std::uint32_t> overflow = std::span<const std::uint32_t>(order_).subspan(colourStart_[std::size_t(colourCount_)]);
    if (!overflow.empty()) collision::warmStart(contacts, overflow, bodies);
}

void ColouredContacts::solve(std::span<ContactConstraint> contacts, std::span<SolverBody> bodies, double h,
                             const Softness& soft, const Softness& staticSoft, double pushMaxVelocity, bool useBias,
                             bool reverse, std::span<double> deepest) {
    if (!simd_) {
        solveContacts(contacts, order_, bodies, h, soft, staticSoft, pushMaxVelocity, useBias, reverse);
        return;
    }
    double* const deepestOut = useBias || deepest.empty() ? nullptr : deepest.data();
    const std::span<const std::uint32_t> overflow = std::span<const std::uint32_t>(order_).subspan(colourStart_[std::size_t(colourCount_)]);
    const auto solveOverflow = [&] {
        if (!overflow.empty())
            solveContacts(contacts, overflow, bodies, h, soft, staticSoft, pushMaxVelocity, useBias, reverse);
    };
    if (reverse) solveOverflow();
    const PassKernel kernel = useBias ? passKernel<1>() : passKernel<2>();
    for (int k = 0; k < colourCount_; ++k) {
        const std::size_t c = std::size_t(reverse ? colourCount_ - 1 - k : k);
        PassArgs args{bodies.data(), one_.data() + oneStart_[c], oneStart_[c + 1] - oneStart_[c],
                      two_.data() + twoStart_[c], twoStart_[c + 1] - twoStart_[c], soft, staticSoft, 1.0 / h,
                      pushMaxVelocity, deepestOut};
        kernel(args);
    }
    if (!reverse) solveOverflow();
}

template <class Self, class Contacts, class Visit>
void ColouredContacts::forEachHeld(Self& self, Contacts& contacts, Visit&& visit) {
    const auto points = [&](std::uint32_t k) {
        auto& c = contacts[k];
        for (int i = 0; i < c.pointCount; ++i)
            visit(c.bodyA, c.bodyB, k, i, c.points[i].normalImpulse, c.points[i].tangentImpulse);
    };
    if (!self.simd_) {
        for (std::uint32_t k = 0; k < contacts.size(); ++k)
            if (self.colourOf_[k] != kHeldOut) points(k);
        return;
    }
    forEachLane<1>(self.one_, visit);
    forEachLane<2>(self.two_, visit);
    const std::span<const std::uint32_t> order(self.order_);
    for (const std::uint32_t k : order.subspan(self.colourStart_[std::size_t(self.colourCount_)])) points(k);
}

void ColouredContacts::saveImpulses(std::span<const ContactConstraint> contacts, std::span<const std::uint8_t> marked,
                                    std::vector<double>& out) const {
    out.clear();
    const auto save = [&](std::uint32_t a, std::uint32_t b, std::uint32_t, int, double normal, double tangent) {
        if (!marked[a] && !marked[b]) return;
        out.push_back(normal);
        out.push_back(tangent);
    };
    forEachHeld(*this, contacts, save);
}

void ColouredContacts::restoreImpulses(std::span<ContactConstraint> contacts, std::span<const std::uint8_t> marked,
                                       std::span<const double> saved, std::span<SolverBody> bodies,
                                       std::span<const std::uint8_t> takeBack) {
    std::size_t at = 0;
    takenBack_.clear();
    const auto restore = [&](std::uint32_t a, std::uint32_t b, std::uint32_t k, int i, double& normal,
                             double& tangent) {
        if (!marked[a] && !marked[b]) return;
        if (marked[a] != marked[b] && (takeBack[a] || takeBack[b]))
            takenBack_.push_back({2 * k + std::uint32_t(i), normal - saved[at], tangent - saved[at + 1]});
        normal = saved[at];
        tangent = saved[at + 1];
        at += 2;
    };
    forEachHeld(*this, contacts, restore);
    // In contact order, whichever path holds the impulses: a body's
    // velocity then sums the same terms in the same order (the same bits).
    std::sort(takenBack_.begin(), takenBack_.end(),
              [](const TakenBack& x, const TakenBack& y) { return x.point < y.point; });
    for (const TakenBack& e : takenBack_) {
        const ContactConstraint& c = contacts[e.point / 2];
        const ContactPoint& p = c.points[e.point % 2];
        const Vec2 t{c.normal.y, -c.normal.x};
        const Vec2 impulse = e.normal * c.normal + e.tangent * t;
        if (takeBack[c.bodyA]) {
            SolverBody& body = bodies[c.bodyA];
            body.v += body.invMass * impulse;
            body.w += body.invInertia * (p.rnA * e.normal - p.dnA * e.tangent);
        } else {
            SolverBody& body = bodies[c.bodyB];
            body.v -= body.invMass * impulse;
            body.w -= body.invInertia * (p.rnB * e.normal - p.dnB * e.tangent);
        }
    }
}

void ColouredContacts::storeImpulses(std::span<ContactConstraint> contacts) const {
    if (!simd_) return;
    storeLanes<1>(one_, contacts);
    storeLanes<2>(two_, contacts);
}

} // namespace stepwise::collision
