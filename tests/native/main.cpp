// The C++ test runner (doctest): `ctest --test-dir build` runs every TEST_CASE of tests/native.
#define DOCTEST_CONFIG_IMPLEMENT_WITH_MAIN
#include <doctest/doctest.h>
