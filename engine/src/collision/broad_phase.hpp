#pragma once
// Broad phase: candidate pairs whose (fattened) AABBs overlap. Two
// strategies, chosen by measurement (bench/collision/collision_vs_box2d.cpp; docs/collisions.md): sweep and
// prune on x, and a uniform grid. Both return the same pairs in the same
// order (sorted by (a, b)), so the solver's result does not depend on which
// one ran; the one exception is a crowd (a grid cell with more than
// kDenseCell boxes whose shapes cover it kCrowdedCover times over), where
// the grid bounds the pairs per box.

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

private:
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
};

} // namespace stepwise::collision
