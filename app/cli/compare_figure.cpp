// compare_figure.cpp — drawing the compare figure: panels, captions and the table of effects.
#include "cli/compare_figure.h"

#include <algorithm>

#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#endif
#include "stb_easy_font.h"
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

namespace caustica::cli {

Canvas::Canvas(int w, int h, std::uint8_t grey) : width(w), height(h), rgb(static_cast<size_t>(w) * h * 3, grey) {}

void Canvas::fill(int x, int y, int w, int h, const std::uint8_t color[3]) {
  for (int j = std::max(0, y); j < std::min(height, y + h); ++j)
    for (int i = std::max(0, x); i < std::min(width, x + w); ++i)
      for (int c = 0; c < 3; ++c) rgb[(static_cast<size_t>(j) * width + i) * 3 + c] = color[c];
}

void Canvas::blit(int x, int y, int w, int h, const std::vector<std::uint8_t>& src) {
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      int X = x + i, Y = y + j;
      if (X < 0 || Y < 0 || X >= width || Y >= height) continue;
      for (int c = 0; c < 3; ++c)
        rgb[(static_cast<size_t>(Y) * width + X) * 3 + c] = src[(static_cast<size_t>(j) * w + i) * 3 + c];
    }
}

int Canvas::textWidth(const std::string& text, int scale) {
  std::string t = text;
  return stb_easy_font_width(t.data()) * scale;
}

int Canvas::textHeight(int scale) { return 12 * scale; }

int Canvas::text(int x, int y, const std::string& text, int scale, const std::uint8_t color[3]) {
  std::string t = text;
  std::vector<char> buffer(t.size() * 300 + 64);
  int quads = stb_easy_font_print(0.0f, 0.0f, t.data(), nullptr, buffer.data(), static_cast<int>(buffer.size()));
  struct Vertex {
    float x, y, z;
    unsigned char c[4];
  };
  const auto* v = reinterpret_cast<const Vertex*>(buffer.data());
  for (int q = 0; q < quads; ++q) {
    const Vertex* quad = v + 4 * q;  // axis-aligned: corners 0 and 2 are opposite
    int x0 = static_cast<int>(std::min(quad[0].x, quad[2].x)), x1 = static_cast<int>(std::max(quad[0].x, quad[2].x));
    int y0 = static_cast<int>(std::min(quad[0].y, quad[2].y)), y1 = static_cast<int>(std::max(quad[0].y, quad[2].y));
    fill(x + x0 * scale, y + y0 * scale, (x1 - x0) * scale, (y1 - y0) * scale, color);
  }
  return textWidth(text, scale);
}

const std::vector<std::vector<std::string>>& effectsTable() {
  static const std::vector<std::vector<std::string>> table = {
      {"effect", "raster", "whitted", "path"},
      {"direct light", "yes", "yes", "yes"},
      {"sharp shadows", "maps", "yes", "yes"},
      {"soft shadows", "no", "no", "yes"},
      {"mirror reflection", "planar", "yes", "yes"},
      {"refraction, TIR", "no", "yes", "yes"},
      {"caustics", "no", "no", "yes"},
      {"colour bleeding", "no", "no", "yes"},
      {"area lights", "points", "points", "yes"},
  };
  return table;
}

Canvas composeCompareFigure(const std::vector<ComparePanel>& panels, const ToneMapSettings& tone, const std::string& title) {
  const std::uint8_t white[3] = {235, 235, 235}, grey[3] = {150, 150, 150}, yes[3] = {120, 220, 120},
                     no[3] = {230, 110, 100}, partial[3] = {230, 200, 100};
  const int pw = panels.empty() ? 0 : panels[0].image.width, ph = panels.empty() ? 0 : panels[0].image.height;
  const int scale = std::max(1, std::min(3, ph / 200));
  const int margin = 6 * scale, lineH = Canvas::textHeight(scale);
  const auto& table = effectsTable();
  int col0 = 0, colW = 0;
  for (const auto& row : table) {
    col0 = std::max(col0, Canvas::textWidth(row[0], scale));
    for (size_t c = 1; c < row.size(); ++c) colW = std::max(colW, Canvas::textWidth(row[c], scale));
  }
  col0 += 3 * margin;
  colW += 2 * margin;
  const int tableW = col0 + 3 * colW + margin;
  const int tableH = static_cast<int>(table.size()) * (lineH + margin / 2) + margin;
  const int top = margin + lineH + margin;  // title row
  const int captionH = 2 * lineH + margin;
  const int width = margin + static_cast<int>(panels.size()) * (pw + margin) + tableW + margin;
  const int height = std::max(top + captionH + ph, top + tableH) + margin;
  Canvas canvas(width, height, 24);
  canvas.text(margin, margin, title, scale, white);
  for (size_t i = 0; i < panels.size(); ++i) {
    const int x = margin + static_cast<int>(i) * (pw + margin);
    canvas.text(x, top, panels[i].label, scale, white);
    canvas.text(x, top + lineH, panels[i].detail, scale, grey);
    canvas.blit(x, top + captionH, pw, ph, tonemapImage(panels[i].image.rgb, tone));
  }
  const int tx = margin + static_cast<int>(panels.size()) * (pw + margin);
  for (size_t r = 0; r < table.size(); ++r) {
    const int y = top + static_cast<int>(r) * (lineH + margin / 2);
    canvas.text(tx + margin, y, table[r][0], scale, r == 0 ? white : grey);
    for (size_t c = 1; c < table[r].size(); ++c) {
      const std::string& cell = table[r][c];
      const std::uint8_t* color = r == 0 ? white : cell == "yes" ? yes : cell == "no" ? no : partial;
      canvas.text(tx + col0 + static_cast<int>(c - 1) * colW, y, cell, scale, color);
    }
  }
  return canvas;
}

}  // namespace caustica::cli
