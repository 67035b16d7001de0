// report.cpp — the bench's outputs: CSV call sites, gnuplot scripts (and running gnuplot), the
// reference previews and the summary.md table.
#include "cli/bench/report.h"

#include <sys/wait.h>

#include <spawn.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <utility>

#include "cli/cli_common.h"
#include "util/error.h"

extern char** environ;

namespace caustica::cli {

namespace {

namespace fs = std::filesystem;

// Runs a program with arguments, no shell; returns its exit status (127 if it could not start).
int runProgram(const std::vector<std::string>& argv) {
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawnp(&pid, args[0], nullptr, nullptr, args.data(), environ) != 0) return 127;
  int status = 0;
  if (waitpid(pid, &status, 0) < 0) return 127;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

// The checkpoint times (seconds) and errors of a run: whole image, or its caustic region.
std::pair<std::vector<double>, std::vector<double>> errorCurve(const RunResult& r, bool causticRegion) {
  std::vector<double> t, e;
  for (const auto& row : r.rows) {
    t.push_back(row.seconds);
    e.push_back(causticRegion ? row.relMseCaustic : row.relMse);
  }
  return {t, e};
}

}  // namespace

std::string glRendererName(const std::string& glInfo) {
  size_t a = glInfo.find(" | ");
  if (a == std::string::npos) return glInfo;
  size_t b = glInfo.find(" | ", a + 3);
  return glInfo.substr(a + 3, b == std::string::npos ? std::string::npos : b - a - 3);
}

std::string estimatorName(const RenderSettings& settings, bool sceneHasCasters) {
  std::string name = integratorName(settings.integrator);
  if (settings.integrator == Integrator::Mis && sceneHasCasters &&
      settings.casterProbability != RenderSettings{}.casterProbability)
    name += formatDouble(" casters=%g", settings.casterProbability);
  if (settings.integrator == Integrator::Mis && sceneHasCasters && settings.manifold != RenderSettings{}.manifold)
    name += std::string(" manifold=") + manifoldModeName(settings.manifold);
  if (settings.integrator == Integrator::Mis && sceneHasCasters &&
      settings.guideProbability != RenderSettings{}.guideProbability)
    name += formatDouble(" guide=%g", settings.guideProbability);
  if (settings.integrator == Integrator::Mis && sceneHasCasters && settings.lightTracing != RenderSettings{}.lightTracing)
    name += std::string(" light-tracing=") + (settings.lightTracing ? "on" : "off");
  if (settings.integrator == Integrator::Mis && sceneHasCasters && settings.lightPaths != RenderSettings{}.lightPaths)
    name += formatDouble(" light-paths=%g", settings.lightPaths);
  return name;
}

std::string gnuplotQuote(const std::string& text) {
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("''") : std::string(1, c);
  return out + "'";
}

std::string gnuplotScript(const BenchSetup& setup, const std::string& scene, int width, int height,
                          const std::vector<RunResult>& results) {
  const std::string gp = "bench-" + scene + ".gp", png = "bench-" + scene + ".png";
  std::ostringstream f;
  f << "# " << gp << " - written by caustica bench; run: gnuplot " << gp << "\n";
  f << "set terminal pngcairo size 900,600 font 'sans,10'\n";
  f << "set output " << gnuplotQuote(png) << "\n";
  f << "set title "
    << gnuplotQuote(scene + ", " + std::to_string(width) + "x" + std::to_string(height) + ", " + setup.glRenderer +
                    " (" + setup.backend + ")")
    << " noenhanced\n";
  f << "set logscale xy\nset format y '10^{%L}'\nset grid xtics ytics mxtics mytics lc rgb '#dddddd'\n";
  double tMin = 1e30, tMax = 0.0;
  for (const auto& r : results)
    for (const auto& row : r.rows) tMin = std::min(tMin, row.seconds), tMax = std::max(tMax, row.seconds);
  if (tMax > 0.0)
    f << "set xrange [" << formatDouble("%.6g", tMin / 1.25) << ":" << formatDouble("%.6g", tMax * 1.25) << "]\n";
  f << "set xlabel 'render time (s)'\nset ylabel 'relMSE'\nset key inside right top noenhanced opaque box\n";
  for (size_t i = 0; i < results.size(); ++i) {
    f << "$run" << i << " << EOD\n# seconds spp relmse relmse_caustic\n";
    for (const auto& r : results[i].rows)
      f << formatDouble("%.6g", r.seconds) << ' ' << r.spp << ' ' << formatDouble("%.6g", r.relMse) << ' '
        << (std::isfinite(r.relMseCaustic) ? formatDouble("%.6g", r.relMseCaustic) : "NaN") << "\n";
    f << "EOD\n";
  }
  const char* colors[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b"};
  std::vector<std::string> terms;
  for (size_t i = 0; i < results.size(); ++i) {
    const RunResult& r = results[i];
    std::string color = colors[i % 6];
    bool multiMode = std::any_of(results.begin(), results.end(),
                                 [&](const RunResult& o) { return o.dispersion != results[0].dispersion; });
    std::string label = r.integrator + (multiMode ? " " + r.dispersion : "");
    terms.push_back("$run" + std::to_string(i) + " using 1:3 with linespoints lw 2 pt 7 ps 0.6 lc rgb '" + color +
                    "' dt 1 title " + gnuplotQuote(label));
    if (r.hasCaustic)
      terms.push_back("$run" + std::to_string(i) + " using 1:4 with linespoints lw 2 pt 6 ps 0.6 lc rgb '" + color +
                      "' dt 2 title " + gnuplotQuote(label + ", caustic region"));
  }
  // The reference's own error: measured curves cannot drop far below it.
  std::vector<std::string> seen;
  for (const auto& r : results) {
    if (std::find(seen.begin(), seen.end(), r.dispersion) != seen.end() || !std::isfinite(r.noise)) continue;
    seen.push_back(r.dispersion);
    std::string suffix = results.back().dispersion != results.front().dispersion ? " " + r.dispersion : "";
    terms.push_back(formatDouble("%.6g", r.noise) + " with lines lc rgb '#888888' dt 3 title " +
                    gnuplotQuote("reference noise" + suffix));
    if (r.hasCaustic && std::isfinite(r.noiseCaustic))
      terms.push_back(formatDouble("%.6g", r.noiseCaustic) + " with lines lc rgb '#888888' dt 4 title " +
                      gnuplotQuote("reference noise" + suffix + ", caustic"));
  }
  f << "plot ";
  for (size_t i = 0; i < terms.size(); ++i) f << (i ? ", \\\n     " : "") << terms[i];
  f << "\n";
  return f.str();
}

std::string adaptiveGainText(const RunResult& adaptive, const RunResult& uniform, bool caustic) {
  auto [ta, ea] = errorCurve(adaptive, caustic);
  auto [tu, eu] = errorCurve(uniform, caustic);
  const ThresholdTime a = timeToThreshold(ta, ea, 0.01), u = timeToThreshold(tu, eu, 0.01);
  const BenchRow &la = adaptive.rows.back(), &lu = uniform.rows.back();
  const double effA = efficiency(caustic ? la.relMseCaustic : la.relMse, la.seconds);
  const double effU = efficiency(caustic ? lu.relMseCaustic : lu.relMse, lu.seconds);
  std::string text = "t(0.01) " + formatThresholdTime(a) + " against " + formatThresholdTime(u);
  // A time already reached at the first checkpoint is only an upper bound: no ratio from it.
  auto measured = [](const ThresholdTime& t) {
    return t.kind == ThresholdTime::Kind::Interpolated || t.kind == ThresholdTime::Kind::Extrapolated;
  };
  if (measured(a) && measured(u) && a.seconds > 0.0)
    text += formatDouble(" (%.2fx less time)", u.seconds / a.seconds);
  return text + ", efficiency " + formatDouble("%.2fx", effA / effU);
}

std::string summaryMarkdown(const BenchSetup& setup, double totalSeconds, const std::vector<RunResult>& all) {
  std::ostringstream md;
  md << "GL renderer: " << setup.glRenderer << " (" << setup.backend << "); time limit "
     << formatDouble("%g", setup.maxSeconds) << " s per run; references: mis, another seed; total "
     << formatDouble("%.0f", totalSeconds) << " s\n\n";
  md << "| scene | estimator | size | spp | samples/s | rays/s | relMSE | t(0.01) | t(0.001) | efficiency | "
        "caustic relMSE | caustic t(0.01) | caustic t(0.001) | caustic eff. | ref. spp | ref. noise (caustic) |\n";
  md << "|---|---|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|\n";
  for (const auto& r : all) {
    const BenchRow& last = r.rows.back();
    auto [t, e] = errorCurve(r, false);
    md << "| " << r.scene << " | " << r.integrator << (r.dispersion == "rgb" ? "" : " " + r.dispersion) << " | "
       << last.width << "x" << last.height << " | " << last.spp << " | " << formatSci(last.samplesPerSecond) << " | "
       << formatSci(last.raysPerSecond) << " | " << formatSci(last.relMse) << " | "
       << formatThresholdTime(timeToThreshold(t, e, 0.01)) << " | "
       << formatThresholdTime(timeToThreshold(t, e, 0.001)) << " | "
       << formatSci(efficiency(last.relMse, last.seconds)) << " | ";
    if (r.hasCaustic) {
      auto [tc, ec] = errorCurve(r, true);
      md << formatSci(last.relMseCaustic) << " | " << formatThresholdTime(timeToThreshold(tc, ec, 0.01)) << " | "
         << formatThresholdTime(timeToThreshold(tc, ec, 0.001)) << " | "
         << formatSci(efficiency(last.relMseCaustic, last.seconds)) << " | ";
    } else {
      md << "- | - | - | - | ";
    }
    md << (r.referenceSpp > 0 ? std::to_string(r.referenceSpp) : "file") << " | " << formatSci(r.noise)
       << (r.hasCaustic ? " (" + formatSci(r.noiseCaustic) + ")" : "") << " |\n";
  }
  // mis against naive at the same scene and dispersion mode: the ratio of efficiencies.
  std::ostringstream cmp;
  for (const auto& m : all) {
    if (m.integrator.rfind("mis", 0) != 0 || m.integrator.find(" adaptive") != std::string::npos) continue;
    for (const auto& n : all) {
      if (n.integrator != "naive" || n.scene != m.scene || n.dispersion != m.dispersion) continue;
      const BenchRow &a = m.rows.back(), &b = n.rows.back();
      double whole = efficiency(a.relMse, a.seconds) / efficiency(b.relMse, b.seconds);
      cmp << "- " << m.scene << (m.dispersion == "rgb" ? "" : " (" + m.dispersion + ")") << ": " << m.integrator
          << "/naive efficiency " << formatDouble("%.2fx", whole) << " whole image";
      if (m.hasCaustic)
        cmp << ", "
            << formatDouble("%.2fx", efficiency(a.relMseCaustic, a.seconds) / efficiency(b.relMseCaustic, b.seconds))
            << " caustic region";
      cmp << "\n";
    }
  }
  // Adaptive against uniform sampling of the same estimator: time to relMSE 0.01 measured against the
  // reference (whole image and caustic region), and the efficiency ratio at the last checkpoint.
  const std::string suffix = " adaptive";
  for (const auto& a : all) {
    if (a.integrator.size() <= suffix.size() ||
        a.integrator.compare(a.integrator.size() - suffix.size(), suffix.size(), suffix) != 0)
      continue;
    const std::string base = a.integrator.substr(0, a.integrator.size() - suffix.size());
    for (const auto& u : all) {
      if (u.integrator != base || u.scene != a.scene || u.dispersion != a.dispersion) continue;
      cmp << "- " << a.scene << (a.dispersion == "rgb" ? "" : " (" + a.dispersion + ")") << ": " << a.integrator
          << "/" << base << " " << adaptiveGainText(a, u, false);
      if (a.hasCaustic) cmp << "; caustic region " << adaptiveGainText(a, u, true);
      cmp << "\n";
    }
  }
  if (!cmp.str().empty()) md << "\n" << cmp.str();
  md << "\nt(x): render time to reach relMSE x, interpolated on log-log axes; '~' extrapolated as 1/time past the "
        "last checkpoint, '<=' already reached at the first. efficiency = 1 / (relMSE x seconds) at the last "
        "checkpoint.\n";
  return md.str();
}

Image outlined(Image image, const PixelRect& region, float value) {
  auto put = [&](int x, int y) {
    if (x < 0 || y < 0 || x >= image.width || y >= image.height) return;
    image.at(x, y, 0) = 0.0f;
    image.at(x, y, 1) = value;
    image.at(x, y, 2) = value;
  };
  const PixelRect& r = region;
  for (int x = r.x0 - 1; x <= r.x1; ++x) put(x, r.y0 - 1), put(x, r.y1);
  for (int y = r.y0 - 1; y <= r.y1; ++y) put(r.x0 - 1, y), put(r.x1, y);
  return image;
}

void writeReferencePreview(const std::string& outDir, const std::string& scene, const std::string& dispersion,
                           const Image& reference, const std::optional<PixelRect>& caustic) {
  const float outline = 4.0f;  // linear radiance: bright cyan after tone mapping
  std::string preview = (fs::path(outDir) / (scene + "-" + dispersion + "-reference.png")).string();
  writeImage(preview, caustic ? outlined(reference, *caustic, outline) : reference);
}

std::string writeSceneCsv(const std::string& outDir, const std::string& scene,
                          const std::vector<RunResult>& results) {
  std::vector<BenchRow> rows;
  for (const auto& r : results) rows.insert(rows.end(), r.rows.begin(), r.rows.end());
  std::string csv = (fs::path(outDir) / ("bench-" + scene + ".csv")).string();
  writeBenchCsv(csv, rows);
  return csv;
}

void writePlot(const std::string& outDir, const std::string& scene, const std::string& script,
               const std::string& gnuplot, bool quiet) {
  fs::path gp = fs::path(outDir) / ("bench-" + scene + ".gp");
  fs::path png = fs::path(outDir) / ("bench-" + scene + ".png");
  std::ofstream f(gp);
  if (!f) throw Error(gp.string() + ": cannot open for writing");
  f << script;
  f.close();
  // gnuplot runs in the output folder so the script's relative output name works when rerun by hand.
  fs::path absGp = fs::absolute(gp);
  fs::path cwd = fs::current_path();
  std::error_code ec;
  fs::current_path(fs::absolute(outDir), ec);
  int rc = ec ? 127 : runProgram({gnuplot, absGp.filename().string()});
  fs::current_path(cwd, ec);
  if (rc == 0) note(quiet, "wrote " + png.string());
  else
    note(quiet, "warning: '" + gnuplot + "' failed or is missing (exit " + std::to_string(rc) + "): no " +
                    png.string() + "; install gnuplot-nox and run 'gnuplot " + gp.filename().string() + "' in " +
                    outDir);
}

void writeSummary(const std::string& outDir, const std::string& markdown, bool quiet) {
  std::cout << markdown;
  std::string path = (fs::path(outDir) / "summary.md").string();
  std::ofstream f(path);
  f << markdown;
  if (!f) throw Error(path + ": cannot write");
  note(quiet, "wrote " + path);
}

}  // namespace caustica::cli
