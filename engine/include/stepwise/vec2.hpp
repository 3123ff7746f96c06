#pragma once
/// \file vec2.hpp
/// 2D vector and colour value types shared by the whole engine.
/// Units are those of the quantity stored (metres, m/s, newtons...).

#include <cmath>

namespace stepwise {

/// A 2D vector of doubles. Plain aggregate so arrays of it are contiguous
/// pairs of doubles (the integrators rely on this layout).
struct Vec2 {
    double x = 0.0;
    double y = 0.0;

    constexpr Vec2& operator+=(Vec2 o) { x += o.x; y += o.y; return *this; }
    constexpr Vec2& operator-=(Vec2 o) { x -= o.x; y -= o.y; return *this; }
    constexpr Vec2& operator*=(double s) { x *= s; y *= s; return *this; }
    friend constexpr Vec2 operator+(Vec2 a, Vec2 b) { return {a.x + b.x, a.y + b.y}; }
    friend constexpr Vec2 operator-(Vec2 a, Vec2 b) { return {a.x - b.x, a.y - b.y}; }
    friend constexpr Vec2 operator-(Vec2 a) { return {-a.x, -a.y}; }
    friend constexpr Vec2 operator*(double s, Vec2 a) { return {s * a.x, s * a.y}; }
    friend constexpr Vec2 operator*(Vec2 a, double s) { return {s * a.x, s * a.y}; }
    friend constexpr Vec2 operator/(Vec2 a, double s) { return {a.x / s, a.y / s}; }
    friend constexpr bool operator==(Vec2 a, Vec2 b) = default;
};

constexpr double dot(Vec2 a, Vec2 b) { return a.x * b.x + a.y * b.y; }
/// z-component of the 3D cross product (a.x, a.y, 0) x (b.x, b.y, 0).
constexpr double cross(Vec2 a, Vec2 b) { return a.x * b.y - a.y * b.x; }
constexpr double lengthSquared(Vec2 a) { return dot(a, a); }
inline double length(Vec2 a) { return std::sqrt(dot(a, a)); }
inline bool isFinite(Vec2 a) { return std::isfinite(a.x) && std::isfinite(a.y); }

/// Linear RGB colour, each channel in 0..1. Serialised as {"x","y","z"}
/// to match the course notes' level files.
struct Rgb {
    double r = 0.8;
    double g = 0.8;
    double b = 0.8;
    friend constexpr bool operator==(Rgb, Rgb) = default;
};

} // namespace stepwise
