// What walks the world's field list (core/state.hpp).
#include "core/state.hpp"

#include "contact/joint_keys.hpp"
#include "core/step.hpp"
#include "core/supports/ties.hpp"

#include <cstring>
#include <istream>
#include <ostream>
#include <stdexcept>
#include <type_traits>

namespace bbm {

namespace {
// "bbm-chp" and the format version as the last byte: 2 lacked the renumbering
// count (a resumed run renumbered its contacts at another step: issue 27); 3 the
// stage monitor's samples (a resumed run's verdict); 4 the installed supports; 5 a
// constant support pressure (excavate's `pressure`); 6 the same fields with a
// hash of the supports' kinematics; 7 the state hash over every saved field (the
// state-field list); 8 a third support type's fields; 9 the
// opening's pressure scale (a pressurise stage); A an excavation's support path;
// B the same fields, with a fingerprint of every parameter of every property
// and support set (A's hashed only the stiffnesses); C the yielding bolts' and the
// viscous boundaries' fields; D the monitor's samples with their model time (a
// dynamic stage's verdict and its end in time); E the rigid faces' dashpots; F
// the removed contacts' dissipated energy (the energy account); G the dynamic
// mode's peak velocities and the bolts' energy (what they dissipated, per set).
constexpr std::uint64_t magic_base = 0x62626d2d63687000ull; // "bbm-chp\0"
constexpr std::uint64_t format = 'G';
constexpr std::uint64_t magic = magic_base | format;

/// FNV-1a, 64 bits.
struct Fnv {
    std::uint64_t h = 1469598103934665603ull;
    void mix(std::span<const std::byte> bytes) {
        for (std::byte c : bytes) h = (h ^ std::uint64_t(c)) * 1099511628211ull;
    }
    template <class T>
    void mix_value(const T& v) {
        mix(std::as_bytes(std::span(&v, 1)));
    }
};

// --- a field as a sequence of elements, whatever its storage ----------------------

template <class F>
std::size_t field_size(const F& x) {
    if constexpr (requires { x.size(); }) return x.size();
    else return 1;
}
/// f(element) for every element in order.
template <class F, class Visit>
void for_each_element(F& x, Visit&& f) {
    if constexpr (is_column_v<std::remove_cvref_t<F>>) {
        for (std::size_t k = 0; k < x.size(); ++k) f(x[k]);
    } else if constexpr (requires { x.data(); }) {
        for (auto& e : x) f(e);
    } else {
        f(x);
    }
}
/// The bytes of every element, in order (a column's as a vector of its members would be).
template <class F>
void mix_elements(Fnv& h, const F& x) {
    if constexpr (is_column_v<F>) {
        for (std::size_t k = 0; k < x.size(); ++k) h.mix_value(x[k]);
    } else if constexpr (requires { x.data(); }) {
        h.mix(std::as_bytes(std::span(x.data(), x.size())));
    } else {
        h.mix_value(x);
    }
}

template <class T>
void put(std::ostream& o, const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    o.write(reinterpret_cast<const char*>(&v), sizeof v);
}
template <class T>
void get(std::istream& i, T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    i.read(reinterpret_cast<char*>(&v), sizeof v);
    if (!i) throw std::runtime_error("checkpoint is truncated");
}
/// A saved field: a vector's or column's length, then its elements; a scalar as it is.
template <class F>
void put_field(std::ostream& o, const F& x) {
    if constexpr (is_column_v<F> || requires { x.data(); }) put(o, std::uint64_t(x.size()));
    for_each_element(x, [&](const auto& e) { put(o, e); });
}
template <class F>
void get_field(std::istream& i, F& x) {
    using T = field_element_t<F>;
    if constexpr (is_column_v<F> || requires { x.data(); }) {
        std::uint64_t n = 0;
        get(i, n);
        if (n > (std::uint64_t(1) << 40) / sizeof(T)) throw std::runtime_error("checkpoint is corrupt (array size)");
        if constexpr (is_column_v<F>) {
            x.records->resize(n);
        } else {
            x.resize(n);
        }
    }
    for_each_element(x, [&](auto& e) { get(i, e); });
}

template <class F>
constexpr bool hashable = ElementTraits<field_element_t<F>>::padding_free;

/// The parameters of every property set: its law, every key a law reads, its
/// softening curves (contact/joint_keys.hpp walks the set's declared keys).
void mix_properties(Fnv& h, const Properties& p) {
    std::vector<double> values;
    for (const auto& spec : p.specs) {
        values.clear();
        contact::law_parameters(spec, values);
        h.mix(std::as_bytes(std::span(values)));
    }
    h.mix_value(std::uint64_t(p.laws.size()));
}

} // namespace

std::uint64_t model_fingerprint(const World& w) {
    // What the model file fixes: initial geometry, masses (materials), supports,
    // loads and property sets. Taken when the world is built, before a study
    // changes loads or support velocities.
    Fnv h;
    for_each_field(w, [&](const FieldInfo& f, const auto& x) {
        if (!(f.uses & field_use::model)) return;
        if constexpr (hashable<decltype(x)>) mix_elements(h, x);
        else throw std::logic_error(std::string("unhashable field ") + f.name);
    });
    mix_properties(h, w.properties);
    std::vector<double> parameters;
    for_each_support(w.supports, [&](auto type, const auto& state) {
        parameters.clear();
        decltype(type)::type::parameters(state, parameters);
        h.mix(std::as_bytes(std::span(parameters)));
    });
    return h.h;
}

std::uint64_t state_hash(const World& w) {
    // Every non-empty hashed field, its name, its length and then its bytes (no
    // padding in any), in list order. An empty field adds nothing, so a capability
    // a model does not use (a support type it has no table of) leaves that
    // model's hash as it was.
    Fnv h;
    for_each_field(w, [&](const FieldInfo& f, const auto& x) {
        if (!(f.uses & field_use::hashed)) return;
        if constexpr (hashable<decltype(x)>) {
            const std::size_t bytes = field_size(x) * sizeof(field_element_t<decltype(x)>);
            if (bytes == 0) return;
            h.mix(std::as_bytes(std::span(f.name, std::strlen(f.name))));
            h.mix_value(std::uint64_t(bytes));
            mix_elements(h, x);
        } else {
            // A field whose elements have padding bytes cannot be hashed (their
            // value is not defined): only rebuilt and unhashed fields may be such.
            throw std::logic_error(std::string("unhashable field ") + f.name);
        }
    });
    return h.h;
}

Memory memory(const World& w) {
    Memory m;
    auto group = [&](MemoryGroup g) -> std::size_t& {
        switch (g) {
        case MemoryGroup::blocks: return m.blocks;
        case MemoryGroup::vertices: return m.vertices;
        case MemoryGroup::nodes: return m.nodes;
        case MemoryGroup::zones: return m.zones;
        case MemoryGroup::contacts: return m.contacts;
        case MemoryGroup::other: break;
        }
        return m.other;
    };
    for_each_field(w, [&](const FieldInfo& f, const auto& x) {
        using X = std::remove_cvref_t<decltype(x)>;
        if constexpr (is_column_v<X>) group(f.group) += x.records->capacity() * sizeof(typename X::element_type);
        else if constexpr (requires { x.capacity(); }) group(f.group) += x.capacity() * sizeof(x[0]);
    });
    return m;
}

std::vector<StateField> state_fields(World& w) {
    std::vector<StateField> fields;
    for_each_field(w, [&](const FieldInfo& f, auto& x) {
        using X = std::remove_cvref_t<decltype(x)>;
        using T = field_element_t<X>;
        StateField out;
        out.name = f.name, out.group = f.group, out.uses = f.uses;
        out.type = ElementTraits<T>::type, out.components = ElementTraits<T>::components;
        out.element_size = sizeof(T);
        out.stride = sizeof(T);
        if constexpr (is_column_v<X>) {
            using R = typename std::remove_const_t<std::remove_pointer_t<decltype(x.records)>>::value_type;
            out.count = x.size();
            out.stride = sizeof(R);
            out.data = out.count ? reinterpret_cast<std::byte*>(&x[0]) : nullptr;
            out.capacity_bytes = x.records->capacity() * sizeof(T);
        } else if constexpr (requires { x.capacity(); }) {
            out.count = x.size();
            out.data = reinterpret_cast<std::byte*>(x.data());
            out.capacity_bytes = x.capacity() * sizeof(T);
        } else {
            out.count = 1;
            out.data = reinterpret_cast<std::byte*>(&x);
        }
        fields.push_back(std::move(out));
    });
    return fields;
}

void save_state(const World& w, std::ostream& o) {
    put(o, magic);
    put(o, std::int64_t(w.bodies.count())), put(o, std::int64_t(w.nodes.count())), put(o, std::int64_t(w.zones.size()));
    put(o, w.fingerprint);
    for_each_field(w, [&](const FieldInfo& f, const auto& x) {
        if (!(f.uses & field_use::saved)) return;
        if constexpr (std::is_trivially_copyable_v<field_element_t<decltype(x)>>) put_field(o, x);
        else throw std::logic_error(std::string("unsavable field ") + f.name);
    });
    put(o, state_hash(w));
    if (!o) throw std::runtime_error("cannot write the checkpoint");
}

namespace {

/// Per hashed field, its name and the hash of its bytes (load_state's check).
std::vector<std::pair<std::string, std::uint64_t>> field_hashes(const World& w) {
    std::vector<std::pair<std::string, std::uint64_t>> out;
    for_each_field(w, [&](const FieldInfo& f, const auto& x) {
        if constexpr (hashable<decltype(x)>) {
            if (f.uses & field_use::hashed) {
                Fnv h;
                mix_elements(h, x);
                out.emplace_back(f.name, h.h);
            }
        }
    });
    return out;
}

void check_header(const World& w, std::istream& i) {
    std::uint64_t m = 0;
    get(i, m);
    if ((m & ~std::uint64_t(0xff)) != magic_base) throw std::runtime_error("not a bbm checkpoint");
    if (m != magic)
        throw std::runtime_error("the solver state is of checkpoint format " + std::string(1, char(m & 0xff)) +
                                 "; this bbm reads format " + std::string(1, char(format)) +
                                 " only (start the run again)");
    std::int64_t nb = 0, nn = 0, nz = 0;
    get(i, nb), get(i, nn), get(i, nz);
    if (nb != w.bodies.count() || nn != w.nodes.count() || nz != w.zones.size())
        throw std::runtime_error("checkpoint is of a different model (" + std::to_string(nb) + " blocks, " +
                                 std::to_string(nn) + " nodes, " + std::to_string(nz) + " zones; this model has " +
                                 std::to_string(w.bodies.count()) + ", " + std::to_string(w.nodes.count()) + ", " +
                                 std::to_string(w.zones.size()) + ")");
    std::uint64_t fingerprint = 0;
    get(i, fingerprint);
    if (fingerprint != w.fingerprint)
        throw std::runtime_error("checkpoint is of a different model (same counts, but the geometry, materials, "
                                 "joint or support properties, or boundaries differ: was the model file edited?)");
}

} // namespace

void load_state(World& w, std::istream& i) {
    check_header(w, i);
    for_each_field(w, [&](const FieldInfo& f, auto& x) {
        if constexpr (std::is_trivially_copyable_v<field_element_t<decltype(x)>>) {
            if (f.uses & field_use::saved) get_field(i, x);
        }
    });
    std::uint64_t hash = 0;
    get(i, hash);
    if (hash != state_hash(w)) throw std::runtime_error("checkpoint is corrupt (state hash differs)");
    const auto loaded = field_hashes(w);
    w.contacts.normal.resize(w.contacts.size());
    if (w.flow) write_contact_pressures(*w.flow, w.contacts);
    for_each_support(w.supports, [&](auto type, auto& state) { decltype(type)::type::after_load(state); });
    index_support_ties(w);
    w.normals_stale = true;
    place_bodies(w); // the faces of assign_face_groups are read off the current geometry
    reindex_contacts(w);
    w.detection.detector.grid_valid = false;
    // What was loaded must not be recomputed: a field that is (an index, a value
    // derived from the vertices) belongs in the list as `rebuilt`.
    const auto now = field_hashes(w);
    for (std::size_t k = 0; k < now.size(); ++k)
        if (now[k].second != loaded[k].second)
            throw std::logic_error("the state list marks " + now[k].first +
                                   " as saved and hashed, but loading a checkpoint recomputes it");
}

} // namespace bbm
