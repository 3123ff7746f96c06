// Exact solve of tree-shaped groups of rigid joints. See direct_joints.hpp.

#include "joints/direct_joints.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace stepwise::joints {

using collision::Rot;
using collision::Softness;
using collision::SolverBody;
using collision::crossSV;
using collision::rotate;

namespace {

/// Rows a joint has here: a hinge's point (x, y); a rigid weld's point and
/// angle (x, y, angle); 0: not solved here.
std::uint32_t directRows(const JointConstraint& j) {
    if (j.broken) return 0;  // out of the run: grouped as if absent
    if (j.kind == JointKind::Hinge) return 2;
    if (j.kind == JointKind::Weld && !(j.stiffnessHz > 0.0)) return 3;
    return 0;
}

/// Regularisation of the relax pass's rigid solve: keeps the matrix
/// positive definite when a group's rows are redundant (two pins on one
/// body), and changes a well-posed solve by about this fraction.
constexpr double kRelaxRegularisation = 1e-9;

/// The projection leaves this much of a joint's error to the soft rows
/// (metres; rad for a weld's angle). A projection moves positions without
/// turning the velocities with them, and the next substep's rows then take
/// the velocity's component into the joint away: an inelastic loss of about
/// (w h)^2 of the kinetic energy per substep (a swinging link with every
/// error projected loses 26% of its energy in 5 s at 4 substeps). The soft
/// rows keep a pendulum's error well under the slop,
/// so only a joint pulled open (a light chain whipped by a heavy end, few
/// substeps) is projected, and only by the excess.
constexpr double kProjectionSlop = 0.0005;
constexpr double kAngularProjectionSlop = 0.002;

/// Groups of at most this many rows are factored dense (12 hinges).
constexpr std::uint32_t kDenseRows = 24;

struct Row3 {
    double x = 0.0, y = 0.0, w = 0.0;  // Jacobian entries for (vx, vy, omega)
};

} // namespace

struct DirectJoints::Group {
    std::vector<std::uint32_t> joints;  // indices into the joint span, ascending
    std::vector<std::uint32_t> offset;  // first row of each joint
    std::uint32_t rows = 0;
    /// Each dynamic end of each joint: (solver body, joint's place in
    /// `joints`, 0 for end a / 1 for end b), sorted by body, so the joints
    /// meeting at a body are side by side.
    struct End {
        std::uint32_t body, k, side;
    };
    std::vector<End> ends;
    std::vector<std::uint32_t> bodyStart;  // ends of one body: [bodyStart[i], bodyStart[i+1])
    /// Small groups (a ragdoll, a short chain) are factored dense: for a
    /// few rows the sparse factorisation's bookkeeping costs more than the
    /// arithmetic (200 five-link chains: 2.15 ms a step sparse).
    bool dense = false;
    Eigen::MatrixXd denseMatrix;
    Eigen::LDLT<Eigen::MatrixXd> denseLdlt;
    Eigen::SparseMatrix<double> matrix;
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
    std::vector<Eigen::Triplet<double>> triplets;
    Eigen::VectorXd rhs, x;
    std::vector<double> diag;  // per joint, its 3x3 block of J M^-1 J^T, row-major
    std::vector<Vec2> rA, rB;  // per joint, anchors at the current rotation
    std::vector<std::uint32_t> rowsOf;  // per joint, its row count here (2 or 3)
    std::vector<Row3> jacobian;  // per end, its three rows (point x, point y, angle) at the current rotation
    bool analysed = false;
    bool factored = false;
};

DirectJoints::DirectJoints() = default;
DirectJoints::~DirectJoints() = default;
DirectJoints::DirectJoints(DirectJoints&&) noexcept = default;
DirectJoints& DirectJoints::operator=(DirectJoints&&) noexcept = default;

