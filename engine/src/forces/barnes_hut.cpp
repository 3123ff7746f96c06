// The Barnes–Hut tree of the attractors. See barnes_hut.hpp.

#include "forces/barnes_hut.hpp"
#include "forces/force_model.hpp"

#include <algorithm>
#include <cmath>

namespace stepwise::detail {

namespace {
// Coincident attractors cannot be separated by halving: past this depth a
// cell is a leaf whatever its count (2^-48 of the scene's extent).
constexpr int kMaxDepth = 48;
} // namespace

bool AttractorTree::build(const std::vector<AttractorData>& attractors, const double* x, double theta) {
    theta_ = theta;
    nodes_.clear();
    items_.clear();
    double minX = INFINITY, minY = INFINITY, maxX = -INFINITY, maxY = -INFINITY;
    for (const AttractorData& at : attractors) {
        const double px = at.body == kNoBody ? at.px : x[2 * at.body];
        const double py = at.body == kNoBody ? at.py : x[2 * at.body + 1];
        if (!std::isfinite(px) || !std::isfinite(py)) return false;
        items_.push_back({px, py, at.gm, at.eps2, at.body});
        minX = std::min(minX, px);
        minY = std::min(minY, py);
        maxX = std::max(maxX, px);
        maxY = std::max(maxY, py);
    }
    if (items_.empty()) return false;
    scratch_.resize(items_.size());
    // A square around all of them (a little larger, so that the largest
    // coordinate falls strictly inside the upper half).
    const double side = std::max(maxX - minX, maxY - minY) * (1.0 + 1e-12) + 1e-300;
    if (!std::isfinite(side)) return false;
    nodes_.reserve(2 * items_.size() / kLeafSize + 16);
    buildNode(0, std::uint32_t(items_.size()), minX, minY, side, 0);
    return true;
}

std::uint32_t AttractorTree::buildNode(std::uint32_t begin, std::uint32_t end, double x0, double y0, double side,
                                       int depth) {
    const std::uint32_t index = std::uint32_t(nodes_.size());
    nodes_.emplace_back();
    // Monopole: total G m, |G m|-weighted centre and softening. |G m| so a
    // negative G (repulsion) still gives a centre inside the cell; equal
    // weights when every G m is 0.
    double gm = 0.0, gmDynamic = 0.0, w = 0.0, wx = 0.0, wy = 0.0, we = 0.0;
    for (std::uint32_t i = begin; i < end; ++i) {
        const Item& it = items_[i];
        gm += it.gm;
        if (it.body != kNoBody) gmDynamic += it.gm;
        const double weight = std::fabs(it.gm);
        w += weight;
        wx += weight * it.x;
        wy += weight * it.y;
        we += weight * it.eps2;
    }
    Node node;
    if (w > 0.0) {
        node.cx = wx / w;
        node.cy = wy / w;
        node.eps2 = we / w;
    } else {
        double sx = 0.0, sy = 0.0, se = 0.0;
        for (std::uint32_t i = begin; i < end; ++i) {
            sx += items_[i].x;
            sy += items_[i].y;
            se += items_[i].eps2;
        }
        const double count = double(end - begin);
        node.cx = sx / count;
        node.cy = sy / count;
        node.eps2 = se / count;
    }
    node.gm = gm;
    node.gmDynamic = gmDynamic;
    for (std::uint32_t i = begin; i < end; ++i) {
        const Item& it = items_[i];
        const double ex = it.x - node.cx, ey = it.y - node.cy, e2 = ex * ex + ey * ey;
        node.qxx += it.gm * (3.0 * ex * ex - e2);
        node.qxy += it.gm * (3.0 * ex * ey);
        node.qyy += it.gm * (3.0 * ey * ey - e2);
    }
    const double delta = std::hypot(node.cx - (x0 + 0.5 * side), node.cy - (y0 + 0.5 * side));
    const double open = side / theta_ + delta;
    node.open2 = open * open;
    node.begin = begin;
    node.end = end;
    node.leaf = end - begin <= kLeafSize || depth >= kMaxDepth;
    if (!node.leaf) {
        // Stable partition into the four quadrants (lower-left,
        // lower-right, upper-left, upper-right), through scratch_.
        const double half = 0.5 * side, mx = x0 + half, my = y0 + half;
        std::uint32_t count[4] = {0, 0, 0, 0};
        auto quadrant = [&](const Item& it) { return (it.x >= mx ? 1 : 0) + (it.y >= my ? 2 : 0); };
        for (std::uint32_t i = begin; i < end; ++i) ++count[quadrant(items_[i])];
        std::uint32_t start[4] = {begin, begin + count[0], begin + count[0] + count[1],
                                  begin + count[0] + count[1] + count[2]};
        std::uint32_t fill[4] = {start[0], start[1], start[2], start[3]};
        for (std::uint32_t i = begin; i < end; ++i) scratch_[fill[quadrant(items_[i])]++] = items_[i];
        std::copy(scratch_.begin() + begin, scratch_.begin() + end, items_.begin() + begin);
        nodes_[index] = node;
        for (int q = 0; q < 4; ++q) {
            if (count[q] == 0) continue;
            buildNode(start[q], start[q] + count[q], (q & 1) ? mx : x0, (q & 2) ? my : y0, half, depth + 1);
        }
        nodes_[index].skip = std::uint32_t(nodes_.size());
        return index;
    }
    node.skip = index + 1;
    nodes_[index] = node;
    return index;
}

template <bool Potential>
void AttractorTree::accumulate(double px, double py, std::uint32_t self, double& ax, double& ay, double* phiFixed,
                               double* phiDynamic) const {
    const Node* nodes = nodes_.data();
    const std::uint32_t count = std::uint32_t(nodes_.size());
    double fixedSum = 0.0, dynamicSum = 0.0;  // potential, in registers (see exactField)
    std::uint32_t i = 0;
    while (i < count) {
        const Node& node = nodes[i];
        const double dx = node.cx - px, dy = node.cy - py;
        const double d2 = dx * dx + dy * dy;
        if (d2 > node.open2) {
            // Far: the whole cell as one softened mass plus its
            // quadrupole. (dx, dy) = -r, from the point to the centre.
            // One division and one square root per cell: 1/rho^3, and from
            // it 1/rho^2 = rho/rho^3 and 1/rho^5.
            const double q = d2 + node.eps2;
            const double r = std::sqrt(q);
            const double i3 = 1.0 / (q * r);
            const double i2 = i3 * r;
            const double i5 = i3 * i2;
            const double s = node.gm * i3;
            const double qrx = -(node.qxx * dx + node.qxy * dy), qry = -(node.qxy * dx + node.qyy * dy);  // Q r
            const double rqr = -(dx * qrx + dy * qry);
            const double radial = 2.5 * rqr * i5 * i2;  // times r = -(dx, dy)
            ax += s * dx + i5 * qrx + radial * dx;
            ay += s * dy + i5 * qry + radial * dy;
            if constexpr (Potential) {
                // The quadrupole term is shared in proportion to G m.
                const double phi = s * q + 0.5 * rqr * i5;  // s q = G M / rho, without a division
                const double dynamicShare = node.gm != 0.0 ? node.gmDynamic / node.gm : 0.0;
                dynamicSum += dynamicShare * phi;
                fixedSum += (1.0 - dynamicShare) * phi;
            }
            i = node.skip;
        } else if (node.leaf) {
            // Near leaf: each attractor exactly (the pairwise formula).
            for (std::uint32_t k = node.begin; k < node.end; ++k) {
                const Item& it = items_[k];
                if (it.body == self && self != kNoBody) continue;
                const double ex = it.x - px, ey = it.y - py;
                const double q = ex * ex + ey * ey + it.eps2;
                if (!(q > 0.0)) continue;
                const double r = std::sqrt(q);
                const double s = it.gm / (q * r);
                ax += s * ex;
                ay += s * ey;
                if constexpr (Potential) (it.body == kNoBody ? fixedSum : dynamicSum) += s * q;
            }
            i = node.skip;
        } else {
            ++i;  // open: the first child follows its parent
        }
    }
    if constexpr (Potential) {
        *phiFixed += fixedSum;
        *phiDynamic += dynamicSum;
    }
}

template void AttractorTree::accumulate<false>(double, double, std::uint32_t, double&, double&, double*,
                                               double*) const;
template void AttractorTree::accumulate<true>(double, double, std::uint32_t, double&, double&, double*,
                                              double*) const;

} // namespace stepwise::detail
