#!/usr/bin/env python3
# make_wild_data.py — the uncompressed sources of tests/data/wild/ (scripts/make-test-data compresses
# them with npm's gltf-transform and gltfpack): a small textured Cornell box with a smooth textured
# sphere and a box with vertex colours, and a normal-mapped sphere with tangents. Standard library
# only; deterministic. Uses the builders of make_assets.py.
"""Usage: python3 scripts/make_wild_data.py             (writes tests/data/wild/*-source.gltf)
       python3 scripts/make_wild_data.py --corrupt   (tests/data/bad/ files from the compressed variants)"""

import json
import math
import os
import struct
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make_assets as ma  # noqa: E402

WILD = os.path.join(ma.ROOT, "tests", "data", "wild")


def add_colors(g, primitive, colors):
    """Adds COLOR_0 (float VEC4, linear RGBA) to a primitive dict made by Gltf.primitive."""
    primitive["attributes"]["COLOR_0"] = g.floats(colors, "VEC4")


def add_tangents(g, primitive, tangents):
    primitive["attributes"]["TANGENT"] = g.floats(tangents, "VEC4")


def bumps_png(rotated=False):
    """64x64 tangent-space normal map (linear RGB): a grid of round bumps, 16 texels apart. rotated:
    the same normals in a frame turned 90 degrees about the normal (tangent' = bitangent,
    bitangent' = -tangent: x' = y, y' = -x), for a mesh whose TANGENT is turned likewise."""
    def encode(v):
        return int(round((v * 0.5 + 0.5) * 255))

    def pixel(x, y):
        r, g, b = base(x, y)
        if not rotated:
            return (encode(r), encode(g), encode(b))
        return (encode(g), encode(-r), encode(b))

    def base(x, y):
        u, v = (x % 16) - 7.5, (y % 16) - 7.5
        r = math.hypot(u, v)
        if r > 6.0:
            return (0.0, 0.0, 1.0)
        # a spherical cap: the normal tilts away from the bump's centre; +y of the map is up in the
        # image (towards -v), glTF's convention
        s = 0.6 * r / 6.0
        nx, ny = s * u / max(r, 1e-6), -s * v / max(r, 1e-6)
        return (nx, ny, math.sqrt(max(0.0, 1.0 - nx * nx - ny * ny)))
    return ma.png_bytes(64, 64, pixel)


def compress_source():
    """The scene every compressed variant is made from: textured Cornell walls, the warm ceiling
    light, a smooth textured sphere (normals, TEXCOORD_0) and a box whose faces carry vertex colours."""
    g = ma.Gltf()
    ma.add_cornell_box(g, textured=True)
    ma.add_ceiling_light(g, 0.5, 0.4)
    checker = g.texture_png(ma.checker_png(), {"magFilter": ma.LINEAR, "minFilter": ma.LINEAR,
                                               "wrapS": ma.REPEAT, "wrapT": ma.REPEAT})
    sphere_material = g.material("checker sphere", color=(1.0, 1.0, 1.0), roughness=0.5, specular=0.5,
                                 base_texture=checker)
    g.object("sphere", ma.uv_sphere(0.4, 32, 16), sphere_material, translation=(-0.4, 0.4, 0.1))
    # The box: one colour per vertex, so faces show gradients (multiplies the white base colour).
    cube = ma.unit_cube()
    colors = []
    for p in cube.positions:
        colors.append((0.25 + 0.7 * (p[0] + 0.5), 0.25 + 0.7 * (p[1] + 0.5), 0.25 + 0.7 * (p[2] + 0.5), 1.0))
    box_material = g.material("vertex-coloured box", color=(0.9, 0.9, 0.9))
    prim = g.primitive(cube, box_material)
    add_colors(g, prim, colors)
    box = g.mesh("coloured box", [prim])
    g.node("coloured box", mesh=box, translation=(0.45, 0.3, -0.2), rotation=ma.quat_y(-25.0),
           scale_=(0.6, 0.6, 0.6))
    g.camera("camera", **ma.CORNELL_CAMERA)
    return g.finish()


