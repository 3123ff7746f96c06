// Collision detection and response against analytic answers. These tests
// drive the collision stages directly with a minimal semi-implicit Euler
// loop, so a failure points at the collision code, not the integrators.

#include "collision/collision_system.hpp"
#include "collision/narrow_phase.hpp"
#include "integrators/integrator.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <iterator>
#include <numbers>
#include <random>

using namespace stepwise;
using namespace stepwise::collision;

namespace {

Shape circle(double r) { return Shape{ShapeKind::Circle, r, {}, {}, 0.0}; }
Shape box(double w, double h) { return Shape{ShapeKind::Box, 0.0, {w / 2, h / 2}, {}, 0.0}; }
Shape plane(Vec2 n, double offset) { return Shape{ShapeKind::Plane, 0.0, {}, n / length(n), offset / length(n)}; }

/// The smallest world that exercises the collision pipeline the way World
/// does: detect once per step, then per substep integrate (gravity,
/// semi-implicit Euler) and solve contacts.
struct MiniWorld {
    CollisionSystem collision;
    std::vector<Vec2> x, v;
    std::vector<double> mass;
    Vec2 gravity{0.0, 0.0};
    int substeps = 4;

    int dynamic(const Shape& s, Vec2 p, Vec2 vel, double m, double e = 0.0, double f = 0.2, double angle = 0.0) {
        const int body = int(x.size());
        x.push_back(p);
        v.push_back(vel);
        mass.push_back(m);
        Collider c;
        c.shape = s;
        c.body = body;
        c.mass = m;
        c.restitution = e;
        c.friction = f;
        c.entity = Entity{std::uint32_t(collision.colliderCount()), 0};
        collision.add(c, angle, 0.0);
        return body;
    }
    void fixed(const Shape& s, Vec2 p, double e = 0.0, double f = 0.2, double angle = 0.0) {
        Collider c;
        c.shape = s;
        c.staticPosition = p;
        c.restitution = e;
        c.friction = f;
        c.entity = Entity{std::uint32_t(collision.colliderCount()), 0};
        collision.add(c, angle, 0.0);
    }
    void step(double dt) {
        collision.beginStep(x, v, dt, substeps);
        const double h = dt / substeps;
        for (int s = 0; s < substeps; ++s) {
            for (std::size_t i = 0; i < x.size(); ++i) {
                v[i] += h * gravity;
                x[i] += h * v[i];
            }
            collision.solveSubstep(x, v, h);
        }
        collision.endStep();
    }
    double kinetic() const {
        double k = 0.0;
        for (std::size_t i = 0; i < x.size(); ++i) k += 0.5 * mass[i] * lengthSquared(v[i]);
        for (std::size_t c = 0; c < collision.colliderCount(); ++c) {
            const Collider& col = collision.collider(c);
            if (col.body < 0) continue;
            const double w = collision.angularVelocity(c);
            k += 0.5 * momentOfInertia(col.shape, col.mass) * w * w;
        }
        return k;
    }
    Vec2 momentum() const {
        Vec2 p;
        for (std::size_t i = 0; i < x.size(); ++i) p += mass[i] * v[i];
        return p;
    }
};

} // namespace

// ---------------------------------------------------------------- narrow phase

TEST(NarrowPhase, CirclesOverlapAlongTheLineOfCentres) {
    const Manifold m = collideCircles(1.0, {0, 0}, 0.5, {1.2, 0.9}, 0.0);  // distance 1.5
    ASSERT_EQ(m.pointCount, 1);
    EXPECT_NEAR(m.normal.x, 0.8, 1e-15);
    EXPECT_NEAR(m.normal.y, 0.6, 1e-15);
    EXPECT_NEAR(m.points[0].separation, 0.0, 1e-15);
    EXPECT_EQ(collideCircles(1.0, {0, 0}, 0.5, {3.0, 0.0}, 0.0).pointCount, 0);
    EXPECT_EQ(collideCircles(1.0, {0, 0}, 0.5, {3.0, 0.0}, 1.6).pointCount, 1) << "speculative margin";
}

TEST(NarrowPhase, BoxRestingOnBoxGivesTwoPointsWithTheOverlap) {
    // 1x1 box whose bottom is 0.01 m into a 4x1 ground box.
    const Manifold m = collideBoxes({2.0, 0.5}, {0, 0}, Rot{}, {0.5, 0.5}, {0.3, 0.99}, Rot{}, 0.0);
    ASSERT_EQ(m.pointCount, 2);
    EXPECT_NEAR(m.normal.x, 0.0, 1e-15);
    EXPECT_NEAR(m.normal.y, 1.0, 1e-15);
    for (int i = 0; i < 2; ++i) EXPECT_NEAR(m.points[i].separation, -0.01, 1e-12);
    EXPECT_NEAR(std::abs(m.points[0].point.x - m.points[1].point.x), 1.0, 1e-12);
}

TEST(NarrowPhase, RotatedBoxCornerOnPlane) {
    // A unit box turned 45 degrees: its lowest corner is sqrt(2)/2 below the centre.
    const double halfDiagonal = std::sqrt(0.5);
    const Manifold m = collidePlaneBox({0, 1}, 0.0, {0.5, 0.5}, {0.0, halfDiagonal - 0.02},
                                       Rot::fromAngle(std::numbers::pi / 4), 0.0);
    ASSERT_EQ(m.pointCount, 1);
    EXPECT_NEAR(m.points[0].separation, -0.02, 1e-12);
    EXPECT_NEAR(m.points[0].point.x, 0.0, 1e-12);
}

