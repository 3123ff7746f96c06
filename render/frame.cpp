// Frame building: scene + overlays + camera -> instance batches (no GL).
//
// Coordinates: every instance is emitted in pixels (origin bottom-left, y
// up). The world -> pixel transform is done here in double precision, so a
// level far from the origin draws as crisply as one near it (float world
// coordinates in the shaders would lose sub-pixel precision past ~1e4 m).

#include "frame.hpp"
#include "scene_bounds.hpp"

#include "stepwise/components.hpp"
#include "stepwise/world.hpp"

#define STB_EASY_FONT_IMPLEMENTATION
#include <stb/stb_easy_font.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <unordered_map>
#include <unordered_set>

namespace stepwise::render {

namespace {

// ---- Palette (dark theme; linear 0..1 RGB, alpha last) ---------------------
struct Rgba {
    float r, g, b, a;
};
constexpr Rgba rgb(int hex, float a = 1.0f) {
    return {float((hex >> 16) & 255) / 255.0f, float((hex >> 8) & 255) / 255.0f, float(hex & 255) / 255.0f, a};
}
constexpr Rgba kGridMinor = rgb(0x171c25);
constexpr Rgba kGridMajor = rgb(0x212835);
constexpr Rgba kGridAxis = rgb(0x2f3a4c);
constexpr Rgba kDefaultBody = rgb(0x9fb3c8);
constexpr Rgba kSpringColor = rgb(0xcbd5e0);
constexpr Rgba kAnchorColor = rgb(0x718096);
constexpr Rgba kVelocity = rgb(0x4fd1c5);
// Its own hue, apart from the bodies' velocity (teal) it averages: with both
// overlays on, a sample arrow and a body's arrow must not be confused.
constexpr Rgba kVelocityField = rgb(0x5a7dff, 0.85f);
constexpr Rgba kForce = rgb(0xf6ad55);
constexpr Rgba kNetForce = rgb(0xf687b3);
constexpr Rgba kForceField = rgb(0xa78bfa, 0.5f);
constexpr Rgba kContactPoint = rgb(0xff6b6b);
constexpr Rgba kContactNormal = rgb(0xffa8a8);
constexpr Rgba kJointColor = rgb(0x90cdf4);
constexpr Rgba kJointCentre = rgb(0x2d3748);
constexpr Rgba kJointTick = rgb(0xfbd38d);
constexpr Rgba kJointForce = rgb(0x9ae6b4);
constexpr double kPiD = 3.14159265358979323846;
constexpr Rgba kAabb = rgb(0x68d391, 0.75f);
constexpr Rgba kSelectionRing = rgb(0xffd166);  // the shaders' uHighlight (renderer.cpp)
constexpr Rgba kKinematicMark = rgb(0x8be9fd);  // a kinematic body's diamond and motion marks
constexpr Rgba kEmitterMark = rgb(0xffb86c);    // an emitter's ring, direction and spread
constexpr Rgba kAabbCell = rgb(0x68d391, 0.06f);
// The overlay's layer (Builder::boundingBoxes) is one colour with alpha per pixel.
static_assert(kAabbCell.r == kAabb.r && kAabbCell.g == kAabb.g && kAabbCell.b == kAabb.b);
constexpr Rgba kText = rgb(0xd5dde8);
constexpr Rgba kTextDim = rgb(0x8190a5);
constexpr Rgba kPanel = rgb(0x0a0d12, 0.82f);
constexpr Rgba kPanelBorder = rgb(0x2d3748);

// Instance flags shared with disc.frag / box.frag.
constexpr float kSelected = 1, kStatic = 2, kTick = 4, kGlow = 8, kFlat = 16;
constexpr float kOutline = 4;  // box.frag

Rgba colourOf(const Scene& scene, Entity e, Rgba fallback) {
    if (const Color* c = scene.registry.tryGet<Color>(e))
        return {float(c->value.r), float(c->value.g), float(c->value.b), 1.0f};
    return fallback;
}

Rgba withAlpha(Rgba c, float a) { return {c.r, c.g, c.b, a}; }

/// Smallest 1-2-5 x 10^k number >= x (x > 0).
double niceCeil(double x) {
    const double decade = std::pow(10.0, std::floor(std::log10(x)));
    for (double m : {1.0, 2.0, 5.0, 10.0})
        if (m * decade >= x * (1.0 - 1e-12)) return m * decade;
    return 10.0 * decade;
}

/// Largest 1-2-5 x 10^k number <= x (x > 0).
double niceFloor(double x) {
    const double decade = std::pow(10.0, std::floor(std::log10(x)));
    for (double m : {5.0, 2.0, 1.0})
        if (m * decade <= x * (1.0 + 1e-12)) return m * decade;
    return decade;
}

/// Reference magnitude for a set of arrows: the median magnitude rounded up
/// to a 1-2-5 number, so a typical arrow is about the reference length and
/// the legend reads as a round number. Magnitudes under 1% of the largest
/// are left out: bodies at rest (a settled pile, a standing pyramid) carry
/// 1e-7 m/s of solver noise, and counting them would set the reference there
/// and clamp every moving body's arrow.
double autoReference(std::vector<double> magnitudes) {
    std::erase_if(magnitudes, [](double m) { return !(m > 0.0) || !std::isfinite(m); });
    if (magnitudes.empty()) return 1.0;
    const double largest = *std::max_element(magnitudes.begin(), magnitudes.end());
    std::erase_if(magnitudes, [&](double m) { return m < 0.01 * largest; });
    auto mid = magnitudes.begin() + std::ptrdiff_t(magnitudes.size() / 2);
    std::nth_element(magnitudes.begin(), mid, magnitudes.end());
    return niceCeil(*mid);
}

/// Reference magnitude for forces: the 10th percentile of the non-zero
/// magnitudes, rounded up to a 1-2-5 number. Forces in one view span orders
/// of magnitude (gravity beside an attractor's pull). Taken from the low end,
/// the weakest force that acts draws at about the reference length and the
/// strong ones are compressed by the logarithmic length; a median reference
/// shrank gravity to dots next to an attractor.
double lowReference(std::vector<double> magnitudes) {
    std::erase_if(magnitudes, [](double m) { return !(m > 0.0) || !std::isfinite(m); });
    if (magnitudes.empty()) return 1.0;
    const double largest = *std::max_element(magnitudes.begin(), magnitudes.end());
    // Rounding-level values (a field cancelling at a point) say nothing.
    std::erase_if(magnitudes, [&](double m) { return m < 1e-9 * largest; });
    auto low = magnitudes.begin() + std::ptrdiff_t(magnitudes.size() / 10);
    std::nth_element(magnitudes.begin(), low, magnitudes.end());
    return niceCeil(*low);
}

std::string formatNumber(double v) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%g", v);
    return buffer;
}

std::string formatLength(double metres) {
    if (metres < 0.01) return formatNumber(metres * 1000.0) + " mm";
    if (metres < 1.0) return formatNumber(metres * 100.0) + " cm";
    if (metres >= 1000.0) return formatNumber(metres / 1000.0) + " km";
    return formatNumber(metres) + " m";
}

/// A set of entity handles as a table by index (0: absent, else the
/// handle's generation + 1), so a lookup is one load and filling it
/// allocates once. An unordered_set allocates and frees a node per entity:
/// for a settled pile's 2,000 sleeping bodies, 2,000 mallocs and frees a
/// frame, more of the editor's frame than any overlay's drawing.
class EntityTable {
public:
    void insert(Entity e) {
        if (e.isNull()) return;
        if (e.index >= slots_.size()) slots_.resize(std::size_t(e.index) + 1, 0);
        slots_[e.index] = std::uint64_t(e.generation) + 1;
        any_ = true;
    }
    bool count(Entity e) const { return !e.isNull() && e.index < slots_.size() && slots_[e.index] == std::uint64_t(e.generation) + 1; }
    bool empty() const { return !any_; }

private:
    std::vector<std::uint64_t> slots_;
    bool any_ = false;
};

class Builder {
public:
    Builder(DrawData& out, const FrameInput& input, int w, int h, const BuildOptions& options)
        : out_(out), in_(input), options_(options), scene_(*input.scene), w_(w), h_(h),
          ppm_(input.camera.pixelsPerMetre(h)),
          // 1.5 pixels per font unit from a 360 px image up to 700 (capitals
          // about 10 px tall, like the editor's 13 px UI font; one unit would
          // print 7 px in the editor's viewport and the 960x540 renders).
          // From 700 px, whole units (2 at 720 and 1080).
          textScale_(h < 360 ? 1.0 : h < 700 ? 1.5 : double(h / 700 + 1)),
          arrowRef_(0.06 * h) {
        for (Entity e : input.selection) selected_.insert(e);
        if (input.world)
            for (Entity e : input.world->sleepingBodies()) sleeping_.insert(e);
        // Level of detail: with thousands of bodies, per-body lines get
        // thinner and trails coarser. Legibility is unchanged (the arrows
        // would overlap anyway) and llvmpipe shades a third of the pixels.
        dense_ = scene_.registry.count<Position>() > 2000;
    }

    void build();

private:
    // ---- coordinates ---------------------------------------------------
    Vec2 toPx(Vec2 p) const {
        return {(p.x - in_.camera.center.x) * ppm_ + 0.5 * w_, (p.y - in_.camera.center.y) * ppm_ + 0.5 * h_};
    }
    Vec2 toWorld(Vec2 px) const {
        return {(px.x - 0.5 * w_) / ppm_ + in_.camera.center.x, (px.y - 0.5 * h_) / ppm_ + in_.camera.center.y};
    }
    /// True when a circle of radius r (pixels) around p touches the image.
    bool visible(Vec2 p, double r) const {
        return p.x + r >= 0 && p.y + r >= 0 && p.x - r <= w_ && p.y - r <= h_;
    }
    bool segmentVisible(Vec2 a, Vec2 b, double pad) const {
        return std::max(a.x, b.x) + pad >= 0 && std::max(a.y, b.y) + pad >= 0 && std::min(a.x, b.x) - pad <= w_ &&
               std::min(a.y, b.y) - pad <= h_;
    }

