// Lab-test specimens shared by the fast and the long test suites.
#pragma once

#include "studies/labtest.hpp"

namespace bbm::test {

/// The paper's specimen with trigon blocks of the paper's trigon stiffness, sized
/// by equal area (the specimens issue 12 found locking).
inline LabTestOptions area_trigon_ucs() {
    auto o = LabTestOptions::paper_ucs();
    o.pattern = meshing::PatternSpec::Kind::trigon;
    o.joint.kn = 162e9, o.joint.ks = 68e9;
    o.size_measure = meshing::PatternSpec::SizeMeasure::area;
    return o;
}

} // namespace bbm::test