TEST(NarrowPhase, CircleAgainstBoxFaceAndCorner) {
    Manifold face = collideBoxCircle({1.0, 0.5}, {0, 0}, Rot{}, 0.25, {0.2, 0.7}, 0.0);
    ASSERT_EQ(face.pointCount, 1);
    EXPECT_NEAR(face.normal.y, 1.0, 1e-15);
    EXPECT_NEAR(face.points[0].separation, -0.05, 1e-12);
    Manifold corner = collideBoxCircle({1.0, 0.5}, {0, 0}, Rot{}, 0.5, {1.3, 0.9}, 0.0);  // 0.5 from the corner
    ASSERT_EQ(corner.pointCount, 1);
    EXPECT_NEAR(corner.normal.x, 0.6, 1e-12);
    EXPECT_NEAR(corner.normal.y, 0.8, 1e-12);
    EXPECT_NEAR(corner.points[0].separation, 0.0, 1e-12);
}

TEST(BroadPhase, StrategiesAgreeWithBruteForce) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> pos(-20, 20), size(0.1, 2.0);
    std::vector<Aabb> boxes;
    std::vector<std::uint8_t> movable;
    for (int i = 0; i < 500; ++i) {
        const Vec2 p{pos(rng), pos(rng)};
        const Vec2 h{size(rng), size(rng)};
        boxes.push_back({p - h, p + h});
        movable.push_back(i % 5 != 0);
    }
    boxes.push_back({{-30, -25}, {30, -21}});  // a long wall
    movable.push_back(0);
    std::vector<ProxyPair> brute, sap, grid;
    BroadPhase(BroadPhaseKind::BruteForce).findPairs(boxes, movable, brute);
    BroadPhase(BroadPhaseKind::SweepAndPrune).findPairs(boxes, movable, sap);
    BroadPhase(BroadPhaseKind::UniformGrid).findPairs(boxes, movable, grid);
    EXPECT_GT(brute.size(), 100u);
    EXPECT_EQ(sap, brute);
    EXPECT_EQ(grid, brute);
}

// The pair sort counts pairs by their first box and sorts each box's pairs
// by insertion, or with std::sort past 32; the grid's cells are counted
// when the grid is dense and radix-sorted when it is sparse. A floor first
// (index 0, meeting every box) and boxes spread over thousands of cells per axis
// (200 m apart) reach the other branches; every strategy still gives brute force's pairs.
TEST(BroadPhase, StrategiesAgreeWithAFloorFirstAndASparseGrid) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> x(-20, 20), size(0.1, 0.5);
    std::vector<Aabb> boxes{{{-30, -1}, {30, 0.05}}};  // the floor, box 0
    std::vector<std::uint8_t> movable{0};
    for (int i = 0; i < 300; ++i) {
        const Vec2 p{x(rng), 0.0}, h{size(rng), size(rng)};
        boxes.push_back({p - h, p + h});
        movable.push_back(1);
    }
    for (int i = 0; i < 40; ++i) {  // sparse: far apart, in pairs that touch
        const Vec2 p{200.0 * i, 300.0 * (i % 7)};
        boxes.push_back({p, p + Vec2{0.3, 0.3}});
        boxes.push_back({p + Vec2{0.2, 0.2}, p + Vec2{0.5, 0.5}});
        movable.push_back(1);
        movable.push_back(1);
    }
    std::vector<ProxyPair> brute, sap, grid;
    BroadPhase(BroadPhaseKind::BruteForce).findPairs(boxes, movable, brute);
    BroadPhase(BroadPhaseKind::SweepAndPrune).findPairs(boxes, movable, sap);
    BroadPhase(BroadPhaseKind::UniformGrid).findPairs(boxes, movable, grid);
    std::size_t floorPairs = 0;
    for (const ProxyPair& p : brute) floorPairs += p.a == 0 ? 1 : 0;
    EXPECT_GT(floorPairs, 200u);
    EXPECT_EQ(sap, brute);
    EXPECT_EQ(grid, brute);
    // The sparse part alone: 80 boxes over a grid far larger than the keys.
    std::vector<Aabb> sparse(boxes.end() - 80, boxes.end());
    std::vector<std::uint8_t> sparseMovable(80, 1);
    std::vector<ProxyPair> sparseBrute, sparseGrid;
    BroadPhase(BroadPhaseKind::BruteForce).findPairs(sparse, sparseMovable, sparseBrute);
    BroadPhase(BroadPhaseKind::UniformGrid).findPairs(sparse, sparseMovable, sparseGrid);
    EXPECT_EQ(sparseBrute.size(), 40u);
    EXPECT_EQ(sparseGrid, sparseBrute);
}

// A crowded grid cell (a crowd pressed together) bounds the pairs among its
// moving boxes, but each of its static boxes (the segments of a wall the
// crowd presses on) must still meet every box it overlaps: a missed wall
// pair lets a body through the wall. Swept over the crowd's size.
TEST(BroadPhase, ACrowdedCellPairsEveryBoxWithItsStaticShapes) {
    for (const int crowd : {65, 200, 1000}) {
        std::mt19937 rng{std::uint32_t(crowd)};
        std::uniform_real_distribution<double> x(0.0, 1.0);
        std::vector<Aabb> boxes;
        std::vector<std::uint8_t> movable;
        for (int i = 0; i < crowd; ++i) {
            const Vec2 p{x(rng), x(rng)};
            boxes.push_back({p - Vec2{0.3, 0.3}, p + Vec2{0.3, 0.3}});
            movable.push_back(1);
        }
        for (int k = 0; k < 4; ++k) {  // a wall of four segments through the crowd
            boxes.push_back({{0.25 * k, 0.45}, {0.25 * (k + 1), 0.55}});
            movable.push_back(0);
        }
        std::vector<ProxyPair> brute, grid;
        BroadPhase(BroadPhaseKind::BruteForce).findPairs(boxes, movable, brute);
        BroadPhase grids(BroadPhaseKind::UniformGrid);
        grids.findPairs(boxes, movable, grid);
        ASSERT_FALSE(grids.crowded().empty());
        EXPECT_EQ(grids.crowded()[0], 1) << crowd << ": the crowd should fill one cell";
        std::vector<ProxyPair> bruteStatic, gridStatic;
        const auto withWall = [&](const ProxyPair& p) { return !movable[p.a] || !movable[p.b]; };
        std::copy_if(brute.begin(), brute.end(), std::back_inserter(bruteStatic), withWall);
        std::copy_if(grid.begin(), grid.end(), std::back_inserter(gridStatic), withWall);
        EXPECT_GT(bruteStatic.size(), std::size_t(crowd)) << crowd;
        EXPECT_EQ(gridStatic, bruteStatic) << crowd << " bodies in one cell";
        EXPECT_LT(grid.size(), brute.size()) << crowd << ": the moving pairs stay bounded";
    }
}

