#pragma once
// The boxes of shapes that do not move while some islands sleep: static
// shapes and sleeping bodies. Built once when the sleeping set changes;
// each step, only the awake bodies' boxes query it, so a sleeping pile
// costs the broad phase nothing (its pairs with itself and with the floor
// are never re-tested). Sorted by lower x; boxes much wider than the
// median (a floor, a wall) are kept apart and tested against every query.

#include "collision/collision_types.hpp"

#include <cstdint>
#include <span>
#include <vector>

namespace stepwise::collision {

class FrozenBoxes {
public:
    /// `boxes[k]` belongs to proxy `proxies[k]`.
    void build(std::span<const Aabb> boxes, std::span<const std::uint32_t> proxies);
    void clear() { sorted_.clear(), large_.clear(), lowerX_.clear(); }
    bool empty() const { return sorted_.empty() && large_.empty(); }
    /// Calls visit(proxy) for every frozen box overlapping `box`, in no
    /// particular order.
    template <typename Visit>
    void query(const Aabb& box, Visit&& visit) const {
        for (const Entry& e : large_)
            if (overlaps(e.box, box)) visit(e.proxy);
        if (sorted_.empty()) return;
        // Candidates start no further left than box.lower.x - maxWidth_.
        std::size_t k = firstAtOrAfter(box.lower.x - maxWidth_);
        for (; k < sorted_.size() && sorted_[k].box.lower.x <= box.upper.x; ++k)
            if (overlaps(sorted_[k].box, box)) visit(sorted_[k].proxy);
    }

private:
    struct Entry {
        Aabb box;
        std::uint32_t proxy;
    };
    std::size_t firstAtOrAfter(double x) const;
    std::vector<Entry> sorted_;   // by box.lower.x
    std::vector<double> lowerX_;  // sorted_[k].box.lower.x, packed for the search
    std::vector<Entry> large_;
    double maxWidth_ = 0.0;       // widest box in sorted_, metres
};

} // namespace stepwise::collision
