#pragma once
// Which bodies a body never collides with, and why: the inspector lists
// them so a designer can see what a filter or a joint leaves out.

#include "stepwise/scene.hpp"

#include <string>
#include <vector>

namespace stepwise::editor {

/// A body that `of` never collides with.
struct ExcludedPartner {
    Entity body;
    /// "filter" (categories, masks or groups) or "joint NAME" (a joint
    /// between the two with collide_connected false).
    std::string reason;
};

/// Every shaped body that the shaped body `of` never collides with, in
/// scene order. Empty when `of` has no shape. Pairs of two static bodies
/// are left out: they never meet anyway.
std::vector<ExcludedPartner> excludedPartners(const Scene& scene, Entity of);

} // namespace stepwise::editor
