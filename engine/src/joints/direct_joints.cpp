// Exact solve of tree-shaped groups of rigid joints. See direct_joints.hpp.

#include "joints/direct_joints.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <array>
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
/// A pivot of the block elimination below this fraction of its row's own
/// diagonal entry (the relax pass's regularisation) marks redundant rows.
constexpr double kPivotFloor = kRelaxRegularisation;

/// How many times the projection halves a step that would leave its joints
/// further open than it found them, before dropping it.
constexpr int kProjectionHalvings = 6;
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

struct Row3 {
    double x = 0.0, y = 0.0, w = 0.0;  // Jacobian entries for (vx, vy, omega)
};

/// A 3x3 block, row-major. A hinge's two rows use the upper-left 2x2; its
/// third row and column are zero off the diagonal, so every joint is
/// eliminated by the same code.
using Block = std::array<double, 9>;

/// The inverse of the symmetric N x N block in the corner of `a`, through
/// its LDL^T with diagonal pivoting (the largest remaining diagonal first).
/// False when a pivot falls below its row's `floor` or the block is not
/// finite: the group's rows are redundant (a body pinned twice, a weld and
/// a pin on one rigid piece), where an elimination without pivoting across
/// blocks loses the regularised system to rounding.
template <int N>
bool invertSpd(const Block& a, const std::array<double, 3>& floor, Block& out) {
    double m[N][N], l[N][N] = {}, d[N];
    int perm[N];
    for (int r = 0; r < N; ++r) {
        perm[r] = r;
        for (int c = 0; c < N; ++c) m[r][c] = a[std::size_t(3 * r + c)];
    }
    for (int s = 0; s < N; ++s) {
        int p = s;
        for (int i = s + 1; i < N; ++i)
            if (m[i][i] > m[p][p]) p = i;
        if (p != s) {
            for (int c = 0; c < N; ++c) std::swap(m[s][c], m[p][c]);
            for (int r = 0; r < N; ++r) std::swap(m[r][s], m[r][p]);
            for (int c = 0; c < s; ++c) std::swap(l[s][c], l[p][c]);
            std::swap(perm[s], perm[p]);
        }
        l[s][s] = 1.0;
        d[s] = m[s][s];
        if (!(d[s] >= floor[std::size_t(perm[s])])) return false;
        for (int i = s + 1; i < N; ++i) l[i][s] = m[i][s] / d[s];
        for (int i = s + 1; i < N; ++i)
            for (int j = s + 1; j < N; ++j) m[i][j] -= l[i][s] * l[j][s] * d[s];
    }
    // Column c of the inverse: solve L D L^T w = P e_c, then undo P.
    for (int c = 0; c < N; ++c) {
        double w[N];
        for (int r = 0; r < N; ++r) w[r] = perm[r] == c ? 1.0 : 0.0;
        for (int r = 0; r < N; ++r)
            for (int k = 0; k < r; ++k) w[r] -= l[r][k] * w[k];
        for (int r = 0; r < N; ++r) w[r] /= d[r];
        for (int r = N - 1; r >= 0; --r)
            for (int k = r + 1; k < N; ++k) w[r] -= l[k][r] * w[k];
        for (int r = 0; r < N; ++r) out[std::size_t(3 * perm[r] + c)] = w[r];
    }
    for (int r = 0; r < N; ++r)
        for (int c = N; c < 3; ++c) out[std::size_t(3 * r + c)] = out[std::size_t(3 * c + r)] = 0.0;
    if constexpr (N == 2) out[8] = 0.0;
    for (const double v : out)
        if (!std::isfinite(v)) return false;
    return true;
}

/// out = a b, in the N x N corner
template <int N>
void multiply(const Block& a, const Block& b, Block& out) {
    for (int r = 0; r < N; ++r)
        for (int c = 0; c < N; ++c) {
            double sum = 0.0;
            for (int m = 0; m < N; ++m) sum += a[3 * r + m] * b[3 * m + c];
            out[std::size_t(3 * r + c)] = sum;
        }
}

/// target -= a b^T, in the N x N corner
template <int N>
void subtractTransposed(const Block& a, const Block& b, Block& target) {
    for (int r = 0; r < N; ++r)
        for (int c = 0; c < N; ++c) {
            double sum = 0.0;
            for (int m = 0; m < N; ++m) sum += a[3 * r + m] * b[3 * c + m];
            target[std::size_t(3 * r + c)] -= sum;
        }
}

} // namespace

