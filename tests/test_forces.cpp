// Force systems against their formulas: springs, damping, drag, softened
// attractors (and the field probe), boids on the grid against brute force,
// and the analytic Jacobians against finite differences.

#include "physics_scenes.hpp"
#include "report/scenes.hpp"

#include "world/world_internals.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <random>

using namespace stepwise;
using namespace stepwise::testing;

namespace {

TEST(Forces, SpringBetweenTwoBodiesIsHookePlusAxialDamping) {
    Scene s = emptyScene("rk4", 0.01);
    addBody(s, "a", {0.0, 0.0}, {1.0, 2.0}, 2.0);
    addBody(s, "b", {3.0, 4.0}, {-1.0, 0.5}, 1.0);  // length 5
    addSpring(s, "s", "a", "b", 10.0, 0.5, 4.0);
    World w = buildOrDie(s);
    const std::vector<Vec2> f = w.bodyForces();
    // u = (a - b)/5 = (-0.6, -0.8); rate = u.(v_a - v_b) = -0.6*2 - 0.8*1.5 = -2.4
    // tension = 10 (5 - 4) + 0.5 (-2.4) = 8.8; F_a = -8.8 u.
    EXPECT_NEAR(f[0].x, 8.8 * 0.6, 1e-12);
    EXPECT_NEAR(f[0].y, 8.8 * 0.8, 1e-12);
    EXPECT_NEAR(f[1].x, -8.8 * 0.6, 1e-12);
    EXPECT_NEAR(f[1].y, -8.8 * 0.8, 1e-12);
    EXPECT_NEAR(w.energy().springs, 0.5 * 10.0 * 1.0, 1e-12);
}

TEST(Forces, StaticEndAndAnchorAreFixedPoints) {
    Scene s = emptyScene("rk4", 0.01);
    addStatic(s, "wall", {0.0, 0.0});
    addBody(s, "a", {2.0, 0.0}, {0.0, 0.0});
    addBody(s, "b", {0.0, -3.0}, {0.0, 0.0});
    addSpring(s, "s1", "wall", "a", 5.0, 0.0, 1.0);  // static end first: swapped internally
    addAnchoredSpring(s, "s2", "b", {0.0, 0.0}, 2.0, 0.0, 1.0);
    World w = buildOrDie(s);
    ASSERT_EQ(w.bodyCount(), 2u);
    const std::vector<Vec2> f = w.bodyForces();
    EXPECT_NEAR(f[0].x, -5.0, 1e-12);
    EXPECT_NEAR(f[1].y, 4.0, 1e-12);
    for (int i = 0; i < 10; ++i) ASSERT_TRUE(w.step().ok());
    Scene back = s;
    w.writeBack(back);
    EXPECT_EQ(back.registry.tryGet<Position>(back.registry.entities()[0])->value, (Vec2{0.0, 0.0}));
}

TEST(Forces, DragAndGravity) {
    Scene s = emptyScene("rk4", 0.01, {0.0, -9.81});
    Entity e = addBody(s, "a", {0.0, 0.0}, {2.0, -1.0}, 4.0);
    s.registry.emplace<Drag>(e, {0.5});
    World w = buildOrDie(s);
    EXPECT_EQ(w.activeSystems(), (std::vector<std::string_view>{"gravity", "drag"}));
    const Vec2 f = w.bodyForces()[0];
    EXPECT_NEAR(f.x, -1.0, 1e-12);
    EXPECT_NEAR(f.y, -4.0 * 9.81 + 0.5, 1e-12);
    // Drag is not part of the probe (it depends on the body's own b).
    EXPECT_EQ(w.probeForce({5.0, 5.0}, {1.0, 1.0}), (Vec2{0.0, -9.81}));
}

TEST(Forces, SoftenedAttractorAndProbeUseTheSameFormula) {
    Scene s = emptyScene("rk4", 0.01);
    s.world.G = 2.0;
    Entity sun = addStatic(s, "sun", {1.0, 1.0}, 3.0);
    s.registry.emplace<Attractor>(sun, {0.5});
    addBody(s, "p", {4.0, 5.0}, {0.0, 0.0}, 0.25);
    World w = buildOrDie(s);
    // d = (-3, -4), |d|^2 = 25, q = 25.25; a = G m_a d / q^1.5.
    const double q = 25.25, scale = 2.0 * 3.0 / (q * std::sqrt(q));
    const Vec2 f = w.bodyForces()[0];
    EXPECT_NEAR(f.x, 0.25 * scale * -3.0, 1e-14);
    EXPECT_NEAR(f.y, 0.25 * scale * -4.0, 1e-14);
    const Vec2 probe = w.probeForce({4.0, 5.0});
    EXPECT_DOUBLE_EQ(probe.x, scale * -3.0);
    EXPECT_DOUBLE_EQ(probe.y, scale * -4.0);
    EXPECT_NEAR(w.energy().attractors, -2.0 * 3.0 * 0.25 / std::sqrt(q), 1e-14);
    // At the centre of a softened attractor the pull vanishes.
    EXPECT_EQ(w.probeForce({1.0, 1.0}), (Vec2{0.0, 0.0}));
}

TEST(Forces, DynamicAttractorsPullEachOtherNBody) {
    Scene s = emptyScene("rk4", 0.001);
    Entity a = addBody(s, "a", {-1.0, 0.0}, {0.0, -0.5}, 1.0);
    Entity b = addBody(s, "b", {1.0, 0.0}, {0.0, 0.5}, 1.0);
    s.registry.emplace<Attractor>(a, {0.0});
    s.registry.emplace<Attractor>(b, {0.0});
    World w = buildOrDie(s);
    const std::vector<Vec2> f = w.bodyForces();
    EXPECT_NEAR(f[0].x, 0.25, 1e-14);  // G m m / r^2 = 1/4
    EXPECT_NEAR(f[1].x, -0.25, 1e-14);
    EXPECT_NEAR(w.energy().attractors, -0.5, 1e-14);  // the pair counted once
    const EnergyReport e0 = w.energy();
    for (int i = 0; i < 2000; ++i) ASSERT_TRUE(w.step().ok());
    const EnergyReport e1 = w.energy();
    EXPECT_NEAR(e1.total(), e0.total(), 1e-9);
    EXPECT_NEAR(e1.momentum.x, 0.0, 1e-12);
    EXPECT_NEAR(e1.momentum.y, 0.0, 1e-12);
}

TEST(Forces, BoidGridMatchesBruteForce) {
    Scene s = emptyScene("semi_implicit_euler", 0.01);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> pos(-15.0, 15.0), vel(-3.0, 3.0), radius(1.0, 3.0);
    for (int i = 0; i < 400; ++i) {
        Entity e = addBody(s, "b" + std::to_string(i), {pos(rng), pos(rng)}, {vel(rng), vel(rng)});
        Boid boid;
        boid.neighborRadius = radius(rng);  // mixed radii: cell = the largest
        boid.separationRadius = 0.8;
        if (i % 2) boid.goal = Vec2{1.0, 2.0};
        s.registry.emplace<Boid>(e, boid);
    }
    World w = buildOrDie(s);
    const detail::ForceModel& model = internals(w).model;
    const std::size_t m = 2 * model.n;
    std::vector<double> grid(m, 0.0), brute(m, 0.0);
    model.boids.accumulate(internals(w).xs(), internals(w).vs(), grid.data());
    model.boids.accumulateBruteForce(internals(w).xs(), internals(w).vs(), brute.data());
    int withNeighbours = 0;
    for (std::size_t i = 0; i < m; ++i) {
        EXPECT_NEAR(grid[i], brute[i], 1e-12) << i;
        withNeighbours += grid[i] != 0.0;
    }
    EXPECT_GT(withNeighbours, 100);
}

TEST(Forces, BoidSteersTowardGoalAndLimitsSpeed) {
    Scene s = emptyScene("semi_implicit_euler", 1.0 / 60.0);
    Entity e = addBody(s, "solo", {0.0, 0.0}, {0.0, 0.0});
    Boid boid;
    boid.goal = Vec2{10.0, 0.0};
    boid.goalWeight = 2.0;
    boid.maxSpeed = 3.0;
    s.registry.emplace<Boid>(e, boid);
    World w = buildOrDie(s);
    // At rest: desired velocity (3, 0), steering (3 - 0)/3 * 2 = 2 m/s^2.
    EXPECT_NEAR(w.bodyForces()[0].x, 2.0, 1e-12);
    double fastest = 0.0;
    for (int i = 0; i < 240; ++i) {
        ASSERT_TRUE(w.step().ok());
        fastest = std::max(fastest, length(w.bodyVelocity(0)));
    }
    EXPECT_LT(fastest, 3.0 + 1e-9);  // seek never asks for more than max speed
    EXPECT_GT(w.bodyPosition(0).x, 5.0);
}

// Collects Jacobian blocks into dense 2n x 2n dF/dx and dF/dv.
struct DenseSink : detail::JacobianSink {
    const detail::ForceModel& model;
    std::vector<double> K, D;
    std::size_t m;
    explicit DenseSink(const detail::ForceModel& f) : model(f), K(4 * f.n * f.n), D(4 * f.n * f.n), m(2 * f.n) {}
    void add(std::vector<double>& M, std::size_t r, std::size_t c, double sign, const std::array<double, 4>& b) {
        for (int e = 0; e < 4; ++e) M[(2 * r + std::size_t(e / 2)) * m + 2 * c + std::size_t(e % 2)] += sign * b[e];
    }
    void spring(std::size_t s, const std::array<double, 4>& dFdx, const std::array<double, 4>& dFdv) override {
        const auto& sp = model.springs[s];
        add(K, sp.a, sp.a, 1, dFdx);
        add(D, sp.a, sp.a, 1, dFdv);
        if (sp.b != detail::kNoBody) {
            add(K, sp.b, sp.b, 1, dFdx);
            add(K, sp.a, sp.b, -1, dFdx);
            add(K, sp.b, sp.a, -1, dFdx);
            add(D, sp.b, sp.b, 1, dFdv);
            add(D, sp.a, sp.b, -1, dFdv);
            add(D, sp.b, sp.a, -1, dFdv);
        }
    }
    void drag(std::size_t body, double minusB) override {
        D[(2 * body) * m + 2 * body] += minusB;
        D[(2 * body + 1) * m + 2 * body + 1] += minusB;
    }
    void attraction(std::size_t k, std::size_t body, const std::array<double, 4>& dFdx) override {
        add(K, body, body, 1, dFdx);
        if (model.attractors[k].body != detail::kNoBody) add(K, body, model.attractors[k].body, -1, dFdx);
    }
};

TEST(Forces, AnalyticJacobiansMatchFiniteDifferences) {
    // Undamped springs (the damping's position derivative is the one term
    // the solver drops, documented in force_model.cpp), drag, a static and
    // a dynamic attractor.
    Scene s = emptyScene("implicit_euler", 0.01, {0.0, -9.81});
    addStatic(s, "post", {0.0, 0.0});
    addBody(s, "a", {1.1, 0.2}, {0.3, -0.1}, 0.5);
    Entity b = addBody(s, "b", {2.0, -0.7}, {-0.2, 0.4}, 0.7);
    addBody(s, "c", {0.4, -1.5}, {0.0, 0.0}, 1.3);
    s.registry.emplace<Drag>(b, {0.3});
    s.registry.emplace<Attractor>(b, {0.2});
    Entity sun = addStatic(s, "sun", {-2.0, 1.0}, 4.0);
    s.registry.emplace<Attractor>(sun, {0.1});
    addSpring(s, "s1", "post", "a", 30.0, 0.0, 0.8);
    addSpring(s, "s2", "a", "b", 20.0, 0.0, 1.5);  // compressed: the tension term is negative
    addSpring(s, "s3", "b", "c", 10.0, 0.0, 0.5);
    World w = buildOrDie(s);
    const detail::ForceModel& f = internals(w).model;
    const std::size_t m = 2 * f.n;
    std::vector<double> x(internals(w).xs(), internals(w).xs() + m), v(internals(w).vs(), internals(w).vs() + m);
    DenseSink sink(f);
    f.jacobian(x.data(), v.data(), sink);
    auto force = [&](const std::vector<double>& xx, const std::vector<double>& vv) {
        std::vector<double> a(m);
        f.accelerations(xx.data(), vv.data(), a.data());
        for (std::size_t i = 0; i < m; ++i) a[i] *= f.mass[i / 2];
        return a;
    };
    const double eps = 1e-6;
    for (std::size_t j = 0; j < m; ++j) {
        std::vector<double> xp = x, xm = x, vp = v, vm = v;
        xp[j] += eps;
        xm[j] -= eps;
        vp[j] += eps;
        vm[j] -= eps;
        const auto fxp = force(xp, v), fxm = force(xm, v), fvp = force(x, vp), fvm = force(x, vm);
        for (std::size_t i = 0; i < m; ++i) {
            EXPECT_NEAR(sink.K[i * m + j], (fxp[i] - fxm[i]) / (2 * eps), 1e-6) << "dF" << i << "/dx" << j;
            EXPECT_NEAR(sink.D[i * m + j], (fvp[i] - fvm[i]) / (2 * eps), 1e-6) << "dF" << i << "/dv" << j;
        }
    }
}

TEST(Forces, ConservativeSceneConservesEnergyUnderRk4) {
    // Springs + gravity + attractor, no dissipation: total energy from
    // energy() is what the forces conserve (the potentials match the forces).
    Scene s = emptyScene("rk4", 1e-3, {0.0, -9.81});
    addStatic(s, "post", {0.0, 0.0});
    addBody(s, "a", {1.0, 0.0}, {0.0, 1.0}, 0.5);
    addBody(s, "b", {2.0, 0.5}, {0.5, 0.0}, 0.8);
    addSpring(s, "s1", "post", "a", 40.0, 0.0, 1.0);
    addSpring(s, "s2", "a", "b", 25.0, 0.0, 1.0);
    Entity sun = addStatic(s, "sun", {0.0, -3.0}, 5.0);
    s.registry.emplace<Attractor>(sun, {0.3});
    World w = buildOrDie(s);
    const double e0 = w.energy().total();
    EXPECT_NE(w.energy().springs, 0.0);
    for (int i = 0; i < 3000; ++i) ASSERT_TRUE(w.step().ok());
    EXPECT_NEAR(w.energy().total(), e0, 1e-8 * std::abs(e0) + 1e-9);
}

} // namespace