// A pile of shapes side by side, moving fast: each box is fattened by its
// motion to several times its shape, so a grid cell holds far more boxes
// than a crowd's threshold count, yet no two shapes overlap. Every pair is
// a contact the step may need, so the grid finds them all once it is told
// the boxes' cores; told nothing, it takes the cell for a crowd and drops
// most of them. Shapes piled on top of each other are still a crowd.
// Swept over the margin (shapes 0.7 m wide, 0.75 m apart; past a margin
// of a metre the cells hold more boxes than the crowd count).
TEST(BroadPhase, AFastPileSideBySideKeepsEveryPairAndACrowdStaysBounded) {
    for (const double margin : {0.05, 0.3, 0.6, 1.2, 2.4}) {
        std::vector<Aabb> boxes;
        std::vector<std::uint8_t> movable;
        std::vector<double> cores;
        for (int row = 0; row < 30; ++row)
            for (int col = 0; col < 60; ++col) {
                const Vec2 p{0.75 * col, 0.75 * row}, h{0.35 + margin, 0.35 + margin};
                boxes.push_back({p - h, p + h});
                movable.push_back(1);
                cores.push_back(0.7 * 0.7);
            }
        std::vector<ProxyPair> brute, told, untold;
        BroadPhase(BroadPhaseKind::BruteForce).findPairs(boxes, movable, brute);
        BroadPhase grid(BroadPhaseKind::UniformGrid);
        grid.findPairs(boxes, movable, told, cores);
        EXPECT_EQ(told, brute) << "margin " << margin;
        EXPECT_EQ(std::count(grid.crowded().begin(), grid.crowded().end(), 1), 0) << "margin " << margin;
        BroadPhase(BroadPhaseKind::UniformGrid).findPairs(boxes, movable, untold);
        if (margin >= 1.2) EXPECT_LT(untold.size(), brute.size() / 2) << "margin " << margin << ": cores decide";
    }
    for (const int crowd : {200, 1000}) {  // on top of each other: cores cover the cell many times
        std::mt19937 rng{std::uint32_t(crowd)};
        std::uniform_real_distribution<double> x(0.0, 1.0);
        std::vector<Aabb> boxes;
        std::vector<std::uint8_t> movable(std::size_t(crowd), 1);
        std::vector<double> cores(std::size_t(crowd), 0.5 * 0.5);
        for (int i = 0; i < crowd; ++i) {
            const Vec2 p{x(rng), x(rng)};
            boxes.push_back({p - Vec2{0.3, 0.3}, p + Vec2{0.3, 0.3}});
        }
        std::vector<ProxyPair> brute, grid;
        BroadPhase(BroadPhaseKind::BruteForce).findPairs(boxes, movable, brute);
        BroadPhase phase(BroadPhaseKind::UniformGrid);
        phase.findPairs(boxes, movable, grid, cores);
        EXPECT_EQ(phase.crowded()[0], 1) << crowd;
        EXPECT_LT(grid.size(), brute.size() / 10) << crowd << ": the pairs stay bounded";
    }
}

