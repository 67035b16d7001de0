// bench_test_main.cpp — doctest entry point for the benchmark's unit tests (no OpenGL needed).
#define DOCTEST_CONFIG_IMPLEMENT_WITH_MAIN
#include <doctest/doctest.h>
