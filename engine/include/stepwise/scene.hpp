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
    /// Each step is `substeps` steps of dt/substeps. 0: not given (a file
    /// without the key); World::build then chooses from the scene
    /// (chooseSubsteps in world.hpp), and a save writes no key.
    int substeps = 0;
    double time = 0.0;                       ///< simulated seconds so far
    /// Contact solver velocity iterations (addition). 0: not given; World::build
    /// uses 8, or its own choice when substeps is not given either.
    int solverIterations = 0;
    /// m/s: impacts slower than this do not bounce. Absent: derived from
    /// gravity and the substep (derivedRestitutionThreshold in world.hpp).
    std::optional<double> restitutionThreshold;

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
