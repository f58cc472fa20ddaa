// bbm meshing, internal: a region cut by its real discontinuities, exactly.
//
// A region with real joints, joint sets or a fracture network is cut by one exact
// computation: CGAL arrangements of segments on the exact kernel (Epeck), where no
// coordinate is rounded until the blocks are read off, so no network — however
// dense, whatever its seed — can hand a later step a polygon that crosses itself.
//
//   1. The region's arrangement: its boundary (the region on the left of every
//      edge) and every trace, unclipped. Its faces inside the region are the rock
//      blocks. A fracture that ends at an earlier one ends exactly on it (where
//      their lines cross, not at a rounded point near it). A rock block under
//      `min_face_area` (where traces cross nearly at one point) is merged into the
//      neighbour it shares most boundary with, losing that stretch of trace.
//   2. Each rock block's arrangement: its exact boundary — traces that end inside
//      it included, as edges with the block on both sides — and the edges of the
//      cells the pattern lays over it. The faces inside the block are the blocks,
//      each with the cell it lies in as its parent. Then, until nothing changes:
//      * a trace that ends inside a block (a vertex of degree 1) goes on along its
//        line to the first edge it meets: the rock bridge, an ordinary inner joint
//        that can break;
//      * a block with a hole — a smaller block inside it, free, touching it at a
//        vertex, or tied to it by a trace — is cut along the vertical line through
//        the middle of the hole's x-range, from the hole up and down to the next
//        edges (the line moved off any vertex);
//      * a block under `min_area`, or whose rounded polygon is not simple, is
//        merged into the neighbour across a cell edge (never a trace or a rock
//        bridge) that it shares most boundary with;
//      and two lobes of a block touching at a vertex are two blocks. The pattern's
//      short edges are collapsed before the rules (as in a rock block no trace ends
//      in): the collapsed pieces are laid again, their ends on the boundary put
//      exactly on it.
// Cells that no edge of the rock block comes near are kept as they were generated:
// only the cells at its edges are cut.
#pragma once

#include "meshing/detail.hpp"

#include <functional>
#include <memory>
#include <span>
#include <vector>

namespace bbm::meshing::detail {

/// A real discontinuity as the cutter takes it: the segment from `a` to `b`, except
/// that an end whose `*_at` names another trace lies exactly where this trace's line
/// (through line_a, line_b) crosses that trace's line, and one marked `on_boundary`
/// (a fracture clipped to the region) where it crosses the region's boundary.
struct CutTrace {
    static constexpr int on_boundary = -2;
    Vec2 a{}, b{};
    Vec2 line_a{}, line_b{};
    int a_at = -1, b_at = -1;
};

/// What the cutting did beyond the plain overlay, for the summary.
struct CutStats {
    int merged_slivers = 0; ///< rock blocks and blocks merged into a neighbour
    int slivers_left = 0;   ///< small blocks with no neighbour they could merge with
    int rock_bridges = 0;   ///< traces ending inside a block, carried on to its edge
    int hole_cuts = 0;      ///< vertical cuts opening a block with a hole
};

/// A point from which every edge of a polygon is seen; false if there is none.
using CentreOf = std::function<bool(const std::vector<Vec2>&, Vec2&)>;
/// Collapses the short edges of a rock block's pieces; returns how many.
using Collapse = std::function<int(Cells&)>;

class RegionCut {
public:
    /// The arrangement of `domain`'s boundary and `traces`; rock blocks (bounded by
    /// traces alone) under `min_face_area` merged, losing the trace between them;
    /// blocks under `min_area` merged across a cell edge, losing none; `tol` is the
    /// rounding scale (1e-9 of the model).
    RegionCut(const cgal::Domain& domain, std::span<const CutTrace> traces, double min_area, double min_face_area,
              double tol);
    ~RegionCut();
    RegionCut(const RegionCut&) = delete;
    RegionCut& operator=(const RegionCut&) = delete;

    /// Rock blocks, in the arrangement's order.
    int face_count() const;
    /// Rock block k rounded, for the pattern generators (seeds, sizes, lattice
    /// ranges): its largest loop the ring, the other loops holes; not always simple.
    const cgal::PolygonWithHoles& face(int k) const;
    /// Whether rock block k is a simple polygon as it is (no hole, no trace ending in
    /// it, no vertex twice): then face(k).outer is exactly it.
    bool plain(int k) const;
    /// The traces' edges inside the region (rounded), for tagging and output.
    std::vector<SegmentSpec> real_segments() const;
    /// Rock blocks merged because they were under min_area, and the length of
    /// trace between them and the neighbours they were merged into (gone).
    int merged_faces() const;
    double merged_trace_length() const;

    /// `cells` clipped to rock block k (parent: the cell's index), no rule applied:
    /// for relaxing the seeds of a pattern.
    FaceFill clip(int k, const Cells& cells) const;
    /// The blocks of rock block k: `cells` (none: the rock block itself) cut to it,
    /// their short edges collapsed by `collapse` (if given), then the rules above.
    /// `fitted`: the cells already tile face(k) (constrained Delaunay triangles of
    /// its sampled boundary), so their ends on its boundary are put exactly on it.
    /// With `centre_of` (trigon) each piece is fanned from its centre into
    /// triangles before the rules (parent: the piece).
    FaceFill blocks(int k, const Cells& cells, bool fitted, const Collapse& collapse, const CentreOf& centre_of,
                    CutStats& stats) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace bbm::meshing::detail
