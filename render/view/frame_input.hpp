#pragma once
/// \file frame_input.hpp
/// What a frame shows: scene, optional world (for forces and contacts),
/// overlay choices, camera, selection and trails. Plain data, no GL: the
/// editor model fills it, the renderer (frame.hpp) turns it into batches.

#include "camera.hpp"
#include "overlay_set.hpp"
#include "trail_recorder.hpp"

#include "stepwise/entity.hpp"
#include "stepwise/scene.hpp"
#include "stepwise/vec2.hpp"

#include <optional>
#include <span>
#include <string>
#include <vector>

namespace stepwise {
class World;
struct ContactRecord;
}

namespace stepwise::render {

/// Reference magnitudes for arrows: an arrow of magnitude `ref` is drawn
/// `referencePixels` long; lengths grow as log2(1 + m/ref) so a field
/// spanning orders of magnitude stays legible (3*ref is twice as long,
/// 7*ref three times). 0 means "choose from the data": a 1-2-5 number near
/// the median magnitude, except for forces (see `force`). Fix them for a
/// frame sequence so arrows compare.
struct ArrowScales {
    double velocity = 0.0;       ///< m/s
    double velocityField = 0.0;  ///< m/s
    /// N, applied and net force alike (so their arrows compare). Chosen
    /// from the applied forces' low end (10th percentile), so the weakest
    /// force that acts, gravity next to a strong attractor, draws at about
    /// the reference length and stronger ones grow logarithmically.
    double force = 0.0;
    double forceField = 0.0;     ///< N per kg (= m/s^2); chosen like `force`
    double impulse = 0.0;        ///< N*s
    double jointForce = 0.0;     ///< N (joints overlay)
};

struct FrameInput {
    const Scene* scene = nullptr;          ///< required
    const World* world = nullptr;          ///< optional; force, force-field, contacts need it
    /// The contacts overlay's records instead of `world`'s: the editor keeps
    /// the last step's across an edit that leaves them as they were (the
    /// World recompiled by the edit has none until its next step).
    std::optional<std::span<const ContactRecord>> contacts;
    OverlaySet overlays;
    Camera camera;
    std::vector<Entity> selection;         ///< drawn with a highlight ring
    const TrailRecorder* trails = nullptr; ///< optional; the trails overlay needs it
    ArrowScales scales;                    ///< 0 entries are chosen per frame
    std::string caption;                   ///< top-left text ("" for none)
    bool hud = true;                       ///< scale bar, legend, caption
    /// Pixels at the top of the image that the caller draws over (the
    /// editor's line about edits while running): the legend keeps below.
    double reservedTopPx = 0.0;
    /// The editor's polygon tool: the outline it would make (world metres,
    /// counter-clockwise) and the vertices clicked so far. Empty: none.
    std::vector<Vec2> polygonPreview, polygonClicks;
};

} // namespace stepwise::render