struct DirectJoints::Group {
    /// Indices into the joint span, in elimination order: the bodies of the
    /// tree walked children first, each body's joints to the static world,
    /// then the joint to its parent. A joint is eliminated once every joint
    /// at one of its ends is, so the joints after it that it meets all meet
    /// at one body, are already coupled, and no block fills in (Baraff).
    std::vector<std::uint32_t> joints;
    std::vector<std::uint32_t> offset;  // first row of each joint: 3 per joint
    /// Each dynamic end of each joint: (solver body, joint's place in
    /// `joints`, 0 for end a / 1 for end b), sorted by body, so the joints
    /// meeting at a body are side by side.
    struct End {
        std::uint32_t body, k, side;
    };
    std::vector<End> ends;
    std::vector<std::uint32_t> bodyStart;  // ends of one body: [bodyStart[i], bodyStart[i+1])
    /// The joints after joint k that share a body with it:
    /// later[laterStart[k] .. laterStart[k + 1]); their blocks of the
    /// matrix (rows of the later joint, columns of k), then of the factor.
    std::vector<std::uint32_t> laterStart, later;
    std::vector<Block> coupling;
    /// Where each pair of ends at one body (p, q, place p after place q),
    /// in the order factor() visits them, adds its entries: a slot of
    /// `coupling`.
    std::vector<std::uint32_t> pairSlot;
    std::vector<Block> pivot, pivotInverse;  // per joint: its diagonal block, then its inverse
    /// Per joint and row: the least a pivot may fall to in the elimination,
    /// the regularisation's share of the row's own diagonal entry; below
    /// it the group is factored by the sparse LDL^T instead.
    std::vector<std::array<double, 3>> pivotFloor;
    std::vector<double> rhs, x;  // 3 per joint (a hinge's third is 0)
    std::vector<double> diag;  // per joint, its 3x3 block of J M^-1 J^T, row-major
    std::vector<Vec2> rA, rB;  // per joint, anchors at the current rotation
    std::vector<std::uint32_t> rowsOf;  // per joint, its row count here (2 or 3)
    std::vector<Row3> jacobian;  // per end, its three rows (point x, point y, angle) at the current rotation
    std::vector<Block> scratch;  // the factor's blocks of one joint's later joints
    bool factored = false;
    /// Redundant rows (the block elimination met a pivot under its floor):
    /// this factor call's matrix went to Eigen's sparse LDL^T, whose
    /// minimum-degree order carries the regularised system through. The
    /// pattern is analysed the first time a group needs it.
    bool sparse = false;
    bool analysed = false;
    Eigen::SparseMatrix<double> matrix;
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
    std::vector<Eigen::Triplet<double>> triplets;

    /// Rows a block uses: 2 when every joint is a hinge (its blocks are
    /// 2 x 2), else 3.
    int dim = 3;

    /// Factors the assembled pivots and couplings in place; false when a
    /// pivot is not positive definite.
    template <int N>
    bool eliminate();
    bool eliminate() { return dim == 2 ? eliminate<2>() : eliminate<3>(); }
    /// J M^-1 J^T at the anchors rA, rB into the joints' own blocks (diag)
    /// and their couplings; N as `dim`.
    template <int N>
    void assemble(std::span<const SolverBody> bodies);
    /// The assembled matrix (own blocks scaled by `diagScale`) by the sparse
    /// LDL^T; sets `sparse` and `factored`.
    void factorSparse(double diagScale);
    /// x = A^-1 rhs with the factor (forward, pivots, backward).
    template <int N>
    void solveWith();
    void solveFactored() {
        if (sparse) {
            const Eigen::VectorXd solved = ldlt.solve(Eigen::Map<const Eigen::VectorXd>(rhs.data(), Eigen::Index(rhs.size())));
            std::copy(solved.data(), solved.data() + solved.size(), x.begin());
        } else if (dim == 2) {
            solveWith<2>();
        } else {
            solveWith<3>();
        }
    }
};

