// The Catch2 v2 runner: one translation unit holds main.
#define CATCH_CONFIG_MAIN
#include <catch2/catch.hpp>
