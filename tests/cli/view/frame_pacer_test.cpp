// frame_pacer_test.cpp — the viewer's time model against a simulated GPU: bands fit the time left,
// pass spp and preview scale follow the budget within their clamps, the cost model converges.
#include <doctest/doctest.h>

#include <cmath>
#include <functional>
#include <random>

#include "cli/view/frame_pacer.h"

using namespace caustica;

namespace {

PacingConfig config(double costMs, double budgetMs = 30.0) {
  PacingConfig c;
  c.budgetMs = budgetMs;
  c.initialCostMs = costMs;
  return c;
}

// A simulated GPU: ms per pixel sample of image row y.
using RowCost = std::function<double(int y)>;

double bandMs(const Band& b, int width, const RowCost& cost) {
  double ms = 0.0;
  for (int y = b.y0; y < b.y1; ++y) ms += cost(y) * width * b.spp;
  return ms;
}

// Runs bands of one pass (from wherever the pass is) to its end, each given `remainingMs`.
void runPass(FramePacer& p, int width, int height, const RowCost& cost, double remainingMs = 1e9, int spp = 0) {
  for (;;) {
    Band b = p.nextBand(width, height, spp, remainingMs);
    if (p.finishBand(b, width, height, bandMs(b, width, cost))) return;
  }
}

}  // namespace

TEST_CASE("a band takes the rows the model expects to fit the time left, at least one") {
  FramePacer p(config(1e-3));
  // 100x50 at 1e-3 ms per pixel sample: a 1-spp pass is 5 ms, so a pass gets floor(15 / 5) = 3 spp
  // and a row 100 * 3 * 1e-3 = 0.3 ms.
  Band b = p.nextBand(100, 50, 0, 1.0);
  CHECK(b.y0 == 0);
  CHECK(b.y1 == 3);
  CHECK(b.spp == 3);
  CHECK(b.predictedMs == doctest::Approx(0.9));
  p.finishBand(b, 100, 50, 0.9);
  CHECK(p.passRow() == 3);

  Band one = p.nextBand(100, 50, 0, 0.1);  // not even one row fits: one row anyway
  CHECK(one.y0 == 3);
  CHECK(one.y1 == 4);
  CHECK(one.predictedMs == doctest::Approx(0.3));
  p.finishBand(one, 100, 50, 0.3);
  CHECK(p.nextBand(100, 50, 0, -5.0).rows() == 1);  // the budget already overrun

  Band rest = p.nextBand(100, 50, 0, 1e6);  // never past the last row
  CHECK(rest.y0 == 4);
  CHECK(rest.y1 == 50);
  CHECK(p.finishBand(rest, 100, 50, rest.predictedMs));
  CHECK(p.passRow() == 0);
}

TEST_CASE("bands never exceed the time left except the one-row minimum") {
  const int w = 64, h = 48;
  // Uneven rows (a bright band of glass costs 10x) under a constant budget: after one pass has measured
  // every row, each band's measured time fits what was left of its frame, unless it is a single row.
  RowCost cost = [](int y) { return y >= 20 && y < 30 ? 2e-3 : 2e-4; };
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> budget(0.05, 20.0);
  FramePacer p(config(1e-3, 30.0));
  for (int pass = 0; pass < 2; ++pass) {
    for (int y = 0; y < h; ++y) {  // one row per band: exact per-row costs
      Band b = p.nextBand(w, h, 0, 0.0);
      REQUIRE(b.rows() == 1);
      p.finishBand(b, w, h, bandMs(b, w, cost));
    }
  }
  CHECK(p.rowMs(25, w, 1) == doctest::Approx(2e-3 * w));
  CHECK(p.rowMs(5, w, 1) == doctest::Approx(2e-4 * w));
  int bands = 0, multiRow = 0;
  for (int frame = 0; frame < 200; ++frame) {
    const double frameBudget = budget(rng);
    double elapsed = 0.0;
    bool forced = false;  // a band of one row that was expected not to fit
    for (;;) {
      double remaining = frameBudget - elapsed;
      Band b = p.nextBand(w, h, 0, remaining);
      double ms = bandMs(b, w, cost);
      forced = forced || (b.rows() == 1 && b.predictedMs > remaining);
      CHECK((b.rows() == 1 || b.predictedMs <= remaining));
      CHECK((b.rows() == 1 || ms <= remaining * (1.0 + 1e-9)));
      // The band is as long as fits: one more row would not have.
      if (b.y1 < h) CHECK(b.predictedMs + p.rowMs(b.y1, w, b.spp) > remaining);
      ++bands;
      multiRow += b.rows() > 1;
      elapsed += ms;
      p.finishBand(b, w, h, ms);
      if (!p.nextRowFits(w, frameBudget - elapsed)) break;
    }
    CHECK((elapsed <= frameBudget * (1.0 + 1e-9) || forced));
  }
  CHECK(multiRow > bands / 4);  // the property was tested on real bands, not just single rows
}

