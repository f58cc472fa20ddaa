// bbm core: the keys of the [[boundary]] and [[joint_assignment]] tables — the
// loads on the model and which property its joints get — one declaration each
// (base/keys.hpp). The model file's reader checks both by them
// (io/model_input.cpp) and docs/reference/boundary.md is generated from them
// (tests/test_reference.cpp).
#pragma once

#include "base/keys.hpp"
#include "core/model_spec.hpp"

#include <string>

namespace bbm {

using BoundaryKey = Key<BoundarySpec>;
using AssignmentKey = Key<JointAssignmentSpec>;

/// A boundary's types, in the order of BoundarySpec::Kind.
inline constexpr std::string_view boundary_type_words = "velocity, stress, viscous";
/// An incident wave's pulses and kinds, in the order of IncidentWaveSpec's enums.
inline constexpr std::string_view pulse_words = "none, ricker, half_sine, harmonic, file";
inline constexpr std::string_view wave_words = "p, s";
/// The joint tags, in the order of meshing::JointTag.
inline constexpr std::string_view joint_tag_words = "inner, radial, peripheral, real_joint, interface, fracture";

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
/// Every key of [[boundary]]. A block or an exposed edge is selected when it belongs
/// to one of `regions` (if given) and its centroid (an edge: its midpoint) lies in
/// `box` (if given).
inline constexpr BoundaryKey boundary_keys[] = {
    {.key = "name", .kind = KeyKind::text, .required = true, .meaning = "Non-empty, unique; named by histories"},
    {.key = "type", .kind = KeyKind::choice, .required = true,
     .meaning = "velocity: prescribed velocities of blocks (and nodes); stress: a traction σ·n on the exposed "
                "block edges selected (n their outward normal; on a deformable block it goes to the nodes); "
                "viscous: dashpots ρ c_p (normal) and ρ c_s (shear) per unit length on the exposed edges of "
                "deformable blocks selected, which absorb the waves that reach them (Lysmer & Kuhlemeyer 1969) "
                "and send in an incident wave (needs [solver] mode = \"dynamic\")",
     .words = boundary_type_words},
    {.key = "regions", .kind = KeyKind::names, .meaning = "Select in these regions only; not empty, no repeats",
     .absent = "any region"},
    {.key = "box", .kind = KeyKind::table, .bounds = unbounded(" m"),
     .meaning = "{ min = [x, y], max = [x, y] }, max above min in x and y: select by position", .absent = "no box"},
    {.key = "touching", .kind = KeyKind::boolean, .only = "velocity",
     .meaning = "Select the rigid blocks with an edge in box (both its ends) instead of those whose centroid is in "
                "it: a symmetry plane or a support face; nodes are selected by position either way",
     .absent = "false"},
    {.key = "vx", .bounds = unbounded(" m/s"), .only = "velocity",
     .meaning = "Prescribed x velocity; 0 fixes the block (or node) in x. At least one of vx, vy, omega",
     .absent = "free"},
    {.key = "vy", .bounds = unbounded(" m/s"), .only = "velocity", .meaning = "Prescribed y velocity",
     .absent = "free"},
    {.key = "omega", .bounds = unbounded(" rad/s"), .only = "velocity",
     .meaning = "Prescribed angular velocity of rigid blocks, counter-clockwise (nodes have no rotation)",
     .absent = "free"},
    {.key = "sxx", .bounds = unbounded(" Pa"), .only = "stress",
     .meaning = "σxx at y_ref, tension positive: σ(y) = σ0 + (y − y_ref) dσ/dy", .absent = "0"},
    {.key = "syy", .bounds = unbounded(" Pa"), .only = "stress",
     .meaning = "σyy at y_ref (syy = -1e6 on a top edge pushes it down with 1 MPa)", .absent = "0"},
    {.key = "sxy", .bounds = unbounded(" Pa"), .only = "stress", .meaning = "σxy at y_ref", .absent = "0"},
    {.key = "y_ref", .bounds = unbounded(" m"), .only = "stress", .meaning = "The level of σ0", .absent = "0"},
    {.key = "dsxx_dy", .bounds = unbounded(" Pa/m"), .only = "stress", .meaning = "dσxx/dy", .absent = "0"},
    {.key = "dsyy_dy", .bounds = unbounded(" Pa/m"), .only = "stress", .meaning = "dσyy/dy", .absent = "0"},
    {.key = "dsxy_dy", .bounds = unbounded(" Pa/m"), .only = "stress", .meaning = "dσxy/dy", .absent = "0"},
    {.key = "pulse", .kind = KeyKind::choice, .only = "viscous",
     .meaning = "The incident wave's particle velocity at the boundary, v(t) from `start`: ricker (peak frequency "
                "f, its peak 1.2/f after start), half_sine (one half period of sin 2πft), harmonic (sin 2πft "
                "over `cycles` periods), file (a CSV record of time and particle velocity: `file`); sent in as the "
                "traction 2 ρ c v(t) (the dashpot takes half)",
     .absent = "none: the boundary only absorbs", .words = pulse_words},
    {.key = "wave", .kind = KeyKind::choice, .only = "viscous",
     .meaning = "p: the particle velocity along the inward normal (c = c_p); s: along the edge, counter-clockwise "
                "about the model (c = c_s)",
     .absent = "p", .words = wave_words},
    {.key = "file", .kind = KeyKind::text, .only = "viscous",
     .meaning = "pulse = \"file\": a CSV of rows time (s, from `start`), particle velocity (m/s), times increasing "
                "(a header line and # comments skipped), relative to the model file; linear between rows, 0 after "
                "the last",
     .absent = "required with pulse = \"file\""},
    {.key = "velocity", .bounds = unbounded(" m/s"), .only = "viscous",
     .meaning = "The incident wave's peak particle velocity; with a file, the factor on its velocities",
     .absent = "0; with a file, 1",
     .set = [](BoundarySpec& s, double v) { s.incident.velocity = v; }},
    {.key = "frequency", .bounds = above(0, " Hz"), .only = "viscous", .meaning = "Of the pulse",
     .absent = "required with a named pulse (not with a file)", .set = [](BoundarySpec& s, double v) { s.incident.frequency = v; }},
    {.key = "cycles", .bounds = above(0, ""), .only = "viscous", .meaning = "harmonic: the train's length in periods",
     .absent = "1", .set = [](BoundarySpec& s, double v) { s.incident.cycles = v; }},
    {.key = "start", .bounds = at_least(0, " s"), .only = "viscous",
     .meaning = "When the pulse starts, in the model's time", .absent = "0",
     .set = [](BoundarySpec& s, double v) { s.incident.start = v; }},
};

/// Every key of [[joint_assignment]]: the rules are applied in file order, a later
/// rule that matches a joint overriding an earlier one.
inline constexpr AssignmentKey assignment_keys[] = {
    {.key = "property", .kind = KeyKind::text, .required = true, .meaning = "The name of a [[joint_property]]"},
    {.key = "tags", .kind = KeyKind::names,
     .meaning = "An array of the kinds of joint the rule applies to, not empty, no repeats: inner (between the inner "
                "blocks of a voronoi, delaunay, hexagonal or brick pattern), radial and peripheral (trigon: within "
                "one Voronoi cell, between cells), real_joint (a real discontinuity), interface (between regions), "
                "fracture (a [[region.dfn]] set's; a set's own property overrides the rules)",
     .absent = "every tag", .words = joint_tag_words},
    {.key = "regions", .kind = KeyKind::names,
     .meaning = "The rule applies to joints between blocks of these regions; not empty, no repeats",
     .absent = "any region"},
};
#pragma GCC diagnostic pop

/// docs/reference/boundary.md: the tables of keys.
inline std::string boundary_keys_markdown() {
    return "# [[boundary]] and [[joint_assignment]] keys\n\n"
           "Generated from core/boundary_keys.hpp by tests/test_reference.cpp (`BBM_WRITE_REFERENCE=1` rewrites it; "
           "the test fails when it is stale). How blocks and edges are selected, `touching` and the stress a "
           "`touching` boundary adds to its blocks: [input.md](../input.md).\n\n"
           "## [[boundary]]\n\nA boundary acts in every stage; its selection is made once, in the initial "
           "geometry. Keys of the other type are errors.\n\n" +
           key_table_markdown(boundary_keys, "types") +
           "\n## [[joint_assignment]]\n\nWhich property set the joints of the initial assembly get; contacts formed "
           "during the run get `[solver]`'s `new_contact_property`.\n\n" +
           key_table_markdown(assignment_keys);
}

} // namespace bbm
