// test_main.cpp — doctest entry point shared by the test programs that need no OpenGL context.
#define DOCTEST_CONFIG_IMPLEMENT_WITH_MAIN
#include <doctest/doctest.h>
