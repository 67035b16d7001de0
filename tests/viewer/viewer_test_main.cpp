// viewer_test_main.cpp — doctest entry point for camera_controller_test (the viewer's camera math).
#define DOCTEST_CONFIG_IMPLEMENT_WITH_MAIN
#include <doctest/doctest.h>