void DirectJoints::build(std::span<JointConstraint> joints, std::span<const SolverBody> bodies) {
    groups_.clear();
    directCount_ = 0;
    built_ = true;
    builtFor_ = joints.size();
    // Union-find over solver bodies; body 0 (static, the world) joins
    // nothing, so pins to the ground never make a loop.
    const std::size_t n = bodies.size();
    std::vector<std::uint32_t> parent(n);
    std::iota(parent.begin(), parent.end(), 0u);
    std::vector<std::uint8_t> loop(n, 0);
    std::vector<std::uint32_t> rowCount(n, 0), bodyCount(n, 1);
    const auto find = [&](std::uint32_t i) {
        while (parent[i] != i) i = parent[i] = parent[parent[i]];
        return i;
    };
    for (JointConstraint& j : joints) {
        j.direct = false;
        const std::uint32_t rows = directRows(j);
        if (rows == 0) continue;
        const std::uint32_t a = j.a.solverBody, b = j.b.solverBody;
        if (a != 0 && b != 0) {
            std::uint32_t ra = find(a), rb = find(b);
            if (ra == rb) loop[ra] = 1;
            else {
                if (rb < ra) std::swap(ra, rb);  // the smaller index stays root: deterministic
                parent[rb] = ra;
                loop[ra] = std::uint8_t(loop[ra] | loop[rb]);
                rowCount[ra] += rowCount[rb];
                bodyCount[ra] += bodyCount[rb];
            }
        }
        rowCount[find(a != 0 ? a : b)] += rows;
    }
    // A group is solved here when it is a tree and not over-constrained
    // (more rows than its bodies' 3 degrees of freedom each: redundant rows
    // would make the rigid solve singular).
    std::vector<std::int32_t> groupOf(n, -1);
    for (std::uint32_t k = 0; k < joints.size(); ++k) {
        JointConstraint& j = joints[k];
        const std::uint32_t rows = directRows(j);
        if (rows == 0) continue;
        const std::uint32_t root = find(j.a.solverBody != 0 ? j.a.solverBody : j.b.solverBody);
        if (loop[root] || rowCount[root] > 3 * bodyCount[root]) continue;
        if (groupOf[root] < 0) {
            groupOf[root] = std::int32_t(groups_.size());
            groups_.push_back(std::make_unique<Group>());
        }
        Group& g = *groups_[std::size_t(groupOf[root])];
        const std::uint32_t place = std::uint32_t(g.joints.size());
        g.joints.push_back(k);
        g.rowsOf.push_back(rows);
        g.offset.push_back(g.rows);
        g.rows += rows;
        if (j.a.solverBody != 0) g.ends.push_back({j.a.solverBody, place, 0});
        if (j.b.solverBody != 0) g.ends.push_back({j.b.solverBody, place, 1});
        j.direct = true;
        ++directCount_;
    }
    for (const std::unique_ptr<Group>& gp : groups_) {
        Group& g = *gp;
        std::stable_sort(g.ends.begin(), g.ends.end(), [](const Group::End& l, const Group::End& r) { return l.body < r.body; });
        g.bodyStart.clear();
        for (std::uint32_t e = 0; e < g.ends.size(); ++e)
            if (e == 0 || g.ends[e].body != g.ends[e - 1].body) g.bodyStart.push_back(e);
        g.bodyStart.push_back(std::uint32_t(g.ends.size()));
        g.dense = g.rows <= kDenseRows;
        if (g.dense) g.denseMatrix.resize(g.rows, g.rows);
        else g.matrix.resize(g.rows, g.rows);
        g.rhs.resize(g.rows);
        g.x.resize(g.rows);
        g.diag.assign(9 * g.joints.size(), 0.0);
        g.rA.resize(g.joints.size());
        g.rB.resize(g.joints.size());
    }
}

