// compare_figure.h — the figure of `caustica compare`: the three render modes side by side, each
// labelled with its render time, and the paper's table of effects beside them. No GL.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "image/image_io.h"

namespace caustica::cli {

// An 8-bit RGB picture with rectangles and text (stb_easy_font, scaled by whole pixels).
struct Canvas {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;  // width * height * 3, row 0 at the top
  Canvas(int w, int h, std::uint8_t grey);
  void fill(int x, int y, int w, int h, const std::uint8_t color[3]);
  void blit(int x, int y, int w, int h, const std::vector<std::uint8_t>& src);  // src: w*h*3
  // Draws `text` with its top-left at (x, y), each font pixel `scale` pixels; returns its width.
  int text(int x, int y, const std::string& text, int scale, const std::uint8_t color[3]);
  static int textWidth(const std::string& text, int scale);
  static int textHeight(int scale);
};

struct ComparePanel {
  std::string label;  // "raster", "whitted", "path"
  std::string detail; // e.g. "64 spp, 31.2 s"
  Image image;
};

// Panels tone-mapped with `tone`, side by side, captions above, the table of effects on the right.
Canvas composeCompareFigure(const std::vector<ComparePanel>& panels, const ToneMapSettings& tone, const std::string& title);

// The paper's table: effect, then what raster, Whitted and path tracing show of it.
const std::vector<std::vector<std::string>>& effectsTable();

}  // namespace caustica::cli
