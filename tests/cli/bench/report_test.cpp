// report_test.cpp — the bench's report text: GL renderer and estimator names, gnuplot quoting and
// the whole plot script, the summary.md table and mis/naive ratios, the caustic-region outline.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include "cli/bench/report.h"

using namespace caustica;
using namespace caustica::cli;

namespace {

// A run with checkpoints at `seconds` with whole-image errors `relMse` and caustic errors `caustic`
// (empty: the scene has no caustic region); 16x16 pixels, spp = 10 x checkpoint number.
RunResult makeRun(const std::string& scene, const std::string& integrator, const std::string& dispersion,
                  const std::vector<double>& seconds, const std::vector<double>& relMse,
                  const std::vector<double>& caustic) {
  RunResult r;
  r.scene = scene;
  r.integrator = integrator;
  r.dispersion = dispersion;
  r.hasCaustic = !caustic.empty();
  r.referenceSpp = 64;
  r.noise = 0.001;
  r.noiseCaustic = r.hasCaustic ? 0.002 : std::nan("");
  for (size_t i = 0; i < seconds.size(); ++i) {
    BenchRow row;
    row.scene = scene;
    row.integrator = integrator;
    row.dispersion = dispersion;
    row.width = row.height = 16;
    row.checkpoint = static_cast<int>(i);
    row.seconds = seconds[i];
    row.spp = 10 * static_cast<int>(i + 1);
    row.samplesPerSecond = 2560.0;
    row.raysPerSecond = 1e6;
    row.relMse = relMse[i];
    row.relMseCaustic = r.hasCaustic ? caustic[i] : std::nan("");
    r.rows.push_back(row);
  }
  return r;
}

}  // namespace

TEST_CASE("the GL renderer is the middle part of the context's description") {
  CHECK(glRendererName("Mesa/X.org | llvmpipe (LLVM 15.0.6, 256 bits) | 4.5 (Core Profile) Mesa 22.3.6") ==
        "llvmpipe (LLVM 15.0.6, 256 bits)");
  CHECK(glRendererName("NVIDIA Corporation | NVIDIA H200/PCIe/SSE2") == "NVIDIA H200/PCIe/SSE2");
  CHECK(glRendererName("no separators") == "no separators");
}

TEST_CASE("a non-default caster probability is part of a mis estimator's name on scenes with casters") {
  RenderSettings s;
  s.integrator = Integrator::Naive;
  CHECK(estimatorName(s, true) == "naive");
  s.casterProbability = 0.3f;
  CHECK(estimatorName(s, true) == "naive");  // naive never aims at casters
  s.integrator = Integrator::Mis;
  CHECK(estimatorName(s, true) == "mis casters=0.3");
  CHECK(estimatorName(s, false) == "mis");  // nothing to aim at
  s.casterProbability = RenderSettings{}.casterProbability;
  CHECK(estimatorName(s, true) == "mis");
}

TEST_CASE("gnuplot strings are single-quoted with quotes doubled") {
  CHECK(gnuplotQuote("mis") == "'mis'");
  CHECK(gnuplotQuote("it's") == "'it''s'");
  CHECK(gnuplotQuote("''") == "''''''");
  CHECK(gnuplotQuote("") == "''");
}