void DirectJoints::factor(std::span<JointConstraint> joints, std::span<const SolverBody> bodies, const Softness& soft,
                          bool biased) {
    if (!built_ || builtFor_ != joints.size()) build(joints, bodies);
    // Fixed point of the soft Gauss-Seidel row: J v + bias + (1/c) K lambda
    // = 0 with massScale = c / (1 + c), impulseScale = 1 / (1 + c).
    biased_ = biased;
    gamma_ = biased && soft.massScale > 0.0 ? soft.impulseScale / soft.massScale : 0.0;
    biasRate_ = biased ? soft.biasRate : 0.0;
    const double diagScale = 1.0 + (biased ? gamma_ : kRelaxRegularisation);
    for (const std::unique_ptr<Group>& gp : groups_) {
        Group& g = *gp;
        g.factored = false;
        if (joints[g.joints.front()].asleep) continue;  // a group is one island's: it sleeps whole
        for (std::size_t k = 0; k < g.joints.size(); ++k) {
            const JointConstraint& j = joints[g.joints[k]];
            g.rA[k] = rotate(bodies[j.a.solverBody].dq, j.anchorA);
            g.rB[k] = rotate(bodies[j.b.solverBody].dq, j.anchorB);
        }
        std::fill(g.diag.begin(), g.diag.end(), 0.0);
        g.triplets.clear();
        // A dense group sums its entries straight into the matrix, in the
        // order the triplets would list them (so the same sums, bit for
        // bit): a list to replay would be written and read again for nothing.
        if (g.dense) g.denseMatrix.setZero();
        // Jacobian rows of one end: point x, point y, angle (weld).
        const auto rowsOf = [&](const Group::End& e, Row3 out[3]) {
            const double s = e.side == 0 ? -1.0 : 1.0;
            const Vec2 r = e.side == 0 ? g.rA[e.k] : g.rB[e.k];
            out[0] = {s, 0.0, -s * r.y};
            out[1] = {0.0, s, s * r.x};
            out[2] = {0.0, 0.0, s};
        };
        g.jacobian.resize(3 * g.ends.size());
        for (std::size_t e = 0; e < g.ends.size(); ++e) rowsOf(g.ends[e], &g.jacobian[3 * e]);
        for (std::size_t bi = 0; bi + 1 < g.bodyStart.size(); ++bi) {
            const std::uint32_t first = g.bodyStart[bi], last = g.bodyStart[bi + 1];
            const SolverBody& body = bodies[g.ends[first].body];
            const double m = body.invMass, i = body.invInertia;
            for (std::uint32_t p = first; p < last; ++p) {
                const Row3* jp = &g.jacobian[3 * p];
                const std::uint32_t kp = g.ends[p].k;
                const std::uint32_t np = g.rowsOf[kp];
                for (std::uint32_t q = first; q < last; ++q) {
                    const Row3* jq = &g.jacobian[3 * q];
                    const std::uint32_t kq = g.ends[q].k;
                    const std::uint32_t nq = g.rowsOf[kq];
                    for (std::uint32_t a = 0; a < np; ++a)
                        for (std::uint32_t c = 0; c < nq; ++c) {
                            const double v = m * (jp[a].x * jq[c].x + jp[a].y * jq[c].y) + i * jp[a].w * jq[c].w;
                            if (kp == kq) {
                                g.diag[9 * kp + 3 * a + c] += v;
                                if (p != q) continue;  // both ends of one joint never meet at one body
                            }
                            const std::uint32_t row = g.offset[kp] + a, col = g.offset[kq] + c;
                            if (row < col) continue;
                            const double entry = kp == kq ? diagScale * v : v;
                            if (g.dense) g.denseMatrix(row, col) += entry;
                            else g.triplets.emplace_back(int(row), int(col), entry);
                        }
                }
            }
        }
        if (g.dense) {
            g.denseLdlt.compute(g.denseMatrix);  // reads the lower triangle
            g.factored = g.denseLdlt.info() == Eigen::Success;
            continue;
        }
        g.matrix.setFromTriplets(g.triplets.begin(), g.triplets.end());
        if (!g.analysed) {
            g.ldlt.analyzePattern(g.matrix);
            g.analysed = true;
        }
        g.ldlt.factorize(g.matrix);
        g.factored = g.ldlt.info() == Eigen::Success;
    }
}