    // ---- batches -------------------------------------------------------
    // Each stage of build() is a layer: what it draws goes to one pending
    // batch per kind, in the order the kinds first appear, and endLayer()
    // appends them to the output. Layers keep their order (grid under
    // planes under bodies under overlays); inside a layer, kinds are drawn
    // one after another. A stage that alternates kinds per item (a contact
    // is an arrow and a dot, an anchored spring a pin and segments) would
    // otherwise start a new batch, one draw call, per item: 2,000 contacts
    // would make 4,000 draw calls, 13 ms a frame on llvmpipe.
    std::vector<float>& batch(BatchKind kind, bool plain = false) {
        for (Batch& b : layer_)
            if (b.kind == kind && b.plain == plain) return b.data;
        layer_.push_back({kind, plain, {}});
        return layer_.back().data;
    }
    void endLayer() {
        for (Batch& b : layer_) {
            if (b.data.empty()) continue;
            if (!out_.batches.empty() && out_.batches.back().kind == b.kind && out_.batches.back().plain == b.plain) {
                std::vector<float>& d = out_.batches.back().data;
                d.insert(d.end(), b.data.begin(), b.data.end());
            } else {
                out_.batches.push_back(std::move(b));
            }
        }
        layer_.clear();
    }
    static void push(std::vector<float>& d, std::initializer_list<double> values) {
        for (double v : values) d.push_back(float(v));
    }
    void disc(Vec2 c, double r, double angle, Rgba col, float flags) {
        if (!visible(c, r + 8)) return;
        const bool plain = (int(flags) & int(kSelected + kStatic + kGlow)) == 0;
        push(batch(BatchKind::Disc, plain), {c.x, c.y, r, angle, col.r, col.g, col.b, col.a, flags});
    }
    void box(Vec2 c, Vec2 half, double angle, Rgba col, float flags, double rounding = 0.0) {
        if (!visible(c, std::hypot(half.x, half.y) + 8)) return;
        const bool plain = (int(flags) & int(kSelected + kStatic)) == 0 && (int(flags) & int(kFlat + kOutline)) != 0;
        push(batch(BatchKind::Box, plain), {c.x, c.y, half.x, half.y, angle, col.r, col.g, col.b, col.a, flags, rounding});
    }
    /// A polygon body: the fill as a triangle fan, shaded like box.frag
    /// shades boxes (a light from the upper left, darker when static), with
    /// a lighter rim, and the selection ring 3.5 px outside the outline.
    void polygon(const Polygon& poly, Vec2 position, double angle, Rgba col, bool selected, bool isStatic) {
        const double c = std::cos(angle), s = std::sin(angle);
        std::vector<Vec2> px;
        Bounds box;
        for (const Vec2 v : poly.vertices) {
            px.push_back(toPx(position + Vec2{c * v.x - s * v.y, s * v.x + c * v.y}));
            box.add(px.back());
        }
        if (!segmentVisible(box.lo, box.hi, 8)) return;
        Vec2 centre;
        for (const Vec2 q : px) centre += q;
        centre = centre / double(px.size());
        const double shade = isStatic ? 0.72 : 0.9;  // static bodies darker (boxes hatch them)
        const Rgba fill{float(col.r * shade), float(col.g * shade), float(col.b * shade), col.a};
        auto& tri = batch(BatchKind::Solid);
        for (std::size_t i = 0; i < px.size(); ++i) {
            const Vec2 q0 = px[i], q1 = px[(i + 1) % px.size()];
            // Each fan triangle's colour leans with its edge's facing, so
            // the body reads as a solid lit from the upper left.
            const Vec2 mid = 0.5 * (q0 + q1) - centre;
            const double len = std::max(length(mid), 1e-9);
            const double lit = 1.0 + 0.08 * dot(mid / len, Vec2{-0.45, 0.6});
            const Rgba f{float(fill.r * lit), float(fill.g * lit), float(fill.b * lit), fill.a};
            for (const Vec2 q : {centre, q0, q1}) push(tri, {q.x, q.y, f.r, f.g, f.b, f.a});
        }
        const Rgba rim{float(col.r + (1.0 - col.r) * 0.4), float(col.g + (1.0 - col.g) * 0.4),
                       float(col.b + (1.0 - col.b) * 0.4), col.a};
        for (std::size_t i = 0; i < px.size(); ++i) segment(px[i], px[(i + 1) % px.size()], 1.6, rim);
        if (selected) {
            // The ring: each edge pushed out 3.5 px along its normal, the
            // corners joined by their own short segments.
            for (std::size_t i = 0; i < px.size(); ++i) {
                const Vec2 q0 = px[i], q1 = px[(i + 1) % px.size()], edge = q1 - q0;
                const double len = length(edge);
                if (!(len > 0.0)) continue;
                const Vec2 out = Vec2{edge.y, -edge.x} / len * 3.5;
                segment(q0 + out, q1 + out, 2.0, kSelectionRing);
                const Vec2 q2 = px[(i + 2) % px.size()], next = q2 - q1;
                const double nextLen = length(next);
                if (nextLen > 0.0) segment(q1 + out, q1 + Vec2{next.y, -next.x} / nextLen * 3.5, 2.0, kSelectionRing);
            }
        }
    }
    void segment(Vec2 a, Vec2 b, double width, Rgba col) {
        if (!segmentVisible(a, b, width + 2)) return;
        push(batch(BatchKind::Segment), {a.x, a.y, b.x, b.y, width, col.r, col.g, col.b, col.a});
    }
    void arrow(Vec2 a, Vec2 b, double width, Rgba col) {
        if (!segmentVisible(a, b, 12)) return;
        push(batch(BatchKind::Arrow), {a.x, a.y, b.x, b.y, width, col.r, col.g, col.b, col.a});
    }
    void rect(double x0, double y0, double x1, double y1, Rgba col) {
        auto& d = batch(BatchKind::Solid);
        const double v[6][2] = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y0}, {x1, y1}, {x0, y1}};
        for (const auto& p : v) push(d, {p[0], p[1], col.r, col.g, col.b, col.a});
    }
    /// Text with its top-left corner at pixel (x, yTop); y measured up from
    /// the bottom like everything else. Returns the width in pixels.
    double text(double x, double yTop, const std::string& s, Rgba col);
    double textWidth(const std::string& s) const {
        std::string copy = s;
        return double(stb_easy_font_width(copy.data())) * textScale_;
    }
    double textHeight() const { return 7.0 * textScale_; }

    /// Arrow length in pixels for magnitude m against reference `ref` drawn
    /// `refPx` long: log2(1 + m/ref) keeps both tiny and huge values visible.
    static double arrowLength(double m, double ref, double refPx, double maxPx) {
        return std::min(refPx * std::log2(1.0 + m / ref), maxPx);
    }

    // ---- layers --------------------------------------------------------
    void grid();
    void planes();
    void attractorGlows();
    void fields();
    void trails();
    void springs();
    void bodies();
    void kinematicMarks();
    void emitterMarks();
    void joints();
    void jointForces();
    void polygonPreview();
    /// The aabb overlay: occupied grid cells, then each box's outline.
    void boundingBoxes();
    /// The occupied cells of the grid the overlay pictures, as whole-pixel
    /// rectangles {x0, y0, x1, y1} (the cell 1 px in from each side), from
    /// every shape's bounding box (metres).
    std::vector<std::array<double, 4>> occupiedCells(const std::vector<ShapeBox>& boxes) const;
    void bodyArrows();
    void contacts();
    void hud();
    /// Pixels of the rectangle (x, y, w, h; y up) that moving bodies cover.
    double coveredBodyArea(double x, double y, double w, double h) const;

    DrawData& out_;
    const FrameInput& in_;
    BuildOptions options_;
    const Scene& scene_;
    int w_, h_;
    double ppm_;        ///< pixels per metre at this image height
    double textScale_;  ///< pixels per unit of the bitmap font (its strokes are one unit)
    double arrowRef_;   ///< pixels drawn for a reference-magnitude arrow

    /// Level of detail for per-body and per-contact marks (arrows, trails,
    /// contact markers). Up to kThinAbove marks on screen, every one is
    /// drawn. Past that, at most one mark starts in each square cell of
    /// thinCellPx() pixels, the first in scene order, so the choice is
    /// deterministic and stays put while bodies stay in their cells. Marks of
    /// selected bodies are always drawn (see keep()).
    ///
    /// Why: a 2,000-body pile puts a body every 13 px, and arrows about
    /// arrowRef_ (48 px at 800 px) long on each overlap into a solid mat
    /// that hides the bodies and says nothing. Half an arrow per cell shows
    /// the flow; zooming in shows every body's arrow again. It is also what
    /// keeps llvmpipe at 60 fps: its cost is per primitive at this size.
    static constexpr std::size_t kThinAbove = 300;
    double thinCellPx() const { return std::max(24.0, 0.5 * arrowRef_); }
    class CellThinner {
    public:
        /// `originsPx`: where each candidate mark starts, pixels.
        CellThinner(const Builder& b, const std::vector<Vec2>& originsPx)
            : cell_(b.thinCellPx()), cols_(int(b.w_ / cell_) + 1), rows_(int(b.h_ / cell_) + 1) {
            const auto onScreen = std::count_if(originsPx.begin(), originsPx.end(),
                                                [&](Vec2 p) { return b.visible(p, 0.0); });
            active_ = std::size_t(onScreen) > kThinAbove;
            if (active_) used_.assign(std::size_t(cols_) * std::size_t(rows_), false);
        }
        bool active() const { return active_; }
        /// True when a mark starting at p should be drawn (the first in its
        /// cell when thinning). Off-screen marks are left to the drawing
        /// calls' own culling.
        bool take(Vec2 p) {
            if (!active_) return true;
            const int cx = int(std::floor(p.x / cell_)), cy = int(std::floor(p.y / cell_));
            if (cx < 0 || cy < 0 || cx >= cols_ || cy >= rows_) return false;
            const std::size_t k = std::size_t(cy) * std::size_t(cols_) + std::size_t(cx);
            if (used_[k]) return false;
            used_[k] = true;
            return true;
        }
        /// take(), except that a selected entity's mark is always drawn.
        bool keep(Vec2 p, bool selected) { return selected || take(p); }

    private:
        double cell_;
        int cols_, rows_;
        bool active_ = false;
        std::vector<bool> used_;
    };
    std::vector<Batch> layer_;  ///< the current stage's batches, one per kind (see batch())
    bool dense_ = false;        ///< thousands of bodies: thinner per-body lines
    EntityTable selected_;
    EntityTable sleeping_;  ///< bodies of sleeping islands: drawn dimmed
    /// A body's fill: its colour, dimmed to 55% (towards black, so it stays
    /// its hue on the dark background) while its island sleeps.
    Rgba bodyColour(Entity e) const {
        Rgba c = colourOf(scene_, e, kDefaultBody);
        // A sensor is a zone, not a solid: see-through, so what is inside shows.
        if (const Sensor* sensor = scene_.registry.tryGet<Sensor>(e); sensor && sensor->value) c.a *= 0.35f;
        // A template is a prefab its emitter copies, not a body: faded.
        if (scene_.registry.has<Template>(e)) c.a *= 0.3f;
        if (sleeping_.empty() || !sleeping_.count(e)) return c;
        return {0.55f * c.r, 0.55f * c.g, 0.55f * c.b, c.a};
    }
    struct LegendRow {
        std::string label;  ///< in full words (DrawData::legend)
        Rgba colour;
        double reference;  ///< magnitude drawn arrowRef_ long
        std::string unit;
        std::string shortLabel = {};  ///< what the drawn legend says, when shorter than `label`
    };
    std::vector<LegendRow> legend_;
};

