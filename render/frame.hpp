#pragma once
/// \file frame.hpp
/// buildDrawData() turns a FrameInput (view/frame_input.hpp: scene, world,
/// overlays, camera, selection, trails) into batches of instances (plain
/// data, no GL), which the Renderer submits with one draw call per batch.
/// Keeping the CPU half apart makes it testable without a context and lets
/// the benchmark time the two halves separately.

#include "frame_input.hpp"

#include <cstdint>
#include <array>
#include <string>
#include <vector>

namespace stepwise::render {

/// Instance batches, each drawn with one call. Floats, pixel coordinates
/// with the origin at the bottom-left (GL's convention), y up.
/// Image: a layer of pixels drawn on the CPU (DrawData::images), for marks
/// so many and so small that llvmpipe would shade far more pixels drawing
/// them one quad at a time than the layer has.
enum class BatchKind : std::uint8_t { Plane, Disc, Box, Segment, Arrow, Solid, Image };

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

/// Marks drawn on the CPU in one colour: per pixel, the alpha to draw the
/// colour with, rows bottom-up (GL's order), placed by an Image batch's
/// record {x0, y0, x1, y1, index}.
/// One byte a pixel instead of RGBA: a quarter of the memory to fill and
/// upload, and llvmpipe samples a one-channel texture faster.
struct PixelLayer {
    int width = 0;
    int height = 0;
    float colour[3] = {0.0f, 0.0f, 0.0f};  ///< RGB, 0..1
    /// Per pixel, the alpha to draw `colour` with (0..255): the marks'
    /// coverage times their alpha, composited "over" one another.
    std::vector<std::uint8_t> coverage;
};

struct DrawData {
    int width = 0;
    int height = 0;
    double gridSpacing = 0.0;     ///< metres between minor grid lines (majors every 5)
    std::vector<Batch> batches;   ///< in drawing order
    std::vector<PixelLayer> images;  ///< what Image batches draw
    ArrowScales scales;           ///< the references used (auto ones resolved)
    std::vector<std::string> notes;  ///< e.g. "force-field: no World (scene has shapes)"
    /// The legend's arrow overlays in full words, e.g. "applied force = 20 N"
    /// (the drawn legend may name one shorter: "net force" for "net force (m dv/dt)").
    std::vector<std::string> legend;
    /// The legend's panel, pixels (x, y, width, height; y up from the
    /// bottom); all zero when there is none.
    std::array<double, 4> legendBox{};
    /// Pixels of the legend's panel over moving bodies (their boxes).
    double legendCoversPx = 0.0;
    /// The scale bar's panel, bottom left (x, y, width, height; y up); all
    /// zero without the HUD. A legend that would meet it goes above it.
    std::array<double, 4> scaleBarBox{};
    std::size_t instanceCount() const;
};

/// Floats per instance of each kind.
std::size_t floatsPerInstance(BatchKind kind);

/// How buildDrawData may draw; the defaults are what every caller wants.
struct BuildOptions {
    /// Crowded AABB outlines as one layer of pixels drawn on the CPU (see
    /// BatchKind::Image); false: one quad per box always (to compare the two).
    bool pixelLayers = true;
};

/// Builds the frame's geometry. Deterministic: same input, same floats.
DrawData buildDrawData(const FrameInput& input, int widthPx, int heightPx, const BuildOptions& options = {});

/// The arrow references buildDrawData would choose for this input (for
/// freezing them across a frame sequence).
ArrowScales resolveScales(const FrameInput& input);

} // namespace stepwise::render
