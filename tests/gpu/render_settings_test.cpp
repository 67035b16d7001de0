// render_settings_test.cpp — RenderSettings validation and compareSettings, the rule Renderer::apply
// follows to decide what a settings change restarts or rebuilds (no GL needed).
#include <doctest/doctest.h>

#include "gpu/render_settings.h"
#include "util/error.h"

using namespace caustica;

TEST_CASE("render settings: defaults are valid, each bound is checked") {
  RenderSettings s;
  CHECK_NOTHROW(s.validate());
  s.maxDepth = kMaxMaxDepth;
  CHECK_NOTHROW(s.validate());
  s.maxDepth = kMaxMaxDepth + 1;
  CHECK_THROWS_WITH_AS(s.validate(), "max depth must be between 1 and 1024", Error);
  s.maxDepth = kMinMaxDepth - 1;
  CHECK_THROWS_AS(s.validate(), Error);
  s = RenderSettings{};
  s.casterProbability = kMaxCasterProbability;
  CHECK_NOTHROW(s.validate());
  s.casterProbability = 0.95f;
  CHECK_THROWS_AS(s.validate(), Error);
  s.casterProbability = -0.0f;
  CHECK_NOTHROW(s.validate());
  s = RenderSettings{};
  s.width = 0;
  CHECK_THROWS_AS(s.validate(), Error);
  s.width = kMaxImageSide + 1;
  CHECK_THROWS_AS(s.validate(), Error);
  s = RenderSettings{};
  s.samplesPerDispatch = kMaxSamplesPerDispatch;
  CHECK_NOTHROW(s.validate());
  s.samplesPerDispatch = kMaxSamplesPerDispatch + 1;
  CHECK_THROWS_WITH_AS(s.validate(), "samples per dispatch must be between 0 (automatic) and 64", Error);
  s.samplesPerDispatch = -1;
  CHECK_THROWS_AS(s.validate(), Error);
}

TEST_CASE("render settings: what each change asks of the renderer") {
  const RenderSettings a;
  SettingsChange none = compareSettings(a, a);
  CHECK_FALSE(none.restart);
  CHECK_FALSE(none.resize);
  CHECK_FALSE(none.shader);
  CHECK_FALSE(none.casters);

  RenderSettings b = a;
  b.seed = 7;
  SettingsChange c = compareSettings(a, b);
  CHECK(c.restart);
  CHECK_FALSE((c.resize || c.shader || c.casters));

  b = a;
  b.maxDepth = 5;
  c = compareSettings(a, b);
  CHECK(c.restart);
  CHECK_FALSE((c.resize || c.shader || c.casters));

  b = a;
  b.height = a.height + 1;
  c = compareSettings(a, b);
  CHECK((c.restart && c.resize));
  CHECK_FALSE((c.shader || c.casters));

  b = a;
  b.integrator = Integrator::Naive;
  c = compareSettings(a, b);
  CHECK((c.restart && c.shader));

  b = a;
  b.dispersion = DispersionMode::Spectral;
  CHECK(compareSettings(a, b).shader);

  // Another non-zero probability: same variant, new UBO. Zero: the variant without casters.
  b = a;
  b.casterProbability = 0.25f;
  c = compareSettings(a, b);
  CHECK((c.restart && c.casters));
  CHECK_FALSE(c.shader);
  b.casterProbability = 0.0f;
  c = compareSettings(a, b);
  CHECK((c.restart && c.casters && c.shader));

  // The all-features shader (--all-features): another variant, same image size.
  b = a;
  b.allFeatures = true;
  c = compareSettings(a, b);
  CHECK((c.restart && c.shader));
  CHECK_FALSE((c.resize || c.casters));

  // Samples per dispatch: the same image, but a change still restarts (like every change).
  b = a;
  b.samplesPerDispatch = 2;
  c = compareSettings(a, b);
  CHECK(c.restart);
  CHECK_FALSE((c.resize || c.casters || c.shader));
}

TEST_CASE("render settings: names round-trip and unknown names are refused") {
  for (Integrator i : {Integrator::Naive, Integrator::Mis}) CHECK(parseIntegrator(integratorName(i)) == i);
  for (DispersionMode d : {DispersionMode::Rgb, DispersionMode::Spectral})
    CHECK(parseDispersionMode(dispersionModeName(d)) == d);
  CHECK_THROWS_AS(parseIntegrator("bdpt"), Error);
  CHECK_THROWS_AS(parseDispersionMode("cmy"), Error);
}

TEST_CASE("render settings: the render mode parses, and a switch restarts with another shader") {
  CHECK(parseRenderMode("path") == RenderMode::Path);
  CHECK(parseRenderMode("whitted") == RenderMode::Whitted);
  CHECK(parseRenderMode("raster") == RenderMode::Raster);
  CHECK_THROWS_WITH_AS(parseRenderMode("Raster"), "unknown render mode 'Raster' (expected path, whitted or raster)", Error);
  RenderSettings a, b;
  CHECK(a.mode == RenderMode::Path);
  b.mode = RenderMode::Raster;
  CHECK(a != b);
  SettingsChange c = compareSettings(a, b);
  CHECK(c.restart);
  CHECK(c.shader);
  CHECK_FALSE(c.resize);
  CHECK_FALSE(c.casters);
}