TEST_CASE("the gnuplot script holds the data inline, a curve per run and the reference noise") {
  BenchSetup setup{"it's GPU", "egl", 2.0};
  std::vector<RunResult> runs = {makeRun("box", "naive", "rgb", {1.0, 2.0}, {0.1, 0.05}, {1.0, 0.5}),
                                 makeRun("box", "mis", "spectral", {1.0, 2.0}, {0.02, 0.005}, {0.2, 0.1})};
  runs[1].rows[0].relMseCaustic = std::nan("");  // an unmeasured value is NaN to gnuplot
  CHECK(gnuplotScript(setup, "box", 16, 12, runs) ==
        "# bench-box.gp - written by caustica bench; run: gnuplot bench-box.gp\n"
        "set terminal pngcairo size 900,600 font 'sans,10'\n"
        "set output 'bench-box.png'\n"
        "set title 'box, 16x12, it''s GPU (egl)' noenhanced\n"
        "set logscale xy\n"
        "set format y '10^{%L}'\n"
        "set grid xtics ytics mxtics mytics lc rgb '#dddddd'\n"
        "set xrange [0.8:2.5]\n"
        "set xlabel 'render time (s)'\n"
        "set ylabel 'relMSE'\n"
        "set key inside right top noenhanced opaque box\n"
        "$run0 << EOD\n"
        "# seconds spp relmse relmse_caustic\n"
        "1 10 0.1 1\n"
        "2 20 0.05 0.5\n"
        "EOD\n"
        "$run1 << EOD\n"
        "# seconds spp relmse relmse_caustic\n"
        "1 10 0.02 NaN\n"
        "2 20 0.005 0.1\n"
        "EOD\n"
        "plot $run0 using 1:3 with linespoints lw 2 pt 7 ps 0.6 lc rgb '#1f77b4' dt 1 title 'naive rgb', \\\n"
        "     $run0 using 1:4 with linespoints lw 2 pt 6 ps 0.6 lc rgb '#1f77b4' dt 2 title 'naive rgb, caustic "
        "region', \\\n"
        "     $run1 using 1:3 with linespoints lw 2 pt 7 ps 0.6 lc rgb '#d62728' dt 1 title 'mis spectral', \\\n"
        "     $run1 using 1:4 with linespoints lw 2 pt 6 ps 0.6 lc rgb '#d62728' dt 2 title 'mis spectral, "
        "caustic region', \\\n"
        "     0.001 with lines lc rgb '#888888' dt 3 title 'reference noise rgb', \\\n"
        "     0.002 with lines lc rgb '#888888' dt 4 title 'reference noise rgb, caustic', \\\n"
        "     0.001 with lines lc rgb '#888888' dt 3 title 'reference noise spectral', \\\n"
        "     0.002 with lines lc rgb '#888888' dt 4 title 'reference noise spectral, caustic'\n");

  // One mode, no caustic region, a reference given as a file (noise unknown): one curve, no noise line.
  RunResult plain = makeRun("box", "mis", "rgb", {0.5}, {0.2}, {});
  plain.noise = std::nan("");
  std::string script = gnuplotScript(setup, "box", 16, 12, {plain});
  CHECK(script.find("set xrange [0.4:0.625]\n") != std::string::npos);
  CHECK(script.find("\nplot $run0 using 1:3 with linespoints lw 2 pt 7 ps 0.6 lc rgb '#1f77b4' dt 1 title 'mis'\n") !=
        std::string::npos);
  CHECK(script.find("reference noise") == std::string::npos);
  CHECK(script.find("using 1:4") == std::string::npos);
}

TEST_CASE("summary.md: a row per run, threshold times, efficiency ratios of mis against naive") {
  BenchSetup setup{"llvmpipe (LLVM 15.0.6, 256 bits)", "osmesa", 0.3};
  RunResult naive = makeRun("box", "naive", "rgb", {1.0, 2.0}, {0.1, 0.05}, {1.0, 0.5});
  RunResult mis = makeRun("box", "mis", "rgb", {1.0, 2.0}, {0.02, 0.005}, {0.2, 0.1});
  RunResult given = makeRun("lens", "mis", "spectral", {1.0}, {0.001}, {});
  given.referenceSpp = 0;
  given.noise = std::nan("");
  std::string md = summaryMarkdown(setup, 12.4, {naive, mis, given});
  const std::string expected =
      "GL renderer: llvmpipe (LLVM 15.0.6, 256 bits) (osmesa); time limit 0.3 s per run; references: mis, another "
      "seed; total 12 s\n"
      "\n"
      "| scene | estimator | size | spp | samples/s | rays/s | relMSE | t(0.01) | t(0.001) | efficiency | caustic "
      "relMSE | caustic t(0.01) | caustic t(0.001) | caustic eff. | ref. spp | ref. noise (caustic) |\n"
      "|---|---|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|\n"
      // naive never reaches 0.01: extrapolated as 1/time from (2 s, 0.05); efficiency 1 / (0.05 x 2).
      "| box | naive | 16x16 | 20 | 2.56e+03 | 1e+06 | 0.05 | ~10 s | ~100 s | 10 | 0.5 | ~100 s | ~1e+03 s | 1 | 64 "
      "| 0.001 (0.002) |\n"
      // mis crosses 0.01 between 0.02 at 1 s and 0.005 at 2 s: error ~ 1/t^2 there, so at sqrt(2) s.
      "| box | mis | 16x16 | 20 | 2.56e+03 | 1e+06 | 0.005 | 1.41 s | ~10 s | 100 | 0.1 | ~20 s | ~200 s | 5 | 64 | "
      "0.001 (0.002) |\n"
      // Already at 0.001 at the first checkpoint; no caustic region; the reference was a file.
      "| lens | mis spectral | 16x16 | 10 | 2.56e+03 | 1e+06 | 0.001 | <=1 s | <=1 s | 1e+03 | - | - | - | - | file | "
      "n/a |\n"
      "\n"
      "- box: mis/naive efficiency 10.00x whole image, 5.00x caustic region\n"
      "\n"
      "t(x): render time to reach relMSE x, interpolated on log-log axes; '~' extrapolated as 1/time past the last "
      "checkpoint, '<=' already reached at the first. efficiency = 1 / (relMSE x seconds) at the last checkpoint.\n";
  CHECK(md == expected);

  // Without a naive run there is nothing to compare: no ratio lines.
  std::string alone = summaryMarkdown(setup, 1.0, {mis});
  CHECK(alone.find("efficiency 10.00x") == std::string::npos);
  CHECK(alone.find("|\n\nt(x): ") != std::string::npos);
}