// --- Barnes–Hut ------------------------------------------------------------

namespace {
std::vector<Vec2> positions(const World& w) {
    std::vector<Vec2> p(w.bodyCount());
    for (std::size_t b = 0; b < p.size(); ++b) p[b] = w.bodyPosition(b);
    return p;
}
} // namespace

TEST(BarnesHut, TenThousandAttractorsAfterFiveStepsWithinOnePercentOfTheDistanceMoved) {
    // The goal, as a bound: the bodies start at rest, so every
    // metre they move is the attraction's doing, and the tree's error is
    // compared with that. Exact pairwise summation (theta 0) is the reference.
    const std::size_t n = 10000;
    World exact = buildOrDie(report::attractorDisc(n, 0.0));
    World tree = buildOrDie(report::attractorDisc(n, 0.5));
    ASSERT_TRUE(internals(tree).model.usesTree());
    ASSERT_FALSE(internals(exact).model.usesTree());
    const std::vector<Vec2> start = positions(exact);
    for (int i = 0; i < 5; ++i) {
        ASSERT_TRUE(exact.step().ok());
        ASSERT_TRUE(tree.step().ok());
    }
    double moved2 = 0.0, error2 = 0.0, worstError = 0.0, meanMoved = 0.0;
    for (std::size_t b = 0; b < n; ++b) {
        const double moved = length(exact.bodyPosition(b) - start[b]);
        const double error = length(tree.bodyPosition(b) - exact.bodyPosition(b));
        moved2 += moved * moved;
        error2 += error * error;
        meanMoved += moved / double(n);
        worstError = std::max(worstError, error);
    }
    const double rmsMoved = std::sqrt(moved2 / double(n)), rmsError = std::sqrt(error2 / double(n));
    EXPECT_GT(rmsMoved, 1e-4);  // they did move
    EXPECT_LT(rmsError, 0.01 * rmsMoved) << "rms error " << rmsError << " m, rms distance moved " << rmsMoved << " m";
    EXPECT_LT(worstError, 0.01 * meanMoved) << "worst error " << worstError << " m, mean distance moved " << meanMoved;
    EXPECT_GT(rmsError, 0.0);  // and the tree really approximated
}

