// render_mode.cpp — the render-mode table: one row per RenderMode (render_mode.h says what each
// column decides). Adding a mode: its shader, a RenderMode value, one row here, its tests.
#include "gpu/render_mode.h"

#include "gpu/render_settings.h"
#include "util/error.h"

namespace caustica {

const std::vector<RenderModeSpec>& renderModes() {
  static const std::vector<RenderModeSpec> modes = {
      // mode, name, help, entry shader, samples, path tracer, coverage, environment, instanced scenes
      {RenderMode::Path, "path", "the path tracer", "pathtrace.comp", SampleRule::Regeneration, true, true, true, true},
      {RenderMode::Whitted, "whitted", "ray tracer: point lights, mirrors, glass, no GI", "whitted.comp",
       SampleRule::OnePerDispatch, false, true, false, true},
      {RenderMode::Raster, "raster", "OpenGL raster pipeline", nullptr, SampleRule::OneFrame, false, false, false, false},
  };
  return modes;
}

const RenderModeSpec& renderModeSpec(RenderMode m) {
  for (const RenderModeSpec& s : renderModes())
    if (s.mode == m) return s;
  throw Error("internal: render mode " + std::to_string(static_cast<int>(m)) + " has no row in renderModes()");
}

std::string renderModeNames(bool (*keep)(const RenderModeSpec&)) {
  std::vector<const char*> names;
  for (const RenderModeSpec& s : renderModes())
    if (!keep || keep(s)) names.push_back(s.name);
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i)
    out += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + std::string(names[i]);
  return out;
}

RenderMode parseRenderMode(const std::string& name) {
  for (const RenderModeSpec& s : renderModes())
    if (name == s.name) return s.mode;
  throw Error("unknown render mode '" + name + "' (expected " + renderModeNames() + ")");
}

const char* renderModeName(RenderMode m) { return renderModeSpec(m).name; }

std::string renderModeHelp() {
  const RenderMode byDefault = RenderSettings{}.mode;
  std::string out;
  const auto& modes = renderModes();
  for (std::size_t i = 0; i < modes.size(); ++i) {
    out += i == 0 ? "" : i + 1 == modes.size() ? " or " : ", ";
    out += std::string(modes[i].name) + " (" + modes[i].help + (modes[i].mode == byDefault ? "; default" : "") + ")";
  }
  return out + " (docs/render-modes.md)";
}

RenderMode nextRenderMode(RenderMode m, bool instancedScene) {
  const auto& modes = renderModes();
  const std::size_t i = static_cast<std::size_t>(&renderModeSpec(m) - modes.data());
  for (std::size_t step = 1; step <= modes.size(); ++step) {
    const RenderModeSpec& next = modes[(i + step) % modes.size()];
    if (next.instancedScenes || !instancedScene) return next.mode;
  }
  return m;
}

}  // namespace caustica