double Builder::text(double x, double yTop, const std::string& s, Rgba col) {
    std::string copy = s;
    // stb_easy_font: 4 vertices (x, y, z, rgba8) = 16 bytes per quad, ~270
    // bytes per character worst case.
    std::vector<char> buffer(copy.size() * 300 + 64);
    unsigned char c8[4] = {255, 255, 255, 255};
    const int quads = stb_easy_font_print(0.0f, 0.0f, copy.data(), c8, buffer.data(), int(buffer.size()));
    auto& d = batch(BatchKind::Solid);
    const double s8 = textScale_;
    for (int q = 0; q < quads; ++q) {
        const float* v = reinterpret_cast<const float*>(buffer.data() + q * 64);
        // Vertices 0 and 2 are opposite corners (x, y, z at +0, +1, +2; stride 4 floats).
        double x0 = x + v[0] * s8, x1 = x + v[8] * s8;
        double y0 = yTop - v[1] * s8, y1 = yTop - v[9] * s8;
        if (s8 != std::floor(s8)) {
            // A fractional scale: whole-pixel edges, so every stroke is
            // solid (1 or 2 px) rather than a blend of two half-lit rows.
            x0 = std::round(x0), x1 = std::round(x1), y0 = std::round(y0), y1 = std::round(y1);
        }
        const double p[6][2] = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y0}, {x1, y1}, {x0, y1}};
        for (const auto& pt : p) push(d, {pt[0], pt[1], col.r, col.g, col.b, col.a});
    }
    return double(stb_easy_font_width(copy.data())) * s8;
}

void Builder::build() {
    // Back to front, one layer per stage (see batch()).
    const auto layer = [this](auto stage) {
        (this->*stage)();
        endLayer();
    };
    layer(&Builder::grid);
    layer(&Builder::planes);
    layer(&Builder::attractorGlows);
    layer(&Builder::fields);
    if (in_.overlays.has(Overlay::Trails)) layer(&Builder::trails);
    layer(&Builder::springs);
    layer(&Builder::bodies);
    layer(&Builder::joints);
    if (in_.overlays.has(Overlay::Joints)) layer(&Builder::jointForces);
    if (!in_.polygonPreview.empty() || !in_.polygonClicks.empty()) layer(&Builder::polygonPreview);
    if (in_.overlays.has(Overlay::Aabb)) layer(&Builder::boundingBoxes);
    layer(&Builder::bodyArrows);
    if (in_.overlays.has(Overlay::Contacts)) layer(&Builder::contacts);
    if (in_.hud) layer(&Builder::hud);
}

void Builder::grid() {
    // Minor lines every 1-2-5 metres, at least 24 px apart; majors every 5
    // minor; the world axes brighter. Each line is one pixel wide and
    // pixel-aligned (two Solid triangles), so it is crisp and costs llvmpipe
    // almost nothing compared with a full-screen shader.
    const double minorM = niceCeil(24.0 / ppm_);
    out_.gridSpacing = minorM;
    const Vec2 lo = toWorld({0, 0}), hi = toWorld({double(w_), double(h_)});
    auto lines = [&](double from, double to, bool vertical) {
        const long long k0 = (long long)std::ceil(from / minorM), k1 = (long long)std::floor(to / minorM);
        if (k1 - k0 > 2000) return;  // never at >= 24 px spacing; guards absurd cameras
        for (long long k = k0; k <= k1; ++k) {
            const Rgba c = k == 0 ? kGridAxis : (k % 5 == 0 ? kGridMajor : kGridMinor);
            const Vec2 p = toPx(vertical ? Vec2{double(k) * minorM, 0.0} : Vec2{0.0, double(k) * minorM});
            const double x = std::floor(vertical ? p.x : p.y);
            if (vertical) rect(x, 0, x + 1, h_, c);
            else rect(0, x, w_, x + 1, c);
        }
    };
    lines(lo.x, hi.x, true);
    lines(lo.y, hi.y, false);
}

void Builder::planes() {
    scene_.registry.each<Plane>([&](Entity e, const Plane& p) {
        // Surface point on the plane, then its pixel-space offset; the
        // normal is unchanged by a uniform scale and translation.
        const Vec2 px = toPx(p.normal * p.offset);
        const double offset = dot(p.normal, px) ;
        const Rgba c = colourOf(scene_, e, rgb(0x8a9bb0));
        // Bounding box of the solid side (dot(n, p) <= offset + 2 px for
        // the edge line) clipped to the image: clip the image rectangle by
        // the half-plane (Sutherland-Hodgman, one edge) and take its box.
        const Vec2 corners[4] = {{0, 0}, {double(w_), 0}, {double(w_), double(h_)}, {0, double(h_)}};
        const double limit = offset + 2.0;
        Bounds box;
        for (int k = 0; k < 4; ++k) {
            const Vec2 a = corners[k], b = corners[(k + 1) % 4];
            const double da = dot(p.normal, a) - limit, db = dot(p.normal, b) - limit;
            if (da <= 0) box.add(a);
            if ((da < 0) != (db < 0)) box.add(a + (b - a) * (da / (da - db)));
        }
        if (box.empty()) return;
        push(batch(BatchKind::Plane), {p.normal.x, p.normal.y, offset, c.r, c.g, c.b, c.a,
                                       selected_.count(e) ? kSelected : 0.0f, box.lo.x, box.lo.y, box.hi.x, box.hi.y});
    });
}

std::vector<std::array<double, 4>> Builder::occupiedCells(const std::vector<ShapeBox>& boxes) const {
    // The broad phase's uniform grid as the renderer pictures it: cells of
    // the 1-2-5 size just above twice the median shape extent, shaded where
    // a bounding box overlaps them. The engine's broad phase does not expose
    // its cells (and below 512 shapes it sweeps and prunes instead of using
    // a grid), so this is the renderer's own picture of bounding-box density.
    std::vector<double> extents;
    extents.reserve(boxes.size());
    for (const auto& [c, half] : boxes) extents.push_back(2.0 * std::max(half.x, half.y));
    std::vector<std::array<double, 4>> rects;
    if (boxes.empty()) return rects;
    const double cell = niceCeil(2.0 * autoReference(extents));
    // The occupied cells, each once, in (x, y) order. Only cells on screen
    // are drawn, so they are marked in a bitmap over the image's cells
    // (a few thousand) instead of listing every box's cells and sorting.
    const Vec2 viewLo = toWorld({0, 0}), viewHi = toWorld({double(w_), double(h_)});
    const long long vx0 = (long long)std::floor(viewLo.x / cell), vx1 = (long long)std::floor(viewHi.x / cell);
    const long long vy0 = (long long)std::floor(viewLo.y / cell), vy1 = (long long)std::floor(viewHi.y / cell);
    const long long nx = vx1 - vx0 + 1, ny = vy1 - vy0 + 1;
    // A cell is drawn 1 px in from each side: under 3 px there is nothing
    // left to draw (and the bitmap stays at most ~w*h/9 entries).
    if (cell * ppm_ < 3.0 || nx <= 0 || ny <= 0) return rects;
    std::vector<std::uint8_t> occupied(std::size_t(nx * ny), 0);
    for (const auto& [c, half] : boxes) {
        const long long x0 = (long long)std::floor((c.x - half.x) / cell), x1 = (long long)std::floor((c.x + half.x) / cell);
        const long long y0 = (long long)std::floor((c.y - half.y) / cell), y1 = (long long)std::floor((c.y + half.y) / cell);
        if ((x1 - x0 + 1) * (y1 - y0 + 1) > 64) continue;  // huge shape: its box says enough
        for (long long x = std::max(x0, vx0); x <= std::min(x1, vx1); ++x)
            for (long long y = std::max(y0, vy0); y <= std::min(y1, vy1); ++y) occupied[std::size_t((x - vx0) * ny + (y - vy0))] = 1;
    }
    for (std::size_t k = 0; k < occupied.size(); ++k) {
        if (!occupied[k]) continue;
        const long long x = vx0 + (long long)k / ny, y = vy0 + (long long)k % ny;
        // Whole-pixel edges, 1 px in from the cell's (a 2 px gap between neighbours).
        const Vec2 lo = toPx({double(x) * cell, double(y) * cell}), hi = toPx({double(x + 1) * cell, double(y + 1) * cell});
        if (!segmentVisible(lo, hi, 0.0)) continue;
        rects.push_back({std::round(lo.x) + 1.0, std::round(lo.y) + 1.0, std::round(hi.x) - 1.0, std::round(hi.y) - 1.0});
    }
    return rects;
}

void Builder::attractorGlows() {
    const double g = length(scene_.world.gravity);
    scene_.registry.each<Attractor, Position>([&](Entity e, const Attractor&, const Position& p) {
        const Mass* m = scene_.registry.tryGet<Mass>(e);
        const double mass = m ? m->value : 1.0;
        const Radius* r = scene_.registry.tryGet<Radius>(e);
        const double bodyPx = (r ? r->value : 0.15) * ppm_;
        // Ring radius: where the attractor's pull G*m/r^2 equals gravity's,
        // the edge of its sphere of dominance. With no gravity: 4 radii.
        double ringM = g > 0.0 ? std::sqrt(scene_.world.G * mass / g) : 4.0 * (r ? r->value : 0.5);
        const double ringPx = std::clamp(ringM * ppm_, bodyPx * 2.0 + 10.0, 0.6 * h_);
        const double glowPx = std::max(3.0 * bodyPx, 18.0);
        const Vec2 c = toPx(p.value);
        const Rgba col = colourOf(scene_, e, rgb(0xf6e05e));
        disc(c, glowPx, 0.0, col, kGlow);
        // Dashed ring as 48 short chords: a full-size quad shaded per pixel
        // would cost llvmpipe tens of milliseconds for a large ring.
        if (!visible(c, ringPx + 4)) return;
        const int dashes = 48;
        for (int k = 0; k < dashes; ++k) {
            const double a0 = 2.0 * std::numbers::pi * k / dashes;
            const double a1 = a0 + std::numbers::pi / dashes;
            segment(c + Vec2{std::cos(a0), std::sin(a0)} * ringPx, c + Vec2{std::cos(a1), std::sin(a1)} * ringPx, 1.2,
                    withAlpha(col, 0.45f));
        }
    });
}

