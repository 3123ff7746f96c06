#pragma once
// Broad phase: candidate pairs whose (fattened) AABBs overlap. Two
// strategies, chosen by measurement (bench/collision/collision_vs_box2d.cpp; docs/collisions.md): sweep and
// prune on x, and a uniform grid. Both return the same pairs in the same
// order (sorted by (a, b)), so the solver's result does not depend on which
// one ran; the one exception is a crowd (a grid cell with more than
// kDenseCell boxes whose shapes cover it kCrowdedCover times over), where
// the grid bounds the pairs per box. The grid keeps the pairs of grown
// boxes between calls while that gives exactly a fresh grid's pairs.

#include "collision/collision_types.hpp"

#include <cstdint>
#include <span>
#include <utility>
#include <vector>

namespace stepwise::collision {

/// A candidate pair of proxy indices, a < b.
struct ProxyPair {
    std::uint32_t a;
    std::uint32_t b;
    friend bool operator<(ProxyPair l, ProxyPair r) { return l.a != r.a ? l.a < r.a : l.b < r.b; }
    friend bool operator==(ProxyPair, ProxyPair) = default;
};

enum class BroadPhaseKind { SweepAndPrune, UniformGrid, BruteForce };

/// Appends every pair (a < b) whose boxes overlap and where at least one of
/// the two is movable (`movable[i]`), sorted by (a, b). Scratch buffers live
/// in the object so steady-state steps allocate nothing.
class BroadPhase {
public:
    explicit BroadPhase(BroadPhaseKind kind = BroadPhaseKind::SweepAndPrune) : kind_(kind) {}
    void setKind(BroadPhaseKind kind) { kind_ = kind; }
    BroadPhaseKind kind() const { return kind_; }

    /// `coreArea[i]`, when given, is the area of box i before any margin
    /// fattened it (m^2): a grid cell is then a crowd only when its boxes'
    /// cores cover it several times over, not merely when fat margins make
    /// many boxes reach into it.
    void findPairs(std::span<const Aabb> boxes, std::span<const std::uint8_t> movable, std::vector<ProxyPair>& pairs,
                   std::span<const double> coreArea = {});
    /// Box-against-box tests the last uniform-grid call made (its cost, for
    /// tests: it must not grow with one huge shape or a crowd).
    std::size_t lastGridOverlapTests() const { return overlapTests_; }
    /// Per box of the last call: 1 when it sat in a crowded grid cell;
    /// empty when no grid ran.
    std::span<const std::uint8_t> crowded() const { return crowded_; }
    /// Whether the last call's pairs came from the kept grown pairs (see
    /// keepGrownPairs) instead of a fresh grid.
    bool lastServedFromKept() const { return servedFromKept_; }

private:
    void sortPairs(std::vector<ProxyPair>& pairs, std::size_t boxCount);
    /// A uniform grid's cells: their side (m) and the corner of cell (0, 0).
    struct GridFrame {
        double cell;
        Vec2 lo;
        std::int64_t cellOf(double v, double origin) const;
    };
    /// The cells of a grid of these boxes; leaves each box's extent in
    /// extents_ and the boxes too large for a cell in large_.
    GridFrame gridFrame(std::span<const Aabb> boxes);
    /// Whether a uniform grid of these boxes would have no cell of over
    /// kDenseCell boxes (so no crowd).
    bool freshGridIsSparse(std::span<const Aabb> boxes);
    bool reuseKept(std::span<const Aabb> boxes, std::span<const std::uint8_t> movable, std::vector<ProxyPair>& pairs);
    bool keepGrownPairs(std::span<const Aabb> boxes, std::span<const std::uint8_t> movable,
                        std::vector<ProxyPair>& pairs, std::span<const double> coreArea);
    void pauseAfterFailure();
    void sweepAndPrune(std::span<const Aabb> boxes, std::span<const std::uint8_t> movable, std::vector<ProxyPair>& pairs);
    void uniformGrid(std::span<const Aabb> boxes, std::span<const std::uint8_t> movable, std::vector<ProxyPair>& pairs,
                     std::span<const double> coreArea);

    BroadPhaseKind kind_;
    /// Grid cells with more entries than this are a crowd: each box there
    /// pairs only with its next kDenseNeighbours boxes (in Z-order of the
    /// centres), so it has about twice that many pairs.
    static constexpr std::size_t kDenseCell = 64;
    /// With core areas given, a cell is a crowd only when its boxes' cores
    /// sum to more than this many times the cell's area. Cores side by side
    /// stay under 4 (a box reaching into a cell lies within the cell grown
    /// by its fat extent, at most half a cell for a median box, so their
    /// cores fit in twice the cell's width); bodies started overlapping
    /// their neighbours by half (Box2D's spinner) reach 8; only shapes on
    /// top of each other reach this.
    static constexpr double kCrowdedCover = 16.0;
    static constexpr std::size_t kDenseNeighbours = 4;
    /// A box wider than this many cells stays out of the grid's cells.
    static constexpr double kLargeCells = 8.0;
    struct SortedBox {
        double lowerX, upperX, lowerY, upperY;
        std::uint32_t index;
        std::uint8_t movable;
    };
    std::vector<std::uint32_t> order_;  // SAP: proxies sorted by lower.x (kept between steps: nearly sorted)
    std::vector<SortedBox> sorted_;     // SAP: the boxes in that order, packed for the sweep
    std::vector<std::uint64_t> cellKeys_;  // grid: (cell, proxy) entries
    struct CellIndex {
        std::int64_t x, y;
    };
    std::vector<CellIndex> lowerCell_;  // grid: the cell of each box's lower corner
    std::vector<CellIndex> upperCell_;  // freshGridIsSparse: the cell of each box's upper corner
    std::vector<std::uint32_t> cellCounts_;  // freshGridIsSparse: boxes per cell
    struct CellBox {
        Aabb box;
        std::int64_t cellX, cellY;  // the cell of its lower corner
        std::uint32_t index;
        std::uint8_t movable;
    };
    std::vector<CellBox> cellBoxes_;  // grid: one cell's boxes, packed for its pair loop
    std::vector<std::uint64_t> mortonKeys_;  // grid, crowded cell: (Z-order code, proxy)
    std::vector<std::uint64_t> pairKeys_, sortScratch_;  // findPairs: pairs as (a << 32 | b), and radixSort's buffer
    std::vector<std::uint32_t> bucketStart_;  // bucketSort's counts
    std::vector<double> extents_, median_;  // grid: each box's larger side, and a copy for the median (m)
    std::vector<std::uint32_t> large_;
    std::size_t overlapTests_ = 0;
    std::vector<std::uint8_t> crowded_;     // grid: boxes too large for the cells

    /// Grid only: the pairs of every box grown by an eighth of its extent,
    /// kept while each box stays inside its grown box. Filtered by the
    /// boxes' own overlap they are exactly the pairs a fresh grid would
    /// find, so a pile at rest does not rebuild its grid every step
    /// (reuseKept says when that holds).
    struct KeptPairs {
        bool valid = false;
        std::vector<Aabb> grown;
        std::vector<std::uint8_t> movable;
        std::vector<ProxyPair> pairs;  // sorted
        std::size_t served = 0;        // calls answered since it was made
    } kept_;
    std::size_t pause_ = 0;          // grid calls left before keeping pairs is tried again
    static constexpr std::size_t kKeepPause = 8, kKeepLongestPause = 64;
    std::size_t pauseLength_ = kKeepPause;  // the next pause's
    bool servedFromKept_ = false;
};

} // namespace stepwise::collision
