// bbm core: the registry of support types — one row each.
//
// The list below is the only place the program lists the support types. The
// model-file reader reads each type's [[table]] through its own reader, the world
// holds one State per type (in this order: the order their ties are numbered and
// their forces gathered), and the outputs (summary.json, `bbm compare`, VTK, the
// picture, Python) iterate the list; none of them names a type. A new type is
// its own files (core/supports/<type>.hpp/.cpp: a struct with the members
// core/supports/support.hpp lists) and one row here.
#pragma once

#include "core/supports/bolt.hpp"
#include "core/supports/dowel.hpp"
#include "core/supports/liner.hpp"
#include "core/supports/yielding_bolt.hpp"

#include <cstddef>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

namespace bbm {

/// The registered support types, in tie order.
using SupportTypes = std::tuple<Bolts, Liners, Dowels, YieldingBolts>;

inline constexpr std::size_t support_type_count = std::tuple_size_v<SupportTypes>;

namespace detail {
template <class Tuple, template <class> class F>
struct map_tuple;
template <class... T, template <class> class F>
struct map_tuple<std::tuple<T...>, F> {
    using type = std::tuple<typename F<T>::type...>;
};
template <class T>
struct state_of {
    using type = typename T::State;
};
template <class T>
struct specs_of {
    using type = std::vector<typename T::Spec>;
};
} // namespace detail

/// One State per registered type (the world's), and one list of Specs per type
/// (the model file's tables, AnalysisSpec::supports).
using SupportStates = typename detail::map_tuple<SupportTypes, detail::state_of>::type;
using SupportSpecs = typename detail::map_tuple<SupportTypes, detail::specs_of>::type;

/// f(std::type_identity<Type>{}, state) for every registered type, in tie order.
template <class States, class F>
void for_each_support(States& states, F&& f) {
    [&]<std::size_t... I>(std::index_sequence<I...>) {
        (f(std::type_identity<std::tuple_element_t<I, SupportTypes>>{}, std::get<I>(states)), ...);
    }(std::make_index_sequence<support_type_count>{});
}

/// f(std::type_identity<Type>{}) for every registered type, in tie order.
template <class F>
void for_each_support_type(F&& f) {
    [&]<std::size_t... I>(std::index_sequence<I...>) {
        (f(std::type_identity<std::tuple_element_t<I, SupportTypes>>{}), ...);
    }(std::make_index_sequence<support_type_count>{});
}

/// The position of a type in the registry.
template <class Type, std::size_t I = 0>
constexpr std::size_t support_index() {
    static_assert(I < support_type_count, "not a registered support type");
    if constexpr (std::is_same_v<std::tuple_element_t<I, SupportTypes>, Type>) return I;
    else return support_index<Type, I + 1>();
}

/// The state (or specs) of one type, for a study or a test that knows which it wants.
template <class Type, class States>
auto& support_state(States& states) {
    return std::get<support_index<Type>()>(states);
}

/// The table names of the registered types ("bolt", "liner", …), for the
/// reader's top-level keys and messages.
inline std::vector<std::string_view> support_tables() {
    std::vector<std::string_view> out;
    for_each_support_type([&](auto type) { out.push_back(decltype(type)::type::table); });
    return out;
}

} // namespace bbm
