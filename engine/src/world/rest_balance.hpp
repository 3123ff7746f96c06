#pragma once
// Whether an island could rest where it touches the static world: the test
// sleep applies before it freezes an island, beside the timers' velocity
// rule. A body on a frictionless slope of a ten-thousandth of a degree
// gains speed slower than any velocity rule can tell from a settling pile's
// jitter, yet no contact can hold it; the forces say so exactly.

#include <cstdint>
#include <span>

#include "collision/static_support.hpp"
#include "stepwise/vec2.hpp"

namespace stepwise::detail {

/// False when no contact forces at `supports` can balance `force` (N, the
/// field's pull on the island's bodies together), so the island must not
/// sleep:
/// - the normals all lie along one line and the pull's part along that line
///   lifts the island off, or its part across exceeds what friction holds
///   (the largest coefficient times the press);
/// - for a lone body (`oneBody`) whose points lie on one line across the
///   normal, the pull's line through the centre of mass passes outside the
///   points, so it tips or rolls (a ball on any slope).
/// True otherwise, and whenever the normals point two ways (a valley, a
/// corner): there the velocity rule of the timers decides.
using collision::Support;

bool couldRest(std::span<const Support> supports, Vec2 force, bool oneBody);

} // namespace stepwise::detail