template <int N>
bool DirectJoints::Group::eliminate() {
    for (std::size_t k = 0; k < joints.size(); ++k) {
        if (!invertSpd<N>(pivot[k], pivotFloor[k], pivotInverse[k])) return false;
        const std::uint32_t first = laterStart[k], last = laterStart[k + 1];
        for (std::uint32_t s = first; s < last; ++s) multiply<N>(coupling[s], pivotInverse[k], scratch[s - first]);
        // Each pair (i, j) of k's later joints, place i >= j: block (i, j)
        // loses L_ik A_jk^T. It is j's own pivot, or sits in j's list of
        // later joints, which holds i (no fill) and, like k's, ascends.
        for (std::uint32_t sj = first; sj < last; ++sj) {
            const std::uint32_t j = later[sj];
            subtractTransposed<N>(scratch[sj - first], coupling[sj], pivot[j]);
            std::uint32_t slot = laterStart[j];
            for (std::uint32_t si = sj + 1; si < last; ++si) {
                while (slot < laterStart[j + 1] && later[slot] != later[si]) ++slot;
                if (slot == laterStart[j + 1]) return false;  // fill: out of the tree's order (never)
                subtractTransposed<N>(scratch[si - first], coupling[sj], coupling[slot]);
            }
        }
        for (std::uint32_t s = first; s < last; ++s) coupling[s] = scratch[s - first];
    }
    return true;
}

template <int N>
void DirectJoints::Group::assemble(std::span<const SolverBody> bodies) {
    std::fill(diag.begin(), diag.end(), 0.0);
    std::fill(coupling.begin(), coupling.end(), Block{});
    // Jacobian rows of each end: point x, point y, angle (weld).
    jacobian.resize(3 * ends.size());
    for (std::size_t e = 0; e < ends.size(); ++e) {
        const double s = ends[e].side == 0 ? -1.0 : 1.0;
        const Vec2 r = ends[e].side == 0 ? rA[ends[e].k] : rB[ends[e].k];
        jacobian[3 * e] = {s, 0.0, -s * r.y};
        jacobian[3 * e + 1] = {0.0, s, s * r.x};
        jacobian[3 * e + 2] = {0.0, 0.0, s};
    }
    // Body by body: the joints meeting at a body couple there. In a group
    // of hinges (N = 2) every joint has two rows; else each its own.
    std::uint32_t pair = 0;
    for (std::size_t bi = 0; bi + 1 < bodyStart.size(); ++bi) {
        const std::uint32_t first = bodyStart[bi], last = bodyStart[bi + 1];
        const SolverBody& body = bodies[ends[first].body];
        const double m = body.invMass, i = body.invInertia;
        for (std::uint32_t p = first; p < last; ++p) {
            const Row3* jp = &jacobian[3 * p];
            const std::uint32_t kp = ends[p].k;
            const std::uint32_t np = N == 2 ? 2 : rowsOf[kp];
            for (std::uint32_t q = first; q < last; ++q) {
                const std::uint32_t kq = ends[q].k;
                // Both ends of one joint never meet at one body, so kp == kq
                // only for p == q: the joint's own block.
                if (kp < kq) continue;
                const Row3* jq = &jacobian[3 * q];
                const std::uint32_t nq = N == 2 ? 2 : rowsOf[kq];
                double* out = kp == kq ? &diag[9 * kp] : coupling[pairSlot[pair++]].data();
                for (std::uint32_t a = 0; a < np; ++a)
                    for (std::uint32_t c = 0; c < nq; ++c)
                        out[3 * a + c] += m * (jp[a].x * jq[c].x + jp[a].y * jq[c].y) + i * jp[a].w * jq[c].w;
            }
        }
    }
}

void DirectJoints::Group::factorSparse(double diagScale) {
    // Every entry of the pattern, zeros included, so the pattern analysed
    // once holds for every call; a hinge's unused third row is a unit.
    triplets.clear();
    const std::size_t count = joints.size();
    for (std::size_t k = 0; k < count; ++k) {
        const int base = int(3 * k);
        for (int a = 0; a < 3; ++a)
            for (int c = 0; c <= a; ++c) {
                const bool used = std::uint32_t(a) < rowsOf[k] && std::uint32_t(c) < rowsOf[k];
                const double v = used ? diagScale * diag[9 * k + std::size_t(3 * a + c)] : (a == c ? 1.0 : 0.0);
                triplets.emplace_back(base + a, base + c, v);
            }
        for (std::uint32_t s = laterStart[k]; s < laterStart[k + 1]; ++s)
            for (int a = 0; a < 3; ++a)
                for (int c = 0; c < 3; ++c)
                    triplets.emplace_back(int(3 * later[s]) + a, base + c, coupling[s][std::size_t(3 * a + c)]);
    }
    matrix.resize(Eigen::Index(3 * count), Eigen::Index(3 * count));
    matrix.setFromTriplets(triplets.begin(), triplets.end());
    if (!analysed) {
        ldlt.analyzePattern(matrix);
        analysed = true;
    }
    ldlt.factorize(matrix);
    factored = sparse = ldlt.info() == Eigen::Success;
}

