// animation.h — glTF 2.0 animation sampling and mesh posing, as pure functions (docs/animation.md):
// keyframe interpolation (STEP, LINEAR with quaternion slerp, CUBICSPLINE with tangents), node TRS
// matrices, morph-target blending and linear-blend skinning. The loader (gltf_animation.cpp) reads the
// file into these types; tests check them against poses computed by hand.
#pragma once
#include <cstddef>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace caustica {

enum class Interpolation { Step, Linear, CubicSpline };
const char* interpolationName(Interpolation i);  // "STEP", "LINEAR", "CUBICSPLINE"

// One animation sampler: key times (seconds, increasing) and the values at them, `components` numbers
// per key (3 for translation and scale, 4 for a rotation quaternion x y z w, the morph-target count for
// weights). CUBICSPLINE keys hold three elements each, in-tangent, value, out-tangent (glTF 3.11).
struct KeyframeCurve {
  std::vector<double> times;
  std::vector<double> values;  // times.size() * components (x3 for CUBICSPLINE)
  std::size_t components = 0;
  Interpolation interpolation = Interpolation::Linear;
  bool rotation = false;  // a unit quaternion: LINEAR is slerp, CUBICSPLINE is normalised
};

// The curve's value at `t` seconds: before the first key the first value, after the last key the last
// (glTF 3.11: the animation is not looped or extrapolated). STEP holds the value of the last key at or
// before t. LINEAR interpolates (slerp for rotations, along the shorter arc). CUBICSPLINE is the
// Hermite spline p(s) = (2s^3 - 3s^2 + 1) v_k + d (s^3 - 2s^2 + s) b_k + (-2s^3 + 3s^2) v_k+1
// + d (s^3 - s^2) a_k+1 with d the key interval, b_k the out-tangent of key k and a_k+1 the in-tangent of
// key k+1 (glTF Appendix C); a rotation is then normalised.
std::vector<double> sampleCurve(const KeyframeCurve& curve, double t);

// Spherical linear interpolation of unit quaternions along the shorter arc (q and -q are the same
// rotation); nearly parallel ones are interpolated linearly and normalised. Double precision.
glm::dquat slerpShortest(const glm::dquat& a, const glm::dquat& b, double s);

// A node's local transform T * R * S (glTF 5.25: translation, rotation quaternion, scale).
struct NodeTrs {
  glm::dvec3 translation{0.0};
  glm::dquat rotation{1.0, 0.0, 0.0, 0.0};  // (w, x, y, z)
  glm::dvec3 scale{1.0};
};
glm::dmat4 trsMatrix(const NodeTrs& trs);

// A morph target's displacements of one primitive (empty where the target does not move that attribute).
struct MorphTarget {
  std::vector<double> positions;  // vertexCount * 3
  std::vector<double> normals;    // vertexCount * 3
};
// base + sum_k weights[k] * target_k, for positions (normals: false) or normals (true); the result has
// base's size. Targets without that attribute and zero weights add nothing.
std::vector<double> morph(const std::vector<double>& base, const std::vector<MorphTarget>& targets,
                          const std::vector<double>& weights, bool normals);

// Linear-blend skinning of one vertex: sum_i weights[i] * jointMatrices[joints[i]] (glTF 3.7.3.3), with
// jointMatrices[j] = world(joint j) * inverseBindMatrix(j). Weights are normalised by their sum when it
// is not already 1 (exporters round them); a vertex whose weights are all zero keeps the identity.
glm::dmat4 skinMatrix(const double* joints, const double* weights, std::size_t influences,
                      const std::vector<glm::dmat4>& jointMatrices);

// What `caustica info` lists of a file's animations: name, the span of its key times, its channels.
struct AnimationInfo {
  std::string name;  // may be empty
  double start = 0.0, end = 0.0;  // first and last key time over its channels, seconds
  std::size_t channels = 0;
  bool weights = false, skins = false;  // animates morph weights / moves skin joints
};

// Which animation(s) a scene is posed with and when (render --anim-time/--frame/--animation).
struct ScenePose {
  // "": the default: every animation when no two animate the same property of a node (one motion split
  // per node), else the first; "all": every animation at once; else an animation's name or its index.
  std::string animation;
  double time = 0.0;  // seconds
};

}  // namespace caustica