void Builder::fields() {
    const bool vField = in_.overlays.has(Overlay::VelocityField);
    const bool fField = in_.overlays.has(Overlay::ForceField);
    if (!vField && !fField) return;
    // Samples sit at the centres of a world-aligned grid about 1/20 of the
    // image height apart, so panning does not make the field shimmer.
    const double spacingPx = std::max(24.0, std::round(h_ / 20.0));
    const double s = spacingPx / ppm_;  // metres
    const Vec2 lo = toWorld({0, 0}), hi = toWorld({double(w_), double(h_)});
    const long long i0 = (long long)std::floor(lo.x / s), i1 = (long long)std::floor(hi.x / s);
    const long long j0 = (long long)std::floor(lo.y / s), j1 = (long long)std::floor(hi.y / s);
    std::vector<Vec2> points;
    for (long long j = j0; j <= j1; ++j)
        for (long long i = i0; i <= i1; ++i) points.push_back({(double(i) + 0.5) * s, (double(j) + 0.5) * s});
    const double maxPx = 0.95 * spacingPx, refPx = 0.42 * spacingPx;

    if (fField) {
        if (!in_.world) {
            out_.notes.push_back("force-field: needs a World (not built)");
        } else {
            std::vector<Vec2> forces;
            std::vector<double> mags;
            forces.reserve(points.size());
            for (Vec2 p : points) {
                forces.push_back(in_.world->probeForce(p));
                mags.push_back(length(forces.back()));
            }
            const double ref = in_.scales.forceField > 0 ? in_.scales.forceField : lowReference(mags);
            out_.scales.forceField = ref;
            for (std::size_t k = 0; k < points.size(); ++k) {
                const double m = mags[k];
                if (!(m > 0.0) || !std::isfinite(m)) continue;
                const double len = arrowLength(m, ref, refPx, maxPx);
                const Vec2 dir = forces[k] / m, c = toPx(points[k]);
                arrow(c - dir * (0.5 * len), c + dir * (0.5 * len), 1.3, kForceField);
            }
            legend_.push_back({"force field", kForceField, ref, "N/kg"});
        }
    }
    if (vField) {
        // Gaussian kernel of width h = grid spacing, cut at 2h. Each body
        // adds itself to the samples within two cells of its own: the
        // kernel is separable, exp(-(dx^2 + dy^2)/2) = exp(-dx^2/2)
        // exp(-dy^2/2), so a body costs 10 exponentials, not one per sample
        // it reaches (up to 25). Sums run in scene order (deterministic).
        const long long ni = i1 - i0 + 1;
        std::vector<Vec2> sums(points.size());
        std::vector<double> weights(points.size(), 0.0);
        scene_.registry.each<Position, Velocity>([&](Entity e, const Position& p, const Velocity& v) {
            if (isStatic(scene_, e)) return;
            const double fx = p.value.x / s, fy = p.value.y / s;  // in grid cells
            const long long cx = (long long)std::floor(fx), cy = (long long)std::floor(fy);
            if (cx < i0 - 2 || cx > i1 + 2 || cy < j0 - 2 || cy > j1 + 2) return;
            double dx2[5], dy2[5], ex[5], ey[5];  // squared offsets to the samples at cells c-2..c+2, and exp(-d^2/2)
            for (int d = 0; d < 5; ++d) {
                const double dx = fx - (double(cx + d - 2) + 0.5), dy = fy - (double(cy + d - 2) + 0.5);
                dx2[d] = dx * dx, dy2[d] = dy * dy;
                ex[d] = std::exp(-0.5 * dx2[d]), ey[d] = std::exp(-0.5 * dy2[d]);
            }
            for (int dj = 0; dj < 5; ++dj) {
                const long long j = cy + dj - 2;
                if (j < j0 || j > j1) continue;
                for (int di = 0; di < 5; ++di) {
                    const long long i = cx + di - 2;
                    if (i < i0 || i > i1 || dx2[di] + dy2[dj] > 4.0) continue;
                    const std::size_t k = std::size_t((j - j0) * ni + (i - i0));
                    const double w = ex[di] * ey[dj];
                    sums[k] += w * v.value;
                    weights[k] += w;
                }
            }
        });
        std::vector<std::pair<Vec2, double>> fieldValues;  // mean velocity, confidence
        std::vector<double> mags;
        for (std::size_t k = 0; k < points.size(); ++k) {
            const Vec2 sum = sums[k];
            const double wsum = weights[k];
            if (wsum < 0.02) {
                fieldValues.push_back({{}, 0.0});
                continue;
            }
            const Vec2 v = sum / wsum;
            fieldValues.push_back({v, std::min(1.0, wsum / 0.6)});
            mags.push_back(length(v));
        }
        const double ref = in_.scales.velocityField > 0 ? in_.scales.velocityField : autoReference(mags);
        out_.scales.velocityField = ref;
        for (std::size_t k = 0; k < points.size(); ++k) {
            const auto& [v, confidence] = fieldValues[k];
            const double m = length(v);
            if (confidence <= 0.0 || !(m > 0.0) || !std::isfinite(m)) continue;
            const double len = arrowLength(m, ref, refPx, maxPx);
            const Vec2 dir = v / m, c = toPx(points[k]);
            arrow(c - dir * (0.5 * len), c + dir * (0.5 * len), 1.3,
                  withAlpha(kVelocityField, float(0.25 + 0.6 * confidence)));
        }
        legend_.push_back({"velocity field", kVelocityField, ref, "m/s"});
    }
}

void Builder::trails() {
    if (!in_.trails) {
        out_.notes.push_back("trails: nothing recorded (use --steps)");
        return;
    }
    std::vector<Vec2> heads;
    for (const TrailRecorder::Trail& t : in_.trails->trails())
        if (t.points.size() >= 2) heads.push_back(toPx(t.points.back()));
    CellThinner thin(*this, heads);
    // Crowded: thinner trails in longer segments (8 px instead of 3 px).
    const bool coarse = dense_ || thin.active();
    for (const TrailRecorder::Trail& t : in_.trails->trails()) {
        if (t.points.size() < 2 || !scene_.registry.alive(t.entity)) continue;
        if (!thin.keep(toPx(t.points.back()), selected_.count(t.entity) != 0)) continue;
        if (t.isPoint()) continue;  // every segment would be empty (a settled pile: all of them)
        const Rgba c = colourOf(scene_, t.entity, kDefaultBody);
        const std::size_t n = t.points.size();
        auto it = t.points.begin();  // a deque: iterators, not an index (a division each)
        Vec2 prev = toPx(*it);
        for (std::size_t k = 1; k < n; ++k) {
            const Vec2 cur = toPx(*++it);
            // Merge steps into segments at least 3 px long (8 px when
            // coarse; the newest one excepted): a 10,000-body scene draws
            // ~8 segments per trail instead of 47, and the curve looks the same.
            if (lengthSquared(cur - prev) < (coarse ? 64.0 : 9.0) && k + 1 < n) continue;
            // Older segments fade out: alpha rises linearly to 0.7 at the body.
            const float a = float(0.7 * double(k) / double(n - 1));
            if (lengthSquared(cur - prev) > 0.01) segment(prev, cur, coarse ? 1.0 : 1.6, withAlpha(c, a));
            prev = cur;
        }
    }
}

void Builder::springs() {
    scene_.registry.each<Spring>([&](Entity e, const Spring& sp) {
        if (scene_.registry.has<Template>(sp.a)) return;  // a template's spring: not drawn, as its joints
        auto endOf = [&](Entity end) -> std::optional<Vec2> {
            const Position* p = scene_.registry.tryGet<Position>(end);
            return p ? std::optional<Vec2>(p->value) : std::nullopt;
        };
        std::optional<Vec2> a = endOf(sp.a);
        std::optional<Vec2> b = sp.b.isNull() ? sp.anchor : endOf(sp.b);
        if (!a || !b) return;
        const Vec2 pa = toPx(*a), pb = toPx(*b);
        const bool sel = selected_.count(e) != 0;
        const Rgba c = sel ? rgb(0xffd166) : colourOf(scene_, e, kSpringColor);
        const double width = sel ? 2.2 : 1.5;
        if (sp.b.isNull()) {
            // Anchor: a small hatched pin.
            disc(pb, 4.5, 0.0, kAnchorColor, kStatic);
        }
        const Vec2 d = pb - pa;
        const double len = length(d);
        if (len < 6.0) {
            segment(pa, pb, width, c);
            return;
        }
        // Zigzag: straight leads at each end, then 12 half-coils of a
        // fixed pixel amplitude, so compression shows as tighter coils.
        const Vec2 axis = d / len, side{-axis.y, axis.x};
        const double lead = std::min(0.18 * len, 14.0);
        const int kinks = 12;
        const double amplitude = std::clamp(0.09 * len, 3.0, 6.0);
        Vec2 prev = pa;
        Vec2 start = pa + axis * lead;
        segment(prev, start, width, c);
        prev = start;
        const double body = len - 2.0 * lead;
        for (int k = 0; k < kinks; ++k) {
            const double t = (double(k) + 0.5) / kinks;
            const Vec2 p = pa + axis * (lead + t * body) + side * (k % 2 == 0 ? amplitude : -amplitude);
            segment(prev, p, width, c);
            prev = p;
        }
        const Vec2 end = pb - axis * lead;
        segment(prev, end, width, c);
        segment(end, pb, width, c);
    });
}

