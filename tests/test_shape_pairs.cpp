// Every pair of shape kinds at rest: a dynamic body of each kind set on a
// support of each kind (a dynamic one on the floor, or a static one), at
// the engine's chosen settings and at 4 substeps, for two mass ratios. The
// analytic height of each centre is the sum of the reaches below it, less
// what the soft contacts let it sink: a contact of effective mass m carrying
// F sinks F / (m w^2), w = 2 pi min(60 Hz, substep rate / 4). On a static
// support that is g / w^2; for a top R times the bottom's mass, both layers
// sink (1 + R) g / w^2.
// Kinds: circle, box, hexagon, rounded box (polygon with radius), capsule,
// compound body (a bar and two discs), and, as static supports only, a
// chain, a plane and a static box.

#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

using namespace stepwise;
using test::exactNumber;
using test::loadError;
using test::vectorJson;
using test::Sim;

namespace {

/// A shape as the JSON of its components, with how far it reaches below
/// and above its position (its centre of mass, for every piece here).
struct Piece {
    std::string label, json;
    double down = 0.0, up = 0.0;
    bool flatTop = true;  ///< whether another body can rest on it
};


std::string point(double x, double y) { return "{\"x\": " + exactNumber(x) + ", \"y\": " + exactNumber(y) + "}"; }

Piece circle(double r) {
    return {"circle", "\"radius\": " + exactNumber(r), r, r, false};
}
Piece box(double w, double h) {
    return {"box", "\"box\": {\"width\": " + exactNumber(w) + ", \"height\": " + exactNumber(h) + "}", h / 2, h / 2};
}
Piece hexagon(double r) {
    // Flat top and bottom: vertices at 0, 60, ... degrees.
    std::string v;
    for (int i = 0; i < 6; ++i) {
        const double a = i * std::numbers::pi / 3.0;
        v += (i ? ", " : "") + point(r * std::cos(a), r * std::sin(a));
    }
    const double h = r * std::sqrt(3.0) / 2.0;
    return {"hexagon", "\"polygon\": {\"vertices\": [" + v + "]}", h, h};
}
Piece roundedBox(double w, double h, double radius) {
    const std::string v = point(-w / 2, -h / 2) + ", " + point(w / 2, -h / 2) + ", " + point(w / 2, h / 2) + ", " +
                          point(-w / 2, h / 2);
    return {"rounded box", "\"polygon\": {\"vertices\": [" + v + "], \"radius\": " + exactNumber(radius) + "}",
            h / 2 + radius, h / 2 + radius};
}
Piece capsule(double length, double r) {
    return {"capsule",
            "\"capsule\": {\"a\": " + point(-length / 2, 0) + ", \"b\": " + point(length / 2, 0) + ", \"radius\": " +
                exactNumber(r) + "}",
            r, r};
}
Piece compound(double w, double h) {
    // A bar with a disc of its own thickness at each end: flat on both
    // sides, centre of mass at the middle.
    const double r = h / 2;
    return {"compound",
            "\"shapes\": [{\"box\": {\"center\": " + point(0, 0) + ", \"width\": " + exactNumber(w) + ", \"height\": " +
                exactNumber(h) + ", \"angle\": 0}}, {\"circle\": {\"center\": " + point(-w / 2, 0) + ", \"radius\": " +
                exactNumber(r) + "}}, {\"circle\": {\"center\": " + point(w / 2, 0) + ", \"radius\": " + exactNumber(r) + "}}]",
            r, r};
}

/// A static support: its entities and the height of its top.
struct Support {
    std::string label, json;
    double top = 0.0;
};

const std::string kFloor = "{\"name\": \"floor\", \"plane\": {\"normal\": {\"x\": 0, \"y\": 1}, \"offset\": 0}}";

struct Outcome {
    double heightError = 0.0, drift = 0.0, turn = 0.0;
    double omega = 0.0;  ///< rad/s, the contacts' stiffness at the settings the run used
};

Outcome settle(const std::string& entities, const std::string& world, double expectedTop,
               double expectedBottom = -1.0) {
    Sim sim("{\"world\": {" + world + "}, \"entities\": [" + entities + "]}");
    Outcome out;
    if (!sim.step(180)) {
        out.heightError = 1e9;
        return out;
    }
    const int substeps = sim.scene.world.substeps > 0 ? sim.scene.world.substeps : sim.world->settingsChoice().substeps;
    out.omega = 2.0 * std::numbers::pi * std::min(60.0, substeps / (4.0 * sim.scene.world.dt));
    out.heightError = std::abs(sim.position("top").y - expectedTop);
    out.drift = std::abs(sim.position("top").x);
    out.turn = std::abs(sim.angle("top"));
    if (expectedBottom >= 0.0) {
        out.heightError = std::max(out.heightError, std::abs(sim.position("bottom").y - expectedBottom));
        out.drift = std::max(out.drift, std::abs(sim.position("bottom").x));
        out.turn = std::max(out.turn, std::abs(sim.angle("bottom")));
    }
    return out;
}

} // namespace

