// bbm io: fracture traces from a DXF drawing (docs/input.md "Fracture networks").
//
// Mapped joints come from CAD as DXF. This reads the ASCII DXF a CAD program or a
// mapping tool writes (any version from R12 on): the LINE, LWPOLYLINE and 2D/3D
// POLYLINE entities of the ENTITIES section become straight traces in the model's
// plane (z dropped; arcs of a polyline, its bulges, split into chords of at most
// 5 degrees); their layer is the trace's set. The drawing units ($INSUNITS) are
// converted to metres. Everything else the drawing holds (text, hatches, blocks)
// is counted and left out. A file that is not ASCII DXF, or an entity whose
// coordinates do not read, is refused at its line.
//
// Written here rather than through a DXF library: the subset is a page of group
// codes, and the maintained one Debian packages (dxflib, GPL-2) does not report
// where in the file an entity came from, which every bbm input error must say.
#pragma once

#include "base/vec2.hpp"

#include <map>
#include <string>
#include <vector>

namespace bbm::io {

struct DxfTrace {
    Vec2 a{}, b{};     ///< in metres
    std::string layer; ///< the entity's layer (group code 8), "0" when not given
    int line = 0;      ///< line of the entity's "0" group code in the file
};

struct DxfDrawing {
    std::vector<DxfTrace> traces;
    int insunits = 0;             ///< $INSUNITS of the header (0 = unitless: read as metres)
    double metres_per_unit = 1.0; ///< the scale applied to every coordinate
    std::map<std::string, int> entities_read;    ///< LINE, LWPOLYLINE, POLYLINE: how many
    std::map<std::string, int> entities_skipped; ///< every other entity type: how many
};

/// Reads `path`; errors (bbm::InputError) name the file, the line in it and `key`
/// (the model file's key that named it). `metres_per_unit` > 0 overrides the
/// drawing's own units.
DxfDrawing read_dxf(const std::string& path, const std::string& key, double metres_per_unit = 0.0);

/// The name of a DXF $INSUNITS code ("mm", "m", "ft", ...), "unitless" for 0.
std::string dxf_unit_name(int insunits);

} // namespace bbm::io
