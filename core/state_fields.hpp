// bbm core: the solver's state as one list of named fields.
//
// Every array and scalar the solver holds is declared once, in one list
// (Solver::for_each_field, core/state.cpp), with what it is for:
//   saved   — evolving state a checkpoint writes and reads (in list order);
//   hashed  — in the state hash (every saved field but the verdict's samples);
//   model   — fixed by the model file: in the model fingerprint a checkpoint
//             carries, so that it is not loaded into another model;
//   rebuilt — built from the model file, or recomputed before it is read (per-step
//             force arrays, indices, balance timings): counted in memory only.
// The checkpoint, the state hash, the model fingerprint, the memory report and
// the generic views (Solver::state_fields(): Python's Model.state, the tests)
// all walk that list, so a field added to it once is saved, hashed and counted
// (tests/test_restart.cpp perturbs every field and sees each in all of them).
#pragma once

#include "base/vec2.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <type_traits>

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
/// as raw bytes.
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

/// A field as the list declares it.
struct FieldInfo {
    const char* name;
    MemoryGroup group;
    unsigned uses; ///< field_use bits
};

/// A field seen through its bytes: what the generic readers get.
struct StateField {
    std::string name;        ///< "blocks.centroid", "contacts.history", "solver.time", …
    MemoryGroup group{};
    unsigned uses = 0;       ///< field_use bits
    ScalarType type{};
    int components = 1;      ///< scalars per element (bytes for a record)
    std::size_t element_size = 0;
    std::span<std::byte> bytes; ///< size() elements, in place
    std::size_t capacity_bytes = 0;
    std::size_t size() const { return element_size ? bytes.size() / element_size : 0; }
};

} // namespace bbm
