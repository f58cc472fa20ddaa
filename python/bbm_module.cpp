// bbm python: the extension module _bbm behind the `bbm` package (python/bbm/).
//
// A thin front end on the library (studies/): Model is studies::Model; the lab
// tests and the calibration parse their keyword arguments, turned into option
// strings by bbm/__init__.py, with the program's own option definitions.
//
// Arrays: the state the solver keeps in flat arrays that never move once the
// model is built (block centroids, velocities, rotations, areas, regions; FE node
// positions and velocities; zone corners, stresses and strains) is handed out as
// read-only numpy views of the solver's memory, alive as long as the model.
// Values derived on request (displacements, block stresses, zone areas) and the
// contact arrays are fresh arrays: contacts are created and removed as blocks
// move, so their storage grows and moves during a run, and a view of it would
// dangle. The GIL is released while the loop runs; a callback, or Ctrl-C every
// 1,000 steps, takes it back.
#include "base/error.hpp"
#include "studies/commands.hpp"
#include "studies/envelope.hpp"
#include "studies/model.hpp"
#include "studies/shear.hpp"

#include <nlohmann/json.hpp>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <cstring>
#include <mutex>
#include <optional>

namespace py = pybind11;
using namespace bbm;
using studies::Model;

namespace {

py::object json_to_python(const nlohmann::json& j) {
    return py::module_::import("json").attr("loads")(j.dump());
}

/// A read-only numpy view of `count` rows of `cols` values of type T starting at
/// `data`, `stride` bytes between rows; `owner` keeps the memory alive.
template <class T>
py::array view(const void* data, py::ssize_t count, py::ssize_t cols, py::ssize_t stride, py::handle owner) {
    std::vector<py::ssize_t> shape{count}, strides{stride};
    if (cols > 0) shape.push_back(cols), strides.push_back(sizeof(T));
    py::array a(py::dtype::of<T>(), shape, strides, data, owner);
    py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
    return a;
}

template <class T>
py::array_t<T> fresh(py::ssize_t count, py::ssize_t cols = 0) {
    if (cols > 0) return py::array_t<T>({count, cols});
    return py::array_t<T>(count);
}

/// Runs `work` without the GIL; a Python callback every `every` steps, and a check
/// for Ctrl-C every 1,000 steps. A Python exception raised in the callback (or
/// KeyboardInterrupt) stops the run after that step and is raised here.
template <class Work>
void run_released(Model& m, const std::optional<py::function>& callback, long every, Work&& work) {
    std::optional<py::error_already_set> failure;
    studies::ModelProgress progress;
    progress.every = every > 0 ? every : 1000;
    progress.callback = [&](const Model&) {
        py::gil_scoped_acquire gil;
        try {
            if (PyErr_CheckSignals() != 0) throw py::error_already_set();
            if (!callback) return true;
            const py::object r = (*callback)(py::cast(m, py::return_value_policy::reference));
            return r.is_none() || r.cast<bool>();
        } catch (py::error_already_set& e) {
            failure.emplace(std::move(e));
            return false;
        }
    };
    {
        py::gil_scoped_release release;
        work(progress);
    }
    if (failure) throw std::move(*failure);
}

/// The arrays of a solver's state: `model` keeps it alive (views point into it);
/// a lab test's frame has none, and its arrays are copied at once (snapshot()).
struct StateArrays {
    py::object model;
    const Solver* solver = nullptr;
};
struct BlockArrays : StateArrays {};
struct ContactArrays : StateArrays {};
struct ZoneArrays : StateArrays {};
struct NodeArrays : StateArrays {};
struct BoltArrays : StateArrays {};
struct LinerArrays : StateArrays {};

const Solver& solver_of(const StateArrays& a) { return *a.solver; }

template <class Arrays>
Arrays arrays_of(py::object model) {
    Arrays a;
    a.solver = &model.cast<const Model&>().solver();
    a.model = std::move(model);
    return a;
}

/// A fresh array of one value per contact (or `cols` values: get fills a row).
template <class T, class Get>
py::array_t<T> per_contact(const ContactArrays& a, Get get, py::ssize_t cols = 0) {
    const Solver& s = solver_of(a);
    const auto& c = s.contacts();
    auto out = fresh<T>(c.size(), cols);
    T* data = out.mutable_data();
    for (int i = 0; i < c.size(); ++i) get(s, c, i, data + (cols > 0 ? cols * i : i));
    return out;
}

/// Every property of `arrays`, copied, as a dict (the solver outlives it not).
py::dict copy_properties(py::object arrays, std::initializer_list<const char*> names) {
    py::dict d;
    for (const char* n : names) d[n] = arrays.attr(n).attr("copy")();
    return d;
}

/// A lab test's state at a frame, copied: the point of the curve, blocks and contacts.
py::dict frame_snapshot(const Solver& s, const StressStrainPoint& p, int realization) {
    py::dict d;
    d["realization"] = realization, d["step"] = p.step, d["axial_strain"] = p.axial_strain;
    d["axial_stress"] = p.axial_stress, d["lateral_strain"] = p.lateral_strain;
    d["cracks_tensile"] = p.cracks_tensile, d["cracks_shear"] = p.cracks_shear;
    BlockArrays b;
    b.solver = &s, b.model = py::none();
    d["blocks"] = copy_properties(py::cast(b), {"centroid", "velocity", "rotation", "area", "region", "removed",
                                                "displacement", "stress"});
    ContactArrays c;
    c.solver = &s, c.model = py::none();
    d["contacts"] = copy_properties(py::cast(c), {"normal_stress", "shear_stress", "normal_displacement",
                                                  "shear_displacement", "damage", "state", "bonded", "property",
                                                  "block_pair", "length", "normal", "position", "edge_parameter"});
    d["property_names"] = s.property_names();
    return d;
}

/// A field of the solver's state list (core/state_fields.hpp) as a numpy copy:
/// shape (count,) or (count, components); records as their bytes (uint8).
py::array state_field_array(const StateField& f) {
    auto dtype = [&]() -> py::dtype {
        switch (f.type) {
        case ScalarType::f64: return py::dtype::of<double>();
        case ScalarType::f32: return py::dtype::of<float>();
        case ScalarType::i32: return py::dtype::of<std::int32_t>();
        case ScalarType::i64: return py::dtype::of<std::int64_t>();
        case ScalarType::u32: return py::dtype::of<std::uint32_t>();
        case ScalarType::u64: return py::dtype::of<std::uint64_t>();
        case ScalarType::u8:
        case ScalarType::record: break;
        }
        return py::dtype::of<std::uint8_t>();
    }();
    std::vector<py::ssize_t> shape{py::ssize_t(f.size())};
    if (f.components > 1) shape.push_back(f.components);
    py::array out(dtype, shape);
    if (!f.bytes.empty()) std::memcpy(out.mutable_data(), f.bytes.data(), f.bytes.size());
    return out;
}

const char* group_name(MemoryGroup g) {
    switch (g) {
    case MemoryGroup::blocks: return "blocks";
    case MemoryGroup::vertices: return "vertices";
    case MemoryGroup::nodes: return "nodes";
    case MemoryGroup::zones: return "zones";
    case MemoryGroup::contacts: return "contacts";
    case MemoryGroup::other: break;
    }
    return "other";
}

} // namespace

