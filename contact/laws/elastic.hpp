// bbm contact: the linear elastic joint (the interfaces of the outer region with
// each other and with the bonded region, SPEC §1): σn = −kn un, τ += ks Δus, no
// strength.
#pragma once

#include "contact/laws/bond.hpp"

#include <array>
#include <string_view>

namespace bbm::contact {

struct ElasticLaw {
    static constexpr std::string_view name = "elastic";
    /// The [[joint_property]] keys it reads.
    static constexpr std::array<const JointKey*, 5> keys{&key_name, &key_law, &key_kn, &key_ks, &key_face_shear};
    static std::optional<KeyProblem> check(const JointPropertySpec&) { return std::nullopt; }
    double kn, ks;
    explicit ElasticLaw(const JointPropertySpec& p) : kn(p.kn), ks(p.ks) {}
    bool starts_bonded() const { return true; }
    /// Never yields: any load is within its strength.
    double elastic_limit(const JointHistory&, const JointHistory&, double cap) const { return cap; }
    void update(JointHistory& h, double dun, double dus) const {
        h.un += dun;
        h.us += dus;
        h.sn = -kn * h.un;
        h.tau += ks * dus;
    }
};

} // namespace bbm::contact
