// The registry's dispatch (contact/joint_law.hpp).
#include "contact/joint_law.hpp"

#include <stdexcept>
#include <string>

namespace bbm::contact {

JointLaw make_law(const JointPropertySpec& p) {
    // By index: the alternative of JointLaw that the set's law names.
    constexpr auto makers = []<std::size_t... I>(std::index_sequence<I...>) {
        return std::array<JointLaw (*)(const JointPropertySpec&), sizeof...(I)>{
            [](const JointPropertySpec& q) -> JointLaw { return std::variant_alternative_t<I, JointLaw>(q); }...};
    }(std::make_index_sequence<std::variant_size_v<JointLaw>>{});
    const std::size_t k = law_index(p.law);
    if (k >= makers.size()) throw std::invalid_argument("unknown joint law '" + p.law + "'");
    return makers[k](p);
}

double normal_stiffness(const JointLaw& law) {
    return std::visit([](const auto& l) { return l.kn; }, law);
}
double shear_stiffness(const JointLaw& law) {
    return std::visit([](const auto& l) { return l.ks; }, law);
}

bool starts_bonded(const JointLaw& law) {
    return std::visit([](const auto& l) { return l.starts_bonded(); }, law);
}

double elastic_limit(const JointLaw& law, const JointHistory& before, const JointHistory& trial, double cap) {
    return std::visit([&](const auto& l) { return l.elastic_limit(before, trial, cap); }, law);
}

JointState state_of(const JointHistory& h) {
    if (h.broken != JointState::intact) return h.broken;
    if (h.slipping) return JointState::sliding;
    return h.damage > 0 ? JointState::softening : JointState::intact;
}

} // namespace bbm::contact

namespace bbm {

std::vector<double> strength_class_factors(double m, int classes) {
    std::vector<double> f(std::max(classes, 1), 1.0);
    if (!(m > 0.0)) return f;
    double mean = 0.0;
    for (std::size_t k = 0; k < f.size(); ++k) {
        const double q = (double(k) + 0.5) / double(f.size());
        f[k] = std::pow(-std::log1p(-q), 1.0 / m);
        mean += f[k];
    }
    mean /= double(f.size());
    for (double& x : f) x /= mean;
    return f;
}

} // namespace bbm
