// The contact passes' kernels over a lane type D (simd_lanes.hpp's D4 or
// D8), included twice by contact_bundles.cpp: once as plain code, for the
// four-lane kernels, and once inside an AVX-512 target region. GCC lowers
// vector masks in an inline function by the target the function itself is
// compiled for, before inlining: compiled without AVX-512, the eight-lane
// kernels compared and combined their masks one lane at a time (perf: no
// faster than two runs of four).
//
// No include guard and no includes: the including file provides
// PassArgs, the bundles and simd_lanes.hpp, in an open namespace.

/// The lanes [off, off + lanesOf<D>) of a bundle's arrays: all of them in
/// one vector of eight, or one half of them in a vector of four.
template <class D>
struct LaneAccess {
    int off;
    [[gnu::always_inline]] D operator()(const double* p) const { return loadAs<D>(p + off); }
    [[gnu::always_inline]] typename MaskOf<D>::type mask(const std::int64_t* p) const {
        return loadMaskAs<D>(p + off);
    }
    [[gnu::always_inline]] void store(double* p, D v) const { storeAs(p + off, v); }
};

// The velocity state of a bundle's two sides while it is solved.
template <class D>
struct Velocities {
    D vAx, vAy, wA, vBx, vBy, wB;
};

// Each formula below is solveContacts' (contact_solver.cpp), with the same
// operations in the same order; comments there say why.

/// The inverse masses (1/kg) and inertias (1/(kg m^2)) of a bundle's two sides.
template <class D>
struct Masses {
    D mA, iA, mB, iB;
};

/// Impulse j (N*s) along (dx, dy) with lever arms armA, armB: applyImpulse
/// of contact_solver.cpp. Friction passes the arms -dnA, -dnB, where
/// solveContacts writes wA + iA dnA j: negation is exact, so the bits agree.
template <class D>
[[gnu::always_inline]] inline void applyLanes(Velocities<D>& v, const Masses<D>& m, D dx, D dy, D armA, D armB, D j) {
    v.vAx = v.vAx - (m.mA * j) * dx;
    v.vAy = v.vAy - (m.mA * j) * dy;
    v.wA = v.wA - (m.iA * armA) * j;
    v.vBx = v.vBx + (m.mB * j) * dx;
    v.vBy = v.vBy + (m.mB * j) * dy;
    v.wB = v.wB + (m.iB * armB) * j;
}

template <class D, int Points>
[[gnu::always_inline]] inline void warmStartBundle(ContactBundle<Points>& c, SolverBody* bodies, int off) {
    const LaneAccess<D> ld{off};
    const BodyLanesOf<D> a = gatherAs<D>(bodies, c.bodyA + off), b = gatherAs<D>(bodies, c.bodyB + off);
    Velocities<D> v{a.vx, a.vy, a.w, b.vx, b.vy, b.w};
    const Masses<D> m{a.invMass, ld(c.invInertiaA), b.invMass, ld(c.invInertiaB)};
    const D nx = ld(c.nx), ny = ld(c.ny);
    const D tx = ny, ty = -nx;
    for (int i = 0; i < Points; ++i) {
        const PointLanes& p = c.points[i];
        const D ni = ld(p.normalImpulse), ti = ld(p.tangentImpulse);
        const D rnA = ld(p.rnA), rnB = ld(p.rnB), dnA = ld(p.dnA), dnB = ld(p.dnB);
        applyLanes(v, m, nx, ny, rnA, rnB, ni);
        applyLanes(v, m, tx, ty, -dnA, -dnB, ti);
    }
    scatterAs<D>(bodies, c.bodyA + off, v.vAx, v.vAy, v.wA, a.invMass);
    scatterAs<D>(bodies, c.bodyB + off, v.vBx, v.vBy, v.wB, b.invMass);
}

/// Bias and soft scaling of one point (solveContacts' targetOf).
template <class D>
struct Target {
    D bias, massScale, impulseScale;
};

