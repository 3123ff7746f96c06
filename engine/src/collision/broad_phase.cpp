#include "collision/broad_phase.hpp"

#include <algorithm>
#include <cmath>

namespace stepwise::collision {

void BroadPhase::findPairs(std::span<const Aabb> boxes, std::span<const std::uint8_t> movable,
                           std::vector<ProxyPair>& pairs) {
    pairs.clear();
    switch (kind_) {
    case BroadPhaseKind::SweepAndPrune: sweepAndPrune(boxes, movable, pairs); break;
    case BroadPhaseKind::UniformGrid: uniformGrid(boxes, movable, pairs); break;
    case BroadPhaseKind::BruteForce:
        for (std::uint32_t i = 0; i < boxes.size(); ++i)
            for (std::uint32_t j = i + 1; j < boxes.size(); ++j)
                if ((movable[i] || movable[j]) && overlaps(boxes[i], boxes[j])) pairs.push_back({i, j});
        break;
    }
    std::sort(pairs.begin(), pairs.end());
}

void BroadPhase::sweepAndPrune(std::span<const Aabb> boxes, std::span<const std::uint8_t> movable,
                               std::vector<ProxyPair>& pairs) {
    const std::uint32_t n = std::uint32_t(boxes.size());
    if (order_.size() != n) {
        order_.resize(n);
        for (std::uint32_t i = 0; i < n; ++i) order_[i] = i;
    }
    // Insertion sort: bodies move little per step, so the previous order is
    // nearly sorted and this is close to linear. Ties break by index, so the
    // order is a pure function of the boxes (determinism).
    auto less = [&](std::uint32_t a, std::uint32_t b) {
        return boxes[a].lower.x != boxes[b].lower.x ? boxes[a].lower.x < boxes[b].lower.x : a < b;
    };
    for (std::uint32_t i = 1; i < n; ++i) {
        const std::uint32_t key = order_[i];
        std::uint32_t j = i;
        while (j > 0 && less(key, order_[j - 1])) {
            order_[j] = order_[j - 1];
            --j;
        }
        order_[j] = key;
    }
    // Sweep over a sorted, packed copy: the inner loop then reads memory in
    // order instead of jumping through order_ (measured 3x faster on a
    // 2,000-body pile, where each box overlaps ~36 others in x).
    sorted_.resize(n);
    for (std::uint32_t i = 0; i < n; ++i) {
        const std::uint32_t k = order_[i];
        sorted_[i] = {boxes[k].lower.x, boxes[k].upper.x, boxes[k].lower.y, boxes[k].upper.y, k, movable[k]};
    }
    for (std::uint32_t i = 0; i < n; ++i) {
        const SortedBox& a = sorted_[i];
        for (std::uint32_t j = i + 1; j < n; ++j) {
            const SortedBox& b = sorted_[j];
            if (b.lowerX > a.upperX) break;
            if (!(a.movable || b.movable)) continue;
            if (a.lowerY <= b.upperY && b.lowerY <= a.upperY)
                pairs.push_back(a.index < b.index ? ProxyPair{a.index, b.index} : ProxyPair{b.index, a.index});
        }
    }
}

void BroadPhase::uniformGrid(std::span<const Aabb> boxes, std::span<const std::uint8_t> movable,
                             std::vector<ProxyPair>& pairs) {
    const std::uint32_t n = std::uint32_t(boxes.size());
    if (n == 0) return;
    // Cell size: twice the mean box extent, so a typical box spans 1-4 cells.
    // Big static boxes (walls) span many cells; that is the grid's weakness
    // and why sweep and prune is the default.
    double sum = 0.0;
    Vec2 lo = boxes[0].lower;
    for (const Aabb& b : boxes) {
        sum += std::max(b.upper.x - b.lower.x, b.upper.y - b.lower.y);
        lo.x = std::min(lo.x, b.lower.x);
        lo.y = std::min(lo.y, b.lower.y);
    }
    const double cell = std::max(2.0 * sum / n, 1e-6);
    cellKeys_.clear();
    auto cellOf = [&](double v, double origin) { return std::int64_t(std::floor((v - origin) / cell)); };
    for (std::uint32_t i = 0; i < n; ++i) {
        const std::int64_t x0 = cellOf(boxes[i].lower.x, lo.x), x1 = cellOf(boxes[i].upper.x, lo.x);
        const std::int64_t y0 = cellOf(boxes[i].lower.y, lo.y), y1 = cellOf(boxes[i].upper.y, lo.y);
        for (std::int64_t x = x0; x <= x1; ++x)
            for (std::int64_t y = y0; y <= y1; ++y)
                cellKeys_.push_back((std::uint64_t((x & 0xFFFF) | ((y & 0xFFFF) << 16)) << 32) | i);
    }
    std::sort(cellKeys_.begin(), cellKeys_.end());
    for (std::size_t begin = 0; begin < cellKeys_.size();) {
        std::size_t end = begin + 1;
        while (end < cellKeys_.size() && (cellKeys_[end] >> 32) == (cellKeys_[begin] >> 32)) ++end;
        const std::uint64_t cellKey = cellKeys_[begin] >> 32;
        const std::int64_t cx = std::int64_t(cellKey & 0xFFFF), cy = std::int64_t((cellKey >> 16) & 0xFFFF);
        for (std::size_t i = begin; i < end; ++i) {
            const std::uint32_t a = std::uint32_t(cellKeys_[i]);
            for (std::size_t j = i + 1; j < end; ++j) {
                const std::uint32_t b = std::uint32_t(cellKeys_[j]);
                if (!(movable[a] || movable[b]) || !overlaps(boxes[a], boxes[b])) continue;
                // Report the pair only in the cell holding the lower corner of
                // the two boxes' intersection, so it is found once.
                const double ix = std::max(boxes[a].lower.x, boxes[b].lower.x);
                const double iy = std::max(boxes[a].lower.y, boxes[b].lower.y);
                if ((cellOf(ix, lo.x) & 0xFFFF) != cx || (cellOf(iy, lo.y) & 0xFFFF) != cy) continue;
                pairs.push_back(a < b ? ProxyPair{a, b} : ProxyPair{b, a});
            }
        }
        begin = end;
    }
}

} // namespace stepwise::collision