// A grid kept between calls (the pairs of grown boxes, filtered) must give
// exactly a fresh grid's pairs and crowd flags on every call. Boxes drift
// and jitter at a speed swept from rest (almost every call served from the
// kept pairs) to faster than their growth (few served), with a floor wider
// than the cells and static boxes; for three calls a crowd of 100 is
// dropped on one point (which a fresh grid thins by its Z-order window) and
// spreads out. Cores are given on one run of each speed and left out on the
// other.
TEST(BroadPhase, KeptPairsEqualAFreshGridOnEveryCallAtAnySpeed) {
    std::size_t servedAtRest = 0, servedFastest = 0;
    for (const double speed : {0.0, 1e-4, 1e-3, 0.01, 0.05, 0.2, 1.0}) {
        for (const bool withCores : {false, true}) {
            std::mt19937 rng{std::uint32_t(1000 * speed) + (withCores ? 7u : 0u)};
            std::uniform_real_distribution<double> unit(-1.0, 1.0);
            std::vector<Vec2> centre, half;
            std::vector<std::uint8_t> movable;
            for (int row = 0; row < 30; ++row)
                for (int col = 0; col < 40; ++col) {
                    centre.push_back({1.05 * col, 1.05 * row + 0.5});
                    half.push_back({0.5 + 0.02 * unit(rng), 0.5 + 0.02 * unit(rng)});
                    movable.push_back(col % 13 == 0 ? 0 : 1);
                }
            centre.push_back({20.0, -0.5});  // a floor far wider than a cell
            half.push_back({30.0, 0.5});
            movable.push_back(0);
            const std::size_t scene = centre.size();
            std::vector<Vec2> crowd(100);
            for (Vec2& p : crowd) p = {10.0 + 0.01 * unit(rng), 40.0 + 0.01 * unit(rng)};
            BroadPhase kept(BroadPhaseKind::UniformGrid);
            std::size_t served = 0;
            for (int call = 0; call < 60; ++call) {
                std::vector<Aabb> boxes;
                std::vector<double> cores;
                for (std::size_t i = 0; i < scene; ++i) {
                    if (movable[i]) centre[i] += speed * Vec2{unit(rng), unit(rng)};
                    const double margin = 0.02 + speed * 0.5 * (1.0 + unit(rng));
                    boxes.push_back({centre[i] - half[i] - Vec2{margin, margin}, centre[i] + half[i] + Vec2{margin, margin}});
                    cores.push_back(4.0 * half[i].x * half[i].y);
                }
                movable.resize(scene);
                if (call >= 30 && call < 33) {
                    for (Vec2& p : crowd) {
                        p = Vec2{10.0, 40.0} + 4.0 * (p - Vec2{10.0, 40.0});
                        boxes.push_back({p - Vec2{0.3, 0.3}, p + Vec2{0.3, 0.3}});
                        cores.push_back(0.36);
                        movable.push_back(1);
                    }
                }
                const std::span<const double> coreArea = withCores ? std::span<const double>(cores) : std::span<const double>();
                std::vector<ProxyPair> keptPairs, freshPairs;
                kept.findPairs(boxes, movable, keptPairs, coreArea);
                BroadPhase fresh(BroadPhaseKind::UniformGrid);
                fresh.findPairs(boxes, movable, freshPairs, coreArea);
                ASSERT_EQ(keptPairs, freshPairs) << "speed " << speed << ", call " << call;
                ASSERT_TRUE(std::ranges::equal(kept.crowded(), fresh.crowded())) << "speed " << speed << ", call " << call;
                served += kept.lastServedFromKept() ? 1 : 0;
            }
            if (speed == 0.0) servedAtRest += served;
            if (speed == 1.0) servedFastest += served;
        }
    }
    // At rest, all but the crowd's calls and the pause after them (8 calls);
    // boxes moving up to a metre a call outrun their growth.
    EXPECT_GE(servedAtRest, 2u * 45u);
    EXPECT_LE(servedFastest, 2u * 10u);
}

// The grown boxes' grid is coarser than a fresh one, so a cluster of small
// boxes can fill one fresh cell past the crowd count while the grown grid
// splits it over four cells (its boundaries fall across the cluster). The
// kept pairs would then hold pairs the fresh grid's Z-order window drops:
// they must not be served. Cells here: 2 m fresh (median extent 1 m, from a
// far row of boxes), 2.5 m grown, one origin at (0, 0) and one at -0.125 m;
// the cluster fills the fresh cell [4, 6) x [4, 6), which the grown cells
// split at 4.875 m.
TEST(BroadPhase, KeptPairsAreNotServedWhereAFreshGridWouldSeeACrowd) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> inCell(4.05, 5.85);
    std::vector<Aabb> boxes{{{0.0, 0.0}, {1.0, 1.0}}};
    for (int i = 0; i < 200; ++i) {
        const Vec2 p{100.0 + 1.5 * (i % 20), 1.5 * (i / 20)};
        boxes.push_back({p, p + Vec2{1.0, 1.0}});
    }
    for (int i = 0; i < 70; ++i) {
        const Vec2 p{inCell(rng), inCell(rng)};
        boxes.push_back({p, p + Vec2{0.1, 0.1}});
    }
    const std::vector<std::uint8_t> movable(boxes.size(), 1);
    BroadPhase kept(BroadPhaseKind::UniformGrid), fresh(BroadPhaseKind::UniformGrid);
    std::vector<ProxyPair> keptPairs, freshPairs, brute;
    for (int call = 0; call < 3; ++call) {
        kept.findPairs(boxes, movable, keptPairs);
        fresh.findPairs(boxes, movable, freshPairs);
        BroadPhase(BroadPhaseKind::BruteForce).findPairs(boxes, movable, brute);
        ASSERT_EQ(std::count(fresh.crowded().begin(), fresh.crowded().end(), 1), 70) << "the cluster is a crowd";
        EXPECT_LT(freshPairs.size(), brute.size()) << "its window thins the pairs";
        EXPECT_FALSE(kept.lastServedFromKept()) << call;
        EXPECT_EQ(keptPairs, freshPairs) << call;
        EXPECT_TRUE(std::ranges::equal(kept.crowded(), fresh.crowded())) << call;
    }
}

// ---------------------------------------------------------------- response

TEST(Collision, HeadOnElasticUnequalMassesMatchTheCourseNotesFormula) {
    MiniWorld w;
    const double m1 = 1.0, m2 = 3.0, v1 = 2.0, v2 = -1.0;
    w.dynamic(circle(0.5), {-2.0, 0.0}, {v1, 0.0}, m1, 1.0, 0.0);
    w.dynamic(circle(0.5), {1.0, 0.0}, {v2, 0.0}, m2, 1.0, 0.0);
    for (int i = 0; i < 120; ++i) w.step(1.0 / 60.0);
    // v1+ = v1 - 2 m2/(m1+m2) (v1-v2), v2+ = v2 + 2 m1/(m1+m2) (v1-v2)
    EXPECT_NEAR(w.v[0].x, v1 - 2 * m2 / (m1 + m2) * (v1 - v2), 1e-9);
    EXPECT_NEAR(w.v[1].x, v2 + 2 * m1 / (m1 + m2) * (v1 - v2), 1e-9);
    EXPECT_NEAR(w.v[0].y, 0.0, 1e-12);
}

