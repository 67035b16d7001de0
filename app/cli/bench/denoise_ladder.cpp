// denoise_ladder.cpp — bench --denoise at fixed sample counts: rendering the ladder and timing the
// denoiser, and its CSV, plot, summary and figure.
#include "cli/bench/denoise_ladder.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace caustica::cli {

namespace {

using Clock = std::chrono::steady_clock;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

template <class F>
double millisecondsOf(F&& f) {
  const auto t0 = Clock::now();
  f();
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

std::string num(double v) { return std::isfinite(v) ? formatDouble("%.4g", v) : "nan"; }

}  // namespace

const std::vector<int>& denoiseLadderSpp() {
  static const std::vector<int> spp = {4, 16, 64, 256};
  return spp;
}

const std::vector<int>& denoiseFigureSpp() {
  static const std::vector<int> spp = {4, 16, 64};
  return spp;
}

DenoiseLadder runDenoiseLadder(Renderer& featured, Renderer& plain, const std::string& scene, const Reference& ref,
                               const std::optional<PixelRect>& caustic, bool quiet) {
  DenoiseLadder out;
  out.scene = scene;
  out.dispersion = dispersionModeName(featured.settings().dispersion);
  out.width = featured.settings().width;
  out.height = featured.settings().height;
  out.noise = ref.noise;
  out.noiseCaustic = ref.noiseCaustic;
  out.referenceSpp = ref.spp;
  out.hasCaustic = caustic.has_value();
  out.reference = ref.image;
  featured.setFeatureBuffers(true);
  featured.reset();
  const PixelRect whole = fullImage(out.width, out.height);
  const double refMean = imageMean(ref.image, whole), refCaustic = caustic ? imageMean(ref.image, *caustic) : 1.0;
  for (int spp : denoiseLadderSpp()) {
    while (featured.samplesPerPixel() < spp)
      featured.renderPass(std::min(std::max(featured.samplesPerDispatch(), 1), spp - featured.samplesPerPixel()));
    const Image raw = featured.image(), den = featured.denoisedImage();
    DenoiseStep s;
    s.spp = spp;
    s.rawRelMse = relMse(raw, ref.image);
    s.denoisedRelMse = relMse(den, ref.image);
    s.rawMean = imageMean(raw, whole) / refMean;
    s.denoisedMean = imageMean(den, whole) / refMean;
    s.rawRelMseCaustic = caustic ? relMse(raw, ref.image, *caustic) : std::nan("");
    s.denoisedRelMseCaustic = caustic ? relMse(den, ref.image, *caustic) : std::nan("");
    s.rawCausticMean = caustic ? imageMean(raw, *caustic) / refCaustic : std::nan("");
    s.denoisedCausticMean = caustic ? imageMean(den, *caustic) / refCaustic : std::nan("");
    out.steps.push_back(s);
    const auto& fig = denoiseFigureSpp();
    if (std::find(fig.begin(), fig.end(), spp) != fig.end()) {
      out.pictures.emplace_back(raw, den);
      out.pictureSpp.push_back(spp);
    }
    if (!quiet)
      std::fprintf(stderr, "caustica: %s denoise %4d spp: relMSE raw %s, denoised %s%s\n", scene.c_str(), spp,
                   formatSci(s.rawRelMse).c_str(), formatSci(s.denoisedRelMse).c_str(),
                   caustic ? (", caustic " + formatSci(s.rawRelMseCaustic) + " / " + formatSci(s.denoisedRelMseCaustic)).c_str()
                           : "");
  }
  // The denoiser against one 1-spp pass at this size, interleaved (the machine's load moves): the plain
  // path tracer and the one with feature buffers. Warmed up first (llvmpipe compiles at first dispatch).
  plain.setFeatureBuffers(false);
  plain.reset();
  plain.renderPass(1);
  featured.denoise();
  std::vector<double> filter, pass, featurePass;
  for (int k = 0; k < 5; ++k) {
    pass.push_back(millisecondsOf([&] { plain.renderPass(1); }));
    filter.push_back(millisecondsOf([&] { featured.denoise(); }));
    featurePass.push_back(millisecondsOf([&] { featured.renderPass(1); }));
  }
  out.filterMs = median(filter);
  out.passMs = median(pass);
  out.featurePassMs = median(featurePass);
  featured.setFeatureBuffers(false);
  return out;
}

std::string denoiseLadderCsv(const std::vector<DenoiseLadder>& ladders) {
  std::ostringstream o;
  o << "scene,dispersion,width,height,spp,relmse_raw,relmse_denoised,relmse_caustic_raw,relmse_caustic_denoised,"
       "mean_raw,mean_denoised,caustic_mean_raw,caustic_mean_denoised,reference_noise,reference_noise_caustic,"
       "reference_spp,filter_ms,pass_ms,feature_pass_ms\n";
  for (const DenoiseLadder& l : ladders)
    for (const DenoiseStep& s : l.steps)
      o << l.scene << ',' << l.dispersion << ',' << l.width << ',' << l.height << ',' << s.spp << ',' << num(s.rawRelMse) << ','
        << num(s.denoisedRelMse) << ',' << num(s.rawRelMseCaustic) << ',' << num(s.denoisedRelMseCaustic) << ','
        << num(s.rawMean) << ',' << num(s.denoisedMean) << ',' << num(s.rawCausticMean) << ',' << num(s.denoisedCausticMean)
        << ',' << num(l.noise) << ',' << num(l.noiseCaustic) << ',' << l.referenceSpp << ',' << num(l.filterMs) << ','
        << num(l.passMs) << ',' << num(l.featurePassMs) << '\n';
  return o.str();
}

std::string denoiseLadderPlot(const BenchSetup& setup, const DenoiseLadder& l, const std::string& stem) {
  std::ostringstream f;
  f << "# bench-denoise-" << stem << ".gp - written by caustica bench --denoise; run: gnuplot bench-denoise-" << stem << ".gp\n";
  f << "set terminal pngcairo size 700,500 font 'sans,10'\n";
  f << "set output " << gnuplotQuote("bench-denoise-" + stem + ".png") << "\n";
  f << "set title " << gnuplotQuote(l.scene + " (" + l.dispersion + "), " + std::to_string(l.width) + "x" + std::to_string(l.height) +
                                    ", raw and denoised, " + setup.glRenderer)
    << " noenhanced\n";
  f << "set logscale xy\nset format y '10^{%L}'\nset grid xtics ytics mxtics mytics lc rgb '#dddddd'\n";
  f << "set xlabel 'samples per pixel'\nset ylabel 'relMSE'\nset key inside right top noenhanced opaque box\n";
  f << "$ladder << EOD\n# spp raw denoised raw_caustic denoised_caustic\n";
  for (const DenoiseStep& s : l.steps)
    f << s.spp << ' ' << formatDouble("%.6g", s.rawRelMse) << ' ' << formatDouble("%.6g", s.denoisedRelMse) << ' '
      << (l.hasCaustic ? formatDouble("%.6g", s.rawRelMseCaustic) : "NaN") << ' '
      << (l.hasCaustic ? formatDouble("%.6g", s.denoisedRelMseCaustic) : "NaN") << "\n";
  f << "EOD\n";
  f << "plot $ladder using 1:2 with linespoints lw 2 pt 7 lc rgb '#1f77b4' title 'raw', \\\n"
       "     $ladder using 1:3 with linespoints lw 2 pt 7 lc rgb '#d62728' title 'denoised'";
  if (l.hasCaustic)
    f << ", \\\n     $ladder using 1:4 with linespoints lw 2 pt 6 dt 2 lc rgb '#1f77b4' title 'raw, caustic region', \\\n"
         "     $ladder using 1:5 with linespoints lw 2 pt 6 dt 2 lc rgb '#d62728' title 'denoised, caustic region'";
  if (std::isfinite(l.noise))
    f << ", \\\n     " << formatDouble("%.6g", l.noise) << " with lines lc rgb '#888888' dt 3 title 'reference noise'";
  f << "\n";
  return f.str();
}

std::string denoiseSummaryMarkdown(const std::vector<DenoiseLadder>& ladders) {
  std::ostringstream o;
  o << "\n## Denoiser (bench --denoise)\n\n"
    << "| scene | denoised 16 spp | raw 256 spp | raw 1024 spp (extrapolated) | raw 16 spp | mean 16 spp | caustic mean 16 spp "
       "(raw) | caustic relMSE 16 spp denoised / raw 256 | filter ms | 1-spp pass ms | filter / pass | feature buffers' cost |\n"
    << "|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|\n";
  for (const DenoiseLadder& l : ladders) {
    const DenoiseStep *s16 = nullptr, *s256 = nullptr;
    for (const DenoiseStep& s : l.steps) {
      if (s.spp == 16) s16 = &s;
      if (s.spp == 256) s256 = &s;
    }
    if (!s16 || !s256) continue;
    // relMSE against a reference carries the reference's own error (noise): raw N spp measures about
    // true(256) * 256 / N + noise.
    const double noise = std::isfinite(l.noise) ? l.noise : 0.0;
    const double raw1024 = (s256->rawRelMse - noise) / 4.0 + noise;
    o << "| " << l.scene << (l.dispersion == "rgb" ? "" : " (" + l.dispersion + ")") << " | " << formatSci(s16->denoisedRelMse)
      << " | " << formatSci(s256->rawRelMse) << " | " << formatSci(raw1024) << " | " << formatSci(s16->rawRelMse) << " | "
      << formatDouble("%.3f", s16->denoisedMean) << " | "
      << (l.hasCaustic ? formatDouble("%.3f", s16->denoisedCausticMean) + " (" + formatDouble("%.3f", s16->rawCausticMean) + ")" : "-")
      << " | "
      << (l.hasCaustic ? formatSci(s16->denoisedRelMseCaustic) + " / " + formatSci(s256->rawRelMseCaustic) : "-") << " | "
      << formatDouble("%.1f", l.filterMs) << " | " << formatDouble("%.1f", l.passMs) << " | "
      << formatDouble("%.2f", l.filterMs / std::max(l.passMs, 1e-9)) << " | "
      << formatDouble("%+.0f %%", 100.0 * (l.featurePassMs / std::max(l.passMs, 1e-9) - 1.0)) << " |\n";
  }
  o << "\nrelMSE against the reference (its own error, the reference noise, included in every figure; raw 1024 spp is "
       "raw 256 spp's error above that noise / 4, plus the noise). Means are over the reference's (1: equal), the "
       "caustic mean's raw figure in brackets (its own noise at 16 spp). Timings are medians of 5 interleaved runs "
       "at the bench's size; the feature buffers' cost is a 1-spp pass with them against one without.\n";
  return o.str();
}

Canvas composeDenoiseFigure(const DenoiseLadder& l, const ToneMapSettings& tone) {
  const std::uint8_t white[3] = {235, 235, 235}, grey[3] = {160, 160, 160};
  const int pw = l.width, ph = l.height, scale = std::max(1, std::min(2, ph / 200));
  const int margin = 6 * scale, lineH = Canvas::textHeight(scale), captionH = lineH + margin / 2;
  const int rows = static_cast<int>(l.pictures.size());
  const int top = margin + lineH + margin;
  const int width = margin + 3 * (pw + margin);
  const int height = top + std::max(rows, 1) * (captionH + ph + margin);
  Canvas c(width, height, 24);
  c.text(margin, margin, l.scene + ": raw | denoised | reference (" + std::to_string(l.referenceSpp) + " spp)", scale, white);
  for (int r = 0; r < rows; ++r) {
    const int y = top + r * (captionH + ph + margin);
    const int spp = l.pictureSpp[static_cast<size_t>(r)];
    const DenoiseStep* s = nullptr;
    for (const DenoiseStep& st : l.steps)
      if (st.spp == spp) s = &st;
    const Image* imgs[3] = {&l.pictures[size_t(r)].first, &l.pictures[size_t(r)].second, &l.reference};
    const std::string captions[3] = {std::to_string(spp) + " spp raw, relMSE " + (s ? formatSci(s->rawRelMse) : ""),
                                     std::to_string(spp) + " spp denoised, " + (s ? formatSci(s->denoisedRelMse) : ""),
                                     r == 0 ? "reference" : ""};
    for (int k = 0; k < 3; ++k) {
      if (k == 2 && r > 0) continue;  // the reference once, at the top
      const int x = margin + k * (pw + margin);
      c.text(x, y, captions[k], scale, k == 2 ? white : grey);
      c.blit(x, y + captionH, pw, ph, tonemapImage(imgs[k]->rgb, tone));
    }
  }
  return c;
}

}  // namespace caustica::cli