/// One point's sequential normal update (solveContacts' else branch).
template <class D>
[[gnu::always_inline]] inline void normalPoint(Velocities<D>& v, PointLanes& p, const Target<D>& t, D nx, D ny,
                                               const Masses<D>& m, const LaneAccess<D>& ld) {
    const D rnA = ld(p.rnA), rnB = ld(p.rnB);
    const D ni = ld(p.normalImpulse);
    const D vn = (((v.vBx - v.vAx) * nx + (v.vBy - v.vAy) * ny) + v.wB * rnB) - v.wA * rnA;
    D impulse = ((-ld(p.normalMass)) * t.massScale) * (vn + t.bias) - t.impulseScale * ni;
    const D total = maxOf(ni + impulse, splatAs<D>(0.0));
    impulse = total - ni;
    ld.store(p.normalImpulse, total);
    applyLanes(v, m, nx, ny, rnA, rnB, impulse);
}

template <class D, int Points, bool UseBias>
[[gnu::always_inline]] inline void solveBundle(ContactBundle<Points>& c, const PassArgs& args, int off) {
    using M = typename MaskOf<D>::type;
    const LaneAccess<D> ld{off};
    SolverBody* bodies = args.bodies;
    const BodyLanesOf<D> a = gatherAs<D>(bodies, c.bodyA + off), b = gatherAs<D>(bodies, c.bodyB + off);
    Velocities<D> v{a.vx, a.vy, a.w, b.vx, b.vy, b.w};
    const Masses<D> m{a.invMass, ld(c.invInertiaA), b.invMass, ld(c.invInertiaB)};
    const D mA = m.mA, iA = m.iA, mB = m.mB, iB = m.iB;
    const D nx = ld(c.nx), ny = ld(c.ny);
    const M flags = ld.mask(c.flags);
    const M isStatic = (flags & kTouchesStatic) != 0;
    const D biasRate = isStatic ? splatAs<D>(args.staticSoft.biasRate) : splatAs<D>(args.soft.biasRate);
    const D massScale = isStatic ? splatAs<D>(args.staticSoft.massScale) : splatAs<D>(args.soft.massScale);
    const D impulseScale = isStatic ? splatAs<D>(args.staticSoft.impulseScale) : splatAs<D>(args.soft.impulseScale);
    const D rigidDepth = isStatic ? splatAs<D>(args.staticSoft.rigidDepth) : splatAs<D>(args.soft.rigidDepth);
    const D baseGap = (b.dpx - a.dpx) * nx + (b.dpy - a.dpy) * ny;
    const D zero = splatAs<D>(0.0), one = splatAs<D>(1.0);
    const M roundA = (flags & kRoundA) != 0, roundB = (flags & kRoundB) != 0;
    const D qcA = roundA ? one : a.qc, qsA = roundA ? zero : a.qs;
    const D qcB = roundB ? one : b.qc, qsB = roundB ? zero : b.qs;
    Target<D> t[2];
    D separations[2];
    for (int i = 0; i < Points; ++i) {
        const PointLanes& p = c.points[i];
        const D separation = separations[i] = ((baseGap + (qcB * ld(p.dnB) + qsB * ld(p.rnB))) -
                               (qcA * ld(p.dnA) + qsA * ld(p.rnA))) +
                              ld(p.adjustedSeparation);
        const M apart = separation > zero;
        const D speculative = separation * splatAs<D>(args.invH);
        if constexpr (UseBias) {
            // Rigid past rigidDepth, or when the approach would carry the
            // point past twice that within this substep (solveContacts says
            // why).
            const D vn = (((v.vBx - v.vAx) * nx + (v.vBy - v.vAy) * ny) + v.wB * ld(p.rnB)) - v.wA * ld(p.rnA);
            const M rigid =
                (!(separation > -rigidDepth)) | (!((separation + vn / splatAs<D>(args.invH)) > -(rigidDepth + rigidDepth)));
            const D toDepth = separation + rigidDepth;
            const D rigidBias = toDepth > zero ? toDepth * splatAs<D>(args.invH)
                                                : maxOf(biasRate * toDepth, splatAs<D>(-args.pushMaxVelocity));
            const D push = maxOf(biasRate * separation, splatAs<D>(-args.pushMaxVelocity));
            t[i] = {apart ? speculative : (rigid ? rigidBias : push), apart ? one : (rigid ? one : massScale),
                    apart ? zero : (rigid ? zero : impulseScale)};
        } else {
            t[i] = {apart ? speculative : zero, one, zero};
        }
    }
    if constexpr (!UseBias) {
        // Asked for in the step's last relax pass, whose positions are the
        // step's last: the position pass then reads each contact's deepest
        // point here (deepest() of correctPositions, the same bits) rather
        // than from the contact.
        if (args.deepest != nullptr) {
            D deepest = separations[0];
            if constexpr (Points == 2) deepest = minOf(separations[0], separations[1]);
            for (int l = 0; l < lanesOf<D>; ++l)
                if (const std::uint32_t k = c.source[off + l]; k != ~0u) args.deepest[k] = deepest[l];
        }
    }
    if constexpr (Points == 1) {
        normalPoint(v, c.points[0], t[0], nx, ny, m, ld);
    } else {
        const M block = (flags & kBlock) != 0;
        const M useBlock = block & (t[0].massScale == t[1].massScale);
        Velocities<D> blockV = v;
        D blockX1 = zero, blockX2 = zero;
        if (anyLane(useBlock)) {
            PointLanes& p1 = c.points[0];
            PointLanes& p2 = c.points[1];
            const D k11 = ld(c.k11), k12 = ld(c.k12), k22 = ld(c.k22);
            // K^-1 as prepareContact forms it; zero in the lanes without a
            // block (as BlockMass leaves it there).
            const D invDet = one / (k11 * k22 - k12 * k12);
            const D i11 = block ? k22 * invDet : zero, i12 = block ? -k12 * invDet : zero,
                     i22 = block ? k11 * invDet : zero;
            const D rnA1 = ld(p1.rnA), rnB1 = ld(p1.rnB), rnA2 = ld(p2.rnA), rnB2 = ld(p2.rnB);
            const D dvx = v.vBx - v.vAx, dvy = v.vBy - v.vAy;
            const D a1 = ld(p1.normalImpulse), a2 = ld(p2.normalImpulse);
            const D vn1 = ((dvx * nx + dvy * ny) + v.wB * rnB1) - v.wA * rnA1;
            const D vn2 = ((dvx * nx + dvy * ny) + v.wB * rnB2) - v.wA * rnA2;
            const D q1 = (vn1 + t[0].bias) - (k11 * a1 + k12 * a2);
            const D q2 = (vn2 + t[1].bias) - (k12 * a1 + k22 * a2);
            // The four cases of the 2x2 complementarity problem, taken in
            // solveContacts' order: both push, only the first, only the
            // second, neither.
            const D both1 = -(i11 * q1 + i12 * q2);
            const D both2 = -(i12 * q1 + i22 * q2);
            const M bothOk = (both1 >= zero) & (both2 >= zero);
            D y1 = both1, y2 = both2;
            if (!allLanes(bothOk)) {
                // Only lanes where both points cannot push need the other
                // cases (and their divisions): settled stacks rarely do.
                const D first1 = -q1 / k11;
                const M firstOk = (first1 >= zero) & (k12 * first1 + q2 >= zero);
                const D second2 = -q2 / k22;
                const M secondOk = (second2 >= zero) & (k12 * second2 + q1 >= zero);
                const M noneOk = (q1 >= zero) & (q2 >= zero);
                const D none1 = noneOk ? zero : a1 / t[0].massScale;
                const D none2 = noneOk ? zero : a2 / t[0].massScale;
                y1 = bothOk ? both1 : firstOk ? first1 : secondOk ? zero : none1;
                y2 = bothOk ? both2 : firstOk ? zero : secondOk ? second2 : none2;
            }
            blockX1 = t[0].massScale * y1;
            blockX2 = t[0].massScale * y2;
            const D d1 = blockX1 - a1, d2 = blockX2 - a2;
            const D d = d1 + d2;
            blockV.vAx = v.vAx - (mA * d) * nx;
            blockV.vAy = v.vAy - (mA * d) * ny;
            blockV.wA = v.wA - iA * (rnA1 * d1 + rnA2 * d2);
            blockV.vBx = v.vBx + (mB * d) * nx;
            blockV.vBy = v.vBy + (mB * d) * ny;
            blockV.wB = v.wB + iB * (rnB1 * d1 + rnB2 * d2);
        }
        if (allLanes(useBlock)) {
            v = blockV;
            ld.store(c.points[0].normalImpulse, blockX1);
            ld.store(c.points[1].normalImpulse, blockX2);
        } else {
            // Some lanes solve the points one after the other; the block
            // lanes keep their block result.
            normalPoint(v, c.points[0], t[0], nx, ny, m, ld);
            normalPoint(v, c.points[1], t[1], nx, ny, m, ld);
            if (anyLane(useBlock)) {
                v.vAx = useBlock ? blockV.vAx : v.vAx;
                v.vAy = useBlock ? blockV.vAy : v.vAy;
                v.wA = useBlock ? blockV.wA : v.wA;
                v.vBx = useBlock ? blockV.vBx : v.vBx;
                v.vBy = useBlock ? blockV.vBy : v.vBy;
                v.wB = useBlock ? blockV.wB : v.wB;
                ld.store(c.points[0].normalImpulse, useBlock ? blockX1 : ld(c.points[0].normalImpulse));
                ld.store(c.points[1].normalImpulse, useBlock ? blockX2 : ld(c.points[1].normalImpulse));
            }
        }
    }
    // Friction: t = (n.y, -n.x), cross(r, t) = -dot(r, n).
    const D tx = ny, ty = -nx;
    const D friction = ld(c.friction);
    for (int i = 0; i < Points; ++i) {
        PointLanes& p = c.points[i];
        const D dnA = ld(p.dnA), dnB = ld(p.dnB);
        const D ti = ld(p.tangentImpulse);
        const D vt = (((v.vBx - v.vAx) * tx + (v.vBy - v.vAy) * ty) - v.wB * dnB) + v.wA * dnA;
        const D maxFriction = friction * ld(p.normalImpulse);
        D impulse = (-ld(p.tangentMass)) * vt;
        const D total = minOf(maxOf(ti + impulse, -maxFriction), maxFriction);  // std::clamp
        impulse = total - ti;
        ld.store(p.tangentImpulse, total);
        applyLanes(v, m, tx, ty, -dnA, -dnB, impulse);
    }
    scatterAs<D>(bodies, c.bodyA + off, v.vAx, v.vAy, v.wA, a.invMass);
    scatterAs<D>(bodies, c.bodyB + off, v.vBx, v.vBy, v.wB, b.invMass);
}

