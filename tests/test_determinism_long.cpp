// Long suite: determinism across thread counts on an odd split (see
// test_determinism.cpp, which compares 1 and 2 threads in the default suite).
#include "tests/determinism.hpp"

#include <doctest/doctest.h>

TEST_CASE("every shipped example ends in the same state on 1 and 3 threads") {
    CHECK(bbm::test::compare_examples_on({3}) >= 20);
}
