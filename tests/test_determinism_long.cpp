// Long suite: determinism across thread counts on an odd split (see
// test_determinism.cpp, which checks 2 threads against the recorded state in the
// default suite).
#include "tests/determinism.hpp"

#include <doctest/doctest.h>

TEST_CASE("every shipped example ends in the recorded state on 1 and 3 threads") {
    CHECK(bbm::test::check_examples_on({1, 3}) >= 20);
}
