// bbm base: a piece of state declared as a named field — what the checkpoint, the
// state hash, the model fingerprint, the memory report and the generic views
// (Python's numpy arrays, the tests) read the simulation's state through.
//
// Each part of the world (core/world.hpp) lists its own arrays and scalars once,
// with what each is for:
//   saved   — evolving state a checkpoint writes and reads (in list order);
//   hashed  — in the state hash (every saved field but the verdict's samples);
//   model   — fixed by the model file: in the model fingerprint a checkpoint
//             carries, so that it is not loaded into another model;
//   rebuilt — built from the model file, or recomputed before it is read (per-step
//             force arrays, indices, balance timings): counted in memory only.
// A field is a std::vector of elements, a scalar, or a Column: one member of every
// record of an array of records (a block's hot record, read by the contact loop as
// one cache line, is four fields: centroid, velocity, omega, theta). A column is
// saved, hashed and viewed element by element exactly as a vector of its members
// would be, so the storage of a part can change for the loop's sake while its
// checkpoints and hashes stay the same bits.
#pragma once

#include "base/vec2.hpp"

#include <array>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

namespace bbm {

/// What a field is indexed by, for the memory report.
enum class MemoryGroup : std::uint8_t { blocks, vertices, nodes, zones, contacts, other };

/// What a field is used for (bits).
namespace field_use {
inline constexpr unsigned rebuilt = 0;
inline constexpr unsigned saved = 1;
inline constexpr unsigned hashed = 2;
inline constexpr unsigned model = 4;
inline constexpr unsigned evolving = saved | hashed;
} // namespace field_use

/// The scalar type of a field's elements, for generic readers (Python's numpy).
enum class ScalarType : std::uint8_t { f64, f32, i32, i64, u8, u32, u64, record };

/// How a field's element type is read generically: its scalar type and count per
/// element, and whether its bytes are all value bits (no padding), which the
/// state hash requires of a hashed field. Records (a joint's history) are read
/// as raw bytes; a record type declares itself beside its definition
/// (PackedRecordTraits, with a static_assert that its members fill it).
template <class T>
struct ElementTraits {
    static constexpr ScalarType type = ScalarType::record;
    static constexpr int components = int(sizeof(T));
    static constexpr bool padding_free = false;
};
template <class T>
    requires std::is_arithmetic_v<T>
struct ElementTraits<T> {
    static constexpr ScalarType type = std::is_floating_point_v<T> ? (sizeof(T) == 8 ? ScalarType::f64 : ScalarType::f32)
                                       : sizeof(T) == 1                ? ScalarType::u8
                                       : sizeof(T) == 4 ? (std::is_signed_v<T> ? ScalarType::i32 : ScalarType::u32)
                                                        : (std::is_signed_v<T> ? ScalarType::i64 : ScalarType::u64);
    static constexpr int components = 1;
    static constexpr bool padding_free = true;
};
template <>
struct ElementTraits<Vec2> {
    static constexpr ScalarType type = ScalarType::f64;
    static constexpr int components = 2;
    static constexpr bool padding_free = sizeof(Vec2) == 2 * sizeof(double);
};
template <class T, std::size_t N>
struct ElementTraits<std::array<T, N>> {
    static constexpr ScalarType type = ElementTraits<T>::type;
    static constexpr int components = ElementTraits<T>::components * int(N);
    static constexpr bool padding_free = ElementTraits<T>::padding_free;
};
/// A record whose members fill it exactly (checked by the static_assert beside
/// its declaration): hashed as raw bytes.
template <class T>
struct PackedRecordTraits {
    static constexpr ScalarType type = ScalarType::record;
    static constexpr int components = int(sizeof(T));
    static constexpr bool padding_free = true;
};

/// A field as a part declares it.
struct FieldInfo {
    const char* name; ///< "<part>.<field>": "blocks.centroid", "contacts.history", …
    MemoryGroup group;
    unsigned uses; ///< field_use bits
};

/// One member of every record of `records`, as one field (see above). `Records`
/// is `std::vector<R>` or `const std::vector<R>`.
template <class Records, class T>
struct Column {
    Records* records;
    T std::remove_const_t<Records>::value_type::* member;
    using element_type = T;
    std::size_t size() const { return records->size(); }
    auto& operator[](std::size_t k) const { return (*records)[k].*member; }
};
template <class Records, class R, class T>
Column<Records, T> column(Records& records, T R::* member) {
    return {&records, member};
}

/// The element type of a field: a vector's, a column's, or a scalar itself.
template <class T>
struct FieldElement {
    using type = T;
};
template <class T, class A>
struct FieldElement<std::vector<T, A>> {
    using type = T;
};
template <class Records, class T>
struct FieldElement<Column<Records, T>> {
    using type = T;
};
template <class Field>
using field_element_t = typename FieldElement<std::remove_cvref_t<Field>>::type;

template <class Field>
inline constexpr bool is_column_v = false;
template <class Records, class T>
inline constexpr bool is_column_v<Column<Records, T>> = true;

/// A part of the world, const or not: what a part's visit_fields is constrained
/// to (`template <part_of<Bodies> P, class V> void visit_fields(P&, V&&)` serves
/// both the readers and the writers of the list).
template <class P, class Part>
concept part_of = std::same_as<std::remove_const_t<P>, Part>;

/// A field seen through its bytes: what the generic readers get.
struct StateField {
    std::string name;        ///< "blocks.centroid", "contacts.history", "solver.time", …
    MemoryGroup group{};
    unsigned uses = 0;       ///< field_use bits
    ScalarType type{};
    int components = 1;      ///< scalars per element (bytes for a record)
    std::size_t element_size = 0;
    std::byte* data = nullptr; ///< the first element, in place
    std::size_t count = 0;     ///< elements
    std::size_t stride = 0;    ///< bytes from one element to the next (element_size but in a column)
    std::size_t capacity_bytes = 0;
    std::size_t size() const { return count; }
    bool empty() const { return count == 0; }
    std::byte* element(std::size_t k) const { return data + k * stride; }
};

} // namespace bbm
