// Long suite: determinism across thread counts (see test_determinism.cpp, whose
// default-suite tests check one thread count each against the recorded state):
// here the thread counts those leave out.
#include "tests/determinism.hpp"

#include <doctest/doctest.h>

TEST_CASE("every shipped example ends in the recorded state on 1 and 3 threads") {
    CHECK(bbm::test::check_examples_on({1, 3}) >= 20);
}

TEST_CASE("the trigon tunnel, past its first 900 cracks, ends in the recorded state on 1 and 3 threads") {
    bbm::test::check_trigon_tunnel_on({1, 3});
}

TEST_CASE("lab tests end in the recorded curve and cracks on 1 and 2 threads") {
    bbm::test::check_lab_tests_on({1, 2});
}
