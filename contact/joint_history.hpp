// bbm contact: the persistent history of one point contact (SPEC §4), which
// every joint law (joint_law.hpp, barton_bandis.hpp) updates in place.
#pragma once

#include "base/fields.hpp"

#include <cstdint>

namespace bbm::contact {

/// Contact state as output (ParaView `state` cell data).
enum class JointState : std::uint8_t { intact, softening, broken_tension, broken_shear, sliding };

/// Persistent history of one contact, one 64-byte cache line. Stresses in Pa,
/// displacements in m.
struct alignas(64) JointHistory {
    double sn = 0.0;  ///< normal stress, compression positive
    double tau = 0.0; ///< shear stress
    double un = 0.0;  ///< normal displacement since bonding, opening positive
    double us = 0.0;  ///< shear displacement
    double upn = 0.0; ///< plastic (irreversible) opening
    double ups = 0.0; ///< accumulated plastic shear displacement (magnitude)
    double dissipated = 0.0; ///< plastic work per unit area, J/m²
    float damage = 0.0f;     ///< D of SPEC §4 (output only: the law recomputes it)
    bool bonded = true;      ///< false once broken, or for contacts formed unbonded
    bool slipping = false;   ///< plastic shear in the last update
    JointState broken = JointState::intact; ///< broken_tension / broken_shear once broken
    bool counted = false; ///< its crack has been recorded (statistics at formation)
};
static_assert(sizeof(JointHistory) == 64);
static_assert(sizeof(JointHistory) == 7 * 8 + 4 + 4); // saved and hashed as raw bytes: no padding

} // namespace bbm::contact

template <>
struct bbm::ElementTraits<bbm::contact::JointHistory> : bbm::PackedRecordTraits<bbm::contact::JointHistory> {};
