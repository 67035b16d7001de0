// animation.cpp — keyframe sampling, TRS matrices, morph blending and skinning (animation.h).
#include "scene/animation.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

namespace caustica {

const char* interpolationName(Interpolation i) {
  switch (i) {
    case Interpolation::Step: return "STEP";
    case Interpolation::Linear: return "LINEAR";
    case Interpolation::CubicSpline: return "CUBICSPLINE";
  }
  return "?";
}

glm::dquat slerpShortest(const glm::dquat& a, const glm::dquat& bIn, double s) {
  glm::dquat b = bIn;
  double cosTheta = glm::dot(a, b);
  if (cosTheta < 0.0) {  // the other end of the same rotation: the shorter arc
    b = -b;
    cosTheta = -cosTheta;
  }
  if (cosTheta > 1.0 - 1e-12) return glm::normalize(a * (1.0 - s) + b * s);
  const double theta = std::acos(std::min(cosTheta, 1.0));
  const double sinTheta = std::sin(theta);
  return a * (std::sin((1.0 - s) * theta) / sinTheta) + b * (std::sin(s * theta) / sinTheta);
}

std::vector<double> sampleCurve(const KeyframeCurve& c, double t) {
  const std::size_t n = c.times.size(), m = c.components;
  const bool cubic = c.interpolation == Interpolation::CubicSpline;
  // Key k's value (the middle element of a cubic key).
  auto value = [&](std::size_t k) { return c.values.data() + (cubic ? (3 * k + 1) * m : k * m); };
  std::vector<double> out(m, 0.0);
  if (n == 0 || m == 0) return out;
  auto copyKey = [&](std::size_t k) {
    std::copy(value(k), value(k) + m, out.begin());
    return out;
  };
  if (!(t > c.times.front())) return copyKey(0);  // also NaN
  if (t >= c.times.back()) return copyKey(n - 1);
  // The last key at or before t: times[k] <= t < times[k + 1].
  const std::size_t k = std::size_t(std::upper_bound(c.times.begin(), c.times.end(), t) - c.times.begin()) - 1;
  const double d = c.times[k + 1] - c.times[k];
  if (c.interpolation == Interpolation::Step || !(d > 0.0)) return copyKey(d > 0.0 ? k : k + 1);
  const double s = (t - c.times[k]) / d;
  const double* v0 = value(k);
  const double* v1 = value(k + 1);
  if (c.interpolation == Interpolation::Linear) {
    if (c.rotation && m == 4) {
      const glm::dquat q = slerpShortest(glm::dquat(v0[3], v0[0], v0[1], v0[2]), glm::dquat(v1[3], v1[0], v1[1], v1[2]), s);
      return {q.x, q.y, q.z, q.w};
    }
    for (std::size_t i = 0; i < m; ++i) out[i] = v0[i] + s * (v1[i] - v0[i]);
    return out;
  }
  // CUBICSPLINE: b_k is key k's out-tangent, a_k+1 key k+1's in-tangent; tangents are per second.
  const double* outTangent = c.values.data() + (3 * k + 2) * m;
  const double* inTangent = c.values.data() + (3 * (k + 1)) * m;
  const double s2 = s * s, s3 = s2 * s;
  const double h00 = 2.0 * s3 - 3.0 * s2 + 1.0, h10 = s3 - 2.0 * s2 + s, h01 = -2.0 * s3 + 3.0 * s2, h11 = s3 - s2;
  for (std::size_t i = 0; i < m; ++i)
    out[i] = h00 * v0[i] + d * h10 * outTangent[i] + h01 * v1[i] + d * h11 * inTangent[i];
  if (c.rotation && m == 4) {
    const double len = std::sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2] + out[3] * out[3]);
    if (len > 0.0)
      for (double& x : out) x /= len;
  }
  return out;
}

glm::dmat4 trsMatrix(const NodeTrs& trs) {
  // The same operations, in the same order, as the loader's static node matrices (gltf_nodes.cpp).
  glm::dmat4 m = glm::translate(glm::dmat4(1.0), trs.translation);
  m *= glm::mat4_cast(trs.rotation);
  return glm::scale(m, trs.scale);
}

std::vector<double> morph(const std::vector<double>& base, const std::vector<MorphTarget>& targets,
                          const std::vector<double>& weights, bool normals) {
  std::vector<double> out = base;
  for (std::size_t k = 0; k < targets.size() && k < weights.size(); ++k) {
    const std::vector<double>& d = normals ? targets[k].normals : targets[k].positions;
    if (d.size() != base.size() || weights[k] == 0.0) continue;
    for (std::size_t i = 0; i < out.size(); ++i) out[i] += weights[k] * d[i];
  }
  return out;
}

glm::dmat4 skinMatrix(const double* joints, const double* weights, std::size_t influences,
                      const std::vector<glm::dmat4>& jointMatrices) {
  double total = 0.0;
  for (std::size_t i = 0; i < influences; ++i) total += weights[i];
  if (!(total > 0.0)) return glm::dmat4(1.0);
  glm::dmat4 m(0.0);
  for (std::size_t i = 0; i < influences; ++i) {
    if (weights[i] == 0.0) continue;
    const std::size_t j = std::size_t(joints[i]);
    if (j < jointMatrices.size()) m += (weights[i] / total) * jointMatrices[j];
  }
  return m;
}

}  // namespace caustica
