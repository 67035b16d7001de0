// environment_options.h — the lighting options every scene command shares (--env, --env-strength,
// --env-rotation, --background) and the default environment of a scene that has no light.
#pragma once
#include <string>
#include <vector>

#include "cli/cli_common.h"
#include "cli/image_settings.h"
#include "scene/scene.h"

namespace caustica::cli {

std::vector<OptionSpec> environmentOptionSpecs();
// Sets scene.environment and scene.background from settings.scene (called by applySceneSettings,
// the one place settings reach the scene). A scene with no emissive triangle and env "auto" gets the
// neutral default (uniform radiance 1) and a line saying so; --env none on such a scene says the image
// will be black. Throws Error naming the bad option or file.
void applyEnvironmentSettings(const ImageSettings& settings, Scene& scene, bool verbose);
// One line on the scene's lighting: emitter triangles, environment, background (info, render, viewer).
std::string lightingSummary(const Scene& scene, std::size_t emitterTriangles);
// The same, short, for the viewer's title: "2 emitter tris + env sky.hdr", "env default (uniform 1)".
std::string lightingTag(const Scene& scene, std::size_t emitterTriangles);

}  // namespace caustica::cli