void Builder::bodies() {
    // Chains first (lines under everything that rests on them), polygons
    // (filled triangles, then their outlines), then boxes and capsules, then
    // discs: each kind is one batch.
    for (Entity e : scene_.registry.entities()) {
        const Chain* chain = scene_.registry.tryGet<Chain>(e);
        const Position* p = scene_.registry.tryGet<Position>(e);
        if (!chain || !p || chain->points.size() < 2) continue;
        const Angle* a = scene_.registry.tryGet<Angle>(e);
        const double angle = a ? a->value : 0.0, c = std::cos(angle), s = std::sin(angle);
        const auto world = [&](Vec2 v) { return p->value + Vec2{c * v.x - s * v.y, s * v.x + c * v.y}; };
        const bool sel = selected_.count(e) != 0;
        const Rgba colour = sel ? rgb(0xffd166) : bodyColour(e);
        const double width = sel ? 3.5 : 2.5;
        const std::size_t n = chain->points.size(), segments = chain->loop ? n : n - 1;
        // Ticks on the solid side (the right of each segment's direction;
        // pixels keep the world's handedness), at a segment's middle once
        // 24 px of line have passed since the last, so short segments share
        // them and the spacing stays even at any zoom.
        double sinceTick = 24.0;
        for (std::size_t k = 0; k < segments; ++k) {
            const Vec2 a0 = toPx(world(chain->points[k])), a1 = toPx(world(chain->points[(k + 1) % n]));
            segment(a0, a1, width, colour);
            const Vec2 d = a1 - a0;
            const double len = length(d);
            sinceTick += 0.5 * len;
            if (len > 0.0 && sinceTick >= 24.0) {
                const Vec2 mid = 0.5 * (a0 + a1);
                segment(mid, mid + (6.0 / len) * Vec2{d.y, -d.x}, 1.5, colour);
                sinceTick = 0.0;
            }
            sinceTick += 0.5 * len;
        }
    }
    for (Entity e : scene_.registry.entities()) {
        const Polygon* poly = scene_.registry.tryGet<Polygon>(e);
        const Position* p = scene_.registry.tryGet<Position>(e);
        if (!poly || !p || poly->vertices.size() < 3) continue;
        const Angle* a = scene_.registry.tryGet<Angle>(e);
        // A rounded polygon is drawn as its outline: each corner an arc of
        // the rounding radius between its two edges' normals.
        Polygon rounded;
        if (const double r = poly->radius.value_or(0.0); r > 0.0) {
            rounded.vertices.clear();
            const std::size_t n = poly->vertices.size();
            for (std::size_t i = 0; i < n; ++i) {
                const Vec2 v = poly->vertices[i], before = v - poly->vertices[(i + n - 1) % n],
                           after = poly->vertices[(i + 1) % n] - v;
                const double a0 = std::atan2(-before.x, before.y), turn = std::atan2(cross(before, after), dot(before, after));
                const int pieces = std::max(2, int(std::ceil(turn / 0.2)));
                for (int k = 0; k <= pieces; ++k) {
                    const double th = a0 + turn * k / pieces;
                    rounded.vertices.push_back(v + r * Vec2{std::cos(th), std::sin(th)});
                }
            }
        }
        polygon(rounded.vertices.size() > poly->vertices.size() ? rounded : *poly, p->value, a ? a->value : 0.0,
                bodyColour(e), selected_.count(e) != 0,
                isStatic(scene_, e));
    }
    for (Entity e : scene_.registry.entities()) {
        const Box* b = scene_.registry.tryGet<Box>(e);
        const Position* p = scene_.registry.tryGet<Position>(e);
        if (!b || !p) continue;
        const Angle* a = scene_.registry.tryGet<Angle>(e);
        float flags = 0;
        if (selected_.count(e)) flags += kSelected;
        if (isStatic(scene_, e)) flags += kStatic;
        // Corner rounding of half a pixel's worth keeps rotated corners clean.
        box(toPx(p->value), {0.5 * b->width * ppm_, 0.5 * b->height * ppm_}, a ? a->value : 0.0,
            bodyColour(e), flags, 1.0);
    }
    // Compound bodies: each shape as the single shape of its kind would be
    // drawn, placed in the body frame, in the same batches.
    for (Entity e : scene_.registry.entities()) {
        const Shapes* shapes = scene_.registry.tryGet<Shapes>(e);
        const Position* p = scene_.registry.tryGet<Position>(e);
        if (!shapes || !p) continue;
        const Angle* a = scene_.registry.tryGet<Angle>(e);
        const double angle = a ? a->value : 0.0, c = std::cos(angle), s = std::sin(angle);
        const auto place = [&](Vec2 v) { return p->value + Vec2{c * v.x - s * v.y, s * v.x + c * v.y}; };
        float flags = 0;
        if (selected_.count(e)) flags += kSelected;
        if (isStatic(scene_, e)) flags += kStatic;
        const Rgba colour = bodyColour(e);
        for (const CompoundShape& shape : shapes->items) {
            switch (shape.kind) {
            case CompoundShape::Kind::Polygon:
                if (shape.vertices.size() >= 3)
                    polygon(Polygon{shape.vertices, shape.cornerRadius}, p->value, angle, colour, selected_.count(e) != 0,
                            isStatic(scene_, e));
                break;
            case CompoundShape::Kind::Box:
                box(toPx(place(shape.center)), {0.5 * shape.width * ppm_, 0.5 * shape.height * ppm_},
                    angle + shape.angle, colour, flags, 1.0);
                break;
            case CompoundShape::Kind::Capsule: {
                const Vec2 axis = shape.b - shape.a;
                const double r = shape.radius * ppm_;
                box(toPx(place(0.5 * (shape.a + shape.b))), {0.5 * length(axis) * ppm_ + r, r},
                    angle + std::atan2(axis.y, axis.x), colour, flags, r);
                break;
            }
            case CompoundShape::Kind::Circle:
                disc(toPx(place(shape.center)), shape.radius * ppm_, angle, colour, flags + kTick);
                break;
            }
        }
    }
    // Capsules in the box batch: a box as long as the capsule and as high
    // as its diameter, rounded by its radius, is exactly the capsule (the
    // same shading, rim and selection ring as boxes).
    for (Entity e : scene_.registry.entities()) {
        const Capsule* cap = scene_.registry.tryGet<Capsule>(e);
        const Position* p = scene_.registry.tryGet<Position>(e);
        if (!cap || !p) continue;
        const Angle* a = scene_.registry.tryGet<Angle>(e);
        const double angle = a ? a->value : 0.0, c = std::cos(angle), s = std::sin(angle);
        const Vec2 mid = 0.5 * (cap->a + cap->b), axis = cap->b - cap->a;
        const Vec2 centre = p->value + Vec2{c * mid.x - s * mid.y, s * mid.x + c * mid.y};
        float flags = 0;
        if (selected_.count(e)) flags += kSelected;
        if (isStatic(scene_, e)) flags += kStatic;
        const double r = cap->radius * ppm_;
        box(toPx(centre), {0.5 * length(axis) * ppm_ + r, r}, angle + std::atan2(axis.y, axis.x), bodyColour(e), flags, r);
    }
    for (Entity e : scene_.registry.entities()) {
        const Position* p = scene_.registry.tryGet<Position>(e);
        if (!p || scene_.registry.has<Box>(e) || scene_.registry.has<Polygon>(e) || scene_.registry.has<Capsule>(e) ||
            scene_.registry.has<Shapes>(e) || scene_.registry.has<Chain>(e) || scene_.registry.has<Spring>(e))
            continue;
        const Radius* r = scene_.registry.tryGet<Radius>(e);
        const Angle* a = scene_.registry.tryGet<Angle>(e);
        float flags = 0;
        if (selected_.count(e)) flags += kSelected;
        if (isStatic(scene_, e)) flags += kStatic;
        const Rgba c = bodyColour(e);
        if (r) {
            disc(toPx(p->value), r->value * ppm_, a ? a->value : 0.0, c, flags + kTick);
        } else {
            // A point mass: a fixed-size dot, larger for an attractor.
            const double dot = scene_.registry.has<Attractor>(e) ? 6.0 : 4.0;
            disc(toPx(p->value), dot, 0.0, c, flags);
        }
    }
    kinematicMarks();
    emitterMarks();
}

void Builder::kinematicMarks() {
    // A kinematic body looks like any other by its colour; a diamond at its
    // centre says it is kinematic, a fixed-length arrow which way it moves,
    // and an arc with an arrow head which way it turns (marks, not
    // measures: the velocity overlay gives the size).
    for (Entity e : scene_.registry.entities()) {
        const Kinematic* k = scene_.registry.tryGet<Kinematic>(e);
        const Position* p = scene_.registry.tryGet<Position>(e);
        if (!k || !k->value || !p) continue;
        const Vec2 c = toPx(p->value);
        constexpr double d = 6.0;
        const Vec2 corner[4] = {c + Vec2{d, 0}, c + Vec2{0, d}, c + Vec2{-d, 0}, c + Vec2{0, -d}};
        for (int i = 0; i < 4; ++i) segment(corner[i], corner[(i + 1) % 4], 1.5, kKinematicMark);
        if (const Velocity* v = scene_.registry.tryGet<Velocity>(e); v && length(v->value) > 0.0) {
            const Vec2 dir = v->value / length(v->value);
            arrow(c + dir * (d + 2.0), c + dir * (d + 26.0), 2.0, kKinematicMark);
        }
        if (const AngularVelocity* w = scene_.registry.tryGet<AngularVelocity>(e); w && w->value != 0.0) {
            // Three quarters of a circle, 14 px round, ending in a head
            // pointing the way of the turn (counter-clockwise for w > 0).
            constexpr double r = 14.0, pi = 3.14159265358979323846;
            const double sense = w->value > 0.0 ? 1.0 : -1.0;
            constexpr int pieces = 12;
            for (int i = 0; i < pieces; ++i) {
                const double a0 = sense * 1.5 * pi * i / pieces, a1 = sense * 1.5 * pi * (i + 1) / pieces;
                const Vec2 q0 = c + r * Vec2{std::cos(a0), std::sin(a0)}, q1 = c + r * Vec2{std::cos(a1), std::sin(a1)};
                if (i + 1 < pieces) segment(q0, q1, 1.5, kKinematicMark);
                else arrow(q0, q1 + (q1 - q0), 1.5, kKinematicMark);
            }
        }
    }
}

void Builder::emitterMarks() {
    // An emitter: a ring with a cross at its position, an arrow along its
    // velocity (fixed length: a mark, not a measure) and the two edges of
    // its spread, the cone its copies leave in.
    for (Entity e : scene_.registry.entities()) {
        const Emitter* em = scene_.registry.tryGet<Emitter>(e);
        const Position* p = scene_.registry.tryGet<Position>(e);
        if (!em || !p) continue;
        const Vec2 c = toPx(p->value);
        constexpr double r = 8.0, reach = 34.0;
        constexpr int pieces = 16;
        for (int i = 0; i < pieces; ++i) {
            const double a0 = 2.0 * 3.14159265358979323846 * i / pieces, a1 = 2.0 * 3.14159265358979323846 * (i + 1) / pieces;
            segment(c + r * Vec2{std::cos(a0), std::sin(a0)}, c + r * Vec2{std::cos(a1), std::sin(a1)}, 1.5, kEmitterMark);
        }
        segment(c + Vec2{-r * 0.5, 0}, c + Vec2{r * 0.5, 0}, 1.5, kEmitterMark);
        segment(c + Vec2{0, -r * 0.5}, c + Vec2{0, r * 0.5}, 1.5, kEmitterMark);
        const double speed = length(em->velocity);
        const Vec2 dir = speed > 0.0 ? em->velocity / speed : Vec2{0.0, -1.0};
        arrow(c + dir * (r + 2.0), c + dir * (r + reach), 2.0, kEmitterMark);
        if (em->spread > 0.0)
            for (const double turn : {-em->spread, em->spread}) {
                const double cs = std::cos(turn), sn = std::sin(turn);
                const Vec2 edge{cs * dir.x - sn * dir.y, sn * dir.x + cs * dir.y};
                segment(c + edge * (r + 2.0), c + edge * (r + reach * 0.8), 1.0, kEmitterMark);
            }
    }
}

