#pragma once
/// \file frame.hpp
/// What a frame shows: scene, optional world (for forces and contacts),
/// overlay choices, camera, selection and trails. buildDrawData() turns it
/// into batches of instances (plain data, no GL), which the Renderer submits
/// with one draw call per batch. Keeping the CPU half apart makes it testable
/// without a context and lets the benchmark time the two halves separately.

#include "stepwise/entity.hpp"
#include "stepwise/result.hpp"
#include "stepwise/scene.hpp"
#include "stepwise/vec2.hpp"

#include <cstdint>
#include <deque>
#include <string>
#include <string_view>
#include <vector>

namespace stepwise {
class World;
}

namespace stepwise::render {

/// Debug views, each switched separately.
enum class Overlay : std::uint32_t {
    Velocity = 1u << 0,       ///< an arrow per body
    VelocityField = 1u << 1,  ///< kernel-weighted velocity of nearby bodies on a grid
    ForceField = 1u << 2,     ///< World::probeForce on a grid (needs a World)
    Force = 1u << 3,          ///< applied force per body (gravity, springs, ...), World::bodyForces (needs a World)
    Contacts = 1u << 4,       ///< World::contacts(): points, normals, impulses
    Aabb = 1u << 5,           ///< bounding boxes and the occupied cells of a uniform grid
    Trails = 1u << 6,         ///< positions over the last N recorded steps
    Joints = 1u << 7,         ///< World::joints(): reaction force at each joint's anchor
    NetForce = 1u << 8,       ///< net force per body over the last step, contacts included, World::netForces
};

struct OverlaySet {
    std::uint32_t bits = 0;
    bool has(Overlay o) const { return (bits & std::uint32_t(o)) != 0; }
    void add(Overlay o) { bits |= std::uint32_t(o); }
    bool needsWorld() const {
        return has(Overlay::ForceField) || has(Overlay::Force) || has(Overlay::NetForce) || has(Overlay::Contacts) ||
               has(Overlay::Joints);
    }
};

/// Command-line names, in drawing-legend order: "velocity", "velocity-field",
/// "force-field", "force" (applied), "net-force", "contacts", "aabb",
/// "trails", "joints".
const std::vector<std::pair<std::string_view, Overlay>>& overlayNames();

/// Parses "velocity,force-field" (or "all", or "" for none). The error names
/// the unknown entry and lists the known ones.
Result<OverlaySet> parseOverlayList(std::string_view list);

/// World-space camera. `zoom` is pixels per metre in a 720-pixel-tall image
/// (the level file's `view.zoom`); other heights scale it so the same region
/// is shown whatever the resolution.
struct Camera {
    Vec2 center;        ///< metres, shown at the middle of the image
    double zoom = 40.0; ///< pixels per metre at 720 px image height
    double pixelsPerMetre(int heightPx) const { return zoom * double(heightPx) / 720.0; }
};

/// Fits the scene's bounds (shapes, points, spring anchors, the nearest part
/// of each plane) with a margin.
Camera fitCamera(const Scene& scene, int widthPx, int heightPx);
/// The level's `view` when it has one, else fitCamera().
Camera sceneCamera(const Scene& scene, int widthPx, int heightPx);

/// Positions of each dynamic body over the last `capacity` recorded steps.
class TrailRecorder {
public:
    explicit TrailRecorder(std::size_t capacity = 48) : capacity_(capacity) {}
    /// Appends every dynamic body's current position (World::bodyPosition).
    void record(const World& world);
    /// Appends every positioned, non-static entity's position from the scene
    /// (used when no World could be built).
    void record(const Scene& scene);
    struct Trail {
        Entity entity;
        std::deque<Vec2> points;  ///< oldest first, metres
    };
    const std::vector<Trail>& trails() const { return trails_; }
    std::size_t capacity() const { return capacity_; }

private:
    Trail& trailFor(Entity e);
    std::size_t capacity_;
    std::vector<Trail> trails_;
    std::vector<std::uint32_t> slotOfIndex_;  // entity index -> trails_ slot + 1 (0: none)
};

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
    OverlaySet overlays;
    Camera camera;
    std::vector<Entity> selection;         ///< drawn with a highlight ring
    const TrailRecorder* trails = nullptr; ///< optional; the trails overlay needs it
    ArrowScales scales;                    ///< 0 entries are chosen per frame
    std::string caption;                   ///< top-left text ("" for none)
    bool hud = true;                       ///< scale bar, legend, caption
    /// The editor's polygon tool: the outline it would make (world metres,
    /// counter-clockwise) and the vertices clicked so far. Empty: none.
    std::vector<Vec2> polygonPreview, polygonClicks;
};

/// Instance batches, each drawn with one call. Floats, pixel coordinates
/// with the origin at the bottom-left (GL's convention), y up.
enum class BatchKind : std::uint8_t { Plane, Disc, Box, Segment, Arrow, Solid };

struct Batch {
    BatchKind kind;
    /// Discs and boxes: no instance uses the rarely drawn features
    /// (selection ring, static hatching, attractor glow; for boxes, the
    /// shading of a body), so the renderer may use a program compiled
    /// without them. llvmpipe runs every branch of a shader for every pixel,
    /// so code an instance does not use still costs.
    bool plain = false;
    std::vector<float> data;  ///< instance (or vertex, for Solid) records, packed
    std::size_t count() const;
};

struct DrawData {
    int width = 0;
    int height = 0;
    double gridSpacing = 0.0;     ///< metres between minor grid lines (majors every 5)
    std::vector<Batch> batches;   ///< in drawing order
    ArrowScales scales;           ///< the references used (auto ones resolved)
    std::vector<std::string> notes;  ///< e.g. "force-field: no World (scene has shapes)"
    std::vector<std::string> legend; ///< the legend's arrow rows, e.g. "applied force = 20 N"
    std::size_t instanceCount() const;
};

/// Floats per instance of each kind.
std::size_t floatsPerInstance(BatchKind kind);

/// Builds the frame's geometry. Deterministic: same input, same floats.
DrawData buildDrawData(const FrameInput& input, int widthPx, int heightPx);

/// The arrow references buildDrawData would choose for this input (for
/// freezing them across a frame sequence).
ArrowScales resolveScales(const FrameInput& input);

} // namespace stepwise::render