TEST_CASE("pass spp aims at half the budget, clamped to 1..64, capped by --spp") {
  CHECK(FramePacer(config(1e-3)).choosePassSpp(100, 10, 0) == 15);  // 1 ms passes in 30 ms: 15
  CHECK(FramePacer(config(1e-3)).choosePassSpp(100, 16, 0) == 9);   // 1.6 ms: floor(9.4)
  CHECK(FramePacer(config(1e-9)).choosePassSpp(100, 10, 0) == FramePacer::kMaxPassSpp);
  CHECK(FramePacer::kMaxPassSpp == 64);
  CHECK(FramePacer(config(1.0)).choosePassSpp(100, 10, 0) == 1);  // a pass far over the budget

  PacingConfig capped = config(1e-9);
  capped.maxSpp = 100;
  FramePacer p(capped);
  CHECK(p.choosePassSpp(100, 10, 0) == 64);
  CHECK(p.choosePassSpp(100, 10, 90) == 10);  // what is left to --spp
  CHECK(p.choosePassSpp(100, 10, 99) == 1);
  CHECK(p.choosePassSpp(100, 10, 100) == 1);  // never below one

  // The spp is chosen at the start of a pass and kept to its end.
  FramePacer q(config(1e-3));
  Band first = q.nextBand(100, 10, 0, 0.0);
  CHECK(first.spp == 15);
  q.finishBand(first, 100, 10, 100.0);  // much slower than the 1.5 ms expected
  CHECK(q.choosePassSpp(100, 10, 0) < 15);
  CHECK(q.nextBand(100, 10, 0, 0.0).spp == 15);
}

TEST_CASE("a scripted run (--frames) traces one sample per pixel per pass") {
  PacingConfig c = config(1e-9);  // cheap enough for 64 spp otherwise
  c.scripted = true;
  FramePacer p(c);
  CHECK(p.choosePassSpp(100, 10, 0) == 1);
  for (int pass = 0; pass < 3; ++pass) {
    Band b = p.nextBand(100, 10, pass, 1e6);
    CHECK(b.spp == 1);
    CHECK(b.rows() == 10);
    CHECK(p.finishBand(b, 100, 10, 1e-6));
  }
}

TEST_CASE("the cost model converges to a constant measured cost") {
  FramePacer p(config(3.3e-3));
  const int w = 80, h = 60;
  // One band moves the estimate 0.3 of the way to its measurement.
  Band b = p.nextBand(w, h, 0, 2.0);
  p.finishBand(b, w, h, 1e-4 * b.rows() * w * b.spp);
  CHECK(p.costMs() == doctest::Approx(3.3e-3 + 0.3 * (1e-4 - 3.3e-3)));
  // A measured row is predicted at its measured cost at once.
  CHECK(p.rowMs(0, w, 2) == doctest::Approx(1e-4 * w * 2));
  for (int pass = 0; pass < 20; ++pass) runPass(p, w, h, [](int) { return 1e-4; }, 2.0);
  CHECK(p.costMs() == doctest::Approx(1e-4).epsilon(1e-6));
  for (int y = 0; y < h; ++y) CHECK(p.rowMs(y, w, 1) == doctest::Approx(1e-4 * w).epsilon(1e-9));
  CHECK(p.rowMs(h + 5, w, 1) == doctest::Approx(p.costMs() * w));  // outside the image: the mean
}

TEST_CASE("preview: wanted while moving when full passes are slow; scale 2..16 with hysteresis") {
  // 1e-3 ms per pixel sample at 1000x1000: a 1-spp pass takes 1000 ms against a 30 ms budget.
  // Preview passes aim at 15 ms: scale ceil(sqrt(1000 / 15)) = 9.
  FramePacer p(config(1e-3));
  p.noteMotion(0.0);
  ResolutionChoice r = p.chooseResolution(1000, 1000, 0.1, false);
  CHECK(r.preview);
  CHECK(p.previewing());
  CHECK(p.previewScale() == 9);
  CHECK(r.width == 1000 / 9);
  CHECK(r.height == 1000 / 9);

  // Re-chosen only at a restart that changes it by 2 or more.
  CHECK(p.chooseResolution(1300, 1000, 0.1, true).width == 1300 / 9);  // would be 10
  CHECK(p.previewScale() == 9);
  CHECK(p.chooseResolution(1600, 1000, 0.1, true).width == 1600 / 11);  // 11
  CHECK(p.previewScale() == 11);
  CHECK(p.chooseResolution(1000, 1000, 0.1, false).width == 1000 / 11);  // no restart: kept
  CHECK(p.previewScale() == 11);
  p.chooseResolution(1000, 1000, 0.1, true);
  CHECK(p.previewScale() == 9);

  // Clamped: a very slow scene previews at 1/16; one just over the slow threshold at 1/2.
  FramePacer slow(config(1.0));
  slow.noteMotion(0.0);
  CHECK(slow.chooseResolution(1000, 1000, 0.0, false).width == 1000 / 16);
  CHECK(slow.previewScale() == FramePacer::kMaxPreviewScale);
  FramePacer justSlow(config(2.5e-5));  // 25 ms > 0.8 * 30
  CHECK(justSlow.chooseResolution(1000, 1000, 0.0, true).width == 500);
  CHECK(justSlow.previewScale() == FramePacer::kMinPreviewScale);

  // Full passes that fit 0.8 of the budget, or --no-preview: always full resolution.
  FramePacer fast(config(2.3e-5));  // 23 ms
  fast.noteMotion(0.0);
  ResolutionChoice full = fast.chooseResolution(1000, 1000, 0.0, true);
  CHECK(!full.preview);
  CHECK(full.width == 1000);
  PacingConfig off = config(1.0);
  off.preview = false;
  FramePacer never(off);
  never.noteMotion(0.0);
  CHECK(!never.chooseResolution(1000, 1000, 0.0, true).preview);
}