TEST(Collision, ObliqueEqualMassesLeaveAtRightAnglesKeepingMomentumAndEnergy) {
    MiniWorld w;
    w.dynamic(circle(0.5), {-3.0, 0.37}, {2.0, 0.0}, 1.0, 1.0, 0.0);
    w.dynamic(circle(0.5), {0.0, 0.0}, {0.0, 0.0}, 1.0, 1.0, 0.0);
    const Vec2 p0 = w.momentum();
    const double e0 = w.kinetic();
    for (int i = 0; i < 120; ++i) w.step(1.0 / 60.0);
    ASSERT_GT(length(w.v[1]), 0.1) << "the balls must have collided";
    EXPECT_NEAR(dot(w.v[0], w.v[1]) / (length(w.v[0]) * length(w.v[1])), 0.0, 1e-9);
    EXPECT_NEAR(length(w.momentum() - p0) / length(p0), 0.0, 1e-9);
    EXPECT_NEAR((w.kinetic() - e0) / e0, 0.0, 1e-9);
}

TEST(Collision, PerfectlyInelasticMovesOnTogether) {
    MiniWorld w;
    w.dynamic(circle(0.5), {-2.0, 0.0}, {3.0, 0.0}, 2.0, 0.0, 0.0);
    w.dynamic(circle(0.5), {1.0, 0.0}, {0.0, 0.0}, 1.0, 0.0, 0.0);
    for (int i = 0; i < 90; ++i) w.step(1.0 / 60.0);
    const double common = (2.0 * 3.0) / 3.0;
    EXPECT_NEAR(w.v[0].x, common, 1e-6);
    EXPECT_NEAR(w.v[1].x, common, 1e-6);
    EXPECT_NEAR(w.momentum().x, 6.0, 1e-12);
}

TEST(Collision, BounceApexScalesWithRestitutionSquared) {
    for (double e : {0.5, 0.8}) {
        MiniWorld w;
        w.gravity = {0.0, -9.81};
        w.fixed(plane({0, 1}, 0.0), {}, e);
        const double drop = 2.0;
        w.dynamic(circle(0.25), {0.0, 0.25 + drop}, {0.0, 0.0}, 1.0, e, 0.0);
        double apex = 0.0;
        bool bounced = false;
        for (int i = 0; i < 600; ++i) {
            w.step(1.0 / 240.0);
            if (w.v[0].y > 0.0) bounced = true;
            if (bounced && w.v[0].y <= 0.0) {
                apex = w.x[0].y - 0.25;
                break;
            }
        }
        ASSERT_TRUE(bounced);
        // Discrete time: the apex is found to within one step of travel.
        EXPECT_NEAR(apex / drop, e * e, 0.02) << "e = " << e;
    }
}

TEST(Collision, NoTunnellingThroughPlanesOrThinBoxesAt600MetresPerSecond) {
    MiniWorld w;
    w.substeps = 1;
    w.fixed(plane({-1, 0}, -10.0), {});          // wall at x = 10, facing -x
    w.fixed(box(0.05, 4.0), {0.0, -10.0});        // 5 cm thick static wall at x = 0
    w.dynamic(circle(0.1), {-30.0, 0.0}, {600.0, 0.0}, 1.0);
    w.dynamic(circle(0.1), {-30.0, -10.0}, {600.0, 0.0}, 1.0);
    w.dynamic(box(0.2, 0.2), {-30.0, -9.0}, {600.0, 0.0}, 1.0);
    double maxX0 = -1e9, maxX1 = -1e9, maxX2 = -1e9;
    for (int i = 0; i < 30; ++i) {
        w.step(1.0 / 60.0);
        maxX0 = std::max(maxX0, w.x[0].x);
        maxX1 = std::max(maxX1, w.x[1].x);
        maxX2 = std::max(maxX2, w.x[2].x);
    }
    EXPECT_LE(maxX0, 10.0 - 0.1 + 0.01) << "through the plane";
    EXPECT_LE(maxX1, -0.025 - 0.1 + 0.01) << "through the thin box";
    EXPECT_LE(maxX2, -0.025 - 0.1 + 0.01) << "box through the thin box";
}

TEST(Collision, NewtonsCradleOneBallInOneBallOut) {
    MiniWorld w;
    const int n = 5;
    w.dynamic(circle(0.5), {-3.0, 0.0}, {2.0, 0.0}, 1.0, 1.0, 0.0);
    for (int i = 1; i < n; ++i) w.dynamic(circle(0.5), {double(i - 1), 0.0}, {0.0, 0.0}, 1.0, 1.0, 0.0);
    for (int i = 0; i < 120; ++i) w.step(1.0 / 60.0);
    for (int i = 0; i < n - 1; ++i) EXPECT_NEAR(length(w.v[i]), 0.0, 1e-9) << "ball " << i << " should be still";
    EXPECT_NEAR(w.v[n - 1].x, 2.0, 1e-9);
}

namespace {
/// Box pyramid on static ground; returns the world and sets `top`.
MiniWorld pyramid(int rows, int& top) {
    MiniWorld w;
    w.gravity = {0.0, -10.0};
    w.fixed(box(100.0, 1.0), {0.0, -0.5}, 0.0, 0.6);
    const double size = 1.0;
    for (int row = 0; row < rows; ++row) {
        for (int i = 0; i < rows - row; ++i) {
            const double x = (i - (rows - row - 1) * 0.5) * size * 1.05;
            top = w.dynamic(box(size, size), {x, 0.5 * size + row * size}, {}, 1.0, 0.0, 0.6);
        }
    }
    return w;
}
} // namespace