def tangent_source(rotated=False):
    """A normal-mapped sphere whose TANGENT is the mesh's own dp/du (unit, w = 1), lit by a quad
    light: the same image with or without the TANGENT attribute, since caustica's fallback is the
    triangle's dp/du. rotated (tangent-rotated.gltf): TANGENT turned 90 degrees about the normal (the
    bitangent direction) and the map's normals turned to match: the same image, but only when TANGENT
    is used."""
    g = ma.Gltf()
    bumps = g.texture_png(bumps_png(rotated), {"magFilter": ma.LINEAR, "minFilter": ma.LINEAR,
                                        "wrapS": ma.REPEAT, "wrapT": ma.REPEAT})
    floor = g.material("floor", color=(0.6, 0.6, 0.6))
    mesh = ma.MeshData()
    mesh.polygon([(-3, 0, -3), (3, 0, -3), (3, 0, 3), (-3, 0, 3)], (0, 1, 0))
    g.object("floor", mesh, floor)
    light = g.material("light", color=(0.0, 0.0, 0.0), emissive=(1.0, 1.0, 1.0), strength=8.0)
    lamp = ma.MeshData()
    lamp.polygon([(-0.5, 2.5, -0.5), (0.5, 2.5, -0.5), (0.5, 2.5, 0.5), (-0.5, 2.5, 0.5)], (0, -1, 0))
    g.object("lamp", lamp, light, translation=(0.8, 0.0, 0.8))
    sphere = ma.uv_sphere(0.6, 48, 24)
    tangents = []
    for n in sphere.normals:
        # dp/du of uv_sphere (u = phi / 2 pi, position = r (sin t cos phi, cos t, -sin t sin phi)):
        # along (-sin phi, 0, -cos phi); at the poles any horizontal unit vector.
        phi = math.atan2(-n[2], n[0])
        t = (-math.sin(phi), 0.0, -math.cos(phi))
        if rotated:
            t = ma.normalize(ma.cross(n, t))
        tangents.append((ma.clean(t[0]), ma.clean(t[1]), ma.clean(t[2]), 1.0))
    for i, uv in enumerate(sphere.uvs):
        sphere.uvs[i] = (uv[0] * 4.0, uv[1] * 2.0)
    bumped = g.material("bumped", color=(0.8, 0.8, 0.8), roughness=0.6)
    g.doc["materials"][bumped]["normalTexture"] = {"index": bumps}
    prim = g.primitive(sphere, bumped)
    add_tangents(g, prim, tangents)
    g.node("sphere", mesh=g.mesh("sphere", [prim]), translation=(0.0, 0.6, 0.0))
    g.camera("camera", position=(0.0, 1.2, 2.6), yfov=0.7, rotation=ma.quat_look((0.0, -0.6, -2.6)))
    return g.finish()


# ---- malformed compressed files (tests/data/bad/), made from the compressed variants ---------------
def read_glb(path):
    with open(path, "rb") as f:
        data = f.read()
    json_length = struct.unpack("<I", data[12:16])[0]
    doc = json.loads(data[20:20 + json_length])
    bin_at = 20 + json_length
    bin_length = struct.unpack("<I", data[bin_at:bin_at + 4])[0]
    return doc, bytearray(data[bin_at + 8:bin_at + 8 + bin_length])


def write_glb(path, doc, bin_data):
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    bin_data = bytes(bin_data) + b"\0" * (-len(bin_data) % 4)
    out = struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(text) + 8 + len(bin_data))
    out += struct.pack("<I4s", len(text), b"JSON") + text + struct.pack("<I4s", len(bin_data), b"BIN\0") + bin_data
    with open(path, "wb") as f:
        f.write(out)


def draco_primitive(doc):
    for mesh in doc["meshes"]:
        for prim in mesh["primitives"]:
            if "KHR_draco_mesh_compression" in prim.get("extensions", {}):
                return prim
    raise ValueError("no Draco primitive")


def meshopt_views(doc, mode):
    return [v for v in doc["bufferViews"] if v.get("extensions", {}).get("EXT_meshopt_compression", {}).get("mode") == mode]


