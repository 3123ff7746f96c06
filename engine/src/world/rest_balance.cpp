#include "world/rest_balance.hpp"

#include <algorithm>
#include <cmath>

namespace stepwise::detail {

bool couldRest(std::span<const Support> supports, Vec2 force, bool oneBody) {
    if (supports.empty()) return true;  // nothing to rest on: the velocity rule decides
    const double pull = length(force);
    if (!(pull > 0.0)) return true;     // no pull (or not finite): nothing to balance
    // Normals within a nanoradian are one line: a floor of boxes placed end
    // to end, a chain's straight run. Rounding tilts such normals by 1e-16.
    constexpr double kParallel = 1e-9;
    // The balance is exact but for rounding in the pull and the normals,
    // 1e-16 of each: a slope of 1e-12 rad is still a slope.
    constexpr double kForceTolerance = 1e-12;
    const Vec2 n = supports.front().normal;
    double friction = 0.0;
    for (const Support& s : supports) {
        if (std::abs(cross(n, s.normal)) > kParallel) return true;
        // Pushed from both sides (a body wedged between floor and ceiling):
        // a squeeze of any size may hold it by friction.
        if (dot(n, s.normal) < 0.0) return true;
        friction = std::max(friction, s.friction);
    }
    const Vec2 t{n.y, -n.x};
    const double press = -dot(force, n), across = dot(force, t);
    const double tolerance = kForceTolerance * pull;
    if (press < -tolerance) return false;  // pulled off its supports
    if (std::abs(across) > friction * std::max(press, 0.0) + tolerance) return false;  // slides
    if (!oneBody || !(press > tolerance)) return true;
    // Torque about the centre of mass. With every point at one height u
    // below it, normal forces l_i at offsets a_i and friction f_i balance
    // the pull's turn when sum a_i l_i = u sum f_i = -u across, so the
    // centre of pressure -u across / press must lie between the points.
    double lowest = supports.front().up[0], highest = lowest;
    double first = supports.front().along[0], last = first, upSum = 0.0;
    int count = 0;
    for (const Support& s : supports)
        for (int i = 0; i < s.points; ++i) {
            lowest = std::min(lowest, s.up[i]);
            highest = std::max(highest, s.up[i]);
            first = std::min(first, s.along[i]);
            last = std::max(last, s.along[i]);
            upSum += s.up[i];
            ++count;
        }
    if (count == 0) return true;
    const double up = upSum / double(count);
    const double scale = std::abs(up) + (last - first);
    // Points at different heights (a body on a step's edge and its floor)
    // need the full friction problem; the velocity rule decides there.
    if (highest - lowest > 1e-6 * scale) return true;
    const double centreOfPressure = -up * across / press;
    const double slack = 1e-10 * scale;
    return centreOfPressure >= first - slack && centreOfPressure <= last + slack;
}

} // namespace stepwise::detail
