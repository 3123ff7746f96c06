#pragma once
// The force model of a compiled world: every force system over the packed
// state of the dynamic bodies. State arrays are plain doubles, interleaved
// per body (x0, y0, x1, y1, ...), 2*n long: a Vec2 array without the
// aliasing question, and the layout the springs want (one cache line holds
// both coordinates of a body). Split x[]/y[] arrays would speed the
// streaming Euler kernel (~30% while the state fits in cache, ~10% at 1e6
// bodies, memory-bound), but the spring pass, which gathers both ends, is
// ~11% faster interleaved at 1e6; springs dominate every scene that has
// them, and the streaming kernels are memory-bound where it matters
// (bench/stepwise_bench.cpp Layout/*, docs/performance.md, "Integrators").
//
// Each system appends to an acceleration array (m/s^2), never to forces, so
// the integrators need no mass division. A system that the scene does not
// contain has no data and is never visited ("model only what a scene
// needs").

#include "forces/barnes_hut.hpp"
#include "stepwise/entity.hpp"
#include "stepwise/vec2.hpp"

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <new>
#include <string_view>
#include <vector>

namespace stepwise::detail {

inline constexpr std::uint32_t kNoBody = 0xFFFFFFFFu;

/// Allocates on 64-byte cache-line boundaries. The streaming kernels load
/// and store 64 bytes at a time (AVX-512): on malloc's 16-byte alignment
/// most of those accesses straddle two cache lines.
template <class T>
struct CacheLineAllocator {
    using value_type = T;
    static constexpr std::align_val_t kAlignment{64};
    CacheLineAllocator() = default;
    template <class U>
    CacheLineAllocator(const CacheLineAllocator<U>&) noexcept {}
    T* allocate(std::size_t count) { return static_cast<T*>(::operator new(count * sizeof(T), kAlignment)); }
    void deallocate(T* p, std::size_t) noexcept { ::operator delete(p, kAlignment); }
    template <class U>
    bool operator==(const CacheLineAllocator<U>&) const noexcept {
        return true;
    }
};
/// A state or per-body array the streaming kernels read or write.
using AlignedDoubles = std::vector<double, CacheLineAllocator<double>>;

/// Force systems, in pipeline order. Index into ForceModel::systemSeconds.
enum class ForceSystem : int { Gravity = 0, Drag, Springs, Attractors, Boids, Count };
std::string_view forceSystemName(ForceSystem s);

/// One spring-damper. `a` is always a dynamic body; `b` is a dynamic body or
/// kNoBody, in which case the end is the fixed point (fx, fy): an `anchor`
/// or a static body (static bodies never move, so they are anchors).
struct SpringData {
    std::uint32_t a = kNoBody;
    std::uint32_t b = kNoBody;
    double k = 0.0;        ///< N/m
    double c = 0.0;        ///< N*s/m along the axis
    double rest = 0.0;     ///< m
    double fx = 0.0, fy = 0.0;  ///< fixed end when b == kNoBody, m
    std::uint32_t sceneIndex = 0;  ///< the spring entity's place in scene order (messages)
    Entity entity;
};

/// One attractor: a dynamic body (`body`) or a fixed point (static body).
struct AttractorData {
    std::uint32_t body = kNoBody;
    double px = 0.0, py = 0.0;  ///< position when fixed, m
    double gm = 0.0;            ///< G * m_a, m^3/s^2
    double eps2 = 0.0;          ///< softening squared, m^2
    double mass = 0.0;          ///< m_a, kg (energy)
};

/// Per-boid parameters (components.hpp Boid), copied so the hot loop reads
/// one contiguous array.
struct BoidParams {
    double neighborRadius2 = 4.0, separationRadius = 0.8;
    double separation = 4.0, alignment = 1.0, cohesion = 1.0;
    double goalX = 0.0, goalY = 0.0, goalWeight = 0.0;  ///< goalWeight 0 when no goal
    double maxSpeed = 4.0;
    double neighborRadius = 2.0;
};

/// Rate (1/s) at which a boid above its max speed is slowed back towards
/// it: a smooth limiter keeps the flock an ordinary ODE (no velocity clamp,
/// which would break every integrator's order and the implicit solve).
inline constexpr double kBoidSpeedLimitRate = 4.0;

/// Boids with a uniform hash grid: cell size = the largest neighbour radius,
/// so a boid's neighbours are in its own and the 8 surrounding cells; the
/// grid is rebuilt per force evaluation by a counting sort (O(n), buffers
/// allocated once at build).
class BoidSystem {
public:
    std::vector<std::uint32_t> body;  ///< dynamic body index of each boid
    std::vector<BoidParams> params;
    double cellSize = 1.0;