void Builder::joints() {
    // Each joint: a thin line from each body's centre to its anchor, a ring
    // at the anchor (a filled pin for the world), the line between the two
    // anchors for distance and rope, the axis for a slider, and a hinge's
    // angle limits as an arc with a tick at b's current direction.
    for (Entity e : scene_.registry.entities()) {
        const Joint* j = scene_.registry.tryGet<Joint>(e);
        // A template's joints hold nothing until it is copied: its faded
        // bodies show the prefab, without the joints' marks.
        if (!j || scene_.registry.has<Template>(j->a)) continue;
        struct End {
            Vec2 centre;
            double angle = 0.0;
            bool body = false;
        };
        const auto endOf = [&](Entity b) {
            End end;
            if (b.isNull() || !scene_.registry.alive(b)) return end;
            const Position* p = scene_.registry.tryGet<Position>(b);
            if (!p) return end;
            end.centre = p->value;
            const Angle* a = scene_.registry.tryGet<Angle>(b);
            end.angle = a ? a->value : 0.0;
            end.body = true;
            return end;
        };
        const End a = endOf(j->a), b = endOf(j->b);
        if (!a.body) continue;
        const auto world = [](const End& end, Vec2 local) {
            const double c = std::cos(end.angle), s = std::sin(end.angle);
            return end.centre + Vec2{c * local.x - s * local.y, s * local.x + c * local.y};
        };
        const Vec2 anchorA = j->anchor ? *j->anchor : world(a, j->localA);
        const Vec2 anchorB = j->anchor ? *j->anchor : world(b, j->localB);
        const bool sel = selected_.count(e) != 0;
        const Rgba c = sel ? rgb(0xffd166) : colourOf(scene_, e, kJointColor);
        const double width = sel ? 2.2 : 1.4;
        const Vec2 pa = toPx(anchorA), pb = toPx(anchorB);
        // Centre-to-anchor lines stay faint: on a ragdoll they cross the bodies.
        segment(toPx(a.centre), pa, 0.7 * width, withAlpha(c, 0.45f));
        if (b.body) segment(toPx(b.centre), pb, 0.7 * width, withAlpha(c, 0.45f));
        if (j->type == "distance" || j->type == "rope") segment(pa, pb, j->type == "rope" ? 1.2 : 2.4, c);
        if (j->type == "slider" || j->type == "wheel") {
            const Vec2 axis = j->axis ? *j->axis : Vec2{1.0, 0.0};
            const double len = length(axis);
            if (len > 0.0) {
                const double ca = std::cos(a.angle), sa = std::sin(a.angle);
                const Vec2 u = Vec2{ca * axis.x - sa * axis.y, sa * axis.x + ca * axis.y} / len;
                const double lo = j->lower ? *j->lower : -1.0, hi = j->upper ? *j->upper : 1.0;
                segment(toPx(anchorA + u * lo), toPx(anchorA + u * hi), 1.2, c);
            }
        }
        if (j->type == "hinge" && (j->lower || j->upper)) {
            // The arc spans the allowed directions of b's x axis: a's angle
            // plus the reference angle plus [lower, upper].
            const double base = a.angle + j->referenceAngle.value_or(0.0);
            const double lo = base + j->lower.value_or(-kPiD), hi = base + j->upper.value_or(kPiD);
            const double radius = 16.0;
            const int pieces = std::clamp(int((hi - lo) / 0.2) + 1, 2, 64);
            Vec2 prev = pb + radius * Vec2{std::cos(lo), std::sin(lo)};
            segment(pb, prev, 1.0, withAlpha(c, 0.6f));
            for (int k = 1; k <= pieces; ++k) {
                const double t = lo + (hi - lo) * double(k) / pieces;
                const Vec2 p = pb + radius * Vec2{std::cos(t), std::sin(t)};
                segment(prev, p, 1.6, c);
                prev = p;
            }
            segment(pb, prev, 1.0, withAlpha(c, 0.6f));
            segment(pb, pb + (radius + 4.0) * Vec2{std::cos(b.angle), std::sin(b.angle)}, 1.6, kJointTick);
        }
        if (b.body) disc(pb, 4.0, 0.0, c, kFlat);
        else disc(pb, 4.5, 0.0, kAnchorColor, kStatic);
        disc(pa, 2.5, 0.0, kJointCentre, kFlat);
    }
}

void Builder::jointForces() {
    if (!in_.world) {
        out_.notes.push_back("joints: needs a World (not built)");
        return;
    }
    const auto records = in_.world->joints();
    if (records.empty()) return;
    std::vector<double> mags;
    for (const JointRecord& r : records) mags.push_back(length(r.force));
    const double ref = in_.scales.jointForce > 0 ? in_.scales.jointForce : autoReference(mags);
    out_.scales.jointForce = ref;
    for (const JointRecord& r : records) {
        // The force on a (what holds body a), drawn from a's anchor.
        const double m = length(r.force);
        if (!(m > 0.0)) continue;
        const Vec2 p = toPx(r.anchorA);
        const double len = std::max(8.0, arrowLength(m, ref, arrowRef_, 3.2 * arrowRef_));
        arrow(p, p - r.force / m * len, 1.6, kJointForce);
    }
    legend_.push_back({"joint force on a", kJointForce, ref, "N", "joint force"});
}

void Builder::polygonPreview() {
    // The polygon tool's shape-to-be: a translucent fill, the outline in the
    // selection colour, and a dot on each clicked vertex.
    const std::vector<Vec2>& outline = in_.polygonPreview;
    if (outline.size() >= 3) {
        std::vector<Vec2> px;
        Vec2 centre;
        for (const Vec2 v : outline) {
            px.push_back(toPx(v));
            centre += px.back();
        }
        centre = centre / double(px.size());
        auto& tri = batch(BatchKind::Solid);
        const Rgba fill{kSelectionRing.r, kSelectionRing.g, kSelectionRing.b, 0.18f};
        for (std::size_t i = 0; i < px.size(); ++i)
            for (const Vec2 q : {centre, px[i], px[(i + 1) % px.size()]}) push(tri, {q.x, q.y, fill.r, fill.g, fill.b, fill.a});
        for (std::size_t i = 0; i < px.size(); ++i) segment(px[i], px[(i + 1) % px.size()], 1.5, kSelectionRing);
    }
    for (const Vec2 v : in_.polygonClicks) disc(toPx(v), 3.5, 0.0, kSelectionRing, kFlat);
}