template <int N>
void DirectJoints::Group::solveWith() {
    const std::size_t count = joints.size();
    x = rhs;
    for (std::size_t k = 0; k < count; ++k) {
        const double* yk = &x[3 * k];
        for (std::uint32_t s = laterStart[k]; s < laterStart[k + 1]; ++s) {
            const Block& l = coupling[s];
            double* yi = &x[3 * later[s]];
            for (int r = 0; r < N; ++r) {
                double sum = 0.0;
                for (int m = 0; m < N; ++m) sum += l[std::size_t(3 * r + m)] * yk[m];
                yi[r] -= sum;
            }
        }
    }
    for (std::size_t k = 0; k < count; ++k) {
        const Block& d = pivotInverse[k];
        double* y = &x[3 * k];
        double z[N];
        for (int r = 0; r < N; ++r) {
            z[r] = 0.0;
            for (int m = 0; m < N; ++m) z[r] += d[std::size_t(3 * r + m)] * y[m];
        }
        for (int r = 0; r < N; ++r) y[r] = z[r];
    }
    for (std::size_t k = count; k-- > 0;) {
        double* xk = &x[3 * k];
        for (std::uint32_t s = laterStart[k]; s < laterStart[k + 1]; ++s) {
            const Block& l = coupling[s];
            const double* xi = &x[3 * later[s]];
            for (int c = 0; c < N; ++c) {
                double sum = 0.0;
                for (int m = 0; m < N; ++m) sum += l[std::size_t(3 * m + c)] * xi[m];
                xk[c] -= sum;
            }
        }
    }
}

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
        if (rows == 0 || (j.a.solverBody == 0 && j.b.solverBody == 0)) continue;  // nothing there moves
        const std::uint32_t root = find(j.a.solverBody != 0 ? j.a.solverBody : j.b.solverBody);
        if (loop[root] || rowCount[root] > 3 * bodyCount[root]) continue;
        if (groupOf[root] < 0) {
            groupOf[root] = std::int32_t(groups_.size());
            groups_.push_back(std::make_unique<Group>());
        }
        groups_[std::size_t(groupOf[root])]->joints.push_back(k);
        j.direct = true;
        ++directCount_;
    }
    bodyGroup_.assign(n, -1);
    bodyPlace_.assign(n, 0);
    for (std::size_t gi = 0; gi < groups_.size(); ++gi) {
        Group& g = *groups_[gi];
        order(g, joints);
        for (std::uint32_t place = 0; place + 1 < g.bodyStart.size(); ++place) {
            const std::uint32_t body = g.ends[g.bodyStart[place]].body;
            bodyGroup_[body] = std::int32_t(gi);
            bodyPlace_[body] = place;
        }
    }
}

