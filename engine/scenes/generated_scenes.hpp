#pragma once
// Scenes built in code and shared by the benchmarks, the tests and the
// editor. Every pile of circles in a box is one CircleGrid; the callers keep
// their own parameters (and so the exact bytes their measured figures and
// test bounds were taken with: tests/test_scenes.cpp checks them by hash).

#include "stepwise/scene.hpp"

#include <optional>
#include <string>
#include <vector>

namespace stepwise::scenes {

/// How the circles of a grid are offset sideways, so a pile does not stand
/// in perfect columns. Each is deterministic in the circle's index (no
/// std::random: its distributions are not specified bit for bit across
/// library versions), each gives a value in [-1, 1] scaled by the grid's
/// jitterAmplitude. Three sequences because three scenes were measured with
/// three; merging them would change those scenes.
enum class Jitter {
    None,
    Hash,   ///< Knuth's multiplicative hash of the index (hashJitter)
    Lcg,    ///< the index-th draw of a linear congruential generator seeded with 7
    Mod11,  ///< (7919 i mod 11 - 5) / 5: eleven levels
};

/// Knuth's multiplicative hash of i mapped to [-1, 1): cheap, deterministic.
double hashJitter(int i);

enum class CircleColours {
    None,      ///< no Color component
    Palette,   ///< a pastel palette of six cycling with the index
    Gradient,  ///< red grows along a row, blue falls every row and repeats every 20 rows
};

/// `count` circles of one radius in rows of `columns`, filled from the
/// bottom left, row by row. Circle i sits at column c = i mod columns and row
/// r = i / columns, centred at
///   x = first.x + pitch.x c + jitter + centring,   y = first.y + pitch.y r
/// (summed in that order: the order fixes the last bits).
struct CircleGrid {
    int count = 0;
    int columns = 1;
    Vec2 first{};                   ///< m: centre of circle 0 before jitter and centring
    Vec2 pitch{0.5, 0.5};           ///< m: centre to centre along a row (x) and between rows (y)
    double centring = 0.0;          ///< m added to x last (a grid whose `first` is its left edge: pitch.x / 2)
    double radius = 0.25;           ///< m
    Jitter jitter = Jitter::None;
    double jitterAmplitude = 0.0;   ///< m: the largest sideways offset
    /// 1/s. Given: every circle gets a Velocity of (this x its offset, 0),
    /// so a jittered pile also starts with some sideways motion; 0 gives
    /// every circle a zero velocity.
    std::optional<double> velocityPerJitter;
    std::optional<double> mass;      ///< kg; given: every circle gets a Mass
    std::optional<double> friction;  ///< given: every circle gets a Friction
    std::string namePrefix;          ///< non-empty: circle i is named prefix + i
    CircleColours colours = CircleColours::None;
};

/// Appends the grid's circles to `scene`, in index order.
void addCircleGrid(Scene& scene, const CircleGrid& grid);

/// A static box (Position, Static, Box) centred at `centre`, `width` x
/// `height` m, with nothing else.
Entity addStaticBox(Scene& scene, Vec2 centre, double width, double height);

/// A hinge joint from `a` to `b` (null: the world) at anchors `localA` and
/// `localB` in their frames, reference angle 0, as a new entity.
Entity addHinge(Registry& registry, Entity a, Entity b, Vec2 localA, Vec2 localB);

// ---- the collision benchmark's scenes (also levels/pile, pyramid, rain) ----

/// 2,000 circles (radius 0.25 m) in a grid, falling into a 30 m wide box.
Scene circlesInBox(int count = 2000);
/// A pyramid of unit boxes, `rows` at the base, on a static ground box.
Scene boxPyramid(int rows = 20);
/// 1,000 circles raining from a tall sparse column into a container.
Scene circleRain(int count = 1000);

struct NamedScene {
    std::string name;   ///< file stem and report row
    Scene scene;
    double seconds;     ///< simulated time the benchmark runs
};
/// pile, pile300, pyramid and rain, with the simulated time the benchmark runs each.
std::vector<NamedScene> benchmarkScenes();

// ---- the tests' scenes -------------------------------------------------------

/// 30 rows of 10 circles (radius 0.25 m, 1 kg, friction 0.6, unnamed) in a
/// 5.2 m wide box of static boxes, at 60 Hz with the substeps left to the
/// engine: a pile deep enough that 1 substep visibly sinks
/// (tests/test_collision_hard.cpp, docs/collisions.md).
Scene tallPile();

} // namespace stepwise::scenes