TEST_CASE("preview: kept until it finished a pass and the camera settled; then full resolution") {
  RowCost cost = [](int) { return 1e-3; };
  FramePacer p(config(1e-3));
  p.noteMotion(10.0);
  ResolutionChoice r = p.chooseResolution(1000, 1000, 10.0, true);
  REQUIRE(r.preview);
  p.restartPass();
  // Still moving just before kSettleSeconds; settled after, but no preview pass has finished yet.
  CHECK(p.chooseResolution(1000, 1000, 10.0 + FramePacer::kSettleSeconds - 1e-3, false).preview);
  CHECK(p.chooseResolution(1000, 1000, 11.0, false).preview);
  runPass(p, r.width, r.height, cost);
  ResolutionChoice back = p.chooseResolution(1000, 1000, 11.0, false);
  CHECK(!back.preview);
  CHECK(back.leftPreview);  // a finished preview to show under the first full pass
  CHECK(back.width == 1000);
  CHECK(back.height == 1000);
  CHECK(!p.previewing());
  CHECK(!p.chooseResolution(1000, 1000, 11.0, false).leftPreview);  // only once

  // Leaving a preview that finished no pass (the window shrank: full passes fit): nothing to show.
  p.noteMotion(20.0);
  REQUIRE(p.chooseResolution(1000, 1000, 20.0, true).preview);
  p.restartPass();
  ResolutionChoice small = p.chooseResolution(100, 100, 20.0, true);
  CHECK(!small.preview);
  CHECK(!small.leftPreview);
  // settle() ends motion at once (a scripted run finishing).
  p.noteMotion(30.0);
  REQUIRE(p.chooseResolution(1000, 1000, 30.0, true).preview);
  runPass(p, 111, 111, cost);
  p.settle();
  CHECK(!p.chooseResolution(1000, 1000, 30.0, false).preview);
}

TEST_CASE("frames are shown at a rate that keeps display cost to a quarter of the time") {
  FramePacer p(config(1e-3, 30.0));
  p.recordDisplay(50.0, 0);  // the first two measurements replace the estimate
  CHECK(p.displayMs() == doctest::Approx(50.0));
  p.recordDisplay(10.0, 1);
  CHECK(p.displayMs() == doctest::Approx(10.0));
  p.recordDisplay(20.0, 2);  // then a moving average
  CHECK(p.displayMs() == doctest::Approx(12.0));
  CHECK(!p.presentDue(47.9));
  CHECK(p.presentDue(48.0));
  CHECK(p.tracingBudgetMs(false) == doctest::Approx(30.0));
  CHECK(p.tracingBudgetMs(true) == doctest::Approx(18.0));
  for (int i = 0; i < 50; ++i) p.recordDisplay(100.0, 3 + i);
  CHECK(p.tracingBudgetMs(true) == doctest::Approx(7.5));  // at least a quarter of the budget

  p.noteMotion(0.0);
  REQUIRE(p.chooseResolution(1000, 1000, 0.0, true).preview);
  CHECK(p.presentDue(0.0));  // every preview frame is shown
}

TEST_CASE("done at --spp: at full resolution, between passes") {
  PacingConfig c = config(1e-3);
  c.maxSpp = 4;
  FramePacer p(c);
  CHECK(!p.done(3));
  CHECK(p.done(4));
  Band b = p.nextBand(10, 10, 4, 0.0);
  p.finishBand(b, 10, 10, 0.01);
  CHECK(!p.done(4));  // a pass in flight
  p.restartPass();
  CHECK(p.done(4));
  p.noteMotion(0.0);
  REQUIRE(p.chooseResolution(1000, 1000, 0.0, true).preview);
  CHECK(!p.done(4));  // previewing
  CHECK(!FramePacer(config(1e-3)).done(1 << 20));  // no --spp: never done
}