void DirectJoints::order(Group& g, std::span<const JointConstraint> joints) {
    // The group's dynamic bodies and the joints at each.
    std::vector<std::uint32_t> bodies;
    for (const std::uint32_t k : g.joints)
        for (const std::uint32_t b : {joints[k].a.solverBody, joints[k].b.solverBody})
            if (b != 0) bodies.push_back(b);
    std::sort(bodies.begin(), bodies.end());
    bodies.erase(std::unique(bodies.begin(), bodies.end()), bodies.end());
    const auto local = [&](std::uint32_t b) {
        return std::uint32_t(std::lower_bound(bodies.begin(), bodies.end(), b) - bodies.begin());
    };
    std::vector<std::vector<std::uint32_t>> at(bodies.size());  // joint indices at each body, ascending
    for (const std::uint32_t k : g.joints)
        for (const std::uint32_t b : {joints[k].a.solverBody, joints[k].b.solverBody})
            if (b != 0) at[local(b)].push_back(k);
    const auto otherEnd = [&](std::uint32_t k, std::uint32_t body) {
        const JointConstraint& j = joints[k];
        return j.a.solverBody == body ? j.b.solverBody : j.a.solverBody;
    };
    // Depth first from the body of lowest index, children before parents:
    // a body's joints to the static world, then the joint to its parent.
    std::vector<std::uint32_t> ordered;
    ordered.reserve(g.joints.size());
    struct Visit {
        std::uint32_t body, parentJoint, next;
    };
    constexpr std::uint32_t kNone = 0xFFFFFFFFu;
    std::vector<Visit> stack{{bodies.front(), kNone, 0}};
    while (!stack.empty()) {
        Visit& v = stack.back();
        const std::vector<std::uint32_t>& mine = at[local(v.body)];
        if (v.next < mine.size()) {
            const std::uint32_t k = mine[v.next++];
            const std::uint32_t other = otherEnd(k, v.body);
            if (k != v.parentJoint && other != 0) stack.push_back({other, k, 0});
            continue;
        }
        for (const std::uint32_t k : mine)
            if (otherEnd(k, v.body) == 0) ordered.push_back(k);
        if (v.parentJoint != kNone) ordered.push_back(v.parentJoint);
        stack.pop_back();
    }
    g.joints = std::move(ordered);

    const std::size_t count = g.joints.size();
    g.rowsOf.resize(count);
    g.offset.resize(count);
    g.ends.clear();
    for (std::uint32_t place = 0; place < count; ++place) {
        const JointConstraint& j = joints[g.joints[place]];
        g.rowsOf[place] = directRows(j);
        g.offset[place] = 3 * place;
        if (j.a.solverBody != 0) g.ends.push_back({j.a.solverBody, place, 0});
        if (j.b.solverBody != 0) g.ends.push_back({j.b.solverBody, place, 1});
    }
    std::stable_sort(g.ends.begin(), g.ends.end(), [](const Group::End& l, const Group::End& r) { return l.body < r.body; });
    g.bodyStart.clear();
    for (std::uint32_t e = 0; e < g.ends.size(); ++e)
        if (e == 0 || g.ends[e].body != g.ends[e - 1].body) g.bodyStart.push_back(e);
    g.bodyStart.push_back(std::uint32_t(g.ends.size()));

    // Each joint's later joints (those it shares a body with), ascending.
    std::vector<std::vector<std::uint32_t>> laterOf(count);
    for (std::size_t bi = 0; bi + 1 < g.bodyStart.size(); ++bi)
        for (std::uint32_t p = g.bodyStart[bi]; p < g.bodyStart[bi + 1]; ++p)
            for (std::uint32_t q = g.bodyStart[bi]; q < g.bodyStart[bi + 1]; ++q)
                if (g.ends[q].k > g.ends[p].k) laterOf[g.ends[p].k].push_back(g.ends[q].k);
    g.laterStart.assign(1, 0);
    g.later.clear();
    for (std::vector<std::uint32_t>& list : laterOf) {
        std::sort(list.begin(), list.end());
        g.later.insert(g.later.end(), list.begin(), list.end());
        g.laterStart.push_back(std::uint32_t(g.later.size()));
    }
    const auto slotOf = [&](std::uint32_t k, std::uint32_t i) {
        return std::uint32_t(std::lower_bound(g.later.begin() + g.laterStart[k], g.later.begin() + g.laterStart[k + 1], i) -
                             g.later.begin());
    };
    g.pairSlot.clear();
    for (std::size_t bi = 0; bi + 1 < g.bodyStart.size(); ++bi)
        for (std::uint32_t p = g.bodyStart[bi]; p < g.bodyStart[bi + 1]; ++p)
            for (std::uint32_t q = g.bodyStart[bi]; q < g.bodyStart[bi + 1]; ++q)
                if (g.ends[p].k > g.ends[q].k) g.pairSlot.push_back(slotOf(g.ends[q].k, g.ends[p].k));
    g.dim = std::all_of(g.rowsOf.begin(), g.rowsOf.end(), [](std::uint32_t r) { return r == 2; }) ? 2 : 3;
    g.coupling.resize(g.later.size());
    g.scratch.resize(g.later.size());
    g.pivot.resize(count);
    g.pivotInverse.resize(count);
    g.pivotFloor.resize(count);
    g.rhs.assign(3 * count, 0.0);
    g.x.assign(3 * count, 0.0);
    g.diag.assign(9 * count, 0.0);
    g.rA.resize(count);
    g.rB.resize(count);
}

