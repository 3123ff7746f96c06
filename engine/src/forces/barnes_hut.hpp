#pragma once
// Barnes–Hut quadtree over the attractors (Barnes & Hut, Nature 324, 1986).
// A cell far enough from the point that feels it is replaced by its
// multipole expansion about its centre of mass, to quadrupole order, so a
// force evaluation costs O(n log n) instead of O(n * attractors). With
// r = point - centre, rho^2 = |r|^2 + eps^2 and the traceless quadrupole
// Q = sum G m (3 d d^T - |d|^2 I) (d: attractor - centre):
//   a = -G M r / rho^3 + Q r / rho^5 - 5/2 (r.Q r) r / rho^7,
//   potential sum G m / r ~ G M / rho + 1/2 (r.Q r) / rho^5.
// The quadrupole costs ~15 flops per cell and cuts the force error at a
// given theta several times over (RMS relative force error at theta 0.5 in
// a uniform disc: 8.3e-3 with the monopole alone on 2,000 attractors;
// 1.3e-3 with the quadrupole on 10,000, `stepwise bench accuracy`).
//
// Opening rule (Barnes' "modified" criterion, with the offset of the centre
// of mass, as in Salmon & Warren 1994): a cell of side s whose centre of
// mass lies delta from its square's centre is used whole when the point is
// farther than s/theta + delta from the centre of mass. For theta <= 1 a
// point inside the square never satisfies it, so a body never feels its own
// cell as one mass (and never itself). Leaves hold up to kLeafSize
// attractors and are summed exactly.
//
// Softening of a cell: the |G m|-weighted mean of its attractors' eps^2
// (each leaf attractor keeps its own). Far cells, where the rule accepts
// them, are many softening lengths away in any sensible scene, so the mean
// only matters where the monopole error already dominates.
//
// Determinism: the tree is rebuilt from the positions at every evaluation
// (no state between evaluations), partitioning is stable, traversal is
// depth-first in a fixed child order, one thread.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace stepwise::detail {

struct AttractorData;

class AttractorTree {
public:
    static constexpr std::uint32_t kLeafSize = 8;

    /// Builds over `attractors`, dynamic ones at their positions in x.
    /// Returns false (and builds nothing) when a position is not finite:
    /// the caller then sums pairwise, which propagates the NaN the world's
    /// divergence check reports.
    bool build(const std::vector<AttractorData>& attractors, const double* x, double theta);

    /// Adds the pull on a point at (px, py) from every attractor except
    /// body `self` to (ax, ay), m/s^2. With `potential`, also adds
    /// sum G m_a / r over the fixed attractors to *phiFixed and over the
    /// dynamic ones to *phiDynamic (m^2/s^2; the caller weights and signs).
    /// The acceleration arithmetic is the same with or without `potential`,
    /// so both give the same bits.
    template <bool Potential>
    void accumulate(double px, double py, std::uint32_t self, double& ax, double& ay, double* phiFixed,
                    double* phiDynamic) const;

    std::size_t nodeCount() const { return nodes_.size(); }

private:
    struct Node {
        double cx = 0.0, cy = 0.0;    ///< centre of mass (|gm|-weighted), m
        double gm = 0.0;              ///< sum of G m, m^3/s^2
        double gmDynamic = 0.0;       ///< the part from dynamic attractors
        double eps2 = 0.0;            ///< |gm|-weighted mean softening^2, m^2
        double qxx = 0.0, qxy = 0.0, qyy = 0.0;  ///< quadrupole about (cx, cy), m^5/s^2
        double open2 = 0.0;           ///< (s/theta + delta)^2: used whole beyond this, m^2
        std::uint32_t begin = 0, end = 0;  ///< leaf: range of order_
        std::uint32_t skip = 0;       ///< next node in depth-first order after this subtree
        bool leaf = false;
    };
    struct Item {
        double x, y, gm, eps2;
        std::uint32_t body;  ///< dynamic body index; kNoBody (force_model.hpp) when fixed
    };
    std::uint32_t buildNode(std::uint32_t begin, std::uint32_t end, double x0, double y0, double side, int depth);

    std::vector<Node> nodes_;
    std::vector<Item> items_;    ///< attractors, reordered so each leaf is a contiguous range
    std::vector<Item> scratch_;  ///< partition buffer
    double theta_ = 0.5;
};

} // namespace stepwise::detail
