// The tag of a validation test case (tests/main.cpp): a run of a lab test, a
// tunnel or a restart to its answer, tens of seconds in Release. The checking
// build (.ci/sanitize) skips them and runs the unit tests:
//     TEST_CASE("uniaxial compression, paper specimen, ..." * validation) { ... }
#pragma once

#include <doctest/doctest.h>

inline const doctest::test_suite validation{"validation"};
