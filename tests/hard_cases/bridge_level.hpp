#pragma once
// The hard cases' bridge: twelve 2 kg planks (1 m x 0.2 m) hinged end to
// end between two static piers (2 x 4 m) over a floor, with a crate to
// drop on it and boxes to stack on the crate.

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

namespace stepwise::test {

struct BridgeLevel {
    double halfSpan = 6.0;      ///< m from the middle to each pier's pin (6: the planks' length)
    bool laidStraight = false;  ///< planks laid from x = -6 to 6; else in a V that meets the pins
    double crateMass = 0.0;     ///< kg of a 1.2 m crate dropped from 2.6 m above the pins; 0: none
    int boxes = 0;              ///< 0.8 m boxes of half the crate's mass stacked above it
    int substeps = 0;           ///< 0: not given
    bool gravity = false;       ///< gravity -10 m/s^2 given; else the default
};

inline std::string bridgeJson(const BridgeLevel& b) {
    const auto num = [](double v) {
        std::ostringstream s;
        s.precision(17);
        s << v;
        return s.str();
    };
    std::ostringstream s;
    s << "{";
    if (b.gravity || b.substeps > 0) {
        s << R"("world": {)";
        if (b.gravity) s << R"("gravity": {"x": 0, "y": -10})" << (b.substeps > 0 ? ", " : "");
        if (b.substeps > 0) s << R"("substeps": )" << b.substeps;
        s << "}, ";
    }
    s << R"("entities": [
        {"name": "ground", "position": {"x": 0, "y": -4.5}, "static": true, "box": {"width": 40, "height": 1}},
        {"name": "left pier", "position": {"x": )" << num(-b.halfSpan - 1.0) << R"(, "y": -2}, "static": true, "box": {"width": 2, "height": 4}},
        {"name": "right pier", "position": {"x": )" << num(b.halfSpan + 1.0) << R"(, "y": -2}, "static": true, "box": {"width": 2, "height": 4}})";
    if (b.crateMass > 0.0)
        s << R"(, {"name": "crate", "position": {"x": 0.5, "y": 2.5}, "mass": )" << num(b.crateMass)
          << R"(, "box": {"width": 1.2, "height": 1.2}, "friction": 0.6})";
    for (int i = 0; i < b.boxes; ++i)
        s << R"(, {"name": "box )" << i << R"(", "position": {"x": 0.5, "y": )" << num(3.8 + 0.9 * i)
          << R"(}, "mass": )" << num(0.5 * b.crateMass) << R"(, "box": {"width": 0.8, "height": 0.8}, "friction": 0.6})";
    // Each half of the V is 6 m long; the pins are halfSpan from the middle.
    const double slope = b.laidStraight ? 0.0 : std::acos(std::min(1.0, b.halfSpan / 6.0));
    double x = b.laidStraight ? -6.0 : -b.halfSpan, y = -0.1;
    for (int i = 0; i < 12; ++i) {
        const double angle = i < 6 ? -slope : slope;
        const double cx = x + 0.5 * std::cos(angle), cy = y + 0.5 * std::sin(angle);
        s << R"(, {"name": "plank )" << i << R"(", "position": {"x": )" << num(cx) << R"(, "y": )" << num(cy)
          << R"(}, "angle": )" << num(angle) << R"(, "mass": 2, "box": {"width": 1, "height": 0.2}, "friction": 0.6})";
        x += std::cos(angle);
        y += std::sin(angle);
    }
    const auto pin = [&](int i, const std::string& a, const std::string& p, double ax, double px, double py) {
        s << R"(, {"name": "pin )" << i << R"(", "joint": {"type": "hinge", "a": ")" << a << R"(", "b": ")" << p
          << R"(", "local_a": {"x": )" << num(ax) << R"(, "y": 0}, "local_b": {"x": )" << num(px) << R"(, "y": )"
          << num(py) << "}}}";
    };
    pin(0, "plank 0", "left pier", -0.5, 1.0, 1.9);
    for (int i = 1; i < 12; ++i) pin(i, "plank " + std::to_string(i), "plank " + std::to_string(i - 1), -0.5, 0.5, 0.0);
    pin(12, "plank 11", "right pier", 0.5, -1.0, 1.9);
    s << "]}";
    return s.str();
}

} // namespace stepwise::test