void DirectJoints::solve(std::span<JointConstraint> joints, std::span<SolverBody> bodies) {
    for (const std::unique_ptr<Group>& gp : groups_) {
        Group& g = *gp;
        if (!g.factored) continue;
        for (std::size_t k = 0; k < g.joints.size(); ++k) {
            const JointConstraint& j = joints[g.joints[k]];
            const SolverBody& a = bodies[j.a.solverBody];
            const SolverBody& b = bodies[j.b.solverBody];
            const Vec2 rA = g.rA[k], rB = g.rB[k];
            const Vec2 cdot = b.v + crossSV(b.w, rB) - a.v - crossSV(a.w, rA);
            const std::uint32_t o = g.offset[k];
            const bool weld = directRows(j) == 3;
            double r[3] = {cdot.x, cdot.y, weld ? b.w - a.w : 0.0};
            if (biased_) {
                const Vec2 separation = (b.dp - a.dp) + (rB - rA) + j.deltaCenter;
                const double lambda[3] = {j.linearImpulse.x, j.linearImpulse.y, j.angularImpulse};
                const double C[3] = {separation.x, separation.y,
                                     weld ? j.deltaAngle + std::atan2(b.dq.s, b.dq.c) - std::atan2(a.dq.s, a.dq.c) : 0.0};
                const double* d = &g.diag[9 * k];
                for (int row = 0; row < (weld ? 3 : 2); ++row) {
                    double dl = 0.0;
                    for (int c = 0; c < (weld ? 3 : 2); ++c) dl += d[3 * row + c] * lambda[c];
                    r[row] += biasRate_ * C[row] + gamma_ * dl;
                }
            }
            g.rhs[o] = -r[0];
            g.rhs[o + 1] = -r[1];
            if (weld) g.rhs[o + 2] = -r[2];
        }
        if (g.dense) g.x = g.denseLdlt.solve(g.rhs);
        else g.x = g.ldlt.solve(g.rhs);
        for (std::size_t k = 0; k < g.joints.size(); ++k) {
            JointConstraint& j = joints[g.joints[k]];
            SolverBody& a = bodies[j.a.solverBody];
            SolverBody& b = bodies[j.b.solverBody];
            const std::uint32_t o = g.offset[k];
            const Vec2 p{g.x[o], g.x[o + 1]};
            const double turn = directRows(j) == 3 ? g.x[o + 2] : 0.0;
            j.linearImpulse += p;
            j.angularImpulse += turn;
            // -p on a, +p on b (the static body 0 has no mass and stays put).
            a.v -= a.invMass * p;
            a.w -= a.invInertia * (cross(g.rA[k], p) + turn);
            b.v += b.invMass * p;
            b.w += b.invInertia * (cross(g.rB[k], p) + turn);
        }
    }
}

void DirectJoints::project(std::span<const JointConstraint> joints, std::span<const SolverBody> bodies,
                           std::vector<Move>& moves, std::vector<std::uint32_t>& moved) {
    moves.assign(bodies.size(), Move{});
    moved.clear();
    for (const std::unique_ptr<Group>& gp : groups_) {
        Group& g = *gp;
        if (!g.factored) continue;
        bool any = false;
        for (std::size_t k = 0; k < g.joints.size(); ++k) {
            const JointConstraint& j = joints[g.joints[k]];
            const SolverBody& a = bodies[j.a.solverBody];
            const SolverBody& b = bodies[j.b.solverBody];
            // Only the part of the error past the slop: below it the soft
            // rows close the joint without the projection's loss.
            const Vec2 separation = (b.dp - a.dp) + (g.rB[k] - g.rA[k]) + j.deltaCenter;
            const double len = length(separation);
            const Vec2 excess = len > kProjectionSlop ? ((len - kProjectionSlop) / len) * separation : Vec2{};
            const std::uint32_t o = g.offset[k];
            g.rhs[o] = -excess.x;
            g.rhs[o + 1] = -excess.y;
            any = any || len > kProjectionSlop;
            if (directRows(j) == 3) {
                const double angle = j.deltaAngle + std::atan2(b.dq.s, b.dq.c) - std::atan2(a.dq.s, a.dq.c);
                g.rhs[o + 2] = -std::copysign(std::max(std::abs(angle) - kAngularProjectionSlop, 0.0), angle);
                any = any || g.rhs[o + 2] != 0.0;
            }
        }
        if (!any) continue;  // every joint within the slop: nothing moves
        if (g.dense) g.x = g.denseLdlt.solve(g.rhs);
        else g.x = g.ldlt.solve(g.rhs);
        for (std::size_t k = 0; k < g.joints.size(); ++k) {
            const JointConstraint& j = joints[g.joints[k]];
            const std::uint32_t o = g.offset[k];
            const Vec2 p{g.x[o], g.x[o + 1]};
            const double turn = directRows(j) == 3 ? g.x[o + 2] : 0.0;
            const auto push = [&](std::uint32_t body, double sign, Vec2 r) {
                if (body == 0) return;
                const SolverBody& sb = bodies[body];
                Move& m = moves[body];
                if (m.dp == Vec2{} && m.dq == 0.0) moved.push_back(body);
                m.dp += (sign * sb.invMass) * p;
                m.dq += sign * sb.invInertia * (cross(r, p) + turn);
            };
            push(j.a.solverBody, -1.0, g.rA[k]);
            push(j.b.solverBody, 1.0, g.rB[k]);
        }
    }
    std::sort(moved.begin(), moved.end());
    moved.erase(std::unique(moved.begin(), moved.end()), moved.end());
}

} // namespace stepwise::joints
