#!/usr/bin/env python3
# make_animated_gltf.py — writes the animated glTF 2.0 test scenes of tests/data/animated/ (docs/animation.md):
# node TRS animated with LINEAR (slerp), STEP and CUBICSPLINE keys and an animated camera (trs.gltf, two
# animations), morph-target weights (morph.gltf), a two-joint skin (skin.gltf), and the static scenes that
# hold the poses of trs.gltf at t = 1 s and of morph.gltf at t = 1 s baked into node TRS and vertices
# (trs-at-1.gltf, morph-at-1.gltf). Every number is exactly representable in float32 and every pose at a
# key time is computed without rounding, so the animated file at that time and its static twin load to
# the same bits. Standard library only; deterministic (same bytes on every run).
"""Usage: python3 scripts/make_animated_gltf.py   (writes into the repository this script lives in)"""

import base64
import json
import math
import os
import struct

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "tests", "data", "animated")
BAD = os.path.join(ROOT, "tests", "data", "bad")

FLOAT, UNSIGNED_BYTE, UNSIGNED_SHORT = 5126, 5121, 5123


def f32(x):
    """x rounded to float32 (as a Python float)."""
    return struct.unpack("<f", struct.pack("<f", x))[0]


class Builder:
    """Accumulates one buffer, its views and accessors, and the document's arrays."""

    def __init__(self):
        self.data = bytearray()
        self.doc = {"asset": {"version": "2.0", "generator": "caustica scripts/make_animated_gltf.py"},
                    "scene": 0, "scenes": [{"nodes": []}], "nodes": [], "meshes": [], "materials": [],
                    "accessors": [], "bufferViews": []}

    def accessor(self, values, kind, component=FLOAT, minmax=False):
        """values: flat list; kind: SCALAR, VEC2, VEC3, VEC4 or MAT4."""
        n = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}[kind]
        fmt = {FLOAT: "f", UNSIGNED_BYTE: "B", UNSIGNED_SHORT: "H"}[component]
        while len(self.data) % 4:
            self.data.append(0)
        offset = len(self.data)
        self.data += struct.pack("<%d%s" % (len(values), fmt), *values)
        self.doc["bufferViews"].append({"buffer": 0, "byteOffset": offset, "byteLength": len(self.data) - offset})
        acc = {"bufferView": len(self.doc["bufferViews"]) - 1, "componentType": component,
               "count": len(values) // n, "type": kind}
        if minmax:
            acc["min"] = [min(values[i::n]) for i in range(n)]
            acc["max"] = [max(values[i::n]) for i in range(n)]
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def material(self, color, emission=None):
        m = {"pbrMetallicRoughness": {"baseColorFactor": list(color) + [1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}}
        if emission:
            m["emissiveFactor"] = list(emission)
        self.doc["materials"].append(m)
        return len(self.doc["materials"]) - 1

    def mesh(self, positions, normals, indices, material, targets=None, weights=None, extra=None):
        prim = {"attributes": {"POSITION": self.accessor(positions, "VEC3", minmax=True),
                               "NORMAL": self.accessor(normals, "VEC3")},
                "indices": self.accessor(indices, "SCALAR", UNSIGNED_SHORT), "material": material}
        for name, (values, kind, component) in (extra or {}).items():
            prim["attributes"][name] = self.accessor(values, kind, component)
        if targets:
            prim["targets"] = [{name: self.accessor(v, "VEC3", minmax=(name == "POSITION")) for name, v in t.items()}
                               for t in targets]
        mesh = {"primitives": [prim]}
        if weights:
            mesh["weights"] = weights
        self.doc["meshes"].append(mesh)
        return len(self.doc["meshes"]) - 1

    def node(self, root=True, **fields):
        self.doc["nodes"].append(fields)
        index = len(self.doc["nodes"]) - 1
        if root:
            self.doc["scenes"][0]["nodes"].append(index)
        return index

    def write(self, name, folder=OUT):
        self.doc["buffers"] = [{"byteLength": len(self.data),
                                "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(self.data)).decode()}]
        with open(os.path.join(folder, name), "w") as f:
            json.dump(self.doc, f, indent=1, sort_keys=True)
            f.write("\n")


def cube():
    """A unit cube centred at the origin: 24 vertices (flat normals), 12 triangles, outward fronts."""
    pos, nrm, idx = [], [], []
    for axis in range(3):
        for sign in (-1.0, 1.0):
            n = [0.0, 0.0, 0.0]
            n[axis] = sign
            u = [0.0, 0.0, 0.0]
            v = [0.0, 0.0, 0.0]
            u[(axis + 1) % 3] = 1.0
            v[(axis + 2) % 3] = 1.0
            base = len(pos) // 3
            for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                pos += [0.5 * (n[i] + a * u[i] + b * v[i]) for i in range(3)]
                nrm += n
            quad = [0, 1, 2, 0, 2, 3] if sign > 0 else [0, 2, 1, 0, 3, 2]
            idx += [base + q for q in quad]
    return pos, nrm, idx


def quad(y, half):
    """A horizontal square at height y facing +Y (a floor)."""
    pos = [-half, y, half, half, y, half, half, y, -half, -half, y, -half]
    return pos, [0.0, 1.0, 0.0] * 4, [0, 1, 2, 0, 2, 3]


def camera(b):
    b.doc["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0.75, "aspectRatio": 1.0, "znear": 0.1}}]


def quat(axis, degrees):
    """A unit quaternion (x, y, z, w) rounded to float32."""
    s, c = math.sin(math.radians(degrees) / 2), math.cos(math.radians(degrees) / 2)
    return [f32(axis[0] * s), f32(axis[1] * s), f32(axis[2] * s), f32(c)]


# ---- trs.gltf: node TRS animations of every interpolation, an animated camera, two animations -----
# Animation 0 "move" (0..2 s):
#   node "cube": translation LINEAR (-1, .5, 0) -> (1, .5, 0) -> (1, 1.5, 0) at t = 0, 1, 2;
#                rotation LINEAR (slerp) identity -> 60 -> 120 deg about +Y at t = 0, 1, 2, the middle key
#                stored as -q (the same rotation: only the shorter arcs give 30 deg at t = 0.5 and 90 deg
#                at t = 1.5);
#                scale STEP 1 -> 0.5 at t = 0, 1.5.
#   node "box": translation CUBICSPLINE between (0, .5, -1.5) at t = 0 and (2, .5, -1.5) at t = 2, with
#               out-tangent (1, 2, 0) at key 0 and in-tangent (1, -2, 0) at key 1 (units per second);
#               its mesh is the cube's (one mesh placed twice).
#   node "camera": translation LINEAR (0, 1.5, 6) -> (0.5, 1.5, 5) at t = 0, 2.
# Animation 1 "spin" (0..1 s): node "box" rotation STEP: identity, then 90 deg about +Y at t = 0.5, and
# its translation held at its node's value (so "move" and "spin" animate the same property: an
# alternative motion, not a part of one; by default only the first plays).
TRS_CUBE_T = [[-1.0, 0.5, 0.0], [1.0, 0.5, 0.0], [1.0, 1.5, 0.0]]
TRS_CUBE_R = [quat((0, 1, 0), 0), [-x for x in quat((0, 1, 0), 60)], quat((0, 1, 0), 120)]
TRS_CUBE_S = [[1.0, 1.0, 1.0], [0.5, 0.5, 0.5]]
TRS_BOX_C = [[0.0, 0.0, 0.0], [0.0, 0.5, -1.5], [1.0, 2.0, 0.0],   # key 0: in-tangent, value, out-tangent
             [1.0, -2.0, 0.0], [2.0, 0.5, -1.5], [0.0, 0.0, 0.0]]  # key 1
TRS_CAMERA_T = [[0.0, 1.5, 6.0], [0.5, 1.5, 5.0]]


def trs_scene(b):
    """Floor, cube, box and camera nodes; returns their indices."""
    grey = b.material((0.7, 0.7, 0.7))
    orange = b.material((0.8, 0.4, 0.1))
    floor = b.mesh(*quad(0.0, 3.0), grey)
    box = b.mesh(*cube(), orange)
    camera(b)
    return grey, floor, box


def write_trs():
    b = Builder()
    _, floor, box = trs_scene(b)
    b.node(name="floor", mesh=floor)
    cube_node = b.node(name="cube", mesh=box, translation=TRS_CUBE_T[0])
    box_node = b.node(name="box", mesh=box, translation=TRS_BOX_C[1])
    cam = b.node(name="camera", camera=0, translation=TRS_CAMERA_T[0])

    def channel(anim, node, path, times, values, kind, interpolation):
        anim["samplers"].append({"input": b.accessor(times, "SCALAR", minmax=True),
                                 "output": b.accessor([x for v in values for x in v], kind),
                                 "interpolation": interpolation})
        anim["channels"].append({"sampler": len(anim["samplers"]) - 1, "target": {"node": node, "path": path}})

    move = {"name": "move", "channels": [], "samplers": []}
    channel(move, cube_node, "translation", [0.0, 1.0, 2.0], TRS_CUBE_T, "VEC3", "LINEAR")
    channel(move, cube_node, "rotation", [0.0, 1.0, 2.0], TRS_CUBE_R, "VEC4", "LINEAR")
    channel(move, cube_node, "scale", [0.0, 1.5], TRS_CUBE_S, "VEC3", "STEP")
    channel(move, box_node, "translation", [0.0, 2.0], TRS_BOX_C, "VEC3", "CUBICSPLINE")
    channel(move, cam, "translation", [0.0, 2.0], TRS_CAMERA_T, "VEC3", "LINEAR")
    spin = {"name": "spin", "channels": [], "samplers": []}
    channel(spin, box_node, "rotation", [0.0, 0.5], [quat((0, 1, 0), 0), quat((0, 1, 0), 90)], "VEC4", "STEP")
    channel(spin, box_node, "translation", [0.0], [TRS_BOX_C[1]], "VEC3", "STEP")
    b.doc["animations"] = [move, spin]
    b.write("trs.gltf")


def write_trs_at_1():
    """trs.gltf's pose at t = 1 s of "move", as static nodes (every value a key value or exact)."""
    b = Builder()
    _, floor, box = trs_scene(b)
    b.node(name="floor", mesh=floor)
    # cube: translation and rotation key 1, scale key 0 (STEP holds it until t = 1.5).
    b.node(name="cube", mesh=box, translation=TRS_CUBE_T[1], rotation=TRS_CUBE_R[1], scale=TRS_CUBE_S[0])
    # box: the cubic spline at s = 1/2 (d = 2): p = v0/2 + d/8 b0 + v1/2 - d/8 a1, exact in binary.
    s = 0.5
    h00, h10, h01, h11 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s, -2 * s**3 + 3 * s**2, s**3 - s**2
    v0, b0, a1, v1 = TRS_BOX_C[1], TRS_BOX_C[2], TRS_BOX_C[3], TRS_BOX_C[4]
    p = [h00 * v0[i] + 2.0 * h10 * b0[i] + h01 * v1[i] + 2.0 * h11 * a1[i] for i in range(3)]
    b.node(name="box", mesh=box, translation=p)
    b.node(name="camera", camera=0, translation=[(TRS_CAMERA_T[0][i] + TRS_CAMERA_T[1][i]) / 2 for i in range(3)])
    b.write("trs-at-1.gltf")


# ---- morph.gltf: a strip of two quads with two morph targets, weights animated LINEAR 0..1 s -----
# Base: vertices (x, y, 0) for x in (-0.5, 0.5), y in (0, 1, 2), normals +Z. Target 0 lifts the top row
# by 1 and tilts its normals by (0, 0.5, 0); target 1 moves every vertex by (0.5, 0, 0). The mesh's
# default weights are (0, 0); the animation goes from (0, 0) at t = 0 to (1, 0.5) at t = 1.
MORPH_BASE = [x for y in (0.0, 1.0, 2.0) for x in (-0.5, y, 0.0, 0.5, y, 0.0)]
MORPH_NORMALS = [0.0, 0.0, 1.0] * 6
MORPH_T0_POS = [0.0, 0.0, 0.0] * 4 + [0.0, 1.0, 0.0] * 2
MORPH_T0_NRM = [0.0, 0.0, 0.0] * 4 + [0.0, 0.5, 0.0] * 2
MORPH_T1_POS = [0.5, 0.0, 0.0] * 6
MORPH_INDICES = [0, 1, 3, 0, 3, 2, 2, 3, 5, 2, 5, 4]
MORPH_WEIGHTS_AT_1 = [1.0, 0.5]


def morph_common(b):
    grey = b.material((0.7, 0.7, 0.7))
    red = b.material((0.8, 0.1, 0.1))
    floor = b.mesh(*quad(0.0, 3.0), grey)
    camera(b)
    b.node(name="floor", mesh=floor)
    return red


def write_morph():
    b = Builder()
    red = morph_common(b)
    strip = b.mesh(MORPH_BASE, MORPH_NORMALS, MORPH_INDICES, red,
                   targets=[{"POSITION": MORPH_T0_POS, "NORMAL": MORPH_T0_NRM}, {"POSITION": MORPH_T1_POS}],
                   weights=[0.0, 0.0])
    strip_node = b.node(name="strip", mesh=strip, translation=[0.0, 0.0, -0.5])
    b.node(name="camera", camera=0, translation=[0.0, 1.5, 6.0])
    b.doc["animations"] = [{"name": "blend", "samplers": [
        {"input": b.accessor([0.0, 1.0], "SCALAR", minmax=True),
         "output": b.accessor([0.0, 0.0] + MORPH_WEIGHTS_AT_1, "SCALAR"), "interpolation": "LINEAR"}],
        "channels": [{"sampler": 0, "target": {"node": strip_node, "path": "weights"}}]}]
    b.write("morph.gltf")


def write_morph_at_1():
    """morph.gltf at t = 1 s: the blended vertices (exact) as a plain mesh."""
    b = Builder()
    red = morph_common(b)
    w0, w1 = MORPH_WEIGHTS_AT_1
    pos = [MORPH_BASE[i] + w0 * MORPH_T0_POS[i] + w1 * MORPH_T1_POS[i] for i in range(len(MORPH_BASE))]
    nrm = [MORPH_NORMALS[i] + w0 * MORPH_T0_NRM[i] for i in range(len(MORPH_NORMALS))]
    strip = b.mesh(pos, nrm, MORPH_INDICES, red)
    b.node(name="strip", mesh=strip, translation=[0.0, 0.0, -0.5])
    b.node(name="camera", camera=0, translation=[0.0, 1.5, 6.0])
    b.write("morph-at-1.gltf")


# ---- skin.gltf: a strip of two quads skinned to two joints --------------------------------------
# Vertices (x, y, 0), x in (-0.25, 0.25), y in (0, 1, 2). Joint 0 ("root") at the origin, joint 1
# ("tip") its child at (0, 1, 0); inverse bind matrices: identity and translate(0, -1, 0). Row y = 0
# follows the root (weights 1, 0), y = 1 both (0.5, 0.5), y = 2 the tip (0, 1). The mesh node is
# translated by (5, 0, 0), which skinning ignores (glTF 3.7.3.3). Animation "bend": the tip turns about
# +X from 0 to 90 deg, LINEAR over 0..1 s.
def write_skin():
    b = Builder()
    grey = b.material((0.7, 0.7, 0.7))
    blue = b.material((0.1, 0.2, 0.8))
    floor = b.mesh(*quad(0.0, 3.0), grey)
    camera(b)
    b.node(name="floor", mesh=floor)
    pos = [x for y in (0.0, 1.0, 2.0) for x in (-0.25, y, 0.0, 0.25, y, 0.0)]
    joints = [0, 1, 0, 0] * 6
    weights = [1.0, 0.0, 0.0, 0.0] * 2 + [0.5, 0.5, 0.0, 0.0] * 2 + [0.0, 1.0, 0.0, 0.0] * 2
    strip = b.mesh(pos, [0.0, 0.0, 1.0] * 6, MORPH_INDICES, blue,
                   extra={"JOINTS_0": (joints, "VEC4", UNSIGNED_BYTE), "WEIGHTS_0": (weights, "VEC4", FLOAT)})
    tip = b.node(root=False, name="tip", translation=[0.0, 1.0, 0.0])
    root = b.node(name="root", children=[tip])
    ibm = [1.0, 0, 0, 0, 0, 1.0, 0, 0, 0, 0, 1.0, 0, 0, 0, 0, 1.0] + \
          [1.0, 0, 0, 0, 0, 1.0, 0, 0, 0, 0, 1.0, 0, 0, -1.0, 0, 1.0]
    b.doc["skins"] = [{"joints": [root, tip], "inverseBindMatrices": b.accessor(ibm, "MAT4"), "skeleton": root}]
    b.node(name="strip", mesh=strip, skin=0, translation=[5.0, 0.0, 0.0])
    b.node(name="camera", camera=0, translation=[0.0, 1.5, 6.0])
    b.doc["animations"] = [{"name": "bend", "samplers": [
        {"input": b.accessor([0.0, 1.0], "SCALAR", minmax=True),
         "output": b.accessor(quat((1, 0, 0), 0) + quat((1, 0, 0), 90), "VEC4"), "interpolation": "LINEAR"}],
        "channels": [{"sampler": 0, "target": {"node": tip, "path": "rotation"}}]}]
    b.write("skin.gltf")


# ---- split.gltf: one motion written as one animation per node (as COLLADA2GLTF does) --------------
# Animation "a" moves node "left" from x = -1 to x = -2, animation "b" node "right" from x = 1 to x = 2,
# LINEAR over 0..1 s. No two animate the same property, so by default both play.
def write_split():
    b = Builder()
    grey = b.material((0.7, 0.7, 0.7))
    box = b.mesh(*cube(), grey)
    left = b.node(name="left", mesh=box, translation=[-1.0, 0.5, 0.0])
    right = b.node(name="right", mesh=box, translation=[1.0, 0.5, 0.0])
    anims = []
    for name, node, x0, x1 in (("a", left, -1.0, -2.0), ("b", right, 1.0, 2.0)):
        anims.append({"name": name, "samplers": [
            {"input": b.accessor([0.0, 1.0], "SCALAR", minmax=True),
             "output": b.accessor([x0, 0.5, 0.0, x1, 0.5, 0.0], "VEC3"), "interpolation": "LINEAR"}],
            "channels": [{"sampler": 0, "target": {"node": node, "path": "translation"}}]})
    b.doc["animations"] = anims
    b.write("split.gltf")


# ---- broken animations (tests/data/bad: each must fail with a message naming the file) --------------
def write_bad():
    def one(name, times, values, interpolation="LINEAR"):
        b = Builder()
        grey = b.material((0.7, 0.7, 0.7))
        node = b.node(name="floor", mesh=b.mesh(*quad(0.0, 1.0), grey))
        b.doc["animations"] = [{"samplers": [{"input": b.accessor(times, "SCALAR", minmax=True),
                                              "output": b.accessor(values, "VEC3"), "interpolation": interpolation}],
                                "channels": [{"sampler": 0, "target": {"node": node, "path": "translation"}}]}]
        b.write(name, BAD)
    one("animation-times-decrease.gltf", [0.0, 1.0, 0.5], [0.0] * 9)
    one("animation-output-count.gltf", [0.0, 1.0, 2.0], [0.0] * 6)
    one("animation-bad-interpolation.gltf", [0.0, 1.0], [0.0] * 6, "BEZIER")
    # A skinned vertex naming joint 5 of a skin with 2 joints.
    b = Builder()
    grey = b.material((0.7, 0.7, 0.7))
    strip = b.mesh(*quad(0.0, 1.0), grey, extra={"JOINTS_0": ([5, 0, 0, 0] * 4, "VEC4", UNSIGNED_BYTE),
                                                  "WEIGHTS_0": ([1.0, 0.0, 0.0, 0.0] * 4, "VEC4", FLOAT)})
    j0 = b.node(name="j0")
    j1 = b.node(name="j1")
    b.doc["skins"] = [{"joints": [j0, j1]}]
    b.node(name="strip", mesh=strip, skin=0)
    b.write("skin-joint-out-of-range.gltf", BAD)


if __name__ == "__main__":
    os.makedirs(OUT, exist_ok=True)
    write_trs()
    write_trs_at_1()
    write_morph()
    write_morph_at_1()
    write_skin()
    write_split()
    write_bad()
