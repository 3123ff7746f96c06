#include "collision/frozen_boxes.hpp"

#include <algorithm>

namespace stepwise::collision {

void FrozenBoxes::build(std::span<const Aabb> boxes, std::span<const std::uint32_t> proxies) {
    clear();
    maxWidth_ = 0.0;
    if (boxes.empty()) return;
    std::vector<double> widths(boxes.size());
    for (std::size_t k = 0; k < boxes.size(); ++k) widths[k] = boxes[k].upper.x - boxes[k].lower.x;
    std::vector<double> median = widths;
    std::nth_element(median.begin(), median.begin() + std::ptrdiff_t(median.size() / 2), median.end());
    // Wider than 8 median boxes: a floor or a wall, tested against every
    // query (there are few), so that it does not widen every search window.
    const double large = 8.0 * median[median.size() / 2];
    for (std::size_t k = 0; k < boxes.size(); ++k) {
        const Entry e{boxes[k], proxies[k]};
        if (widths[k] > large) {
            large_.push_back(e);
        } else {
            sorted_.push_back(e);
            maxWidth_ = std::max(maxWidth_, widths[k]);
        }
    }
    std::sort(sorted_.begin(), sorted_.end(), [](const Entry& a, const Entry& b) {
        return a.box.lower.x != b.box.lower.x ? a.box.lower.x < b.box.lower.x : a.proxy < b.proxy;
    });
    lowerX_.resize(sorted_.size());
    for (std::size_t k = 0; k < sorted_.size(); ++k) lowerX_[k] = sorted_[k].box.lower.x;
}

std::size_t FrozenBoxes::firstAtOrAfter(double x) const {
    return std::size_t(std::lower_bound(lowerX_.begin(), lowerX_.end(), x) - lowerX_.begin());
}

} // namespace stepwise::collision