void Builder::boundingBoxes() {
    // The occupied cells, a faint fill, and each box's outline at the box
    // shader's anti-aliased edge (coverage clamp(1.1 - |d|), d the distance
    // to the rectangle), both over the bodies. Drawn as triangles and one
    // quad per box, llvmpipe shades every 4x4-pixel block a triangle
    // touches, once per triangle: a settled pile of 2,000 boxes 10 px wide
    // is about 3 blocks per pixel of the pile for the outlines and one more
    // for the cells. When that is more than twice the blocks of one layer
    // over them all, cells and outlines are drawn on the CPU into that layer
    // instead (the same coverage, pixel for pixel; they share one colour)
    // and the layer is drawn as one quad.
    std::vector<ShapeBox> boxes;  // metres
    for (Entity e : scene_.registry.entities())
        if (const auto shape = shapeBox(scene_, e)) boxes.push_back(*shape);
    const std::vector<std::array<double, 4>> cells = occupiedCells(boxes);
    std::vector<std::pair<Vec2, Vec2>> shown;  // centre, half extents, pixels
    Bounds area;
    double quadBlocks = 0.0;
    for (const auto& [cx0, cy0, cx1, cy1] : cells) {
        area.add({cx0, cy0});
        area.add({cx1, cy1});
        // Two triangles, each shading the blocks it touches (about 0.6 of the rectangle's and its diagonal).
        quadBlocks += 1.2 * (std::floor((cx1 - cx0) / 4.0) + 2.0) * (std::floor((cy1 - cy0) / 4.0) + 2.0);
    }
    for (const ShapeBox& shape : boxes) {
        const Vec2 c = toPx(shape.centre), half = shape.half * ppm_;
        if (!visible(c, std::hypot(half.x, half.y) + 8)) continue;
        shown.emplace_back(c, half);
        area.add(c - half - Vec2{2.0, 2.0});
        area.add(c + half + Vec2{2.0, 2.0});
        // The quad is the box plus 1.5 px (box.vert); each triangle shades the blocks it touches.
        quadBlocks += 1.5 * (std::floor((2.0 * half.x + 3.0) / 4.0) + 2.0) * (std::floor((2.0 * half.y + 3.0) / 4.0) + 2.0);
    }
    if (shown.empty() && cells.empty()) return;
    const int x0 = std::max(0, int(std::floor(area.lo.x))), y0 = std::max(0, int(std::floor(area.lo.y)));
    const int x1 = std::min(w_, int(std::ceil(area.hi.x))), y1 = std::min(h_, int(std::ceil(area.hi.y)));
    const double layerBlocks = (std::floor(double(x1 - x0) / 4.0) + 2.0) * (std::floor(double(y1 - y0) / 4.0) + 2.0);
    if (x1 <= x0 || y1 <= y0 || 2.0 * layerBlocks >= quadBlocks || !options_.pixelLayers) {
        // Axis-aligned cells: plain triangles with whole-pixel edges, not a
        // box quad and its distance shader; drawn first, under the outlines.
        for (const auto& [cx0, cy0, cx1, cy1] : cells) rect(cx0, cy0, cx1, cy1, kAabbCell);
        for (const auto& [c, half] : shown) box(c, half, 0.0, kAabb, kOutline);
        return;
    }
    const int lw = x1 - x0, lh = y1 - y0;
    // Coverage of the boxes, composited "over" like the blend: all share one
    // colour, so only alpha accumulates, in 8 bits as in the framebuffer the
    // quads would blend into (so overlaps round as they would there).
    PixelLayer layer{lw, lh, {kAabb.r, kAabb.g, kAabb.b}, std::vector<std::uint8_t>(std::size_t(lw) * std::size_t(lh), 0)};
    std::uint8_t* const alpha = layer.coverage.data();
    const auto cover = [](float d) {
        return int(std::min(std::max(1.1f - std::abs(d), 0.0f), 1.0f) * kAabb.a * 255.0f + 0.5f);
    };
    const auto over = [](std::uint8_t& dst, int a) { dst = std::uint8_t(a + (int(dst) * (255 - a) + 127) / 255); };
    // The cells first (they do not overlap: a 2 px gap between neighbours).
    const std::uint8_t cellAlpha = std::uint8_t(kAabbCell.a * 255.0f + 0.5f);
    for (const auto& [cx0, cy0, cx1, cy1] : cells) {
        const int i0 = std::max(int(cx0) - x0, 0), i1 = std::min(int(cx1) - x0, lw);
        for (int j = std::max(int(cy0) - y0, 0); j < std::min(int(cy1) - y0, lh); ++j)
            if (i1 > i0) std::fill(alpha + std::size_t(j) * std::size_t(lw) + i0, alpha + std::size_t(j) * std::size_t(lw) + i1, cellAlpha);
    }
    for (const auto& [c, half] : shown) {
        // Only pixels whose centre is within 1.1 px of an edge's line can be
        // covered: bands of rows along the bottom and top edges and bands of
        // columns along the left and right. Where a row band meets a column
        // band (the corners) the distance is box.frag's, exactly; elsewhere
        // it equals the row's distance to its edge (in a row band) or the
        // column's (in a column band), or both give no coverage, so each
        // row's or column's coverage is computed once and blended along it.
        // This runs for thousands of boxes a frame.
        const float cx = float(c.x - x0), cy = float(c.y - y0), hx = float(half.x), hy = float(half.y);
        // Pixels i whose centre i + 0.5 lies in [from, to] (at most 3 for a band 2.2 px wide).
        const auto band = [](float from, float to) { return std::pair{int(std::ceil(from - 0.5f)), int(std::floor(to - 0.5f))}; };
        const auto [b0, b1] = band(cy - hy - 1.1f, cy - hy + 1.1f);  // rows along the bottom edge
        const auto [t0, t1] = band(cy + hy - 1.1f, cy + hy + 1.1f);  // rows along the top edge
        const auto [l0, l1] = band(cx - hx - 1.1f, cx - hx + 1.1f);  // columns along the left edge
        const auto [g0, g1] = band(cx + hx - 1.1f, cx + hx + 1.1f);  // columns along the right edge
        const auto qxOf = [&](int i) { return std::abs(float(i) + 0.5f - cx) - hx; };
        const auto qyOf = [&](int j) { return std::abs(float(j) + 0.5f - cy) - hy; };
        const auto exact = [&](int i, int j) {
            const float qx = qxOf(i), qy = qyOf(j), mx = std::max(qx, 0.0f), my = std::max(qy, 0.0f);
            return cover(std::sqrt(mx * mx + my * my) + std::min(std::max(qx, qy), 0.0f));
        };
        const int jLo = std::max(b0, 0), jHi = std::min(t1, lh - 1), iLo = std::max(l0, 0), iHi = std::min(g1, lw - 1);
        if (b1 >= t0 || l1 >= g0) {
            // Too small for separate bands: every pixel exactly.
            for (int j = jLo; j <= jHi; ++j)
                for (int i = iLo; i <= iHi; ++i) over(alpha[std::size_t(j) * std::size_t(lw) + std::size_t(i)], exact(i, j));
            continue;
        }
        int columnCover[2][4];  // the left and the right band's columns (at most 3 each)
        for (int i = l0; i <= l1; ++i) columnCover[0][i - l0] = cover(qxOf(i));
        for (int i = g0; i <= g1; ++i) columnCover[1][i - g0] = cover(qxOf(i));
        for (int j = jLo; j <= jHi; ++j) {
            std::uint8_t* row = alpha + std::size_t(j) * std::size_t(lw);
            const bool edgeRow = j <= b1 || j >= t0;
            if (edgeRow) {
                for (int i = iLo; i <= std::min(l1, lw - 1); ++i) over(row[i], exact(i, j));
                const int a = cover(qyOf(j));
                if (a > 0)
                    for (int i = std::max(l1 + 1, 0); i <= std::min(g0 - 1, lw - 1); ++i) over(row[i], a);
                for (int i = std::max(g0, 0); i <= iHi; ++i) over(row[i], exact(i, j));
            } else {
                for (int i = iLo; i <= std::min(l1, lw - 1); ++i) over(row[i], columnCover[0][i - l0]);
                for (int i = std::max(g0, 0); i <= iHi; ++i) over(row[i], columnCover[1][i - g0]);
            }
        }
    }
    push(batch(BatchKind::Image), {double(x0), double(y0), double(x1), double(y1), double(out_.images.size())});
    out_.images.push_back(std::move(layer));
}

void Builder::bodyArrows() {
    const double maxPx = 3.2 * arrowRef_;
    const bool applied = in_.overlays.has(Overlay::Force), net = in_.overlays.has(Overlay::NetForce);
    if ((applied || net) && !in_.world) {
        out_.notes.push_back(std::string(applied ? "force" : "net-force") + ": needs a World (not built)");
    } else if (applied || net) {
        // One reference for both, from the applied forces (see ArrowScales::
        // force), so a net arrow reads against the forces that act: a crate
        // resting on the floor has an applied arrow of its weight and a net
        // arrow of about nothing.
        const std::vector<Vec2> appliedForces = in_.world->bodyForces();
        std::vector<double> mags;
        for (Vec2 f : appliedForces) mags.push_back(length(f));
        const double ref = in_.scales.force > 0 ? in_.scales.force : lowReference(mags);
        out_.scales.force = ref;
        std::vector<Vec2> origins;
        for (std::size_t i = 0; i < appliedForces.size(); ++i) origins.push_back(toPx(in_.world->bodyPosition(i)));
        const auto draw = [&](const std::vector<Vec2>& forces, Rgba colour) {
            CellThinner thin(*this, origins);
            for (std::size_t i = 0; i < forces.size(); ++i) {
                const double m = length(forces[i]);
                if (!(m > 0.0) || !std::isfinite(m)) continue;
                const Vec2 from = origins[i];
                if (!thin.keep(from, selected_.count(in_.world->bodyEntity(i)) != 0)) continue;
                const double len = arrowLength(m, ref, arrowRef_, maxPx);
                // Under a pixel there is nothing to see (a resting body's net
                // force), and a settled pile would send an instance per body.
                if (len < 1.0) continue;
                arrow(from, from + forces[i] / m * len, dense_ ? 1.0 : 2.0, colour);
            }
        };
        if (applied) {
            draw(appliedForces, kForce);
            legend_.push_back({"applied force", kForce, ref, "N"});
        }
        if (net) {
            const std::vector<Vec2> netForces = in_.world->netForces();
            if (netForces.empty()) {
                out_.notes.push_back("net force: shown once a step is taken");
            } else {
                draw(netForces, kNetForce);
                legend_.push_back({"net force (m dv/dt)", kNetForce, ref, "N", "net force"});
            }
        }
    }
    if (in_.overlays.has(Overlay::Velocity)) {
        std::vector<Vec2> origins, velocities;  // pixels, m/s
        std::vector<double> mags;
        std::vector<bool> chosen;
        // A sleeping body is at rest: the residue of velocity it fell asleep
        // with (1e-5 m/s) would get an arrow, and would pull the reference
        // down until every such arrow was drawn long.
        std::unordered_set<Entity> asleep;
        if (in_.world)
            for (Entity e : in_.world->sleepingBodies()) asleep.insert(e);
        for (Entity e : scene_.registry.entities()) {
            const Position* p = scene_.registry.tryGet<Position>(e);
            const Velocity* v = scene_.registry.tryGet<Velocity>(e);
            if (!p || !v || isStatic(scene_, e) || asleep.count(e)) continue;
            origins.push_back(toPx(p->value));
            velocities.push_back(v->value);
            mags.push_back(length(v->value));
            chosen.push_back(selected_.count(e) != 0);
        }
        const double ref = in_.scales.velocity > 0 ? in_.scales.velocity : autoReference(mags);
        out_.scales.velocity = ref;
        CellThinner thin(*this, origins);
        for (std::size_t i = 0; i < origins.size(); ++i) {
            if (!(mags[i] > 0.0) || !std::isfinite(mags[i])) continue;
            const Vec2 from = origins[i];
            if (!thin.keep(from, chosen[i])) continue;
            const double len = arrowLength(mags[i], ref, arrowRef_, maxPx);
            arrow(from, from + velocities[i] / mags[i] * len, dense_ ? 1.0 : 2.0, kVelocity);
        }
        legend_.push_back({"velocity", kVelocity, ref, "m/s"});
    }
}

void Builder::contacts() {
    if (!in_.world) {
        out_.notes.push_back("contacts: needs a World (not built)");
        return;
    }
    const std::span<const ContactRecord> records = in_.contacts ? *in_.contacts : in_.world->contacts();
    std::vector<double> mags;
    for (const ContactRecord& c : records) mags.push_back(std::abs(c.normalImpulse));
    const double ref = in_.scales.impulse > 0 ? in_.scales.impulse : autoReference(mags);
    out_.scales.impulse = ref;
    // Level of detail (see CellThinner): a settled pile has about two
    // contacts per body, and their arrows would merge into one red block
    // that hides the bodies. The selected bodies' contacts are always
    // drawn; the contacts table and --contacts still list every contact.
    std::vector<Vec2> points;
    for (const ContactRecord& c : records) points.push_back(toPx(c.point));
    CellThinner thin(*this, points);
    for (std::size_t i = 0; i < records.size(); ++i) {
        const ContactRecord& c = records[i];
        const Vec2 p = points[i];
        if (!thin.keep(p, selected_.count(c.a) != 0 || selected_.count(c.b) != 0)) continue;
        // The impulse on body a, which is along -normal (the normal points
        // from a to b): out of a floor, not into it. Length from the normal
        // impulse (a short stub when the contact carried none, so the
        // direction still shows).
        const double m = std::abs(c.normalImpulse);
        const double len = m > 0.0 ? std::max(8.0, arrowLength(m, ref, arrowRef_, 3.2 * arrowRef_)) : 10.0;
        arrow(p, p - c.normal * len, thin.active() ? 1.0 : 1.5, kContactNormal);
        disc(p, thin.active() ? 2.0 : 3.0, 0.0, kContactPoint, kFlat);
    }
    legend_.push_back({"contact impulse", kContactNormal, ref, "N s"});
}