void DirectJoints::factor(std::span<JointConstraint> joints, std::span<const SolverBody> bodies, const Softness& soft,
                          bool biased) {
    ensureBuilt(joints, bodies);
    ++factorCount_;
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
        const auto assemble = [&] { g.dim == 2 ? g.assemble<2>(bodies) : g.assemble<3>(bodies); };
        assemble();
        // Block LDL^T in the tree's order: eliminating joint k updates only
        // the blocks among its later joints, which meet at one body.
        for (std::size_t k = 0; k < g.joints.size(); ++k) {
            Block& d = g.pivot[k];
            for (int e = 0; e < 9; ++e) d[std::size_t(e)] = diagScale * g.diag[9 * k + std::size_t(e)];
            if (g.rowsOf[k] == 2) d[8] = 1.0;  // a hinge has no third row: a unit pivot that touches nothing
            for (int r = 0; r < 3; ++r) g.pivotFloor[k][std::size_t(r)] = kPivotFloor * d[std::size_t(4 * r)];
        }
        g.sparse = false;
        g.factored = g.eliminate();
        if (!g.factored) {
            assemble();  // the elimination wrote over the blocks
            g.factorSparse(diagScale);
        }
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
            g.rhs[o + 2] = weld ? -r[2] : 0.0;
        }
        g.solveFactored();
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

bool DirectJoints::factored(int group) const { return groups_[std::size_t(group)]->factored; }

std::size_t DirectJoints::responseSize(int group) const {
    const Group& g = *groups_[std::size_t(group)];
    return 3 * (g.bodyStart.size() - 1 + g.joints.size());
}

void DirectJoints::respond(int group, std::uint32_t body, Vec2 dir, double arm, std::span<const SolverBody> bodies,
                           std::span<double> out) {
    Group& g = *groups_[std::size_t(group)];
    const SolverBody& b = bodies[body];
    const Vec2 dv = b.invMass * dir;
    const double dw = b.invInertia * arm;
    // The rows see only the joints at `body`: -(J dv) there, zero elsewhere.
    std::fill(g.rhs.begin(), g.rhs.end(), 0.0);
    const std::uint32_t place = bodyPlace_[body];
    for (std::uint32_t e = g.bodyStart[place]; e < g.bodyStart[place + 1]; ++e) {
        const std::uint32_t k = g.ends[e].k;
        const double sign = g.ends[e].side == 0 ? -1.0 : 1.0;
        const Vec2 r = g.ends[e].side == 0 ? g.rA[k] : g.rB[k];
        const Vec2 cdot = sign * (dv + crossSV(dw, r));
        g.rhs[g.offset[k]] = -cdot.x;
        g.rhs[g.offset[k] + 1] = -cdot.y;
        if (g.rowsOf[k] == 3) g.rhs[g.offset[k] + 2] = -sign * dw;
    }
    g.solveFactored();
    const std::size_t bodyCount = g.bodyStart.size() - 1;
    std::fill(out.begin(), out.begin() + std::ptrdiff_t(responseSize(group)), 0.0);
    out[3 * place] = dv.x;
    out[3 * place + 1] = dv.y;
    out[3 * place + 2] = dw;
    for (std::uint32_t e = 0; e < g.ends.size(); ++e) {
        const std::uint32_t k = g.ends[e].k, o = g.offset[k];
        const double sign = g.ends[e].side == 0 ? -1.0 : 1.0;
        const Vec2 p{g.x[o], g.x[o + 1]};
        const double turn = g.rowsOf[k] == 3 ? g.x[o + 2] : 0.0;
        const SolverBody& sb = bodies[g.ends[e].body];
        const Vec2 r = g.ends[e].side == 0 ? g.rA[k] : g.rB[k];
        const std::uint32_t at = 3 * bodyPlace_[g.ends[e].body];
        out[at] += sign * sb.invMass * p.x;
        out[at + 1] += sign * sb.invMass * p.y;
        out[at + 2] += sign * sb.invInertia * (cross(r, p) + turn);
    }
    for (std::size_t k = 0; k < g.joints.size(); ++k) {
        const std::uint32_t o = g.offset[k];
        double* j = &out[3 * (bodyCount + k)];
        j[0] = g.x[o];
        j[1] = g.x[o + 1];
        j[2] = g.rowsOf[k] == 3 ? g.x[o + 2] : 0.0;
    }
}

