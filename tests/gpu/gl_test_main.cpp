// gl_test_main.cpp — doctest entry for the GPU tests: one headless OSMesa (llvmpipe) context for the
// whole run, so the tests need no GPU and no display.
#define DOCTEST_CONFIG_IMPLEMENT
#include <doctest/doctest.h>

#include <iostream>

#include "util/error.h"
#include "gl_test_util.h"
#include "platform/context.h"

namespace caustica::test {
std::string gGlDescription;
}

int main(int argc, char** argv) {
  doctest::Context ctx(argc, argv);
  // Listing or filtering test names (ctest discovery) needs no context.
  std::unique_ptr<caustica::GlContext> gl;
  bool listing = false;
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]).rfind("--list", 0) == 0 || std::string(argv[i]).rfind("-ltc", 0) == 0) listing = true;
  if (!listing) {
    try {
      gl = caustica::createHeadlessContext(caustica::Backend::OSMesa, &caustica::test::gGlDescription);
    } catch (const caustica::Error& e) {
      std::cerr << "gl_tests: " << e.what() << "\n";
      return 1;
    }
  }
  return ctx.run();
}
