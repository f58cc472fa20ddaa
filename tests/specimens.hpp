// Lab-test specimens shared by the fast and the long test suites.
#pragma once

#include "studies/lab/labtest.hpp"

namespace bbm::test {

/// The paper's trigon specimen (SPEC §8): trigon blocks with the paper's trigon
/// stiffnesses, kn 162 and ks 68 GPa/m.
inline LabTestOptions paper_trigon_ucs() {
    auto o = LabTestOptions::paper_ucs();
    o.rock.pattern.kind = meshing::PatternSpec::Kind::trigon;
    o.rock.bonds.kn = 162e9, o.rock.bonds.ks = 68e9;
    return o;
}

/// The same, sized by equal area (the specimens issue 12 found locking).
inline LabTestOptions area_trigon_ucs() {
    auto o = paper_trigon_ucs();
    o.rock.pattern.size_measure = meshing::PatternSpec::SizeMeasure::area;
    return o;
}

} // namespace bbm::test