/// Asks for the bodies of `bundles[k]`, when there is one: a bundle's
/// passes are longer than the window a core runs ahead in, so without this
/// each bundle waited on its bodies' lines before it could start.
template <int Points>
[[gnu::always_inline]] inline void prefetchBodies(const ContactBundle<Points>* bundles, std::size_t k,
                                                  std::size_t count, const SolverBody* bodies) {
    if (k >= count) return;
    const ContactBundle<Points>& c = bundles[k];
    for (int l = 0; l < kContactLanes; ++l) {
        __builtin_prefetch(&bodies[c.bodyA[l]], 1);
        __builtin_prefetch(&bodies[c.bodyB[l]], 1);
    }
}

// One colour: its one-point bundles, then its two-point bundles (any order
// gives the same bits, since no two of its contacts share a dynamic body),
// in vectors of D's width: a bundle at once, or half after half.
template <int Mode, class D>  // Mode: 0 warm start, 1 biased solve, 2 relax
[[gnu::always_inline]] inline void colourPass(const PassArgs& args) {
    constexpr int kWidth = lanesOf<D>;
    constexpr std::size_t kAhead = 4;  // bundles
    static_assert(kContactLanes % kWidth == 0, "a bundle is whole vectors");
    for (std::size_t k = 0; k < args.oneCount; ++k) {
        prefetchBodies(args.one, k + kAhead, args.oneCount, args.bodies);
        for (int off = 0; off < kContactLanes; off += kWidth) {
            if constexpr (Mode == 0)
                warmStartBundle<D>(args.one[k], args.bodies, off);
            else
                solveBundle<D, 1, Mode == 1>(args.one[k], args, off);
        }
    }
    for (std::size_t k = 0; k < args.twoCount; ++k) {
        prefetchBodies(args.two, k + kAhead, args.twoCount, args.bodies);
        for (int off = 0; off < kContactLanes; off += kWidth) {
            if constexpr (Mode == 0)
                warmStartBundle<D>(args.two[k], args.bodies, off);
            else
                solveBundle<D, 2, Mode == 1>(args.two[k], args, off);
        }
    }
}