double Builder::coveredBodyArea(double x, double y, double w, double h) const {
    // Pixels of the rectangle over the boxes around the moving bodies (a
    // body with no shape counts as 8 x 8 px); static shapes do not count: a
    // floor or a wall runs under any corner.
    double area = 0.0;
    for (Entity e : scene_.registry.entities()) {
        const Position* p = scene_.registry.tryGet<Position>(e);
        if (!p || isStatic(scene_, e)) continue;
        Vec2 c = toPx(p->value), half{4.0, 4.0};
        if (const std::optional<ShapeBox> b = shapeBox(scene_, e)) {
            c = toPx(b->centre);
            half = b->half * ppm_;
        }
        const double ox = std::min(x + w, c.x + half.x) - std::max(x, c.x - half.x);
        const double oy = std::min(y + h, c.y + half.y) - std::max(y, c.y - half.y);
        if (ox > 0 && oy > 0) area += ox * oy;
    }
    return area;
}

void Builder::hud() {
    const double s = textScale_;
    const double margin = 14.0 * s;
    // Where the caption's and the scale bar's panels end: the legend keeps clear.
    double captionRight = 0.0, captionBottom = h_, scaleRight = 0.0, scaleTop = 0.0;
    // ---- caption, top-left -------------------------------------------
    if (!in_.caption.empty()) {
        const double th = textHeight();
        const double width = textWidth(in_.caption);
        captionRight = margin + width + 7 * s;
        captionBottom = h_ - margin - th - 5 * s;
        box({margin + 0.5 * width, h_ - margin - 0.5 * th}, {0.5 * width + 7 * s, 0.5 * th + 5 * s}, 0.0, kPanel,
            kFlat, 4.0 * s);
        text(margin, h_ - margin, in_.caption, kText);
    }
    // ---- scale bar, bottom-left --------------------------------------
    {
        // The largest 1-2-5 length that fits in about 110 px per font scale.
        const double metres = niceFloor(110.0 * s / ppm_);
        const double px = metres * ppm_;
        const std::string label = formatLength(metres);
        const double th = textHeight();
        const double panelW = std::max(px, textWidth(label)) + 16 * s;
        const double panelH = th + 20 * s;
        scaleRight = margin + panelW;
        scaleTop = margin + panelH;
        out_.scaleBarBox = {margin, margin, panelW, panelH};
        box({margin + 0.5 * panelW, margin + 0.5 * panelH}, {0.5 * panelW, 0.5 * panelH}, 0.0, kPanel, kFlat, 4.0 * s);
        const double x0 = std::floor(margin + 8 * s) + 0.5, y = std::floor(margin + 7 * s) + 0.5;
        segment({x0, y}, {x0 + px, y}, 2.0, kText);
        segment({x0, y - 3 * s}, {x0, y + 4 * s}, 1.5, kText);
        segment({x0 + px, y - 3 * s}, {x0 + px, y + 4 * s}, 1.5, kText);
        text(x0 + 0.5 * px - 0.5 * textWidth(label), y + 6 * s + th, label, kText);
    }
    // ---- legend, a corner on the right ---------------------------------
    if (legend_.empty() && out_.notes.empty() && !in_.overlays.has(Overlay::Aabb) && !in_.overlays.has(Overlay::Trails))
        return;
    // A cell per overlay (a sample, its name, its reference), the cells
    // flowing left to right in as few rows as the viewport's width allows,
    // and the notes in rows of their own below. One row per overlay took
    // 44% of the editor's viewport at 1280x720 with every overlay on.
    struct Cell {
        std::string label, value;
        Rgba colour;
        int kind;  // 0 arrow, 1 swatch box, 2 line, 3 text only
        double width = 0.0;
    };
    std::vector<Cell> cells;
    for (const LegendRow& r : legend_) {
        cells.push_back({r.shortLabel.empty() ? r.label : r.shortLabel, formatNumber(r.reference) + " " + r.unit, r.colour, 0});
        out_.legend.push_back(r.label + " = " + cells.back().value);
    }
    // The overlay's own name: "bounding boxes" took the width that kept
    // every overlay in three rows at 1280x720.
    if (in_.overlays.has(Overlay::Aabb)) cells.push_back({"aabb", "", kAabb, 1});
    if (in_.overlays.has(Overlay::Trails) && in_.trails)
        cells.push_back({"trails", std::to_string(in_.trails->capacity()) + " steps", rgb(0x9fb3c8, 0.8f), 2});
    if (!legend_.empty()) cells.push_back({"length ~ log2(1+|x|/ref)", "", kTextDim, 3});
    const double sampleW = arrowRef_;  // a reference-magnitude arrow's length
    const double sampleGap = 5.0 * s, valueGap = 5.0 * s, cellGap = 11.0 * s;
    double widest = 0.0;
    for (Cell& c : cells) {
        c.width = (c.kind == 3 ? 0.0 : sampleW + sampleGap) + textWidth(c.label) +
                  (c.value.empty() ? 0.0 : valueGap + textWidth(c.value));
        widest = std::max(widest, c.width);
    }
    double noteW = 0.0;
    for (const std::string& n : out_.notes) noteW = std::max(noteW, textWidth(n));
    // Each cell's row and left edge (from the panel's inner left) for
    // rows at most `innerW` wide; returns the widest row.
    std::vector<std::size_t> rowOf(cells.size());
    std::vector<double> leftOf(cells.size());
    const auto flow = [&](double innerW) {
        std::size_t row = 0;
        double x = 0.0, widestRow = 0.0;
        for (std::size_t i = 0; i < cells.size(); ++i) {
            if (i > 0 && x + cellGap + cells[i].width > innerW) {
                ++row;
                x = 0.0;
            } else if (i > 0) {
                x += cellGap;
            }
            rowOf[i] = row;
            leftOf[i] = x;
            x += cells[i].width;
            widestRow = std::max(widestRow, x);
        }
        return widestRow;
    };
    const auto rowCount = [&] { return cells.empty() ? std::size_t(0) : rowOf.back() + 1; };
    const double rowH = 10.0 * s, pad = 5.0 * s;
    // As few rows as the width allows, then the narrowest panel with that
    // many (rows of about even length read better than one long row and
    // a short one).
    const double maxInner = std::max(widest, w_ - 2 * margin - 2 * pad);
    flow(maxInner);
    const std::size_t rows = rowCount();
    double lo = widest, hi = maxInner;
    for (int k = 0; k < 40 && hi - lo > 0.5; ++k) {
        const double mid = 0.5 * (lo + hi);
        flow(mid);
        (rowCount() <= rows ? hi : lo) = mid;
    }
    const double innerW = std::max(flow(hi), noteW);
    const double panelW = innerW + 2 * pad;
    const double panelH = double(rows + out_.notes.size()) * rowH - (rowH - textHeight()) + 2 * pad;
    // The bottom right, above the scale bar when the two would meet; or the
    // top right, below the caption when the two would meet (and below the
    // editor's line at the top), when that hides fewer moving bodies: a
    // pile or a pyramid stands on the floor.
    const double x0 = w_ - margin - panelW;
    const double bottomY = x0 < scaleRight + margin ? scaleTop + 0.5 * margin : margin;
    double topEdge = h_ - std::max(margin, in_.reservedTopPx + 0.5 * margin);
    if (!in_.caption.empty() && x0 < captionRight + margin) topEdge = std::min(topEdge, captionBottom - 0.5 * margin);
    const double topY = topEdge - panelH;
    // As few in both: the top, unless the bottom one is in the corner
    // itself (raised above the scale bar, it is in the middle of the scene).
    double y0 = bottomY;
    if (topY > bottomY) {
        const double coverTop = coveredBodyArea(x0, topY, panelW, panelH);
        const double coverBottom = coveredBodyArea(x0, bottomY, panelW, panelH);
        if (coverTop < coverBottom || (coverTop == coverBottom && bottomY > margin)) y0 = topY;
    }
    out_.legendBox = {x0, y0, panelW, panelH};
    out_.legendCoversPx = coveredBodyArea(x0, y0, panelW, panelH);
    box({x0 + 0.5 * panelW, y0 + 0.5 * panelH}, {0.5 * panelW, 0.5 * panelH}, 0.0, kPanel, kFlat, 4.0 * s);
    box({x0 + 0.5 * panelW, y0 + 0.5 * panelH}, {0.5 * panelW, 0.5 * panelH}, 0.0, kPanelBorder, kOutline, 4.0 * s);
    const double firstTop = y0 + panelH - pad;  // the first row's text top
    for (std::size_t i = 0; i < cells.size(); ++i) {
        const Cell& c = cells[i];
        const double yTop = firstTop - double(rowOf[i]) * rowH;
        double x = x0 + pad + leftOf[i];
        if (c.kind == 3) {
            text(x, yTop, c.label, kTextDim);
            continue;
        }
        const double mid = std::floor(yTop - 0.5 * textHeight()) + 0.5;
        if (c.kind == 0) arrow({x, mid}, {x + sampleW, mid}, 1.6, withAlpha(c.colour, 1.0f));
        if (c.kind == 1) box({x + 0.5 * sampleW, mid}, {0.5 * sampleW, 3.5 * s}, 0.0, c.colour, kOutline);
        if (c.kind == 2) segment({x, mid}, {x + sampleW, mid}, 1.6, c.colour);
        x += sampleW + sampleGap;
        x += text(x, yTop, c.label, kText);
        if (!c.value.empty()) text(x + valueGap, yTop, c.value, kTextDim);
    }
    for (std::size_t j = 0; j < out_.notes.size(); ++j)
        text(x0 + pad, firstTop - double(rows + j) * rowH, out_.notes[j], kTextDim);
}

} // namespace

// ---------------------------------------------------------------------------

std::size_t floatsPerInstance(BatchKind kind) {
    switch (kind) {
    case BatchKind::Plane: return 12;
    case BatchKind::Disc: return 9;
    case BatchKind::Box: return 11;
    case BatchKind::Segment: return 9;
    case BatchKind::Arrow: return 9;
    case BatchKind::Solid: return 6;
    case BatchKind::Image: return 5;
    }
    return 1;
}

std::size_t Batch::count() const { return data.size() / floatsPerInstance(kind); }

std::size_t DrawData::instanceCount() const {
    std::size_t n = 0;
    for (const Batch& b : batches) n += b.count();
    return n;
}

DrawData buildDrawData(const FrameInput& input, int widthPx, int heightPx, const BuildOptions& options) {
    DrawData out;
    out.width = widthPx;
    out.height = heightPx;
    out.scales = input.scales;
    if (!input.scene || widthPx <= 0 || heightPx <= 0) return out;
    Builder(out, input, widthPx, heightPx, options).build();
    return out;
}

} // namespace stepwise::render
