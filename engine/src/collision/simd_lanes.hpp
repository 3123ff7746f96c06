#pragma once
// Solver lanes in vector registers (four, or eight for the contact passes
// on AVX-512), shared by the contact and joint bundles: the vector types,
// loads and stores, and the gather and scatter of the lanes' bodies. Each
// helper is one IEEE operation per lane (or pure data movement), so a
// bundle's lanes get the bits of the scalar solve.

#include "collision/contact_solver.hpp"
#include "integrators/integrator.hpp"  // detail::simdLevel: the instruction set the integrators use

#include <cstddef>
#include <cstdint>
#include <cstring>

// The helpers below pass four-double vectors by value; they are always
// inlined, so the baseline build's note that such a call's ABI differs
// from an AVX build's never applies.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace stepwise::collision::simd {

/// Lanes in one D4 vector, the width every instruction set runs.
constexpr int kLanes = 4;

// Four doubles in one GCC/Clang vector: SSE2 runs it as two halves, AVX2
// and AVX-512 in one register; the arithmetic per lane is the same IEEE
// operation everywhere (no FMA: -ffp-contract=off on the engine).
typedef double D4 __attribute__((vector_size(32)));
typedef std::int64_t M4 __attribute__((vector_size(32)));  // a comparison's result: lanes all ones or zeros
// Eight doubles: one AVX-512 register. A kernel written over a lane type
// `D` (D4 or D8) runs eight contacts at once there and four elsewhere;
// lanes never mix, so the width changes no bit.
typedef double D8 __attribute__((vector_size(64)));
typedef std::int64_t M8 __attribute__((vector_size(64)));

template <class D>
constexpr int lanesOf = int(sizeof(D) / sizeof(double));
template <class D>
struct MaskOf;
template <>
struct MaskOf<D4> {
    using type = M4;
};
template <>
struct MaskOf<D8> {
    using type = M8;
};

[[gnu::always_inline]] inline D4 load(const double* p) {
    D4 v;
    std::memcpy(&v, p, sizeof v);
    return v;
}
[[gnu::always_inline]] inline M4 loadMask(const std::int64_t* p) {
    M4 v;
    std::memcpy(&v, p, sizeof v);
    return v;
}
[[gnu::always_inline]] inline void store(double* p, D4 v) { std::memcpy(p, &v, sizeof v); }
[[gnu::always_inline]] inline D4 splat(double x) { return D4{x, x, x, x}; }
template <class D>
[[gnu::always_inline]] inline D loadAs(const double* p) {
    D v;
    std::memcpy(&v, p, sizeof v);
    return v;
}
template <class D>
[[gnu::always_inline]] inline typename MaskOf<D>::type loadMaskAs(const std::int64_t* p) {
    typename MaskOf<D>::type v;
    std::memcpy(&v, p, sizeof v);
    return v;
}
template <class D>
[[gnu::always_inline]] inline void storeAs(double* p, D v) {
    std::memcpy(p, &v, sizeof v);
}
template <class D>
[[gnu::always_inline]] inline D splatAs(double x) {
    D v;
    for (int l = 0; l < lanesOf<D>; ++l) v[l] = x;
    return v;
}
/// std::max(a, b) and std::min(a, b) lane by lane, to the bit (also for
/// NaN and signed zeros): (a < b) ? b : a and (b < a) ? b : a.
template <class D>
[[gnu::always_inline]] inline D maxOf(D a, D b) {
    return a < b ? b : a;
}
template <class D>
[[gnu::always_inline]] inline D minOf(D a, D b) {
    return b < a ? b : a;
}
template <class M>
[[gnu::always_inline]] inline bool anyLane(M m) {
    std::int64_t any = 0;
    for (int l = 0; l < int(sizeof(M) / sizeof(std::int64_t)); ++l) any |= m[l];
    return any != 0;
}
template <class M>
[[gnu::always_inline]] inline bool allLanes(M m) {
    std::int64_t all = -1;
    for (int l = 0; l < int(sizeof(M) / sizeof(std::int64_t)); ++l) all &= m[l];
    return all != 0;
}

/// Velocities of the lanes' bodies, and their motion since the step began.
template <class D>
struct BodyLanesOf {
    D vx, vy, w, invMass, dpx, dpy, qc, qs;
};
using BodyLanes = BodyLanesOf<D4>;
// SolverBody holds (v.x, v.y, w, invMass) and (dp.x, dp.y, dq.c, dq.s) as
// four consecutive doubles each: one load per lane and a 4x4 transpose
// (pure data movement, so it changes no bit) give the lanes.
static_assert(offsetof(SolverBody, w) == 2 * sizeof(double) && offsetof(SolverBody, invMass) == 3 * sizeof(double) &&
                  offsetof(SolverBody, dq) == offsetof(SolverBody, dp) + 2 * sizeof(double),
              "gather() reads SolverBody as two runs of four doubles");