PYBIND11_MODULE(_bbm, mod) {
    mod.doc() = "bbm: bonded-block models of rock failure (2D, plane strain) — the compiled core of the bbm package";

    // Exceptions: bbm.InputError (a ValueError) carries file, line and key.
    static py::exception<InputError> input_error(mod, "InputError", PyExc_ValueError);
    static py::exception<NumericalError> numerical_error(mod, "NumericalError", PyExc_RuntimeError);
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const InputError& e) {
            py::object err = py::reinterpret_borrow<py::object>(input_error.ptr())(py::str(e.what()));
            err.attr("file") = e.file();
            err.attr("line") = e.line();
            err.attr("key") = e.key();
            err.attr("message") = e.message();
            PyErr_SetObject(input_error.ptr(), err.ptr());
        } catch (const GeometryError& e) {
            py::object err = py::reinterpret_borrow<py::object>(input_error.ptr())(py::str(e.what()));
            err.attr("file") = "";
            err.attr("line") = 0;
            err.attr("key") = e.key();
            err.attr("message") = std::string(e.what());
            PyErr_SetObject(input_error.ptr(), err.ptr());
        } catch (const NumericalError& e) {
            numerical_error(e.what());
        }
    });

    py::class_<BlockArrays>(mod, "BlockArrays", "Per-block arrays (N = blocks, excavated ones included)")
        .def_property_readonly("count", [](const BlockArrays& a) { return solver_of(a).blocks().count(); })
        .def_property_readonly("centroid", [](const BlockArrays& a) {
            const auto& b = solver_of(a).blocks();
            return view<double>(b.centroid.data(), b.count(), 2, sizeof(Vec2), a.model);
        }, "N×2 current centroids, m (view)")
        .def_property_readonly("velocity", [](const BlockArrays& a) {
            const auto& b = solver_of(a).blocks();
            return view<double>(b.velocity.data(), b.count(), 2, sizeof(Vec2), a.model);
        }, "N×2 velocities, m/s (quasi-static: m per step) (view)")
        .def_property_readonly("rotation", [](const BlockArrays& a) {
            const auto& b = solver_of(a).blocks();
            return view<double>(b.theta.data(), b.count(), 0, sizeof(double), a.model);
        }, "N rotations, rad, counter-clockwise (view)")
        .def_property_readonly("area", [](const BlockArrays& a) {
            const auto& b = solver_of(a).blocks();
            return view<double>(b.area.data(), b.count(), 0, sizeof(double), a.model);
        }, "N areas, m² (view)")
        .def_property_readonly("region", [](const BlockArrays& a) {
            const auto& b = solver_of(a).blocks();
            return view<int>(b.region.data(), b.count(), 0, sizeof(int), a.model);
        }, "N region indices into Model.region_names (view)")
        .def_property_readonly("removed", [](const BlockArrays& a) {
            const auto& b = solver_of(a).blocks();
            return view<std::uint8_t>(b.removed.data(), b.count(), 0, 1, a.model).attr("astype")("bool");
        }, "N flags: excavated")
        .def_property_readonly("deformable", [](const BlockArrays& a) {
            const auto& b = solver_of(a).blocks();
            return view<std::uint8_t>(b.deformable.data(), b.count(), 0, 1, a.model).attr("astype")("bool");
        }, "N flags: meshed into zones")
        .def_property_readonly("displacement", [](const BlockArrays& a) {
            const auto& b = solver_of(a).blocks();
            auto out = fresh<double>(b.count(), 2);
            auto o = out.mutable_unchecked<2>();
            for (int i = 0; i < b.count(); ++i) {
                const Vec2 d = b.centroid[i] - b.centroid0[i];
                o(i, 0) = d.x, o(i, 1) = d.y;
            }
            return out;
        }, "N×2 centroid displacements since the start, m (computed)")
        .def_property_readonly("stress", [](const BlockArrays& a) {
            const auto s = solver_of(a).block_stresses();
            auto out = fresh<double>(py::ssize_t(s.size()), 3);
            auto o = out.mutable_unchecked<2>();
            for (std::size_t i = 0; i < s.size(); ++i)
                for (int k = 0; k < 3; ++k) o(i, k) = s[i][k];
            return out;
        }, "N×3 block-averaged stress sxx, syy, sxy, Pa, tension positive (SPEC §7; computed)");

    py::class_<ContactArrays>(mod, "ContactArrays", "Per-contact arrays (M = contacts now; fresh copies)")
        .def_property_readonly("count", [](const ContactArrays& a) { return solver_of(a).contacts().size(); })
        .def_property_readonly("normal_stress", [](const ContactArrays& a) {
            return per_contact<double>(a, [](const Solver&, const contact::Contacts& c, int i, double* o) { *o = c.history[i].sn; });
        }, "M normal stresses σn, Pa, compression positive")
        .def_property_readonly("shear_stress", [](const ContactArrays& a) {
            return per_contact<double>(a, [](const Solver&, const contact::Contacts& c, int i, double* o) { *o = c.history[i].tau; });
        }, "M shear stresses τ, Pa")
        .def_property_readonly("damage", [](const ContactArrays& a) {
            return per_contact<double>(a, [](const Solver&, const contact::Contacts& c, int i, double* o) { *o = c.history[i].damage; });
        }, "M damage D of SPEC §4, 0 intact to 1 broken")
        .def_property_readonly("state", [](const ContactArrays& a) {
            return per_contact<std::int32_t>(a, [](const Solver&, const contact::Contacts& c, int i, std::int32_t* o) { *o = int(contact::state_of(c.history[i])); /* as contacts.vtu */ });
        }, "M states: 0 intact, 1 softening, 2 broken in tension, 3 broken in shear, 4 sliding")
        .def_property_readonly("bonded", [](const ContactArrays& a) {
            return per_contact<bool>(a, [](const Solver&, const contact::Contacts& c, int i, bool* o) { *o = c.history[i].bonded; });
        }, "M flags: the bond holds")
        .def_property_readonly("block_pair", [](const ContactArrays& a) {
            return per_contact<std::int32_t>(a, [](const Solver&, const contact::Contacts& c, int i, std::int32_t* o) { o[0] = c.vertex_block[i], o[1] = c.edge_block[i]; }, 2);
        }, "M×2 blocks: the vertex's, the edge's")
        .def_property_readonly("length", [](const ContactArrays& a) {
            return per_contact<double>(a, [](const Solver&, const contact::Contacts& c, int i, double* o) { *o = c.length[i]; });
        }, "M joint lengths the contacts stand for, m")
        .def_property_readonly("normal", [](const ContactArrays& a) {
            return per_contact<double>(a, [](const Solver&, const contact::Contacts& c, int i, double* o) { o[0] = c.normal[i].x, o[1] = c.normal[i].y; }, 2);
        }, "M×2 unit normals (out of the edge's block)")
        .def_property_readonly("position", [](const ContactArrays& a) {
            return per_contact<double>(a, [](const Solver& s, const contact::Contacts& c, int i, double* o) { const Vec2 x = s.blocks().vertex[c.vertex_id[i]];
                o[0] = x.x, o[1] = x.y; }, 2);
        }, "M×2 contact points (the vertices), m")
        .def_property_readonly("normal_displacement", [](const ContactArrays& a) {
            return per_contact<double>(a, [](const Solver&, const contact::Contacts& c, int i, double* o) { *o = c.history[i].un; });
        }, "M normal displacements un since bonding, m, opening positive (overlap negative)")
        .def_property_readonly("shear_displacement", [](const ContactArrays& a) {
            return per_contact<double>(a, [](const Solver&, const contact::Contacts& c, int i, double* o) { *o = c.history[i].us; });
        }, "M shear displacements us, m")
        .def_property_readonly("fluid_pressure", [](const ContactArrays& a) {
            return per_contact<double>(a, [](const Solver&, const contact::Contacts& c, int i, double* o) { *o = c.wet() ? c.fluid_pressure[i] : 0.0; });
        }, "M water pressures on the contacts, Pa ([flow]; 0 in a dry model): the law's normal_stress is the effective one")
        .def_property_readonly("aperture", [](const ContactArrays& a) {
            const Solver& s = solver_of(a);
            const auto values = s.flow() ? s.flow()->contact_apertures(s.contacts()) : std::vector<double>(s.contacts().size(), 0.0);
            auto out = fresh<double>(py::ssize_t(values.size()), 0);
            std::copy(values.begin(), values.end(), out.mutable_data());
            return out;
        }, "M hydraulic apertures of the contacts' joints, m ([flow]; 0: none or sealed)")
        .def_property_readonly("property", [](const ContactArrays& a) {
            return per_contact<std::int32_t>(a, [](const Solver&, const contact::Contacts& c, int i, std::int32_t* o) { *o = c.property[i]; });
        }, "M property sets (indices into Model.property_names; contacts formed in the run get solver.new_contact_property)")
        .def_property_readonly("edge_parameter", [](const ContactArrays& a) {
            return per_contact<double>(a, [](const Solver& s, const contact::Contacts& c, int i, double* o) {
                const auto& v = s.blocks().vertex;
                const Vec2 p = v[c.edge_id[i]], e = v[c.edge_end[i]] - p;
                *o = dot(v[c.vertex_id[i]] - p, e) / dot(e, e);
            });
        }, "M positions of the vertex along its edge, 0 to 1 (outside: a vertex past the edge's end, on the rounded corner)");

    py::class_<ZoneArrays>(mod, "ZoneArrays", "Per-zone arrays of deformable blocks (K = constant-strain triangles)")
        .def_property_readonly("count", [](const ZoneArrays& a) { return solver_of(a).zones().size(); })
        .def_property_readonly("nodes", [](const ZoneArrays& a) {
            const auto& z = solver_of(a).zones();
            return view<int>(z.node.data(), z.size(), 3, sizeof(std::array<int, 3>), a.model);
        }, "K×3 node indices, counter-clockwise (view)")
        .def_property_readonly("stress", [](const ZoneArrays& a) {
            const auto& z = solver_of(a).zones();
            return view<double>(z.stress.data(), z.size(), 3, sizeof(std::array<double, 3>), a.model);
        }, "K×3 stress sxx, syy, sxy, Pa, tension positive (view)")
        .def_property_readonly("strain", [](const ZoneArrays& a) {
            const auto& z = solver_of(a).zones();
            return view<double>(z.strain.data(), z.size(), 3, sizeof(std::array<double, 3>), a.model);
        }, "K×3 strain exx, eyy, exy (tensor shear) (view)")
        .def_property_readonly("block", [](const ZoneArrays& a) {
            const auto& z = solver_of(a).zones();
            return view<int>(z.block.data(), z.size(), 0, sizeof(int), a.model);
        }, "K owning blocks (view)")
        .def_property_readonly("region", [](const ZoneArrays& a) {
            const auto& s = solver_of(a);
            const auto& z = s.zones();
            auto out = fresh<std::int32_t>(z.size());
            auto o = out.mutable_unchecked<1>();
            for (int i = 0; i < z.size(); ++i) o(i) = s.blocks().region[z.block[i]];
            return out;
        }, "K region indices (computed)")
        .def_property_readonly("centroid", [](const ZoneArrays& a) {
            const auto& s = solver_of(a);
            const auto& z = s.zones();
            auto out = fresh<double>(z.size(), 2);
            auto o = out.mutable_unchecked<2>();
            for (int i = 0; i < z.size(); ++i) {
                const auto& p = s.nodes().position;
                const Vec2 c = (p[z.node[i][0]] + p[z.node[i][1]] + p[z.node[i][2]]) / 3.0;
                o(i, 0) = c.x, o(i, 1) = c.y;
            }
            return out;
        }, "K×2 current centroids, m (computed)")
        .def_property_readonly("area", [](const ZoneArrays& a) {
            const auto& s = solver_of(a);
            const auto& z = s.zones();
            auto out = fresh<double>(z.size());
            auto o = out.mutable_unchecked<1>();
            for (int i = 0; i < z.size(); ++i) {
                const auto& p = s.nodes().position;
                o(i) = 0.5 * cross(p[z.node[i][1]] - p[z.node[i][0]], p[z.node[i][2]] - p[z.node[i][0]]);
            }
            return out;
        }, "K current areas, m² (computed)");

    py::class_<NodeArrays>(mod, "NodeArrays", "Per-node arrays of deformable blocks")
        .def_property_readonly("count", [](const NodeArrays& a) { return solver_of(a).nodes().count(); })
        .def_property_readonly("position", [](const NodeArrays& a) {
            const auto& n = solver_of(a).nodes();
            return view<double>(n.position.data(), n.count(), 2, sizeof(Vec2), a.model);
        }, "n×2 positions, m (view)")
        .def_property_readonly("velocity", [](const NodeArrays& a) {
            const auto& n = solver_of(a).nodes();
            return view<double>(n.velocity.data(), n.count(), 2, sizeof(Vec2), a.model);
        }, "n×2 velocities (view)")
        .def_property_readonly("displacement", [](const NodeArrays& a) {
            const auto& n = solver_of(a).nodes();
            auto out = fresh<double>(n.count(), 2);
            auto o = out.mutable_unchecked<2>();
            for (int i = 0; i < n.count(); ++i) {
                const Vec2 d = n.position[i] - n.position0[i];
                o(i, 0) = d.x, o(i, 1) = d.y;
            }
            return out;
        }, "n×2 displacements since the start, m (computed)");

    py::class_<BoltArrays>(mod, "BoltArrays",
                           "Installed bolts (core/bolts.hpp): n nodes, s segments (segment i joins nodes "
                           "segment_node[i] and segment_node[i] + 1). Forces per bolt (times the out-of-plane spacing).")
        .def_property_readonly("node_count", [](const BoltArrays& a) { return solver_of(a).bolts().node_count(); })
        .def_property_readonly("segment_count", [](const BoltArrays& a) { return solver_of(a).bolts().segment_count(); })
        .def_property_readonly("position", [](const BoltArrays& a) {
            const auto& b = solver_of(a).bolts();
            return view<double>(b.position.data(), b.node_count(), 2, sizeof(Vec2), a.model);
        }, "n×2 node positions, m (view)")
        .def_property_readonly("segment_node", [](const BoltArrays& a) {
            const auto& b = solver_of(a).bolts();
            auto out = fresh<int>(b.segment_count());
            std::copy(b.segment_node.begin(), b.segment_node.end(), out.mutable_data());
            return out;
        }, "s first nodes of the segments")
        .def_property_readonly("axial_force", [](const BoltArrays& a) {
            const auto& b = solver_of(a).bolts();
            auto out = fresh<double>(b.segment_count());
            for (int i = 0; i < b.segment_count(); ++i)
                out.mutable_data()[i] = b.axial[i] * b.sets[b.node_set[b.segment_node[i]]].spacing;
            return out;
        }, "s axial forces, N per bolt, tension positive")
        .def_property_readonly("state", [](const BoltArrays& a) {
            const auto& b = solver_of(a).bolts();
            auto out = fresh<int>(b.segment_count());
            std::copy(b.state.begin(), b.state.end(), out.mutable_data());
            return out;
        }, "s segment states: 0 elastic, 1 yielded, 2 broken")
        .def_property_readonly("bond", [](const BoltArrays& a) {
            const auto& b = solver_of(a).bolts();
            auto out = fresh<double>(b.node_count());
            for (int i = 0; i < b.node_count(); ++i) out.mutable_data()[i] = b.bond[i] * b.sets[b.node_set[i]].spacing;
            return out;
        }, "n grout forces along the bolt, N per m of bolt, per bolt")
        .def_property_readonly("set", [](const BoltArrays& a) {
            const auto& b = solver_of(a).bolts();
            auto out = fresh<int>(b.node_count());
            std::copy(b.node_set.begin(), b.node_set.end(), out.mutable_data());
            return out;
        }, "n set index of each node (set_names)")
        .def_property_readonly("set_names", [](const BoltArrays& a) { return solver_of(a).support<BoltSupport>().set_names(); });

    py::class_<LinerArrays>(mod, "LinerArrays",
                            "Installed liners (core/liners.hpp): n nodes, e beam elements (element i joins nodes "
                            "element_node[i] and the next node of its liner). Per metre of tunnel.")
        .def_property_readonly("node_count", [](const LinerArrays& a) { return solver_of(a).liners().node_count(); })
        .def_property_readonly("element_count", [](const LinerArrays& a) { return solver_of(a).liners().element_count(); })
        .def_property_readonly("position", [](const LinerArrays& a) {
            const auto& l = solver_of(a).liners();
            return view<double>(l.position.data(), l.node_count(), 2, sizeof(Vec2), a.model);
        }, "n×2 node positions, m (view)")
        .def_property_readonly("element_node", [](const LinerArrays& a) {
            const auto& l = solver_of(a).liners();
            auto out = fresh<int>(l.element_count());
            std::copy(l.element_node.begin(), l.element_node.end(), out.mutable_data());
            return out;
        }, "e first nodes of the elements")
        .def_property_readonly("thrust", [](const LinerArrays& a) {
            const auto& l = solver_of(a).liners();
            auto out = fresh<double>(l.element_count());
            std::copy(l.thrust.begin(), l.thrust.end(), out.mutable_data());
            return out;
        }, "e thrusts, N/m, compression positive")
        .def_property_readonly("moment", [](const LinerArrays& a) {
            const auto& l = solver_of(a).liners();
            auto out = fresh<double>(l.element_count(), 2);
            for (int e = 0; e < l.element_count(); ++e)
                out.mutable_data()[2 * e] = l.moment_a[e], out.mutable_data()[2 * e + 1] = l.moment_b[e];
            return out;
        }, "e×2 end moments, N·m/m")
        .def_property_readonly("interface_normal_stress", [](const LinerArrays& a) {
            const auto& l = solver_of(a).liners();
            auto out = fresh<double>(l.node_count());
            std::copy(l.normal_stress.begin(), l.normal_stress.end(), out.mutable_data());
            return out;
        }, "n normal stresses on the wall, Pa, tension positive")
        .def_property_readonly("names", [](const LinerArrays& a) { return solver_of(a).support<LinerSupport>().set_names(); });

    py::class_<Model>(mod, "Model")
        .def(py::init([](const std::string& path, int threads, double max_elements) {
                 py::gil_scoped_release release;
                 return Model::from_file(path, threads, max_elements);
             }),
             py::arg("path"), py::arg("threads") = 1, py::arg("max_elements") = 0.0,
             "Reads a model file as `bbm run` does (bbm.InputError naming file, line and key) and builds it.")
        .def_static("_from_text", [](const std::string& text, const std::string& name, int threads, double max_elements) {
                 py::gil_scoped_release release;
                 return Model::from_text(text, name, threads, max_elements);
             }, py::arg("text"), py::arg("name"), py::arg("threads") = 1, py::arg("max_elements") = 0.0)
        .def_static("resume", [](const std::filesystem::path& path, int threads) {
                 py::gil_scoped_release release;
                 return Model::resume(path, threads);
             }, py::arg("path"), py::arg("threads") = 1,
             "A model saved by checkpoint(), ready to continue where it stopped.")
        .def("run", [](Model& m, std::optional<py::function> callback, long every) {
                 run_released(m, callback, every, [&](const studies::ModelProgress& p) { m.run(p); });
             }, py::arg("callback") = py::none(), py::arg("every") = 1000,
             "Runs the stages not yet done. callback(model) every `every` steps and at stage ends; returning "
             "False stops after that step (run() again continues).")
        .def("run_stage", [](Model& m, const std::string& name, std::optional<py::function> callback, long every) {
                 run_released(m, callback, every, [&](const studies::ModelProgress& p) { m.run_stage(name, p); });
             }, py::arg("name"), py::arg("callback") = py::none(), py::arg("every") = 1000,
             "Runs the stages up to and including the one named.")
        .def("step", [](Model& m, long n, std::optional<py::function> callback, long every) {
                 run_released(m, callback, every, [&](const studies::ModelProgress& p) { m.step(n, p); });
             }, py::arg("n") = 1, py::arg("callback") = py::none(), py::arg("every") = 1000,
             "n explicit steps with the boundary conditions as they stand.")
        .def("checkpoint", [](const Model& m, const std::filesystem::path& path) { m.checkpoint(path); },
             py::arg("path"), "Saves the model (its text and state) to continue with Model.resume(path).")
        .def("summary", [](const Model& m) { return json_to_python(m.summary()); },
             "The dict of summary.json (as `bbm run` writes it) for the state now.")
        .def("write_vtk", [](const Model& m, const std::filesystem::path& dir) { m.write_vtk(dir); }, py::arg("dir"),
             "Writes DIR/blocks.vtu, contacts.vtu and result.pvd of the state now, for ParaView.")
        .def_property_readonly("blocks", [](py::object self) { return arrays_of<BlockArrays>(self); })
        .def_property_readonly("contacts", [](py::object self) { return arrays_of<ContactArrays>(self); })
        .def_property_readonly("zones", [](py::object self) { return arrays_of<ZoneArrays>(self); })
        .def_property_readonly("nodes", [](py::object self) { return arrays_of<NodeArrays>(self); })
        .def_property_readonly("bolts", [](py::object self) { return arrays_of<BoltArrays>(self); },
                               "Installed bolts: positions, axial forces, grout forces, states")
        .def_property_readonly("liners", [](py::object self) { return arrays_of<LinerArrays>(self); },
                               "Installed liners: positions, thrusts, moments, interface stresses")
        .def_property_readonly("flow", [](const Model& m) -> py::object {
            const JointFlow* f = m.solver().flow();
            if (!f) return py::none();
            const auto& net = f->network();
            const auto& st = f->state();
            auto domains = fresh<double>(net.domains(), 2), pressure = fresh<double>(net.domains(), 0);
            auto aperture = fresh<double>(net.pipes(), 0), rate = fresh<double>(net.pipes(), 0);
            auto pipes = fresh<std::int32_t>(net.pipes(), 2);
            const auto q = flow::pipe_flows(net, f->fluid(), st);
            for (int d = 0; d < net.domains(); ++d) {
                domains.mutable_data()[2 * d] = net.domain_position[d].x, domains.mutable_data()[2 * d + 1] = net.domain_position[d].y;
                pressure.mutable_data()[d] = st.pressure[d];
            }
            for (int k = 0; k < net.pipes(); ++k) {
                aperture.mutable_data()[k] = flow::hydraulic_aperture(f->fluid(), st.aperture[k]);
                rate.mutable_data()[k] = q[k];
                pipes.mutable_data()[2 * k] = net.pipe_from[k], pipes.mutable_data()[2 * k + 1] = net.pipe_to[k];
            }
            py::dict d;
            d["domain_position"] = domains, d["pressure"] = pressure, d["pipes"] = pipes, d["aperture"] = aperture;
            d["flow_rate"] = rate, d["inflow"] = f->inflow();
            return d;
        }, "Water in the joints ([flow]; None when dry), copied: domain_position (D×2, m), pressure (D, Pa), pipes "
           "(P×2 domains), aperture (P, m), flow_rate (P, m²/s per m, from the first domain to the second), inflow "
           "(into the drained openings, m²/s per m)")
        .def_property_readonly("steps", [](const Model& m) { return m.solver().steps(); })
        .def_property_readonly("time", [](const Model& m) { return m.solver().time(); })
        .def_property_readonly("unbalanced_ratio", [](const Model& m) { return m.solver().unbalanced_ratio(); })
        .def("state_fields", [](Model& m) {
                 py::list out;
                 for (const auto& f : m.solver().state_fields()) {
                     py::dict d;
                     d["name"] = f.name, d["indexed_by"] = group_name(f.group), d["count"] = f.size();
                     d["saved"] = bool(f.uses & field_use::saved), d["hashed"] = bool(f.uses & field_use::hashed);
                     d["model"] = bool(f.uses & field_use::model), d["bytes"] = f.capacity_bytes;
                     out.append(d);
                 }
                 return out;
             },
             "Every field of the solver's state list, as the checkpoint, state hash and memory report see it: "
             "name, what it is indexed by, count, whether saved / hashed / fixed by the model file, bytes held.")
        .def("state", [](Model& m, const std::string& name) {
                 for (const auto& f : m.solver().state_fields())
                     if (f.name == name) return state_field_array(f);
                 throw py::key_error("no state field '" + name + "' (Model.state_fields() lists them)");
             }, py::arg("name"), "A copy of one field of the state list (Model.state_fields()) as a numpy array.")
        .def_property_readonly("state_hash", [](const Model& m) { return std::to_string(m.solver().state_hash()); },
                               "The hash summary.json reports: equal hashes, equal states")
        .def_property_readonly("cracks", [](const Model& m) {
            return py::dict(py::arg("tensile") = m.solver().cracks(contact::JointState::broken_tension),
                            py::arg("shear") = m.solver().cracks(contact::JointState::broken_shear));
        })
        .def_property_readonly("stage_names", &Model::stage_names)
        .def_property_readonly("stages_done", [](const Model& m) {
            std::vector<std::string> names;
            const auto all = m.stage_names();
            for (int k = 0; k < m.cursor().stage && k < int(all.size()); ++k) names.push_back(all[k]);
            return names;
        })
        .def_property_readonly("region_names", [](const Model& m) { return m.solver().region_names(); })
        .def_property_readonly("property_names", [](const Model& m) { return m.solver().property_names(); })
        .def_property_readonly("name", &Model::name);

    mod.def("_labtest", [](const std::string& command, const std::vector<std::string>& args, bool quiet,
                           std::optional<py::function> callback) {
        studies::LabTestStudy study;
        std::function<void(const Solver&, const StressStrainPoint&, int)> on_frame;
        std::optional<py::error_already_set> failure;
        std::mutex once; // realizations on several threads: one callback at a time
        if (callback)
            on_frame = [&](const Solver& s, const StressStrainPoint& p, int realization) {
                std::lock_guard lock(once);
                py::gil_scoped_acquire gil;
                if (failure) return;
                try {
                    (*callback)(frame_snapshot(s, p, realization));
                } catch (py::error_already_set& e) {
                    failure.emplace(std::move(e));
                }
            };
        {
            py::gil_scoped_release release;
            study = studies::run_labtest_args(command, args, quiet, on_frame);
        }
        if (failure) throw std::move(*failure);
        py::list curves;
        for (const auto& r : study.results) {
            const auto n = py::ssize_t(r.curve.size());
            auto step = fresh<std::int64_t>(n);
            auto axial_strain = fresh<double>(n), axial_stress = fresh<double>(n), lateral_strain = fresh<double>(n);
            auto tensile = fresh<std::int32_t>(n), shear = fresh<std::int32_t>(n);
            auto ratio = fresh<double>(n), rate = fresh<double>(n);
            for (py::ssize_t i = 0; i < n; ++i) {
                const auto& p = r.curve[i];
                step.mutable_at(i) = p.step, axial_strain.mutable_at(i) = p.axial_strain;
                axial_stress.mutable_at(i) = p.axial_stress, lateral_strain.mutable_at(i) = p.lateral_strain;
                tensile.mutable_at(i) = p.cracks_tensile, shear.mutable_at(i) = p.cracks_shear;
                ratio.mutable_at(i) = p.unbalanced_ratio, rate.mutable_at(i) = p.strain_per_step;
            }
            py::dict c;
            c["step"] = step, c["axial_strain"] = axial_strain, c["axial_stress"] = axial_stress;
            c["lateral_strain"] = lateral_strain, c["cracks_tensile"] = tensile, c["cracks_shear"] = shear;
            c["unbalanced_ratio"] = ratio, c["strain_per_step"] = rate;
            curves.append(c);
        }
        return py::make_tuple(py::module_::import("json").attr("loads")(study.summary_json), curves);
    }, py::arg("command"), py::arg("args"), py::arg("quiet"), py::arg("callback") = py::none());
    mod.def("_envelope", [](const std::vector<std::string>& args, bool quiet) {
        std::string json;
        {
            py::gil_scoped_release release;
            json = studies::run_envelope_args(args, quiet).summary_json;
        }
        return py::module_::import("json").attr("loads")(json);
    });
    mod.def("_shear", [](const std::vector<std::string>& args, bool quiet) {
        studies::ShearStudy study;
        {
            py::gil_scoped_release release;
            study = studies::run_shear_args(args, quiet);
        }
        // Every run's curve as numpy arrays, in the order of summary["runs"].
        py::list curves;
        for (const auto& r : study.results) {
            const auto n = py::ssize_t(r.curve.size());
            auto step = fresh<std::int64_t>(n);
            auto u = fresh<double>(n), tau = fresh<double>(n), sn = fresh<double>(n), dv = fresh<double>(n);
            auto tensile = fresh<std::int32_t>(n), shear = fresh<std::int32_t>(n);
            for (py::ssize_t i = 0; i < n; ++i) {
                const auto& p = r.curve[i];
                step.mutable_at(i) = p.step, u.mutable_at(i) = p.displacement, tau.mutable_at(i) = p.shear_stress;
                sn.mutable_at(i) = p.normal_stress, dv.mutable_at(i) = p.dilation;
                tensile.mutable_at(i) = p.cracks_tensile, shear.mutable_at(i) = p.cracks_shear;
            }
            py::dict c;
            c["step"] = step, c["shear_displacement"] = u, c["shear_stress"] = tau, c["normal_stress"] = sn;
            c["dilation"] = dv, c["cracks_tensile"] = tensile, c["cracks_shear"] = shear;
            curves.append(c);
        }
        return py::make_tuple(py::module_::import("json").attr("loads")(study.summary_json), curves);
    });
    mod.def("_calibrate", [](const std::vector<std::string>& args, bool quiet) {
        std::string json;
        {
            py::gil_scoped_release release;
            json = studies::run_calibrate_args(args, quiet);
        }
        return py::module_::import("json").attr("loads")(json);
    });
}