    void prepare();  ///< sizes the grid buffers (build time)
    void accumulate(const double* x, const double* v, double* a) const;
    /// O(n^2) reference of accumulate (tests compare the grid against it).
    void accumulateBruteForce(const double* x, const double* v, double* a) const;

private:
    void steer(std::size_t i, const double* x, const double* v, double* a, const std::uint32_t* candidates,
               std::size_t count) const;
    std::size_t bucketOf(double px, double py, int dx, int dy) const;
    std::size_t mask_ = 0;
    mutable std::vector<std::uint32_t> bucketStart_;  ///< mask_+2 entries
    mutable std::vector<std::uint32_t> sorted_;       ///< boid indices by bucket
    mutable std::vector<std::uint32_t> bucketOfBoid_;
    mutable std::vector<std::uint32_t> gather_;       ///< candidates of one boid
};

/// Receives the 2x2 blocks of the force Jacobians (implicit integrators).
/// Indices are dynamic body indices; `block` is row-major.
class JacobianSink {
public:
    virtual ~JacobianSink() = default;
    virtual void spring(std::size_t s, const std::array<double, 4>& dFdx, const std::array<double, 4>& dFdv) = 0;
    virtual void drag(std::size_t body, double minusB) = 0;
    /// d F_body / d p_body for attractor `attractor`; d F_body / d p_attractor
    /// is its negative (when the attractor is dynamic).
    virtual void attraction(std::size_t attractor, std::size_t body, const std::array<double, 4>& dFdx) = 0;
};

class ForceModel {
public:
    std::size_t n = 0;              ///< dynamic bodies
    std::vector<double> mass;       ///< kg
    std::vector<double> invMass;    ///< 1/kg

    bool gravityOn = false;
    double gx = 0.0, gy = 0.0;      ///< m/s^2

    bool dragOn = false;
    std::vector<double> dragB;      ///< kg/s per body (0 = none)
    AlignedDoubles dragRate;        ///< b/m, 1/s per body

    std::vector<SpringData> springs;
    double G = 1.0;
    std::vector<AttractorData> attractors;
    /// Barnes–Hut opening angle (world.theta): 0 sums every pair exactly.
    /// The tree is used only from kTreeMinAttractors attractors on; below
    /// that exact summation is the faster of the two (bench
    /// BarnesHut/crossover), and exact answers satisfy any theta.
    double theta = 0.0;
    static constexpr std::size_t kTreeMinAttractors = 256;
    std::size_t treeMinAttractors = kTreeMinAttractors;  ///< benchmarks lower it to find the crossover
    bool usesTree() const { return theta > 0.0 && attractors.size() >= treeMinAttractors; }
    bool boidsOn = false;
    BoidSystem boids;

    /// Seconds spent in each system since the last resetTimers(); filled
    /// only while `profiling` is true (two clock reads per system call).
    mutable bool profiling = true;
    mutable std::array<double, std::size_t(ForceSystem::Count)> systemSeconds{};

    bool springsOn() const { return !springs.empty(); }
    bool attractorsOn() const { return !attractors.empty(); }
    /// True when every active system is a function of the body's own state
    /// (gravity, drag): integrators may then fuse the force into their loop.
    bool localOnly() const { return !springsOn() && !attractorsOn() && !boidsOn; }
    /// Any system that depends on velocity (for documentation and tests).
    bool velocityDependent() const;

    /// a = F(x, v)/m for every dynamic body. x, v, a: 2n doubles.
    void accelerations(const double* x, const double* v, double* a) const;

    /// Analytic Jacobian blocks of spring, drag and attractor forces
    /// (boids are treated explicitly by the implicit solvers).
    void jacobian(const double* x, const double* v, JacobianSink& sink) const;

    /// Acceleration a unit probe at p feels from gravity and attractors,
    /// skipping attractor body `self` (kNoBody: none). The attractor system
    /// calls this same function per body.
    Vec2 fieldAt(double px, double py, std::uint32_t self, const double* x) const;

    double springEnergy(const double* x) const;
    /// Potential of the attractors at x, J. Computed in the same walk as
    /// their accelerations, which are kept: the next force evaluation at
    /// the same positions (the next step's first) reuses them, so an energy
    /// trace costs about one pass, not an extra one.
    double attractorEnergy(const double* x) const;

    void resetTimers() const { systemSeconds.fill(0.0); }

private:
    void applySprings(const double* x, const double* v, double* a) const;
    void applyAttractors(const double* x, double* a) const;
    /// Attractor acceleration of every body into acc (2n), and with
    /// `Potential` the potential energy, J. Same acceleration bits either way.
    template <bool Potential>
    double attractorPass(const double* x, double* acc) const;
    template <bool Potential>
    Vec2 exactField(double px, double py, std::uint32_t self, const double* x, double* phiFixed,
                    double* phiDynamic) const;

    mutable AttractorTree tree_;
    /// Accelerations computed by attractorEnergy(), valid for the positions
    /// cacheX_ (compared whole, so a hit is exactly a recomputation).
    mutable std::vector<double> cacheX_, cacheAcc_, scratchAcc_;
    mutable double cacheTheta_ = -1.0;
};

/// Scoped timer for one system call; no clock reads when profiling is off.
class SystemTimer {
public:
    SystemTimer(const ForceModel& m, ForceSystem s) : model_(m), system_(s) {
        if (model_.profiling) start_ = std::chrono::steady_clock::now();
    }
    ~SystemTimer() {
        if (model_.profiling)
            model_.systemSeconds[std::size_t(system_)] +=
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    }
    SystemTimer(const SystemTimer&) = delete;
    SystemTimer& operator=(const SystemTimer&) = delete;

private:
    const ForceModel& model_;
    ForceSystem system_;
    std::chrono::steady_clock::time_point start_{};
};

} // namespace stepwise::detail
