// The doctest main of the bbm test suite (tests are discovered by CTest).
#define DOCTEST_CONFIG_IMPLEMENT_WITH_MAIN
#include <doctest/doctest.h>