def corrupt_files():
    """Each breaks one thing a decoder must notice; the loader must fail with a clean error naming it
    (tests/scene/gltf_loader_test.cpp lists the expected messages)."""
    out = {}

    def variant(source, name, change):
        doc, bin_data = read_glb(os.path.join(WILD, source))
        change(doc, bin_data)
        out[name] = (doc, bin_data)

    def truncate_draco(doc, _):
        view = doc["bufferViews"][draco_primitive(doc)["extensions"]["KHR_draco_mesh_compression"]["bufferView"]]
        view["byteLength"] //= 3
    variant("compress-draco.glb", "draco-truncated.glb", truncate_draco)

    def not_draco(doc, _):
        prim = draco_primitive(doc)
        image_view = doc["images"][0]["bufferView"]
        prim["extensions"]["KHR_draco_mesh_compression"]["bufferView"] = image_view
    variant("compress-draco.glb", "draco-not-draco.glb", not_draco)

    def count_mismatch(doc, _):
        prim = draco_primitive(doc)
        doc["accessors"][prim["attributes"]["POSITION"]]["count"] += 1
    variant("compress-draco.glb", "draco-count-mismatch.glb", count_mismatch)

    def unknown_attribute(doc, _):
        draco_primitive(doc)["extensions"]["KHR_draco_mesh_compression"]["attributes"]["POSITION"] = 99
    variant("compress-draco.glb", "draco-unknown-attribute.glb", unknown_attribute)

    def meshopt_header(doc, bin_data):
        ext = meshopt_views(doc, "ATTRIBUTES")[0]["extensions"]["EXT_meshopt_compression"]
        bin_data[ext.get("byteOffset", 0)] = 0  # the vertex codec's header byte (0xa0 | version)
    variant("compress-gltfpack.glb", "meshopt-corrupt-vertices.glb", meshopt_header)

    def meshopt_indices(doc, bin_data):
        ext = meshopt_views(doc, "TRIANGLES")[0]["extensions"]["EXT_meshopt_compression"]
        ext["byteLength"] = 8  # cut short: the index codec runs out of data
    variant("compress-gltfpack.glb", "meshopt-truncated-indices.glb", meshopt_indices)

    def meshopt_stride(doc, _):
        meshopt_views(doc, "ATTRIBUTES")[0]["extensions"]["EXT_meshopt_compression"]["byteStride"] = 6
    variant("compress-gltfpack.glb", "meshopt-bad-stride.glb", meshopt_stride)

    def meshopt_filter(doc, _):
        views = [v for v in meshopt_views(doc, "ATTRIBUTES")
                 if v["extensions"]["EXT_meshopt_compression"].get("filter") == "OCTAHEDRAL"]
        views[0]["extensions"]["EXT_meshopt_compression"]["filter"] = "QUATERNION"
    variant("compress-gltfpack.glb", "meshopt-filter-stride.glb", meshopt_filter)

    def image_in_fallback(doc, _):
        plain = [v for v in doc["bufferViews"] if "extensions" not in v]
        plain[0]["buffer"] = 1  # an image's view, moved into the fallback buffer, which holds nothing
    variant("compress-gltfpack.glb", "meshopt-image-in-fallback.glb", image_in_fallback)

    def no_quantization(doc, _):
        doc["extensionsUsed"].remove("KHR_mesh_quantization")
        doc.get("extensionsRequired", []).remove("KHR_mesh_quantization")
    variant("compress-quantized.glb", "quantized-undeclared.glb", no_quantization)

    def webp_truncated(doc, bin_data):
        view = doc["bufferViews"][doc["images"][0]["bufferView"]]
        start = view.get("byteOffset", 0)
        for i in range(start + 12, start + view["byteLength"]):
            bin_data[i] = 0  # keeps the RIFF/WEBP magic, loses the image
    variant("compress-webp.glb", "webp-corrupt.glb", webp_truncated)

    for name, (doc, bin_data) in sorted(out.items()):
        write_glb(os.path.join(ma.BAD, name), doc, bin_data)
    print("wrote %d malformed compressed files in %s" % (len(out), os.path.relpath(ma.BAD, ma.ROOT)))


def main():
    if sys.argv[1:] == ["--corrupt"]:
        corrupt_files()
        return
    scenes = {
        "compress-source.gltf": compress_source(),
        "tangent-source.gltf": tangent_source(),
        "tangent-rotated.gltf": tangent_source(rotated=True),
    }
    for name, doc in scenes.items():
        path = os.path.join(WILD, name)
        ma.write_json(path, doc)
        print("wrote %s (%d bytes)" % (os.path.relpath(path, ma.ROOT), os.path.getsize(path)))


if __name__ == "__main__":
    main()
