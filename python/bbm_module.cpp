// bbm python: the extension module _bbm behind the `bbm` package (python/bbm/).
//
// A thin front end on the library (studies/): Model is studies::Model; the lab
// tests and the calibration parse their keyword arguments, turned into option
// strings by bbm/__init__.py, with the program's own option definitions.
//
// Arrays: every field of the world's state list (core/world.hpp) is an attribute
// of its group — model.blocks.centroid is "blocks.centroid", a support type's
// fields are model.<type>.<field> — generated from the list (FieldGroup), so a field added to a
// part, or a support type added to the registry, is in Python with no line here.
// Groups whose arrays never move once the model is built (blocks, nodes, zones)
// hand out read-only numpy views of the world's memory, alive as long as the
// model; the others fresh copies: contacts are created and removed as blocks
// move, so their storage grows and moves during a run, and a view of it would
// dangle. Values derived on request (displacements, block stresses, the joints'
// stresses) are the groups' properties. The GIL is released while the loop
// runs; a callback, or Ctrl-C every 1,000 steps, takes it back.
#include "base/error.hpp"
#include "core/events.hpp"
#include "core/measures.hpp"
#include "apps/flags.hpp"
#include "studies/lab/envelope.hpp"
#include "studies/model/model.hpp"
#include "studies/lab/shear.hpp"

#include <nlohmann/json.hpp>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <cstring>
#include <deque>
#include <mutex>
#include <optional>

namespace py = pybind11;
using namespace bbm;
using studies::Model;