[[gnu::always_inline]] inline void transpose(D4& r0, D4& r1, D4& r2, D4& r3) {
    const D4 t0 = __builtin_shufflevector(r0, r1, 0, 4, 2, 6);
    const D4 t1 = __builtin_shufflevector(r0, r1, 1, 5, 3, 7);
    const D4 t2 = __builtin_shufflevector(r2, r3, 0, 4, 2, 6);
    const D4 t3 = __builtin_shufflevector(r2, r3, 1, 5, 3, 7);
    r0 = __builtin_shufflevector(t0, t2, 0, 1, 4, 5);
    r1 = __builtin_shufflevector(t1, t3, 0, 1, 4, 5);
    r2 = __builtin_shufflevector(t0, t2, 2, 3, 6, 7);
    r3 = __builtin_shufflevector(t1, t3, 2, 3, 6, 7);
}
[[gnu::always_inline]] inline BodyLanes gather(const SolverBody* bodies, const std::uint32_t* index) {
    const SolverBody& b0 = bodies[index[0]];
    const SolverBody& b1 = bodies[index[1]];
    const SolverBody& b2 = bodies[index[2]];
    const SolverBody& b3 = bodies[index[3]];
    D4 v0 = load(&b0.v.x), v1 = load(&b1.v.x), v2 = load(&b2.v.x), v3 = load(&b3.v.x);
    D4 p0 = load(&b0.dp.x), p1 = load(&b1.dp.x), p2 = load(&b2.dp.x), p3 = load(&b3.dp.x);
    transpose(v0, v1, v2, v3);  // vx, vy, w, invMass
    transpose(p0, p1, p2, p3);  // dp.x, dp.y, dq.c, dq.s
    return {v0, v1, v2, v3, p0, p1, p2, p3};
}
[[gnu::always_inline]] inline void scatter(SolverBody* bodies, const std::uint32_t* index, const D4& vx, const D4& vy,
                                           const D4& w, const D4& invMass) {
    // Back to one (v.x, v.y, w, invMass) row per lane (invMass as gathered,
    // unchanged), stored in lane order as the one-at-a-time solve stores;
    // lanes on static body 0 write its zeros back.
    D4 r0 = vx, r1 = vy, r2 = w, r3 = invMass;
    transpose(r0, r1, r2, r3);
    store(&bodies[index[0]].v.x, r0);
    store(&bodies[index[1]].v.x, r1);
    store(&bodies[index[2]].v.x, r2);
    store(&bodies[index[3]].v.x, r3);
}

/// Eight lanes as two runs of four: the same loads, transposes and stores.
[[gnu::always_inline]] inline D8 joined(D4 low, D4 high) {
    return __builtin_shufflevector(low, high, 0, 1, 2, 3, 4, 5, 6, 7);
}
[[gnu::always_inline]] inline D4 lowHalf(D8 v) { return __builtin_shufflevector(v, v, 0, 1, 2, 3); }
[[gnu::always_inline]] inline D4 highHalf(D8 v) { return __builtin_shufflevector(v, v, 4, 5, 6, 7); }
template <class D>
[[gnu::always_inline]] inline BodyLanesOf<D> gatherAs(const SolverBody* bodies, const std::uint32_t* index) {
    if constexpr (lanesOf<D> == 4) {
        return gather(bodies, index);
    } else {
        const BodyLanes l = gather(bodies, index), h = gather(bodies, index + 4);
        return {joined(l.vx, h.vx),   joined(l.vy, h.vy),   joined(l.w, h.w),   joined(l.invMass, h.invMass),
                joined(l.dpx, h.dpx), joined(l.dpy, h.dpy), joined(l.qc, h.qc), joined(l.qs, h.qs)};
    }
}
template <class D>
[[gnu::always_inline]] inline void scatterAs(SolverBody* bodies, const std::uint32_t* index, const D& vx, const D& vy,
                                             const D& w, const D& invMass) {
    if constexpr (lanesOf<D> == 4) {
        scatter(bodies, index, vx, vy, w, invMass);
    } else {
        scatter(bodies, index, lowHalf(vx), lowHalf(vy), lowHalf(w), lowHalf(invMass));
        scatter(bodies, index + 4, highHalf(vx), highHalf(vy), highHalf(w), highHalf(invMass));
    }
}

/// The pass `Pass` (always inlined) compiled for SSE2, AVX2 and AVX-512 from
/// the same source; kernelFor picks the one for the instruction set the
/// integrators use (detail::simdLevel).
template <class Args, void (*Pass)(const Args&)>
void onBaseline(const Args& args) {
    Pass(args);
}
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define STEPWISE_SIMD_DISPATCH 1
template <class Args, void (*Pass)(const Args&)>
__attribute__((target("avx2"))) void onAvx2(const Args& args) {
    Pass(args);
}
template <class Args, void (*Pass)(const Args&)>
__attribute__((target("avx512f"))) void onAvx512(const Args& args) {
    Pass(args);
}
#endif
template <class Args, void (*Pass)(const Args&)>
auto kernelFor() -> void (*)(const Args&) {
    switch (detail::simdLevel()) {
#ifdef STEPWISE_SIMD_DISPATCH
        case detail::SimdLevel::Avx512: return onAvx512<Args, Pass>;
        case detail::SimdLevel::Avx2: return onAvx2<Args, Pass>;
#endif
        default: return onBaseline<Args, Pass>;
    }
}

} // namespace stepwise::collision::simd
