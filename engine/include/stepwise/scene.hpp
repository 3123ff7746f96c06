#pragma once
/// \file scene.hpp
/// A level in memory: world settings, an optional camera and the entities.
/// This is the editing representation; the simulation compiles it into
/// packed arrays (world.hpp) and writes results back.

#include "stepwise/registry.hpp"
#include "stepwise/vec2.hpp"

#include <optional>
#include <string>

namespace stepwise {

/// The `world` object of a level file. Defaults are the contract's
/// (shared/SCENE_FORMAT.md).
struct WorldSettings {
    Vec2 gravity{0.0, -9.81};                ///< m/s^2, applied to every dynamic body
    double G = 1.0;                          ///< gravitational constant for attractors, N*m^2/kg^2
    std::string integrator = "semi_implicit_euler";
    double dt = 1.0 / 60.0;                  ///< seconds per step
    int substeps = 1;                        ///< each step is `substeps` steps of dt/substeps
    double time = 0.0;                       ///< simulated seconds so far
    int solverIterations = 8;                ///< contact solver velocity iterations (addition)
    /// Local error per internal step for the error-controlled integrator
    /// (dopri5): each component's error is held to tolerance * (1 + |value|).
    double tolerance = 1e-6;
    /// Barnes–Hut opening angle for attractors, 0..1: a cell of side s is
    /// taken as one mass beyond s/theta (+ its centre-of-mass offset); 0 sums
    /// every pair exactly. 0.5 keeps the force error near 1e-3 (bench
    /// accuracy, Barnes–Hut panel).
    double theta = 0.5;
    /// dopri5's proposed next internal step, s (addition): part of the
    /// state, so that a saved and reloaded run continues bit for bit. 0: none
    /// yet (the first step tries the whole frame).
    double adaptiveStep = 0.0;

    friend bool operator==(const WorldSettings&, const WorldSettings&) = default;
};

/// The `view` object (an addition to the format): the camera a level opens
/// with. `zoom` is pixels per metre in an image 720 pixels tall; other image
/// heights scale it so the same region of the world is shown.
struct View {
    Vec2 center{0.0, 0.0};  ///< metres
    double zoom = 40.0;     ///< pixels per metre at 720 px image height

    friend bool operator==(const View&, const View&) = default;
};

struct Scene {
    int version = 1;
    WorldSettings world;
    std::optional<View> view;
    Registry registry;
};

} // namespace stepwise