TEST(BarnesHut, BelowTheCrossoverAndAtThetaZeroTheSumIsExact) {
    // Fewer attractors than kTreeMinAttractors: exact summation is faster
    // and satisfies any theta, so the bits equal theta = 0's.
    const std::size_t n = detail::ForceModel::kTreeMinAttractors - 1;
    World a = buildOrDie(report::attractorDisc(n, 0.0));
    World b = buildOrDie(report::attractorDisc(n, 0.9));
    EXPECT_FALSE(internals(b).model.usesTree());
    for (int i = 0; i < 3; ++i) {
        ASSERT_TRUE(a.step().ok());
        ASSERT_TRUE(b.step().ok());
    }
    const std::vector<Vec2> pa = positions(a), pb = positions(b);
    EXPECT_EQ(std::memcmp(pa.data(), pb.data(), pa.size() * sizeof(Vec2)), 0);
}

TEST(BarnesHut, ForceErrorShrinksWithThetaAndTheEnergyComesFromTheTreeToo) {
    const std::size_t n = 2000;
    const World exact = buildOrDie(report::attractorDisc(n, 0.0));
    const std::vector<Vec2> reference = exact.bodyForces();
    const double exactEnergy = exact.energy().attractors;
    double previous = INFINITY;
    for (double theta : {1.0, 0.7, 0.5, 0.3}) {
        const World w = buildOrDie(report::attractorDisc(n, theta));
        const std::vector<Vec2> f = w.bodyForces();
        double err2 = 0.0, ref2 = 0.0;
        for (std::size_t b = 0; b < n; ++b) {
            err2 += lengthSquared(f[b] - reference[b]);
            ref2 += lengthSquared(reference[b]);
        }
        const double relative = std::sqrt(err2 / ref2);
        EXPECT_LT(relative, previous) << theta;
        EXPECT_LT(relative, 0.02 * theta * theta) << theta;  // monopole: error ~ theta^2
        EXPECT_NEAR(w.energy().attractors, exactEnergy, 0.01 * theta * theta * std::fabs(exactEnergy)) << theta;
        previous = relative;
    }
}

TEST(BarnesHut, AnEnergyTraceChangesNoBitOfTheRun) {
    // energy() computes the attractors' accelerations with their potential
    // and the next step reuses them: a run that logs energy every step must
    // be the run that does not, bit for bit, exact or through the tree.
    for (double theta : {0.0, 0.5}) {
        World quiet = buildOrDie(report::attractorDisc(600, theta, "rk4"));
        World traced = buildOrDie(report::attractorDisc(600, theta, "rk4"));
        for (int i = 0; i < 4; ++i) {
            ASSERT_TRUE(quiet.step().ok());
            (void)traced.energy();
            ASSERT_TRUE(traced.step().ok());
            (void)traced.energy();
        }
        const std::vector<Vec2> pq = positions(quiet), pt = positions(traced);
        EXPECT_EQ(std::memcmp(pq.data(), pt.data(), pq.size() * sizeof(Vec2)), 0) << theta;
    }
}