void DirectJoints::applyResponse(int group, std::span<const double> response, double scale,
                                 std::span<JointConstraint> joints, std::span<SolverBody> bodies) const {
    const Group& g = *groups_[std::size_t(group)];
    const std::size_t bodyCount = g.bodyStart.size() - 1;
    for (std::size_t place = 0; place < bodyCount; ++place) {
        SolverBody& b = bodies[g.ends[g.bodyStart[place]].body];
        b.v += scale * Vec2{response[3 * place], response[3 * place + 1]};
        b.w += scale * response[3 * place + 2];
    }
    for (std::size_t k = 0; k < g.joints.size(); ++k) {
        JointConstraint& j = joints[g.joints[k]];
        const double* d = &response[3 * (bodyCount + k)];
        j.linearImpulse += scale * Vec2{d[0], d[1]};
        j.angularImpulse += scale * d[2];
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
            g.rhs[o + 2] = 0.0;
            if (directRows(j) == 3) {
                const double angle = j.deltaAngle + std::atan2(b.dq.s, b.dq.c) - std::atan2(a.dq.s, a.dq.c);
                g.rhs[o + 2] = -std::copysign(std::max(std::abs(angle) - kAngularProjectionSlop, 0.0), angle);
                any = any || g.rhs[o + 2] != 0.0;
            }
        }
        if (!any) continue;  // every joint within the slop: nothing moves
        g.solveFactored();
        const std::size_t first = moved.size();
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
        // The step is linear in the moves; the joints are not. Where the
        // linear step is a poor guide it can leave the joints further open
        // than it found them: a chain laid straight between pins closer
        // together than its length can shorten only by buckling, which the
        // linear step cannot see, and along the nearly singular straight
        // line it answered a centimetre of error with most of a metre, torn
        // open again at once. So the errors past the slop are measured again
        // at the moved pose (a weld's angle counted at its arms' length),
        // and a step that leaves more of them is halved until it does not (a
        // few times at most; then it is dropped).
        const auto excessAt = [&](double scale) {
            double excess = 0.0;
            for (std::size_t k = 0; k < g.joints.size(); ++k) {
                const JointConstraint& j = joints[g.joints[k]];
                const auto movedPose = [&](std::uint32_t body, Vec2 r, Vec2& dp, double& turn) {
                    dp = bodies[body].dp;
                    turn = std::atan2(bodies[body].dq.s, bodies[body].dq.c);
                    if (body == 0) return r;
                    dp += scale * moves[body].dp;
                    turn += scale * moves[body].dq;
                    return collision::rotate(collision::rotationBy(scale * moves[body].dq), r);
                };
                Vec2 dpA, dpB;
                double turnA = 0.0, turnB = 0.0;
                const Vec2 rA = movedPose(j.a.solverBody, g.rA[k], dpA, turnA);
                const Vec2 rB = movedPose(j.b.solverBody, g.rB[k], dpB, turnB);
                excess += std::max(length((dpB - dpA) + (rB - rA) + j.deltaCenter) - kProjectionSlop, 0.0);
                if (directRows(j) == 3)
                    excess += std::max(std::abs(j.deltaAngle + turnB - turnA) - kAngularProjectionSlop, 0.0) *
                              (length(g.rA[k]) + length(g.rB[k]));
            }
            return excess;
        };
        const double before = excessAt(0.0);
        double scale = 1.0, after = excessAt(scale);
        for (int halving = 0; halving < kProjectionHalvings && after > before; ++halving) {
            scale *= 0.5;
            after = excessAt(scale);
        }
        if (after > before) scale = 0.0;
        if (scale != 1.0)
            for (std::size_t i = first; i < moved.size(); ++i) {
                moves[moved[i]].dp = scale * moves[moved[i]].dp;
                moves[moved[i]].dq *= scale;
            }
    }
    std::sort(moved.begin(), moved.end());
    moved.erase(std::unique(moved.begin(), moved.end()), moved.end());
}

} // namespace stepwise::joints