TEST(Collision, TwentyRowPyramidStandsStillForTenSeconds) {
    int top = 0;
    MiniWorld w = pyramid(20, top);
    w.collision.settings().iterations = 1;  // levels/pyramid.json's solver_iterations
    const Vec2 start = w.x[std::size_t(top)];
    Vec2 settled;
    double deepest = 0.0;
    for (int i = 0; i < 600; ++i) {
        w.step(1.0 / 60.0);
        if (i == 119) settled = w.x[std::size_t(top)];
        for (const ContactRecord& c : w.collision.contacts()) deepest = std::max(deepest, c.depth);
    }
    // The soft contacts take up their load in the first second (210 boxes,
    // 20 layers); after that nothing may move.
    EXPECT_LT(length(w.x[std::size_t(top)] - start), 0.02) << "top box drifted from where it was placed";
    EXPECT_LT(length(w.x[std::size_t(top)] - settled), 0.001) << "top box crept between t = 2 s and t = 10 s";
    EXPECT_LT(w.kinetic(), 1e-3);
    EXPECT_LT(deepest, 0.005);
}

TEST(Collision, HeavyBoxRestsOnLightBoxes) {
    MiniWorld w;
    w.gravity = {0.0, -10.0};
    w.fixed(plane({0, 1}, 0.0), {}, 0.0, 0.6);
    w.dynamic(box(0.5, 0.5), {-1.0, 0.25}, {}, 1.0, 0.0, 0.6);
    w.dynamic(box(0.5, 0.5), {1.0, 0.25}, {}, 1.0, 0.0, 0.6);
    const int heavy = w.dynamic(box(3.0, 0.5), {0.0, 0.75}, {}, 100.0, 0.0, 0.6);
    for (int i = 0; i < 600; ++i) w.step(1.0 / 60.0);
    EXPECT_NEAR(w.x[std::size_t(heavy)].y, 0.75, 0.02) << "sank into the small boxes";
    EXPECT_NEAR(w.x[std::size_t(heavy)].x, 0.0, 0.01);
    EXPECT_LT(w.kinetic(), 1e-3);
}

TEST(Collision, PileOfCirclesSettlesWithoutEscapes) {
    MiniWorld w;
    w.gravity = {0.0, -10.0};
    w.fixed(plane({0, 1}, 0.0), {});
    w.fixed(plane({1, 0}, -5.0), {});
    w.fixed(plane({-1, 0}, -5.0), {});
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> jitter(-0.05, 0.05);
    for (int i = 0; i < 400; ++i)
        w.dynamic(circle(0.2 + 0.05 * (i % 3)), {-4.5 + 0.6 * (i % 16) + jitter(rng), 0.5 + 0.6 * (i / 16)}, {}, 1.0, 0.1, 0.4);
    for (int i = 0; i < 900; ++i) w.step(1.0 / 60.0);
    double deepest = 0.0;
    for (const ContactRecord& c : w.collision.contacts()) deepest = std::max(deepest, c.depth);
    for (std::size_t i = 0; i < w.x.size(); ++i) {
        ASSERT_GE(w.x[i].x, -5.0) << i;
        ASSERT_LE(w.x[i].x, 5.0) << i;
        ASSERT_GE(w.x[i].y, 0.0) << i;
    }
    // Box2D 2.4.1 (8 velocity + 3 position iterations) leaves this same pile
    // with a deepest overlap of 12.5 mm and 1.1e-7 J per body (measured on
    // this machine, bench/collision); Stepwise must do at least as well.
    EXPECT_LT(deepest, 0.0125);
    EXPECT_LT(w.kinetic() / 400.0, 1.1e-7) << "mean kinetic energy per body at rest, J";
}

namespace {
/// Positions, velocities and angles of every body, as bits.
std::vector<std::uint64_t> stateBits(const MiniWorld& w) {
    std::vector<std::uint64_t> bits;
    for (std::size_t i = 0; i < w.x.size(); ++i)
        for (double d : {w.x[i].x, w.x[i].y, w.v[i].x, w.v[i].y}) bits.push_back(std::bit_cast<std::uint64_t>(d));
    for (std::size_t c = 0; c < w.collision.colliderCount(); ++c)
        for (double d : {w.collision.angle(c), w.collision.angularVelocity(c)})
            bits.push_back(std::bit_cast<std::uint64_t>(d));
    return bits;
}

/// The coloured contacts solved in SIMD bundles on every instruction set the
/// machine has, and one at a time (SolverSettings::simd off), must give the
/// same bits. `make` builds the scene.
template <class Make>
void expectSimdMatchesOneAtATime(Make make, int steps, const char* scene) {
    MiniWorld reference = make();
    reference.collision.settings().simd = false;
    for (int i = 0; i < steps; ++i) reference.step(1.0 / 60.0);
    const std::vector<std::uint64_t> expected = stateBits(reference);
    int levelsRun = 0;
    for (detail::SimdLevel level : {detail::SimdLevel::Baseline, detail::SimdLevel::Avx2, detail::SimdLevel::Avx512}) {
        if (detail::setSimdLevel(level) != level) continue;
        ++levelsRun;
        MiniWorld w = make();
        w.collision.settings().simd = true;
        for (int i = 0; i < steps; ++i) w.step(1.0 / 60.0);
        EXPECT_TRUE(stateBits(w) == expected) << scene << ": SIMD level " << int(level) << " differs from one at a time";
    }
    detail::setSimdLevel(detail::SimdLevel::Avx512);  // back to the best there is
    EXPECT_GE(levelsRun, 1);
}
} // namespace

