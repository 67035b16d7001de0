// render_mode_test.cpp — the render-mode table (app/gpu/render_mode.h): one row per mode, names that
// round-trip, rows the Renderer can carry out, the viewer's M cycle, --mode's help from the rows.
#include <doctest/doctest.h>

#include <set>
#include <string>

#include "gpu/render_mode.h"
#include "gpu/render_settings.h"
#include "gpu/shader_library.h"
#include "util/error.h"

using namespace caustica;

TEST_CASE("render modes: one row per mode, its name round-trips, unknown names list every mode") {
  std::set<RenderMode> modes;
  std::set<std::string> names;
  for (const RenderModeSpec& m : renderModes()) {
    CAPTURE(m.name);
    CHECK(modes.insert(m.mode).second);
    CHECK(names.insert(m.name).second);
    CHECK(&renderModeSpec(m.mode) == &m);
    CHECK(parseRenderMode(m.name) == m.mode);
    CHECK(std::string(renderModeName(m.mode)) == m.name);
    CHECK(std::string(m.help).size() > 0);
  }
  CHECK(modes.size() == 3);  // RenderMode's values: a value without a row throws in renderModeSpec
  CHECK(renderModeNames() == "path, whitted or raster");
  CHECK_THROWS_WITH_AS(parseRenderMode("Raster"), "unknown render mode 'Raster' (expected path, whitted or raster)", Error);
  CHECK(renderModeNames([](const RenderModeSpec& m) { return m.tracksCoverage; }) == "path or whitted");
}

TEST_CASE("render modes: every row is one the Renderer can carry out") {
  ShaderLibrary library;
  for (const RenderModeSpec& m : renderModes()) {
    CAPTURE(m.name);
    if (m.entryShader) {
      CHECK_NOTHROW(library.read(m.entryShader));  // embedded (the shader-library test compiles it)
    } else {
      // The raster pipeline draws it: one deterministic frame, no compute variant, no coverage image.
      CHECK(m.samples == SampleRule::OneFrame);
    }
    // What only a compute entry shader does: path regeneration, the path tracer's variants, coverage.
    if (m.samples == SampleRule::Regeneration || m.pathTracer || m.tracksCoverage) CHECK(m.entryShader != nullptr);
  }
  // The default settings name a mode that traces instanced scenes and sees the environment (the
  // default lighting of a scene without emitters).
  const RenderModeSpec& byDefault = renderModeSpec(RenderSettings{}.mode);
  CHECK(byDefault.instancedScenes);
  CHECK(byDefault.seesEnvironment);
}

TEST_CASE("render modes: M cycles through every mode, skipping those that draw flat scenes only for an instanced scene") {
  for (bool instanced : {false, true}) {
    CAPTURE(instanced);
    std::size_t drawable = 0;
    for (const RenderModeSpec& spec : renderModes()) drawable += !instanced || spec.instancedScenes;
    std::set<RenderMode> seen;
    RenderMode m = RenderSettings{}.mode;
    for (std::size_t i = 0; i < drawable; ++i) {
      seen.insert(m);
      m = nextRenderMode(m, instanced);
    }
    CHECK(m == RenderSettings{}.mode);  // back where it started
    for (const RenderModeSpec& spec : renderModes())
      CHECK(seen.count(spec.mode) == (!instanced || spec.instancedScenes ? 1u : 0u));
  }
  CHECK(nextRenderMode(RenderMode::Path, false) == RenderMode::Whitted);
  CHECK(nextRenderMode(RenderMode::Whitted, false) == RenderMode::Raster);
  CHECK(nextRenderMode(RenderMode::Whitted, true) == RenderMode::Path);
}

TEST_CASE("render modes: --mode's help names every mode with its help and marks the default") {
  const std::string help = renderModeHelp();
  for (const RenderModeSpec& m : renderModes()) {
    CAPTURE(m.name);
    CHECK(help.find(std::string(m.name) + " (" + m.help) != std::string::npos);
  }
  CHECK(help.rfind("path (the path tracer; default), whitted (", 0) == 0);
}