TEST(ShapePairs, EveryKindRestsOnEveryKindAtItsAnalyticHeight) {
    const std::vector<Piece> tops = {circle(0.25),           box(0.8, 0.4),     hexagon(0.35),      roundedBox(0.6, 0.2, 0.05),
                                     capsule(0.8, 0.15),     compound(1.0, 0.3)};
    const std::vector<Piece> bottoms = {box(1.6, 0.4), hexagon(0.6), roundedBox(1.4, 0.2, 0.06), capsule(1.4, 0.2),
                                        compound(1.6, 0.3)};
    const std::vector<Support> supports = {
        {"plane", kFloor, 0.0},
        {"chain", "{\"name\": \"ground\", \"static\": true, \"position\": " + point(0, 0) +
                      ", \"chain\": {\"points\": [" + point(3, 0) + ", " + point(1, 0) + ", " + point(-0.5, 0) + ", " +
                      point(-3, 0) + "]}}",
         0.0},
        {"static box", "{\"name\": \"ground\", \"static\": true, \"position\": " + point(0, -0.25) +
                           ", \"box\": {\"width\": 6, \"height\": 0.5}}",
         0.0},
        {"static rounded box", "{\"name\": \"ground\", \"static\": true, \"position\": " + point(0, -0.3) + ", " +
                                   roundedBox(6.0, 0.4, 0.1).json + "}",
         0.0},
    };
    const std::vector<std::string> worlds = {"\"gravity\": {\"x\": 0, \"y\": -9.81}",
                                             "\"gravity\": {\"x\": 0, \"y\": -9.81}, \"substeps\": 4"};
    double worstHeight = 0.0, worstDrift = 0.0, worstTurn = 0.0;
    int cases = 0;
    for (const std::string& world : worlds) {
        for (const Piece& top : tops) {
            // On a static support.
            for (const Support& s : supports) {
                const double y = s.top + top.down;
                const Outcome o = settle(s.json + ", {\"name\": \"top\", \"mass\": 2, \"position\": " +
                                             point(0, y + 0.001) + ", " + top.json + "}",
                                         world, y);
                const std::string what = top.label + " on a " + s.label + " (" + world + ")";
                EXPECT_LT(o.heightError, 9.81 / (o.omega * o.omega) + 2e-4) << what;
                EXPECT_LT(o.drift, 1e-3) << what;
                EXPECT_LT(o.turn, 1e-3) << what;
                worstHeight = std::max(worstHeight, o.heightError);
                worstDrift = std::max(worstDrift, o.drift);
                worstTurn = std::max(worstTurn, o.turn);
                ++cases;
            }
            // On a dynamic body that rests on the floor.
            for (const Piece& bottom : bottoms) {
                if (!bottom.flatTop) continue;
                for (const double ratio : {0.2, 5.0}) {
                    const double yBottom = bottom.down, yTop = bottom.down + bottom.up + top.down;
                    const Outcome o =
                        settle(kFloor + ", {\"name\": \"bottom\", \"mass\": 1, \"position\": " +
                                   point(0, yBottom + 0.001) + ", " + bottom.json +
                                   "}, {\"name\": \"top\", \"mass\": " + exactNumber(ratio) + ", \"position\": " +
                                   point(0, yTop + 0.002) + ", " + top.json + "}",
                               world, yTop, yBottom);
                    const std::string what = top.label + " on a " + bottom.label + ", mass ratio " + exactNumber(ratio) +
                                             " (" + world + ")";
                    EXPECT_LT(o.heightError, 2.0 * (1.0 + ratio) * 9.81 / (o.omega * o.omega) + 2e-4) << what;
                    // Two sharp hexagons at one substep, the top five times
                    // the bottom: 1.2 mm and 1.04e-3 rad (measured).
                    EXPECT_LT(o.drift, 1.5e-3) << what;
                    EXPECT_LT(o.turn, 1.5e-3) << what;
                    worstHeight = std::max(worstHeight, o.heightError);
                    worstDrift = std::max(worstDrift, o.drift);
                    worstTurn = std::max(worstTurn, o.turn);
                    ++cases;
                }
            }
        }
    }
    std::printf("%d cases: worst height error %.3g m, drift %.3g m, turn %.3g rad\n", cases, worstHeight, worstDrift,
                worstTurn);
}
