// Catch2 entry point for the unit tests (one test file per component beside this one).
#define CATCH_CONFIG_MAIN
#include <catch2/catch.hpp>