TEST(Collision, SimdBundlesGiveTheBitsOfTheOneAtATimeSolveOnEveryInstructionSet) {
    // Boxes: two-point manifolds, block solve, friction, static ground.
    expectSimdMatchesOneAtATime(
        [] {
            int top = 0;
            MiniWorld w = pyramid(12, top);
            w.collision.settings().iterations = 2;
            return w;
        },
        120, "pyramid");
    // Circles with restitution in a box of planes: one-point manifolds,
    // impact propagation, many colours.
    expectSimdMatchesOneAtATime(
        [] {
            MiniWorld w;
            w.gravity = {0.0, -10.0};
            w.fixed(plane({0, 1}, 0.0), {});
            w.fixed(plane({1, 0}, -3.0), {});
            w.fixed(plane({-1, 0}, -3.0), {});
            std::mt19937 rng(5);
            std::uniform_real_distribution<double> jitter(-0.05, 0.05);
            for (int i = 0; i < 150; ++i)
                w.dynamic(circle(0.2 + 0.05 * (i % 3)), {-2.5 + 0.6 * (i % 9) + jitter(rng), 0.5 + 0.6 * (i / 9)}, {},
                          1.0 + 0.5 * (i % 4), 0.3, 0.4);
            // A spinning box falling into it: two-point manifolds against circles.
            w.dynamic(box(1.0, 0.5), {0.3, 12.0}, {0.0, -5.0}, 3.0, 0.0, 0.5, 0.4);
            return w;
        },
        180, "circles");
    // A crowd started at one point: bodies with more contacts than there are
    // colours, so the overflow (solved one at a time between the SIMD
    // colours) takes part.
    const auto crowd = [] {
        MiniWorld w;
        w.fixed(plane({0, 1}, -2.0), {});
        for (int i = 0; i < 60; ++i)  // every pair touches: 59 contacts a body
            w.dynamic(circle(0.3), {0.001 * (i % 8), 0.001 * (i / 8)}, {}, 1.0, 0.0, 0.3);
        return w;
    };
    expectSimdMatchesOneAtATime(crowd, 30, "crowd");
    MiniWorld w = crowd();
    w.step(1.0 / 60.0);
    EXPECT_GT(w.collision.colouredContacts().overflowCount(), 0u) << "the crowd should overflow the colours";
}

TEST(Collision, SmallRotationMatchesLibmWithinTwoUnitsInTheLastPlace) {
    // rotationBy's series against std::sin and std::cos over its range
    // (|x| < 1/16 rad) and past it (libm itself).
    int worstSin = 0, worstCos = 0;
    for (int i = -20000; i <= 20000; ++i) {
        const double x = 0.07 * double(i) / 20000.0 + 1e-7 * double(i % 7);
        const Rot q = rotationBy(x);
        const auto ulps = [](double a, double b) {
            return int(std::abs(std::bit_cast<std::int64_t>(a) - std::bit_cast<std::int64_t>(b)));
        };
        worstSin = std::max(worstSin, ulps(q.s, std::sin(x)));
        worstCos = std::max(worstCos, ulps(q.c, std::cos(x)));
    }
    EXPECT_LE(worstSin, 2);
    EXPECT_LE(worstCos, 2);
    EXPECT_EQ(std::bit_cast<std::uint64_t>(rotationBy(0.0).s), 0u);  // no turn: exactly the identity
    EXPECT_EQ(rotationBy(0.0).c, 1.0);
}

namespace {
std::uint64_t bitsOf(double x) { return std::bit_cast<std::uint64_t>(x); }

/// Two copies of a scene, one whose impact passes read every contact in
/// every pass: every step, both must give the same bits (positions,
/// velocities, spins and the contacts' impulses, restitution included).
/// `looked`: the contacts the shortcut read, and over those the reference read.
struct Looked {
    double count = 0.0, ratio = 0.0;
};
void expectImpactShortcutsExact(const std::function<MiniWorld()>& make, int steps, const std::string& what,
                                Looked& looked) {
    MiniWorld fast = make(), full = make();
    full.collision.impactScratch().lookAtEveryContact = true;
    double lookedFast = 0.0, lookedFull = 0.0, impulse = 0.0, fired = 0.0;
    for (int i = 0; i < steps; ++i) {
        fast.step(1.0 / 60.0);
        full.step(1.0 / 60.0);
        lookedFast += double(fast.collision.impactScratch().looked);
        lookedFull += double(full.collision.impactScratch().looked);
        fired += double(fast.collision.impactScratch().fired);
        ASSERT_EQ(fast.collision.impactScratch().fired, full.collision.impactScratch().fired) << what << ", step " << i;
        const std::string at = what + ", step " + std::to_string(i);
        ASSERT_TRUE(stateBits(fast) == stateBits(full)) << at << ": positions, velocities or angles differ";
        const std::span<const ContactRecord> a = fast.collision.contacts(), b = full.collision.contacts();
        ASSERT_EQ(a.size(), b.size()) << at;
        for (std::size_t k = 0; k < a.size(); ++k) {
            ASSERT_EQ(bitsOf(a[k].normalImpulse), bitsOf(b[k].normalImpulse)) << at << ", contact " << k;
            impulse += a[k].normalImpulse;
        }
    }
    EXPECT_GT(lookedFull, 0.0) << what;
    EXPECT_GT(impulse, 0.0) << what;
    EXPECT_GT(fired, 0.0) << what << ": no impact was propagated";
    EXPECT_LE(lookedFast, lookedFull) << what;
    looked = {lookedFast, lookedFast / lookedFull};
}
} // namespace

