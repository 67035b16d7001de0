// gltf_lights.cpp — KHR_lights_punctual instances: the light a node places, its world position and
// direction (the node's -Z, scale ignored as the spec says), colour x intensity in the spec's units.
// The JSON check (gltf_json_check.cpp) has already refused bad types, ranges and indices.
#include <cmath>
#include <string>

#include "scene/gltf_internal.h"

namespace caustica::gltf {

int SceneBuilder::nodeLight(const tinygltf::Node& node) const {
  const auto it = node.extensions.find("KHR_lights_punctual");
  if (it == node.extensions.end() || !it->second.IsObject()) return -1;
  const tinygltf::Value& light = it->second.Get("light");
  if (!light.IsNumber() && !light.IsInt()) return -1;
  const int index = light.GetNumberAsInt();
  return index >= 0 && std::size_t(index) < model_.lights.size() ? index : -1;
}

void SceneBuilder::addLight(int index, const glm::dmat4& world, const std::string& at) {
  const tinygltf::Light& l = model_.lights[std::size_t(index)];
  const std::string lat = "extensions.KHR_lights_punctual.lights[" + str(std::uint64_t(index)) + "]";
  PunctualLight out;
  out.name = !l.name.empty() ? oneLine(l.name) : lat;
  if (l.type == "point") out.type = PunctualType::Point;
  else if (l.type == "spot") out.type = PunctualType::Spot;
  else if (l.type == "directional") out.type = PunctualType::Directional;
  else fail(lat + ".type is \"" + oneLine(l.type) + "\"; it must be point, spot or directional");
  glm::dvec3 colour(1.0);
  if (l.color.size() == 3) colour = glm::dvec3(l.color[0], l.color[1], l.color[2]);
  if (!(l.intensity >= 0.0) || !std::isfinite(l.intensity) || colour.x < 0.0 || colour.y < 0.0 || colour.z < 0.0)
    fail(lat + ": colour and intensity must be finite and non-negative");
  out.intensity = glm::vec3(colour * l.intensity);
  if (!std::isfinite(out.intensity.x) || !std::isfinite(out.intensity.y) || !std::isfinite(out.intensity.z))
    fail(lat + ": colour x intensity overflows a float");
  out.innerCone = float(l.spot.innerConeAngle);
  out.outerCone = float(l.spot.outerConeAngle);
  if (out.type == PunctualType::Spot && !(out.innerCone >= 0.0f && out.innerCone < out.outerCone &&
                                          double(out.outerCone) <= 0.5 * 3.14159265358979323846 + 1e-7))
    fail(lat + ".spot: cone angles must satisfy 0 <= inner < outer <= pi/2");
  if (l.range > 0.0 && !warnedRange_) {
    warn(lat + ".range is ignored: light falls off with the inverse square of distance, without a cut-off");
    warnedRange_ = true;
  }
  out.position = glm::vec3(glm::dvec3(world * glm::dvec4(0.0, 0.0, 0.0, 1.0)) - origin_);
  const glm::dvec3 d = glm::dmat3(world) * glm::dvec3(0.0, 0.0, -1.0);
  const double len = glm::length(d);
  if (out.type != PunctualType::Point && (!(len > 1e-12) || !std::isfinite(len))) {
    warn(at + ": its transform has no direction (zero scale); light " + out.name + " skipped");
    return;
  }
  if (len > 0.0) out.direction = glm::vec3(d / len);
  if (!std::isfinite(out.position.x) || !std::isfinite(out.position.y) || !std::isfinite(out.position.z))
    fail(at + ": the position of light " + out.name + " overflows a float");
  scene_.punctualLights.push_back(out);
}

}  // namespace caustica::gltf