namespace {

py::object json_to_python(const nlohmann::json& j) {
    return py::module_::import("json").attr("loads")(j.dump());
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

/// A group of the world's field list — every field named "<group>.<name>"
/// (core/world.hpp, Model.state_fields()) — as an object whose attributes are
/// those fields: `model.blocks.centroid` is the field "blocks.centroid". Groups
/// whose arrays never move once the model is built (blocks, nodes, zones) give
/// read-only numpy views of the world's memory, alive as long as the model; the
/// others (contacts, which detection creates and removes, supports, which grow
/// at an install) give fresh copies. Values derived on request (displacements,
/// block stresses, contact stresses from their histories) are the groups'
/// properties. A lab test's frame has no model: its arrays are copied at once
/// (frame_snapshot()).
struct FieldGroup {
    py::object model;
    World* world = nullptr;
    std::string prefix;
    bool views = false; ///< its fields as views (storage that never moves), else copies
};
struct BlockArrays : FieldGroup {};
struct ContactArrays : FieldGroup {};
struct ZoneArrays : FieldGroup {};
struct NodeArrays : FieldGroup {};
struct SupportArrays : FieldGroup {};

const World& world_of(const FieldGroup& g) { return *g.world; }

template <class Group>
Group group_of(py::object model, std::string prefix, bool views) {
    Group g;
    g.world = &model.cast<Model&>().solver().world();
    g.model = std::move(model);
    g.prefix = std::move(prefix);
    g.views = views;
    return g;
}

py::dtype dtype_of(const StateField& f) {
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
}

/// A field of the state list (base/fields.hpp) as a numpy array: shape (count,)
/// or (count, components), records as their bytes (uint8); a view of the world's
/// memory (read-only, `owner` keeping it alive) or a copy.
py::array field_array(const StateField& f, py::handle owner, bool as_view) {
    const py::dtype dtype = dtype_of(f);
    const auto scalar = py::ssize_t(dtype.itemsize());
    std::vector<py::ssize_t> shape{py::ssize_t(f.size())}, strides{py::ssize_t(f.stride)};
    if (f.components > 1) shape.push_back(f.components), strides.push_back(scalar);
    if (as_view) {
        py::array a(dtype, shape, strides, f.data, owner);
        py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
        return a;
    }
    py::array out(dtype, shape);
    auto* to = static_cast<std::byte*>(out.mutable_data());
    for (std::size_t k = 0; k < f.size(); ++k) std::memcpy(to + k * f.element_size, f.element(k), f.element_size);
    return out;
}

/// The field `<group>.<name>`, or AttributeError naming what the group has.
py::object group_field(const FieldGroup& g, const std::string& name) {
    const std::string full = g.prefix + "." + name;
    if (g.prefix == "contacts") contacts(*g.world); // the normals up to date
    std::string known;
    for (const auto& f : state_fields(*g.world)) {
        if (f.name == full) return field_array(f, g.model, g.views);
        if (f.name.rfind(g.prefix + ".", 0) == 0) known += (known.empty() ? "" : ", ") + f.name.substr(g.prefix.size() + 1);
    }
    throw py::attribute_error("'" + g.prefix + "' has no field '" + name + "' (its fields: " + known + ")");
}

/// The names of the group's fields.
std::vector<std::string> group_fields(const FieldGroup& g) {
    std::vector<std::string> out;
    for (const auto& f : state_fields(*g.world))
        if (f.name.rfind(g.prefix + ".", 0) == 0) out.push_back(f.name.substr(g.prefix.size() + 1));
    return out;
}

/// What every group class has: its fields as attributes, their names, dir().
template <class Group>
py::class_<Group> group_class(py::module_& mod, const char* name, const char* doc) {
    py::class_<Group> cls(mod, name, doc);
    cls.def("__getattr__", [](const Group& g, const std::string& field) { return group_field(g, field); })
        .def("__dir__", [](py::object self) {
            py::list names = py::module_::import("builtins").attr("object").attr("__dir__")(self);
            for (const auto& f : group_fields(self.cast<const Group&>())) names.append(f);
            return names;
        })
        .def_property_readonly("fields", [](const Group& g) { return group_fields(g); },
                               "The names of the group's fields (Model.state_fields(): saved, hashed, … each)");
    return cls;
}

template <class T>
py::array_t<T> fresh(py::ssize_t count, py::ssize_t cols = 0) {
    if (cols > 0) return py::array_t<T>({count, cols});
    return py::array_t<T>(count);
}

/// A fresh array of one value per contact (or `cols` values: get fills a row).
template <class T, class Get>
py::array_t<T> per_contact(const ContactArrays& a, Get get, py::ssize_t cols = 0) {
    const World& w = world_of(a);
    const auto& c = contacts(w);
    auto out = fresh<T>(c.size(), cols);
    T* data = out.mutable_data();
    for (int i = 0; i < c.size(); ++i) get(w, c, i, data + (cols > 0 ? cols * i : i));
    return out;
}

/// Every property of `arrays`, copied, as a dict (the world outlives it not).
py::dict copy_properties(py::object arrays, std::initializer_list<const char*> names) {
    py::dict d;
    for (const char* n : names) d[n] = py::array(arrays.attr(n)).attr("copy")();
    return d;
}

/// A lab test's state at a frame, copied: the point of the curve, blocks and contacts.
py::dict frame_snapshot(const Solver& s, const StressStrainPoint& p, int realization) {
    py::dict d;
    d["realization"] = realization, d["step"] = p.step, d["axial_strain"] = p.axial_strain;
    d["axial_stress"] = p.axial_stress, d["lateral_strain"] = p.lateral_strain;
    d["cracks_tensile"] = p.cracks_tensile, d["cracks_shear"] = p.cracks_shear;
    World& w = const_cast<World&>(s.world()); // read only: the groups take a World*
    BlockArrays b;
    b.world = &w, b.model = py::none(), b.prefix = "blocks";
    d["blocks"] = copy_properties(py::cast(b), {"centroid", "velocity", "rotation", "area", "region", "removed",
                                                "displacement", "stress"});
    ContactArrays c;
    c.world = &w, c.model = py::none(), c.prefix = "contacts";
    d["contacts"] = copy_properties(py::cast(c), {"normal_stress", "shear_stress", "normal_displacement",
                                                  "shear_displacement", "damage", "state", "bonded", "property",
                                                  "block_pair", "length", "normal", "position", "edge_parameter"});
    d["property_names"] = w.properties.names;
    return d;
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

/// A fresh array of the contacts' hydraulic apertures (0 in a dry model).
py::array_t<double> contact_aperture(const ContactArrays& a) {
    const World& w = world_of(a);
    const auto values = w.flow ? contact_apertures(*w.flow, contacts(w)) : std::vector<double>(w.contacts.size(), 0.0);
    auto out = fresh<double>(py::ssize_t(values.size()), 0);
    std::copy(values.begin(), values.end(), out.mutable_data());
    return out;
}

/// A fresh array of each contact's vertex position along its edge.
py::array_t<double> contact_edge_parameter(const ContactArrays& a) {
    using contact::Contacts;
    return per_contact<double>(a, [](const World& w, const Contacts& c, int i, double* o) {
        const auto& v = w.vertices.position;
        const Vec2 p = v[c.edge_id[i]], e = v[c.edge_end[i]] - p;
        *o = dot(v[c.vertex_id[i]] - p, e) / dot(e, e);
    });
}

/// The water in the joints, copied (None when dry): Model.flow.
py::object flow_arrays(const Model& m) {
    const auto& flow = m.solver().world().flow;
    if (!flow) return py::none();
    const JointFlow* f = &*flow;
    const auto& net = f->net;
    const auto& st = f->state;
    auto domains = fresh<double>(net.domains(), 2), pressure = fresh<double>(net.domains(), 0);
    auto aperture = fresh<double>(net.pipes(), 0), rate = fresh<double>(net.pipes(), 0);
    auto pipes = fresh<std::int32_t>(net.pipes(), 2);
    const auto q = flow::pipe_flows(net, f->fluid, st);
    for (int d = 0; d < net.domains(); ++d) {
        domains.mutable_data()[2 * d] = net.domain_position[d].x, domains.mutable_data()[2 * d + 1] = net.domain_position[d].y;
        pressure.mutable_data()[d] = st.pressure[d];
    }
    for (int k = 0; k < net.pipes(); ++k) {
        aperture.mutable_data()[k] = flow::hydraulic_aperture(f->fluid, st.aperture[k]);
        rate.mutable_data()[k] = q[k];
        pipes.mutable_data()[2 * k] = net.pipe_from[k], pipes.mutable_data()[2 * k + 1] = net.pipe_to[k];
    }
    py::dict d;
    d["domain_position"] = domains, d["pressure"] = pressure, d["pipes"] = pipes, d["aperture"] = aperture;
    d["flow_rate"] = rate, d["inflow"] = inflow(*f);
    return d;
}

/// The events catalogue ([events]; None without it), copied as numpy arrays, one
/// row an event: the closed ones and, as if closed now, the open ones with a
/// broken bond (core/events.hpp).
py::object event_arrays(const Model& m) {
    const auto& events = m.solver().world().events;
    if (!events) return py::none();
    const std::vector<SeismicEvent> cat = event_catalogue(*events);
    const auto n = py::ssize_t(cat.size());
    auto time = fresh<double>(n), moment = fresh<double>(n), moment_nm = fresh<double>(n), magnitude = fresh<double>(n);
    auto r_value = fresh<double>(n), length = fresh<double>(n), energy = fresh<double>(n), fracture = fresh<double>(n);
    auto position = fresh<double>(n, 2), tensor = fresh<double>(n, 3), settled = fresh<double>(n, 3);
    auto step = fresh<std::int64_t>(n), first_step = fresh<std::int64_t>(n);
    auto bonds = fresh<std::int32_t>(n), tensile = fresh<std::int32_t>(n);
    std::vector<std::string> type;
    for (py::ssize_t k = 0; k < n; ++k) {
        const SeismicEvent& e = cat[std::size_t(k)];
        time.mutable_data()[k] = e.time, step.mutable_data()[k] = e.step, first_step.mutable_data()[k] = e.first_step;
        position.mutable_data()[2 * k] = e.position.x, position.mutable_data()[2 * k + 1] = e.position.y;
        for (int c = 0; c < 3; ++c)
            tensor.mutable_data()[3 * k + c] = e.tensor[std::size_t(c)], settled.mutable_data()[3 * k + c] = e.static_tensor[std::size_t(c)];
        moment.mutable_data()[k] = e.moment, moment_nm.mutable_data()[k] = e.moment_nm, magnitude.mutable_data()[k] = e.magnitude;
        r_value.mutable_data()[k] = e.r_value, length.mutable_data()[k] = e.length;
        bonds.mutable_data()[k] = e.bonds, tensile.mutable_data()[k] = e.tensile_bonds;
        energy.mutable_data()[k] = e.energy, fracture.mutable_data()[k] = e.fracture_energy;
        type.push_back(e.type);
    }
    py::dict d;
    d["time"] = time, d["step"] = step, d["first_step"] = first_step, d["position"] = position;
    d["tensor"] = tensor, d["static_tensor"] = settled, d["moment"] = moment, d["moment_nm"] = moment_nm;
    d["magnitude"] = magnitude, d["r_value"] = r_value, d["type"] = type, d["length"] = length;
    d["bonds"] = bonds, d["tensile_bonds"] = tensile, d["energy"] = energy, d["fracture_energy"] = fracture;
    return d;
}

/// The energy account now (core/measures.hpp; summary.json's energy_balance), J/m;
/// None where it is not kept (a quasi-static run without [solver] energy_account).
py::object energy_dict(const Model& m) {
    if (!m.solver().world().settings.energy_account) return py::none();
    const EnergyAccount a = energy_account(m.solver().world());
    return py::dict(py::arg("work") = a.work, py::arg("wave_input") = a.wave_input, py::arg("kinetic") = a.kinetic,
                    py::arg("strain") = a.strain, py::arg("joints") = a.joints, py::arg("damping") = a.damping,
                    py::arg("radiated") = a.radiated, py::arg("error_in_stage") = a.error);
}

/// A lab test run as its command with these options, the GIL released; a callback
/// gets every frame's snapshot (one at a time), and an exception it raises is
/// raised here once the test is done.
studies::LabTestStudy run_labtest_study(const std::string& command, const std::vector<std::string>& args, bool quiet,
                                        const std::optional<py::function>& callback) {
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
        study = cli::run_labtest_args(command, args, quiet, on_frame);
    }
    if (failure) throw std::move(*failure);
    return study;
}

/// Every realization's curve as numpy arrays, in the order of summary["runs"].
py::list labtest_curves(const studies::LabTestStudy& study) {
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
    return curves;
}

/// Every run's curve as numpy arrays, in the order of summary["runs"].
py::list shear_curves(const studies::ShearStudy& study) {
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
    return curves;
}

py::list creep_curves(const studies::CreepStudy& study) {
    py::list curves;
    for (const CreepRun& r : study.result.runs) {
        const auto n = py::ssize_t(r.curve.size());
        auto time = fresh<double>(n), strain = fresh<double>(n);
        auto tensile = fresh<std::int32_t>(n), shear = fresh<std::int32_t>(n);
        for (py::ssize_t i = 0; i < n; ++i) {
            const CreepPoint& p = r.curve[i];
            time.mutable_at(i) = p.time, strain.mutable_at(i) = p.strain;
            tensile.mutable_at(i) = p.cracks_tensile, shear.mutable_at(i) = p.cracks_shear;
        }
        py::dict c;
        c["creep_time"] = time, c["creep_strain"] = strain, c["cracks_tensile"] = tensile, c["cracks_shear"] = shear;
        curves.append(c);
    }
    return curves;
}

/// bbm.InputError and bbm.NumericalError, and the library's exceptions translated to them.
void bind_errors(py::module_& mod) {
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
}

/// FieldGroup: any group of the state list.
void bind_field_group(py::module_& mod) {
    group_class<FieldGroup>(mod, "FieldGroup",
                            "A group of the state list (Model.group(prefix)): every field '<prefix>.*' of "
                            "Model.state_fields() as an attribute, a fresh copy");
}

/// BlockArrays: Model.blocks.
void bind_block_arrays(py::module_& mod) {
    group_class<BlockArrays>(mod, "BlockArrays",
                             "Per-block arrays (N = blocks, excavated ones included): every field 'blocks.*' of "
                             "Model.state_fields() (centroid, velocity, theta, omega, mass, area, region, …) as a "
                             "read-only numpy view, and what is computed from them")
        .def_property_readonly("count", [](const BlockArrays& a) { return world_of(a).bodies.count(); })
        .def_property_readonly("rotation", [](const BlockArrays& a) { return group_field(a, "theta"); },
                               "N rotations, rad, counter-clockwise (the field theta; view)")
        .def_property_readonly("removed", [](const BlockArrays& a) { return group_field(a, "removed").attr("astype")("bool"); },
                               "N flags: excavated")
        .def_property_readonly("deformable", [](const BlockArrays& a) {
            return group_field(a, "deformable").attr("astype")("bool");
        }, "N flags: meshed into zones")
        .def_property_readonly("displacement", [](const BlockArrays& a) {
            const World& w = world_of(a);
            auto out = fresh<double>(w.bodies.count(), 2);
            auto o = out.mutable_unchecked<2>();
            for (int i = 0; i < w.bodies.count(); ++i) {
                const Vec2 d = w.bodies.state[i].centroid - w.blocks.centroid0[i];
                o(i, 0) = d.x, o(i, 1) = d.y;
            }
            return out;
        }, "N×2 centroid displacements since the start, m (computed)")
        .def_property_readonly("stress", [](const BlockArrays& a) {
            const auto s = block_stresses(world_of(a));
            auto out = fresh<double>(py::ssize_t(s.size()), 3);
            auto o = out.mutable_unchecked<2>();
            for (std::size_t i = 0; i < s.size(); ++i)
                for (int k = 0; k < 3; ++k) o(i, k) = s[i][k];
            return out;
        }, "N×3 block-averaged stress sxx, syy, sxy, Pa, tension positive (SPEC §7; computed)");
}

/// ContactArrays: Model.contacts.
void bind_contact_arrays(py::module_& mod) {
    using contact::Contacts;
    group_class<ContactArrays>(mod, "ContactArrays",
                               "Per-contact arrays (M = contacts now): every field 'contacts.*' of "
                               "Model.state_fields() (vertex_block, length, property, normal, …) as a fresh copy "
                               "(detection creates and removes contacts: their storage moves), and the joints' "
                               "stresses and displacements from their histories")
        .def_property_readonly("count", [](const ContactArrays& a) { return contacts(world_of(a)).size(); })
        .def_property_readonly("normal_stress", [](const ContactArrays& a) {
            return per_contact<double>(a, [](const World&, const Contacts& c, int i, double* o) { *o = c.history[i].sn; });
        }, "M normal stresses σn, Pa, compression positive")
        .def_property_readonly("shear_stress", [](const ContactArrays& a) {
            return per_contact<double>(a, [](const World&, const Contacts& c, int i, double* o) { *o = c.history[i].tau; });
        }, "M shear stresses τ, Pa")
        .def_property_readonly("damage", [](const ContactArrays& a) {
            return per_contact<double>(a, [](const World&, const Contacts& c, int i, double* o) { *o = c.history[i].damage; });
        }, "M damage D of SPEC §4, 0 intact to 1 broken")
        .def_property_readonly("state", [](const ContactArrays& a) {
            return per_contact<std::int32_t>(a, [](const World&, const Contacts& c, int i, std::int32_t* o) {
                *o = int(contact::state_of(c.history[i])); // as contacts.vtu
            });
        }, "M states: 0 intact, 1 softening, 2 broken in tension, 3 broken in shear, 4 sliding")
        .def_property_readonly("bonded", [](const ContactArrays& a) {
            return per_contact<bool>(a, [](const World&, const Contacts& c, int i, bool* o) { *o = c.history[i].bonded; });
        }, "M flags: the bond holds")
        .def_property_readonly("block_pair", [](const ContactArrays& a) {
            return per_contact<std::int32_t>(a, [](const World&, const Contacts& c, int i, std::int32_t* o) {
                o[0] = c.vertex_block[i], o[1] = c.edge_block[i];
            }, 2);
        }, "M×2 blocks: the vertex's, the edge's")
        .def_property_readonly("position", [](const ContactArrays& a) {
            return per_contact<double>(a, [](const World& w, const Contacts& c, int i, double* o) {
                const Vec2 x = w.vertices.position[c.vertex_id[i]];
                o[0] = x.x, o[1] = x.y;
            }, 2);
        }, "M×2 contact points (the vertices), m")
        .def_property_readonly("normal_displacement", [](const ContactArrays& a) {
            return per_contact<double>(a, [](const World&, const Contacts& c, int i, double* o) { *o = c.history[i].un; });
        }, "M normal displacements un since bonding, m, opening positive (overlap negative)")
        .def_property_readonly("shear_displacement", [](const ContactArrays& a) {
            return per_contact<double>(a, [](const World&, const Contacts& c, int i, double* o) { *o = c.history[i].us; });
        }, "M shear displacements us, m")
        .def_property_readonly("fluid_pressure", [](const ContactArrays& a) {
            return per_contact<double>(a, [](const World&, const Contacts& c, int i, double* o) {
                *o = c.wet() ? c.fluid_pressure[i] : 0.0;
            });
        }, "M water pressures on the contacts, Pa ([flow]; 0 in a dry model): the law's normal_stress is the effective one")
        .def_property_readonly("aperture", &contact_aperture,
                               "M hydraulic apertures of the contacts' joints, m ([flow]; 0: none or sealed)")
        .def_property_readonly("edge_parameter", &contact_edge_parameter,
                               "M positions of the vertex along its edge, 0 to 1 (outside: a vertex past the edge's "
                               "end, on the rounded corner)");
}

/// ZoneArrays: Model.zones.
void bind_zone_arrays(py::module_& mod) {
    group_class<ZoneArrays>(mod, "ZoneArrays",
                            "Per-zone arrays of deformable blocks (K = constant-strain triangles): every field "
                            "'zones.*' of Model.state_fields() (node, stress, strain, block, …) as a read-only numpy "
                            "view, and what is computed from them")
        .def_property_readonly("count", [](const ZoneArrays& a) { return world_of(a).zones.size(); })
        .def_property_readonly("nodes", [](const ZoneArrays& a) { return group_field(a, "node"); },
                               "K×3 node indices, counter-clockwise (the field node; view)")
        .def_property_readonly("region", [](const ZoneArrays& a) {
            const World& w = world_of(a);
            auto out = fresh<std::int32_t>(w.zones.size());
            auto o = out.mutable_unchecked<1>();
            for (int i = 0; i < w.zones.size(); ++i) o(i) = w.blocks.region[w.zones.block[i]];
            return out;
        }, "K region indices (computed)")
        .def_property_readonly("centroid", [](const ZoneArrays& a) {
            const World& w = world_of(a);
            const auto& z = w.zones;
            const auto& p = w.nodes.position;
            auto out = fresh<double>(z.size(), 2);
            auto o = out.mutable_unchecked<2>();
            for (int i = 0; i < z.size(); ++i) {
                const Vec2 c = (p[z.node[i][0]] + p[z.node[i][1]] + p[z.node[i][2]]) / 3.0;
                o(i, 0) = c.x, o(i, 1) = c.y;
            }
            return out;
        }, "K×2 current centroids, m (computed)")
        .def_property_readonly("area", [](const ZoneArrays& a) {
            const World& w = world_of(a);
            const auto& z = w.zones;
            const auto& p = w.nodes.position;
            auto out = fresh<double>(z.size());
            auto o = out.mutable_unchecked<1>();
            for (int i = 0; i < z.size(); ++i)
                o(i) = 0.5 * cross(p[z.node[i][1]] - p[z.node[i][0]], p[z.node[i][2]] - p[z.node[i][0]]);
            return out;
        }, "K current areas, m² (computed)");
}

/// NodeArrays: Model.nodes.
void bind_node_arrays(py::module_& mod) {
    group_class<NodeArrays>(mod, "NodeArrays",
                            "Per-node arrays of deformable blocks: every field 'nodes.*' of Model.state_fields() "
                            "(position, velocity, mass, …) as a read-only numpy view")
        .def_property_readonly("count", [](const NodeArrays& a) { return world_of(a).nodes.count(); })
        .def_property_readonly("displacement", [](const NodeArrays& a) {
            const auto& n = world_of(a).nodes;
            auto out = fresh<double>(n.count(), 2);
            auto o = out.mutable_unchecked<2>();
            for (int i = 0; i < n.count(); ++i) {
                const Vec2 d = n.position[i] - n.position0[i];
                o(i, 0) = d.x, o(i, 1) = d.y;
            }
            return out;
        }, "n×2 displacements since the start, m (computed)");
}

/// SupportArrays: one registered support type, Model.<type>.
void bind_support_arrays(py::module_& mod) {
    group_class<SupportArrays>(mod, "SupportArrays",
                               "One registered support type (a property of Model per type of the registry, "
                               "core/supports/registry.hpp): every field '<type>.*' of Model.state_fields() "
                               "(per metre of model) as a fresh copy, its drawn arrays per element and node (as "
                               "<type>.pvd has them) and its sets' figures (as summary.json has them)")
        .def_property_readonly("count", [](const SupportArrays& a) {
            py::object position = group_field(a, "position");
            return py::len(position);
        }, "Its installed nodes")
        .def_property_readonly("lines", [](const SupportArrays& a) {
            py::dict d;
            for (const auto& [type, lines] : support_lines(world_of(a))) {
                if (type != a.prefix) continue;
                for (const auto* arrays : {&lines.cell_data, &lines.point_data})
                    for (const auto& array : *arrays) {
                        auto out = fresh<double>(py::ssize_t(array.values.size()));
                        std::copy(array.values.begin(), array.values.end(), out.mutable_data());
                        d[py::str(array.name)] = out;
                    }
                auto cells = fresh<std::int32_t>(py::ssize_t(lines.cells.size()), 2);
                for (std::size_t k = 0; k < lines.cells.size(); ++k)
                    cells.mutable_data()[2 * k] = lines.cells[k][0], cells.mutable_data()[2 * k + 1] = lines.cells[k][1];
                d["cells"] = cells;
                for (const auto& [name, values] : lines.names) d[py::str(name)] = values;
            }
            return d;
        }, "Its arrays as VTK has them (<type>.pvd): per element and per node (times the out-of-plane spacing "
           "where the type reports per unit); 'cells' the element's two nodes; empty before an install")
        .def_property_readonly("summary", [](const SupportArrays& a) {
            py::list out;
            for (const auto& [type, sets] : support_summaries(world_of(a))) {
                if (type != a.prefix) continue;
                for (const auto& set : sets) {
                    py::dict d;
                    d["name"] = set.name;
                    for (const auto& f : set.figures) d[py::str(f.key)] = f.count ? py::object(py::int_(long(f.value))) : py::object(py::float_(f.value));
                    out.append(d);
                }
            }
            return out;
        }, "Per installed set, its figures (summary.json's entry of the type)")
        .def_property_readonly("set_names", [](const SupportArrays& a) {
            std::vector<std::string> names;
            for_each_support(world_of(a).supports, [&](auto type, const auto& state) {
                using T = typename decltype(type)::type;
                if (T::name == a.prefix) names = T::set_names(state);
            });
            return names;
        }, "Its sets (model-file tables) by name, in file order");
}

/// Model: its construction, its runs and checkpoints, its summary and VTK output.
py::class_<Model> bind_model_runs(py::module_& mod) {
    py::class_<Model> model(mod, "Model");
    model
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
             "Writes DIR/blocks.vtu, contacts.vtu and result.pvd of the state now, for ParaView.");
    return model;
}

/// Model's arrays: blocks, contacts, zones, nodes, any group of the state list, the water in the joints.
void add_model_groups(py::class_<Model>& model) {
    model
        .def_property_readonly("blocks", [](py::object self) { return group_of<BlockArrays>(self, "blocks", true); })
        .def_property_readonly("contacts", [](py::object self) { return group_of<ContactArrays>(self, "contacts", false); })
        .def_property_readonly("zones", [](py::object self) { return group_of<ZoneArrays>(self, "zones", true); })
        .def_property_readonly("nodes", [](py::object self) { return group_of<NodeArrays>(self, "nodes", true); })
        .def("group", [](py::object self, const std::string& prefix) {
            return group_of<FieldGroup>(self, prefix, false);
        }, py::arg("prefix"), "Any group of the state list (Model.state_fields(): 'relax', 'detection', 'flow', "
                              "…) with its fields as attributes (fresh copies)")
        .def_property_readonly("events", &event_arrays,
                               "The seismic events ([events]; None without it), copied, a row an event: time (s), "
                               "step, first_step, position (N×2, m), tensor (N×3: Mxx, Myy, Mxy, N·m/m, the largest "
                               "over its duration), static_tensor (at its close), moment (M0, N·m/m), moment_nm "
                               "(N·m), magnitude (Mw), r_value (%), type (tensile, shear or implosive), length (m), "
                               "bonds, tensile_bonds, energy and fracture_energy (J/m); as events.csv")
        .def_property_readonly("energy", &energy_dict,
                               "The energy account now, J/m (summary.json's energy_balance): work, wave_input, "
                               "kinetic, strain, joints, damping, radiated, error_in_stage; None where it is not "
                               "kept (a quasi-static run without [solver] energy_account)")
        .def_property_readonly("flow", &flow_arrays,
                               "Water in the joints ([flow]; None when dry), copied: domain_position (D×2, m), "
                               "pressure (D, Pa), pipes (P×2 domains), aperture (P, m), flow_rate (P, m²/s per m, "
                               "from the first domain to the second), inflow (into the drained openings, m²/s per m)");
}

/// Model's clock, state list, hash, cracks, stages and names.
void add_model_state(py::class_<Model>& model) {
    model
        .def_property_readonly("steps", [](const Model& m) { return m.solver().world().clock.steps; })
        .def_property_readonly("time", [](const Model& m) { return m.solver().world().clock.time; })
        .def_property_readonly("unbalanced_ratio", [](const Model& m) { return m.solver().world().clock.ratio; })
        .def("state_fields", [](Model& m) {
                 py::list out;
                 for (const auto& f : state_fields(m.solver().world())) {
                     py::dict d;
                     d["name"] = f.name, d["indexed_by"] = group_name(f.group), d["count"] = f.size();
                     d["saved"] = bool(f.uses & field_use::saved), d["hashed"] = bool(f.uses & field_use::hashed);
                     d["model"] = bool(f.uses & field_use::model), d["bytes"] = f.capacity_bytes;
                     out.append(d);
                 }
                 return out;
             },
             "Every field of the world's state list, as the checkpoint, state hash and memory report see it: "
             "name, what it is indexed by, count, whether saved / hashed / fixed by the model file, bytes held.")
        .def("state", [](Model& m, const std::string& name) {
                 contacts(m.solver().world()); // the normals up to date
                 for (const auto& f : state_fields(m.solver().world()))
                     if (f.name == name) return field_array(f, py::none(), false);
                 throw py::key_error("no state field '" + name + "' (Model.state_fields() lists them)");
             }, py::arg("name"), "A copy of one field of the state list (Model.state_fields()) as a numpy array.")
        .def_property_readonly("state_hash", [](const Model& m) { return std::to_string(state_hash(m.solver().world())); },
                               "The hash summary.json reports: equal hashes, equal states")
        .def_property_readonly("cracks", [](const Model& m) {
            const World& w = m.solver().world();
            return py::dict(py::arg("tensile") = cracks(w, contact::JointState::broken_tension),
                            py::arg("shear") = cracks(w, contact::JointState::broken_shear));
        })
        .def_property_readonly("stage_names", &Model::stage_names)
        .def_property_readonly("stages_done", [](const Model& m) {
            std::vector<std::string> names;
            const auto all = m.stage_names();
            for (int k = 0; k < m.cursor().stage && k < int(all.size()); ++k) names.push_back(all[k]);
            return names;
        })
        .def_property_readonly("region_names", [](const Model& m) { return m.solver().world().region_names; })
        .def_property_readonly("property_names", [](const Model& m) { return m.solver().world().properties.names; })
        .def_property_readonly("name", &Model::name);
}

/// One property per registered support type (core/supports/registry.hpp).
void add_support_properties(py::class_<Model>& model) {
    static std::deque<std::string> words; // its name and doc, alive with the module
    for_each_support_type([&](auto type) {
        using T = typename decltype(type)::type;
        const std::string& name = words.emplace_back(T::name);
        const std::string& doc = words.emplace_back("Installed " + name + " (SupportArrays): their fields, drawn arrays and figures");
        model.def_property_readonly(
            name.c_str(), [](py::object self) { return group_of<SupportArrays>(self, std::string(T::name), false); },
            doc.c_str());
    });
}

/// Model and its properties.
void bind_model(py::module_& mod) {
    py::class_<Model> model = bind_model_runs(mod);
    add_model_groups(model);
    add_model_state(model);
    add_support_properties(model);
}

/// The lab tests, envelope, shear and calibration: their summaries and curves.
void bind_lab_tests(py::module_& mod) {
    mod.def("_labtest", [](const std::string& command, const std::vector<std::string>& args, bool quiet,
                           std::optional<py::function> callback) {
        const studies::LabTestStudy study = run_labtest_study(command, args, quiet, callback);
        return py::make_tuple(py::module_::import("json").attr("loads")(study.summary_json), labtest_curves(study));
    }, py::arg("command"), py::arg("args"), py::arg("quiet"), py::arg("callback") = py::none());
    mod.def("_envelope", [](const std::vector<std::string>& args, bool quiet) {
        std::string json;
        {
            py::gil_scoped_release release;
            json = cli::run_envelope_args(args, quiet).summary_json;
        }
        return py::module_::import("json").attr("loads")(json);
    });
    mod.def("_shear", [](const std::vector<std::string>& args, bool quiet) {
        studies::ShearStudy study;
        {
            py::gil_scoped_release release;
            study = cli::run_shear_args(args, quiet);
        }
        return py::make_tuple(py::module_::import("json").attr("loads")(study.summary_json), shear_curves(study));
    });
    mod.def("_creep", [](const std::vector<std::string>& args, bool quiet) {
        studies::CreepStudy study;
        {
            py::gil_scoped_release release;
            study = cli::run_creep_args(args, quiet);
        }
        return py::make_tuple(py::module_::import("json").attr("loads")(study.summary_json), creep_curves(study));
    });
    mod.def("_calibrate", [](const std::vector<std::string>& args, bool quiet) {
        std::string json;
        {
            py::gil_scoped_release release;
            json = cli::run_calibrate_args(args, quiet);
        }
        return py::module_::import("json").attr("loads")(json);
    });
}

} // namespace

PYBIND11_MODULE(_bbm, mod) {
    mod.doc() = "bbm: bonded-block models of rock failure (2D, plane strain) — the compiled core of the bbm package";
    bind_errors(mod);
    bind_field_group(mod);
    bind_block_arrays(mod);
    bind_contact_arrays(mod);
    bind_zone_arrays(mod);
    bind_node_arrays(mod);
    bind_support_arrays(mod);
    bind_model(mod);
    bind_lab_tests(mod);
}