TEST_CASE("summary.md: an adaptive run is compared with the uniform run of its estimator") {
  BenchSetup setup{"llvmpipe", "osmesa", 2.0};
  RunResult naive = makeRun("box", "naive", "rgb", {1.0, 2.0}, {0.1, 0.05}, {});
  RunResult mis = makeRun("box", "mis", "rgb", {1.0, 2.0}, {0.02, 0.01}, {0.2, 0.1});
  RunResult adaptive = makeRun("box", "mis adaptive", "rgb", {1.0, 2.0}, {0.01, 0.005}, {0.05, 0.025});
  // Whole image: 0.01 at the first checkpoint (an upper bound: no time ratio) against 2 s; efficiency
  // 1/(0.005 x 2) against 1/(0.01 x 2). Caustic region: 0.025 at 2 s reaches 0.01 at ~5 s (1/time),
  // uniform 0.1 at ~20 s.
  CHECK(adaptiveGainText(adaptive, mis, false) == "t(0.01) <=1 s against 2 s, efficiency 2.00x");
  CHECK(adaptiveGainText(adaptive, mis, true) == "t(0.01) ~5 s against ~20 s (4.00x less time), efficiency 4.00x");
  const std::string md = summaryMarkdown(setup, 3.0, {naive, mis, adaptive});
  CHECK(md.find("- box: mis adaptive/mis t(0.01) <=1 s against 2 s, efficiency 2.00x; caustic "
                "region t(0.01) ~5 s against ~20 s (4.00x less time), efficiency 4.00x\n") != std::string::npos);
  // mis/naive compares the uniform runs only.
  CHECK(md.find("mis adaptive/naive") == std::string::npos);
  CHECK(md.find("- box: mis/naive efficiency") != std::string::npos);
}

TEST_CASE("the caustic region is outlined one pixel outside it") {
  Image img{6, 6, std::vector<float>(6 * 6 * 3, 1.0f)};
  Image out = outlined(img, PixelRect{2, 2, 4, 4}, 4.0f);
  auto isOutline = [&](int x, int y) {
    return out.at(x, y, 0) == 0.0f && out.at(x, y, 1) == 4.0f && out.at(x, y, 2) == 4.0f;
  };
  auto isUntouched = [&](int x, int y) {
    return out.at(x, y, 0) == 1.0f && out.at(x, y, 1) == 1.0f && out.at(x, y, 2) == 1.0f;
  };
  int outline = 0;
  for (int y = 0; y < 6; ++y)
    for (int x = 0; x < 6; ++x) {
      bool ring = x >= 1 && x <= 4 && y >= 1 && y <= 4 && (x == 1 || x == 4 || y == 1 || y == 4);
      CHECK_MESSAGE((ring ? isOutline(x, y) : isUntouched(x, y)), "pixel " << x << "," << y);
      outline += isOutline(x, y);
    }
  CHECK(outline == 12);
  CHECK(img.at(1, 1, 0) == 1.0f);  // the input is a copy

  // At the image's corner the parts outside are skipped.
  Image corner = outlined(img, PixelRect{0, 0, 2, 2}, 4.0f);
  CHECK(corner.at(2, 0, 0) == 0.0f);
  CHECK(corner.at(0, 2, 1) == 4.0f);
  CHECK(corner.at(2, 2, 2) == 4.0f);
  CHECK(corner.at(0, 0, 0) == 1.0f);
  CHECK(corner.at(3, 3, 0) == 1.0f);
}