TEST(ImpactPropagation, PassingContactsOverGivesTheBitsOfFullPassesInAnyFrame) {
    // The passes skip a contact when its bodies' bounds, measured from the
    // bodies' mean velocity, say it cannot approach at the threshold. Swept
    // over that shared velocity, from rest to 1 km/s, with bouncy and dead
    // bodies. What the passes read follows the relative motion, not the
    // shared one.
    double atRest[2] = {0.0, 0.0};
    for (const Vec2 shared : {Vec2{0.0, 0.0}, Vec2{3.0, -40.0}, Vec2{-700.0, 700.0}}) {
        for (const int bouncy : {0, 1}) {
            const double restitution = 0.6 * bouncy;
            const std::string what = "block moving at (" + std::to_string(shared.x) + ", " +
                                     std::to_string(shared.y) + ") m/s, restitution " + std::to_string(restitution);
            // A block of touching circles, struck by a column of boxes: the
            // block's own contacts barely move relative to each other until
            // the strikes send impacts through it. (No gravity: a block in
            // free fall would soon be fast even in the frame of rest.)
            Looked looked;
            expectImpactShortcutsExact(
                [&] {
                    MiniWorld w;
                    w.collision.settings().restitutionThreshold = 4.0 * 10.0 / 240.0;
                    std::mt19937 rng(11);
                    std::uniform_real_distribution<double> jitter(-0.01, 0.01);
                    for (int i = 0; i < 100; ++i)
                        w.dynamic(circle(0.35), {0.7 * (i % 10), 0.7 * (i / 10)},
                                  shared + Vec2{jitter(rng), jitter(rng)}, 1.0 + 0.5 * (i % 4), restitution, 0.3);
                    for (int i = 0; i < 6; ++i)
                        w.dynamic(box(0.6, 0.5), {-4.0 - 0.3 * i, 0.3 + 1.2 * i}, shared + Vec2{6.0, 100 * jitter(rng)},
                                  1.5, restitution, 0.3, 30 * jitter(rng));
                    return w;
                },
                40, what, looked);
            if (shared == Vec2{}) atRest[bouncy] = looked.count;
            EXPECT_LT(looked.count, 1.1 * atRest[bouncy]) << what << ": read more than the same block at rest";
        }
    }
    // Zero gravity, zero threshold: every approach is an impact and no bound
    // is under the threshold; only contacts whose bodies have not changed
    // since they were last read are skipped.
    Looked zero;
    expectImpactShortcutsExact(
        [] {
            MiniWorld w;
            w.collision.settings().restitutionThreshold = 0.0;
            for (int i = 0; i < 40; ++i)
                w.dynamic(circle(0.3), {0.61 * (i % 8), 0.61 * (i / 8)}, {i % 2 == 0 ? 0.5 : -0.5, 0.0}, 1.0, 0.5);
            return w;
        },
        60, "zero threshold", zero);
    EXPECT_GT(zero.ratio, 0.9);
    // A pyramid landing and settling: once it rests the passes read almost
    // nothing, where bounds measured from rest read most of it (both bodies
    // of each contact carry the substep's g h, half the threshold).
    Looked resting;
    expectImpactShortcutsExact(
        [] {
            int top = 0;
            MiniWorld w = pyramid(12, top);
            w.collision.settings().iterations = 1;
            w.collision.settings().restitutionThreshold = 4.0 * 10.0 / 240.0;
            for (Vec2& v : w.v) v = {0.0, -1.0};  // a landing: impacts at first
            for (Vec2& x : w.x) x.y += 0.01;
            return w;
        },
        120, "pyramid", resting);
    EXPECT_LT(resting.ratio, 0.25) << "the resting pyramid's contacts were read, not passed over";
}

TEST(BroadPhase, ShapesWhoseFiltersExcludeEveryPairFindNoPairsAndGiveTheSameBits) {
    // Box2D's joint grid: circles that overlap but whose filters exclude one
    // another (category 2, every mask bit but 2). The broad phase has
    // nothing to find; a far static circle that could collide with them
    // makes it run, and must change nothing else.
    Filter apart;
    apart.category = 2;
    apart.mask = ~2u;
    const auto make = [&](bool farCircle) {
        MiniWorld w;
        w.gravity = {0.0, -10.0};
        for (int i = 0; i < 100; ++i) {
            const int body = int(w.x.size());
            w.x.push_back({1.0 * (i % 10), 1.0 * (i / 10)});
            w.v.push_back({0.1 * (i % 3), 0.0});
            w.mass.push_back(1.0);
            Collider c;
            c.shape = circle(0.6);  // neighbours overlap by 0.2 m
            c.body = body;
            c.mass = 1.0;
            c.entity = Entity{std::uint32_t(w.collision.colliderCount()), 0};
            w.collision.add(c, 0.0, 0.0, apart);
        }
        if (farCircle) w.fixed(circle(1.0), {1000.0, 1000.0});
        return w;
    };
    MiniWorld skipped = make(false), searched = make(true);
    for (int i = 0; i < 30; ++i) {
        skipped.step(1.0 / 60.0);
        searched.step(1.0 / 60.0);
        ASSERT_EQ(skipped.collision.candidatePairCount(), 0u) << "step " << i;
        ASSERT_GT(searched.collision.candidatePairCount(), 100u) << "step " << i;
        ASSERT_EQ(searched.collision.manifoldCount(), 0u) << "step " << i;
        // The far circle, added last, is static: its angle and spin (the
        // last two entries) stay zero and are left out.
        std::vector<std::uint64_t> searchedBits = stateBits(searched);
        searchedBits.resize(searchedBits.size() - 2);
        ASSERT_TRUE(stateBits(skipped) == searchedBits) << "step " << i;
    }
    // A shape that can meet them, added mid-run, is found the next step.
    const Vec2 below = skipped.x[0] + Vec2{0.0, -1.0};
    skipped.dynamic(circle(0.5), below, skipped.v[0], 1.0);
    skipped.step(1.0 / 60.0);
    EXPECT_GT(skipped.collision.candidatePairCount(), 0u);
    EXPECT_GT(skipped.collision.manifoldCount(), 0u) << "the added circle touches the grid's corner";
}
