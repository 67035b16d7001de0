#!/usr/bin/env python3
# make_assets.py — generates caustica's glTF 2.0 scenes (assets/scenes/), test scenes
# (tests/data/scenes/) and deliberately broken inputs (tests/data/bad/). Standard library only;
# deterministic (same bytes on every run). Units: metres, y up, glTF conventions throughout.
"""Usage: python3 scripts/make_assets.py   (writes into the repository this script lives in)"""

import base64
import json
import math
import os
import struct
import zlib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = os.path.join(ROOT, "assets", "scenes")
TEST_SCENES = os.path.join(ROOT, "tests", "data", "scenes")
BAD = os.path.join(ROOT, "tests", "data", "bad")
BUNNY_OBJ = "/work/shared/data/bunny.obj"

BUNNY_CREDIT = ("The Stanford bunny (low resolution, 1,839 vertices, 3,674 triangles): the Stanford 3D "
                "Scanning Repository (Stanford University Computer Graphics Laboratory), via the npm "
                "package `bunny` 1.0.1.")

# glTF enums
FLOAT, UNSIGNED_BYTE, UNSIGNED_SHORT, UNSIGNED_INT = 5126, 5121, 5123, 5125
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963
REPEAT, NEAREST, LINEAR = 10497, 9728, 9729

# Cornell-box colours (linear albedo) and the classic warm ceiling light (radiance 17, 12, 4).
WHITE = (0.73, 0.73, 0.73)
RED = (0.63, 0.065, 0.05)
GREEN = (0.14, 0.45, 0.09)
WARM_LIGHT = ((1.0, 12.0 / 17.0, 4.0 / 17.0), 17.0)  # emissiveFactor, emissive strength


# ---- small vector helpers -----------------------------------------------------------------------
def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def add(a, b):
    return tuple(x + y for x, y in zip(a, b))


def scale(a, s):
    return tuple(x * s for x in a)


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def normalize(a):
    length = math.sqrt(dot(a, a))
    return scale(a, 1.0 / length)


def clean(x, digits=6):
    """Rounds a float for JSON and removes negative zero, so the output is stable and readable."""
    return round(x, digits) + 0.0


def quat_y(degrees):
    """Unit quaternion (x, y, z, w) rotating by `degrees` about +y."""
    h = math.radians(degrees) / 2.0
    return [0.0, clean(math.sin(h), 9), 0.0, clean(math.cos(h), 9)]


# ---- PNG writer (8-bit RGB or RGBA, no interlace) ------------------------------------------------
def png_bytes(width, height, pixel):
    """pixel(x, y) -> tuple of 3 or 4 ints in 0..255; row y = 0 is the top of the image."""
    channels = len(pixel(0, 0))
    raw = bytearray()
    for y in range(height):
        raw.append(0)  # filter: none
        for x in range(width):
            raw.extend(pixel(x, y))

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    color_type = 2 if channels == 3 else 6
    header = struct.pack(">IIBBBBB", width, height, 8, color_type, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(bytes(raw), 9))
            + chunk(b"IEND", b""))


def checker_png():
    """128x128 checkerboard, 8x8 squares of 16 texels: light grey and a muted blue (sRGB)."""
    def pixel(x, y):
        return (220, 220, 215) if ((x // 16) + (y // 16)) % 2 == 0 else (60, 85, 160)
    return png_bytes(128, 128, pixel)


def grid_png():
    """128x128 beige tile with dark grid lines (2 texels wide, every 32) and a red mark at top-left."""
    def pixel(x, y):
        if x < 12 and y < 12:
            return (190, 40, 30)
        if x % 32 < 2 or y % 32 < 2:
            return (50, 50, 55)
        return (215, 205, 180)
    return png_bytes(128, 128, pixel)


# ---- mesh data -----------------------------------------------------------------------------------
class MeshData:
    """Triangle list with per-vertex positions, normals (optional) and texcoords (optional)."""

    def __init__(self, with_normals=True, with_uvs=False):
        self.positions, self.normals, self.uvs, self.indices = [], [], [], []
        self.with_normals, self.with_uvs = with_normals, with_uvs

    def vertex(self, p, n=None, uv=None):
        self.positions.append(tuple(p))
        if self.with_normals:
            self.normals.append(tuple(n))
        if self.with_uvs:
            self.uvs.append(tuple(uv) if uv is not None else (0.0, 0.0))
        return len(self.positions) - 1

    def polygon(self, corners, facing, uvs=None):
        """Flat convex polygon; vertex order is fixed so that its front face points along `facing`."""
        uvs = list(uvs) if uvs is not None else [None] * len(corners)
        corners = list(corners)
        if dot(cross(sub(corners[1], corners[0]), sub(corners[2], corners[0])), facing) < 0:
            corners.reverse()
            uvs.reverse()
        n = normalize(facing)
        first = [self.vertex(p, n, uv) for p, uv in zip(corners, uvs)]
        for i in range(1, len(first) - 1):
            self.indices += [first[0], first[i], first[i + 1]]


def cornell_walls(uv_back=None, uv_floor=None):
    """Open-front box x in [-1,1], y in [0,2], z in [-1,1]; single-sided walls facing inward.
    Returns {name: MeshData}. uv_* = repeat counts to give that wall texture coordinates."""
    def wall(corners, facing, repeat=None):
        mesh = MeshData(with_uvs=repeat is not None)
        uvs = None
        if repeat is not None:
            # corners listed as top-left, top-right, bottom-right, bottom-left seen from inside:
            # uv v = 0 is the top row of the image.
            uvs = [(0.0, 0.0), (repeat, 0.0), (repeat, repeat), (0.0, repeat)]
        mesh.polygon(corners, facing, uvs)
        return mesh

    return {
        # floor seen from above: "top" = far edge (z = -1)
        "floor": wall([(-1, 0, -1), (1, 0, -1), (1, 0, 1), (-1, 0, 1)], (0, 1, 0), uv_floor),
        "ceiling": wall([(-1, 2, -1), (1, 2, -1), (1, 2, 1), (-1, 2, 1)], (0, -1, 0)),
        "back": wall([(-1, 2, -1), (1, 2, -1), (1, 0, -1), (-1, 0, -1)], (0, 0, 1), uv_back),
        "left": wall([(-1, 0, -1), (-1, 2, -1), (-1, 2, 1), (-1, 0, 1)], (1, 0, 0)),
        "right": wall([(1, 0, -1), (1, 2, -1), (1, 2, 1), (1, 0, 1)], (-1, 0, 0)),
    }


def ceiling_light(width, depth, x=0.0, z=0.0, y=1.98):
    """Horizontal quad light just below the ceiling, front face pointing down (-y)."""
    mesh = MeshData()
    hw, hd = width / 2.0, depth / 2.0
    mesh.polygon([(x - hw, y, z - hd), (x + hw, y, z - hd), (x + hw, y, z + hd), (x - hw, y, z + hd)],
                 (0, -1, 0))
    return mesh


def unit_cube(inward=False):
    """Cube [-0.5,0.5]^3 with flat faces (24 vertices); faces point outward (or inward)."""
    mesh = MeshData(with_uvs=True)
    sign = -1.0 if inward else 1.0
    for axis in range(3):
        for side in (-0.5, 0.5):
            u_axis, v_axis = (axis + 1) % 3, (axis + 2) % 3
            corners = []
            for du, dv in ((-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)):
                p = [0.0, 0.0, 0.0]
                p[axis], p[u_axis], p[v_axis] = side, du, dv
                corners.append(tuple(p))
            facing = [0.0, 0.0, 0.0]
            facing[axis] = sign * (1.0 if side > 0 else -1.0)
            mesh.polygon(corners, tuple(facing), [(0, 0), (1, 0), (1, 1), (0, 1)])
    return mesh


def box_room(half, inward=True):
    """Closed cube room [-half, half]^3 made of six quads facing inward (camera inside)."""
    mesh = MeshData()
    cube = unit_cube(inward=inward)
    for p, n in zip(cube.positions, cube.normals):
        mesh.vertex(scale(p, 2.0 * half), n)
    mesh.indices = list(cube.indices)
    return mesh


def uv_sphere(radius, segments, rings):
    """UV sphere centred at the origin with smooth normals; pole rows use single triangles."""
    mesh = MeshData(with_uvs=True)
    grid = []
    for i in range(rings + 1):
        theta = math.pi * i / rings
        row = []
        for j in range(segments + 1):
            phi = 2.0 * math.pi * j / segments
            n = (math.sin(theta) * math.cos(phi), math.cos(theta), -math.sin(theta) * math.sin(phi))
            row.append(mesh.vertex(scale(n, radius), n, (j / segments, i / rings)))
        grid.append(row)
    for i in range(rings):
        for j in range(segments):
            a, b = grid[i][j], grid[i][j + 1]
            c, d = grid[i + 1][j], grid[i + 1][j + 1]
            # counter-clockwise seen from outside: a (top-left), c (bottom-left), d, b
            if i != 0:
                mesh.indices += [a, c, b]
            if i != rings - 1:
                mesh.indices += [b, c, d]
    return mesh


def prism(side, length):
    """Equilateral triangular prism (apex up), axis along z, centred at the origin, flat faces.
    No NORMAL attribute: the loader derives flat normals."""
    mesh = MeshData(with_normals=False)
    r = side / math.sqrt(3.0)
    tri = [(r * math.cos(math.radians(90 + 120 * k)), r * math.sin(math.radians(90 + 120 * k)))
           for k in range(3)]
    hz = length / 2.0

    def add_face(corners):
        # The prism is convex and centred on the origin: a face's outward direction is its centre.
        facing = scale(tuple(map(sum, zip(*corners))), 1.0 / len(corners))
        cs = list(corners)
        if dot(cross(sub(cs[1], cs[0]), sub(cs[2], cs[0])), facing) < 0:
            cs.reverse()
        first = [mesh.vertex(p) for p in cs]
        for i in range(1, len(first) - 1):
            mesh.indices += [first[0], first[i], first[i + 1]]

    add_face([(x, y, hz) for x, y in tri])
    add_face([(x, y, -hz) for x, y in tri])
    for k in range(3):
        (x0, y0), (x1, y1) = tri[k], tri[(k + 1) % 3]
        add_face([(x0, y0, -hz), (x1, y1, -hz), (x1, y1, hz), (x0, y0, hz)])
    return mesh


def torus_knot_tube(p, q, big_r, small_r, radius, segments, sides):
    """Closed tube of circular cross-section `radius` around the (p, q) torus knot
    ((big_r + small_r cos qt) cos pt, small_r sin qt, (big_r + small_r cos qt) sin pt), t in [0, 2 pi):
    the knot lies flat (y up). Smooth per-vertex normals (the tube's radial directions), fronts
    outward, rings joined end to start through shared vertices, so the surface is closed. Frames are
    parallel-transported along the curve and the leftover twist is spread evenly, so the last ring
    meets the first exactly. Returns (mesh, area of its triangles)."""
    def centre(t):
        rr = big_r + small_r * math.cos(q * t)
        return (rr * math.cos(p * t), small_r * math.sin(q * t), rr * math.sin(p * t))

    ts = [2.0 * math.pi * i / segments for i in range(segments)]
    pts = [centre(t) for t in ts]
    tangents = [normalize(sub(pts[(i + 1) % segments], pts[i - 1])) for i in range(segments)]
    # Parallel transport: project the previous normal onto the plane of the next tangent.
    frames = []
    n = normalize(cross(tangents[0], (0.0, 1.0, 0.0)))
    for i in range(segments + 1):
        t = tangents[i % segments]
        n = normalize(sub(n, scale(t, dot(n, t))))
        frames.append(n)
    # Twist left over after one loop (angle of the transported normal against the first one).
    t0, n0, b0 = tangents[0], frames[0], cross(tangents[0], frames[0])
    twist = math.atan2(dot(frames[segments], b0), dot(frames[segments], n0))
    mesh = MeshData()
    rings = []
    for i in range(segments):
        t = tangents[i]
        nrm = frames[i]
        bin_ = cross(t, nrm)
        ring = []
        for j in range(sides):
            a = 2.0 * math.pi * j / sides - twist * i / segments
            d = add(scale(nrm, math.cos(a)), scale(bin_, math.sin(a)))
            ring.append(mesh.vertex(add(pts[i], scale(d, radius)), d))
        rings.append(ring)
    area = 0.0
    for i in range(segments):
        r0, r1 = rings[i], rings[(i + 1) % segments]
        for j in range(sides):
            k = (j + 1) % sides
            for tri in ((r0[j], r1[j], r1[k]), (r0[j], r1[k], r0[k])):
                a, b, c = (mesh.positions[v] for v in tri)
                nrm = cross(sub(b, a), sub(c, a))
                if dot(nrm, mesh.normals[tri[0]]) < 0.0:  # front face outward
                    tri = (tri[0], tri[2], tri[1])
                mesh.indices += list(tri)
                area += 0.5 * math.sqrt(dot(nrm, nrm))
    return mesh, area


def wavy_sheet(width, depth, amplitude, waves, segments, rows):
    """Open curved sheet (no thickness) y = amplitude * sin(waves * 2 pi x / width) over
    x in [-width/2, width/2], z in [-depth/2, depth/2], smooth normals; front faces point down
    (-y side), so it is a non-convex, open emitter. Returns (mesh, area of its triangles)."""
    k = waves * 2.0 * math.pi / width
    mesh = MeshData()
    grid = []
    for i in range(segments + 1):
        x = -width / 2.0 + width * i / segments
        y = amplitude * math.sin(k * x)
        n = normalize((amplitude * k * math.cos(k * x), -1.0, 0.0))  # downward normal of the curve
        grid.append([mesh.vertex((x, y, -depth / 2.0 + depth * j / rows), n) for j in range(rows + 1)])
    area = 0.0
    for i in range(segments):
        for j in range(rows):
            a, b, c, d = grid[i][j], grid[i + 1][j], grid[i + 1][j + 1], grid[i][j + 1]
            for tri in ((a, b, c), (a, c, d)):
                pa, pb, pc = (mesh.positions[v] for v in tri)
                nrm = cross(sub(pb, pa), sub(pc, pa))
                if dot(nrm, mesh.normals[tri[0]]) < 0.0:
                    tri = (tri[0], tri[2], tri[1])
                mesh.indices += list(tri)
                area += 0.5 * math.sqrt(dot(nrm, nrm))
    return mesh, area


def bunny(height):
    """The Stanford bunny from BUNNY_OBJ, scaled to `height`, base centred at the origin, with
    area-weighted smooth normals."""
    verts, faces = [], []
    with open(BUNNY_OBJ) as f:
        for line in f:
            parts = line.split()
            if not parts:
                continue
            if parts[0] == "v":
                verts.append(tuple(float(x) for x in parts[1:4]))
            elif parts[0] == "f":
                idx = [int(p.split("/")[0]) - 1 for p in parts[1:]]
                for i in range(1, len(idx) - 1):
                    faces.append((idx[0], idx[i], idx[i + 1]))
    lo = [min(v[i] for v in verts) for i in range(3)]
    hi = [max(v[i] for v in verts) for i in range(3)]
    s = height / (hi[1] - lo[1])
    centre = ((lo[0] + hi[0]) / 2.0, lo[1], (lo[2] + hi[2]) / 2.0)
    pos = [scale(sub(v, centre), s) for v in verts]
    normals = [(0.0, 0.0, 0.0)] * len(pos)
    area = 0.0
    for a, b, c in faces:
        n = cross(sub(pos[b], pos[a]), sub(pos[c], pos[a]))  # length = 2 * area
        area += 0.5 * math.sqrt(dot(n, n))
        for i in (a, b, c):
            normals[i] = add(normals[i], n)
    mesh = MeshData()
    for p, n in zip(pos, normals):
        mesh.vertex(p, normalize(n) if dot(n, n) > 0 else (0.0, 1.0, 0.0))
    mesh.indices = [i for face in faces for i in face]
    return mesh, area


# ---- glTF document builder -----------------------------------------------------------------------
class Gltf:
    """Builds one self-contained glTF 2.0 document (single buffer, embedded as a data URI)."""

    def __init__(self, copyright=None):
        self.buffer = bytearray()
        self.doc = {"asset": {"version": "2.0", "generator": "caustica scripts/make_assets.py"},
                    "scene": 0, "scenes": [{"nodes": []}], "nodes": [], "meshes": [], "materials": [],
                    "accessors": [], "bufferViews": [], "buffers": []}
        if copyright:
            self.doc["asset"]["copyright"] = copyright
        self.extensions = set()

    def _view(self, data, target=None):
        while len(self.buffer) % 4:
            self.buffer.append(0)
        view = {"buffer": 0, "byteOffset": len(self.buffer), "byteLength": len(data)}
        if target is not None:
            view["target"] = target
        self.buffer.extend(data)
        self.doc["bufferViews"].append(view)
        return len(self.doc["bufferViews"]) - 1

    def _accessor(self, accessor):
        self.doc["accessors"].append(accessor)
        return len(self.doc["accessors"]) - 1

    def floats(self, rows, kind, with_bounds=False):
        flat = [float(x) for row in rows for x in row]
        view = self._view(struct.pack("<%df" % len(flat), *flat), ARRAY_BUFFER)
        acc = {"bufferView": view, "componentType": FLOAT, "count": len(rows), "type": kind}
        if with_bounds:
            n = len(rows[0])
            f32 = [struct.unpack("<f", struct.pack("<f", x))[0] for x in flat]
            acc["min"] = [min(f32[i::n]) for i in range(n)]
            acc["max"] = [max(f32[i::n]) for i in range(n)]
        return self._accessor(acc)

    def indices(self, values):
        if max(values) < 65536:
            data, ctype = struct.pack("<%dH" % len(values), *values), UNSIGNED_SHORT
        else:
            data, ctype = struct.pack("<%dI" % len(values), *values), UNSIGNED_INT
        view = self._view(data, ELEMENT_ARRAY_BUFFER)
        return self._accessor({"bufferView": view, "componentType": ctype, "count": len(values),
                               "type": "SCALAR"})

    def primitive(self, mesh, material):
        attrs = {"POSITION": self.floats(mesh.positions, "VEC3", with_bounds=True)}
        if mesh.with_normals:
            attrs["NORMAL"] = self.floats(mesh.normals, "VEC3")
        if mesh.with_uvs:
            attrs["TEXCOORD_0"] = self.floats(mesh.uvs, "VEC2")
        return {"attributes": attrs, "indices": self.indices(mesh.indices), "material": material}

    def mesh(self, name, primitives):
        self.doc["meshes"].append({"name": name, "primitives": primitives})
        return len(self.doc["meshes"]) - 1

    def node(self, name, mesh=None, camera=None, translation=None, rotation=None, scale_=None,
             root=True):
        node = {"name": name}
        if mesh is not None:
            node["mesh"] = mesh
        if camera is not None:
            node["camera"] = camera
        if translation is not None:
            node["translation"] = [clean(x) for x in translation]
        if rotation is not None:
            node["rotation"] = rotation
        if scale_ is not None:
            node["scale"] = [clean(x) for x in scale_]
        self.doc["nodes"].append(node)
        index = len(self.doc["nodes"]) - 1
        if root:
            self.doc["scenes"][0]["nodes"].append(index)
        return index

    def object(self, name, mesh_data, material, **transform):
        """A mesh with one primitive, instanced by one root node."""
        return self.node(name, mesh=self.mesh(name, [self.primitive(mesh_data, material)]), **transform)

    def material(self, name, color=(0.8, 0.8, 0.8), alpha=1.0, metallic=0.0, roughness=1.0,
                 emissive=None, strength=1.0, transmission=0.0, ior=None, thickness=None,
                 dispersion=None, double_sided=False, base_texture=None, specular=0.0, clearcoat=None,
                 sheen=None, unlit=False):
        """specular: KHR_materials_specular's specularFactor of the dielectric layer over the diffuse
        base. The shipped Cornell scenes are Lambertian (0, written out); glTF's default is 1.
        clearcoat: (clearcoatFactor, clearcoatRoughnessFactor); sheen: (sheenColorFactor,
        sheenRoughnessFactor); unlit: KHR_materials_unlit."""
        pbr = {"baseColorFactor": [clean(c) for c in color] + [clean(alpha)],
               "metallicFactor": clean(metallic), "roughnessFactor": clean(roughness)}
        if base_texture is not None:
            pbr["baseColorTexture"] = {"index": base_texture}
        mat = {"name": name, "pbrMetallicRoughness": pbr}
        ext = {}
        if emissive is not None:
            mat["emissiveFactor"] = [clean(c) for c in emissive]
            if strength != 1.0:
                ext["KHR_materials_emissive_strength"] = {"emissiveStrength": clean(strength)}
        if transmission > 0.0:
            ext["KHR_materials_transmission"] = {"transmissionFactor": clean(transmission)}
        if ior is not None:
            ext["KHR_materials_ior"] = {"ior": clean(ior)}
        if thickness is not None:
            # Other viewers need a volume to refract (glTF's default is thin-walled);
            # caustica traces the closed mesh itself and ignores the thickness value.
            ext["KHR_materials_volume"] = {"thicknessFactor": clean(thickness)}
        if dispersion is not None:
            ext["KHR_materials_dispersion"] = {"dispersion": clean(dispersion)}
        if specular != 1.0 and metallic < 1.0 and transmission < 1.0:
            ext["KHR_materials_specular"] = {"specularFactor": clean(specular)}
        if clearcoat is not None:
            ext["KHR_materials_clearcoat"] = {"clearcoatFactor": clean(clearcoat[0]),
                                              "clearcoatRoughnessFactor": clean(clearcoat[1])}
        if sheen is not None:
            ext["KHR_materials_sheen"] = {"sheenColorFactor": [clean(c) for c in sheen[0]],
                                          "sheenRoughnessFactor": clean(sheen[1])}
        if unlit:
            ext["KHR_materials_unlit"] = {}
        if ext:
            mat["extensions"] = ext
            self.extensions.update(ext.keys())
        if double_sided:
            mat["doubleSided"] = True
        self.doc["materials"].append(mat)
        return len(self.doc["materials"]) - 1

    def camera(self, name, position, yfov, aspect=1.0, rotation=None):
        cams = self.doc.setdefault("cameras", [])
        cams.append({"name": name, "type": "perspective",
                     "perspective": {"yfov": clean(yfov), "aspectRatio": clean(aspect),
                                     "znear": 0.01, "zfar": 100.0}})
        return self.node(name, camera=len(cams) - 1, translation=position, rotation=rotation)

    def texture_png(self, png, sampler, embed_in_buffer=False):
        images = self.doc.setdefault("images", [])
        if embed_in_buffer:
            images.append({"bufferView": self._view(png), "mimeType": "image/png"})
        else:
            images.append({"uri": "data:image/png;base64," + base64.b64encode(png).decode("ascii")})
        samplers = self.doc.setdefault("samplers", [])
        samplers.append(sampler)
        textures = self.doc.setdefault("textures", [])
        textures.append({"sampler": len(samplers) - 1, "source": len(images) - 1})
        return len(textures) - 1

    def finish(self):
        doc = dict(self.doc)
        doc["buffers"] = [{"byteLength": len(self.buffer),
                           "uri": "data:application/octet-stream;base64,"
                                  + base64.b64encode(bytes(self.buffer)).decode("ascii")}]
        if self.extensions:
            doc["extensionsUsed"] = sorted(self.extensions)
        return doc


def write_json(path, doc):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w", newline="\n") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")


# ---- scenes ----------------------------------------------------------------------------------------
CORNELL_CAMERA = dict(position=(0.0, 1.0, 3.7), yfov=0.6911)  # 39.6 degrees: the opening fills the view


def add_cornell_box(g, textured=False, wall_colors=None):
    """Walls (one node each) of the 2 m Cornell box; returns the index of the plain white material."""
    colors = {"floor": WHITE, "ceiling": WHITE, "back": WHITE, "left": RED, "right": GREEN}
    colors.update(wall_colors or {})
    textures = {}
    if textured:
        textures["back"] = g.texture_png(checker_png(), {"magFilter": NEAREST, "minFilter": NEAREST,
                                                         "wrapS": REPEAT, "wrapT": REPEAT})
        textures["floor"] = g.texture_png(grid_png(), {"magFilter": LINEAR, "minFilter": LINEAR,
                                                       "wrapS": REPEAT, "wrapT": REPEAT},
                                          embed_in_buffer=True)
    walls = cornell_walls(uv_back=3.0 if textured else None, uv_floor=4.0 if textured else None)
    materials = {}
    for name in ("floor", "ceiling", "back", "left", "right"):
        color = colors[name]
        key = (color, textures.get(name))
        if key not in materials:
            if name in textures:
                materials[key] = g.material(name + " (textured)", color=(1.0, 1.0, 1.0),
                                            base_texture=textures[name])
            else:
                label = {WHITE: "white", RED: "red", GREEN: "green"}.get(color, name)
                materials[key] = g.material(label, color=color)
        g.object(name + " wall", walls[name], materials[key])
    return materials.get((WHITE, None))


def add_ceiling_light(g, width, depth, emissive=WARM_LIGHT[0], strength=WARM_LIGHT[1], x=0.0, z=0.0):
    light = g.material("light", color=(0.78, 0.78, 0.78), emissive=emissive, strength=strength)
    g.object("ceiling light", ceiling_light(width, depth, x=x, z=z), light)


def add_two_boxes(g, material):
    """The classic tall and short boxes, rotated, resting on the floor."""
    cube = unit_cube()
    g.object("tall box", cube, material, translation=(-0.38, 0.6, -0.35), rotation=quat_y(17.0),
             scale_=(0.6, 1.2, 0.6))
    g.object("short box", cube, material, translation=(0.38, 0.3, 0.38), rotation=quat_y(-17.0),
             scale_=(0.6, 0.6, 0.6))


def cornell_box():
    g = Gltf()
    white = add_cornell_box(g)
    add_ceiling_light(g, 0.47, 0.38)
    add_two_boxes(g, white)
    g.camera("camera", **CORNELL_CAMERA)
    return g.finish()


def cornell_glass(segments=64, rings=32):
    g = Gltf()
    add_cornell_box(g)
    add_ceiling_light(g, 0.5, 0.4)
    radius = 0.35
    glass = g.material("glass", color=(1.0, 1.0, 1.0), roughness=0.0, transmission=1.0, ior=1.5,
                       thickness=2 * radius)
    mirror = g.material("mirror", color=(0.95, 0.95, 0.95), metallic=1.0, roughness=0.0)
    sphere = uv_sphere(radius, segments, rings)
    # One set of accessors, two meshes (materials are per primitive).
    prim = g.primitive(sphere, glass)
    glass_mesh = g.mesh("glass sphere", [prim])
    mirror_mesh = g.mesh("mirror sphere", [dict(prim, material=mirror)])
    g.node("glass sphere", mesh=glass_mesh, translation=(-0.42, radius, 0.3))
    g.node("mirror sphere", mesh=mirror_mesh, translation=(0.42, radius, -0.35))
    g.camera("camera", **CORNELL_CAMERA)
    return g.finish()


def cornell_materials(segments=48, rings=24):
    """glTF metallic-roughness under two area lights: a rough gold metal sphere, a red plastic sphere
    (GGX specular layer over a diffuse base, glTF's default specular) and a frosted glass sphere."""
    g = Gltf()
    add_cornell_box(g)
    add_ceiling_light(g, 0.4, 0.3, x=-0.35)
    add_ceiling_light(g, 0.4, 0.3, x=0.35)
    radius = 0.3
    gold = g.material("rough gold", color=(1.0, 0.766, 0.336), metallic=1.0, roughness=0.35)
    plastic = g.material("red plastic", color=(0.6, 0.05, 0.04), roughness=0.25, specular=1.0)
    frosted = g.material("frosted glass", color=(1.0, 1.0, 1.0), roughness=0.3, transmission=1.0, ior=1.5,
                         thickness=2 * radius)
    prim = g.primitive(uv_sphere(radius, segments, rings), gold)
    for name, material, position in (("gold sphere", gold, (-0.5, radius, -0.3)),
                                     ("plastic sphere", plastic, (0.5, radius, -0.2)),
                                     ("frosted sphere", frosted, (0.0, radius, 0.35))):
        g.node(name, mesh=g.mesh(name, [dict(prim, material=material)]), translation=position)
    g.camera("camera", **CORNELL_CAMERA)
    return g.finish()


def stripes_png():
    """64x64 poster for an unlit panel: four horizontal bands (sRGB) of saturated colours over a light grey."""
    bands = [(200, 60, 40), (240, 190, 60), (60, 150, 90), (50, 90, 180)]

    def pixel(x, y):
        if 8 <= y < 56 and 6 <= x < 58:
            return bands[(y - 8) // 12]
        return (225, 225, 220)
    return png_bytes(64, 64, pixel)


def cornell_layers(segments=48, rings=24):
    """The layers glTF puts over its materials, in the classic box: a red plastic sphere under a smooth
    clear coat (car paint), a deep red velvet sphere (sheen over a dark diffuse base), a black sphere
    that is nothing but a clear coat (its reflections alone), and an unlit poster on the back wall
    (KHR_materials_unlit: it shows its texture as stored, whatever the light)."""
    g = Gltf()
    add_cornell_box(g)
    add_ceiling_light(g, 0.47, 0.38)
    radius = 0.3
    paint = g.material("coated red paint", color=(0.6, 0.04, 0.03), roughness=0.5, specular=1.0,
                       clearcoat=(1.0, 0.0))
    velvet = g.material("red velvet", color=(0.25, 0.02, 0.04), roughness=1.0, specular=1.0,
                        sheen=((1.0, 0.45, 0.55), 0.35))
    black = g.material("black coat", color=(0.0, 0.0, 0.0), roughness=1.0, specular=0.0, clearcoat=(1.0, 0.0))
    prim = g.primitive(uv_sphere(radius, segments, rings), paint)
    for name, material, position, scale in (("coated sphere", paint, (-0.45, radius, -0.35), 1.0),
                                            ("velvet sphere", velvet, (0.45, radius, -0.2), 1.0),
                                            ("black coated sphere", black, (-0.05, 0.2, 0.4), 2.0 / 3.0)):
        g.node(name, mesh=g.mesh(name, [dict(prim, material=material)]), translation=position,
               scale_=(scale, scale, scale))
    poster = g.texture_png(stripes_png(), {"magFilter": LINEAR, "minFilter": LINEAR, "wrapS": REPEAT,
                                           "wrapT": REPEAT})
    unlit = g.material("unlit poster", color=(1.0, 1.0, 1.0), base_texture=poster, unlit=True)
    panel = MeshData(with_uvs=True)
    panel.polygon([(0.15, 1.55, -0.99), (0.75, 1.55, -0.99), (0.75, 0.95, -0.99), (0.15, 0.95, -0.99)], (0, 0, 1),
                  [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)])
    g.object("unlit poster", panel, unlit)
    g.camera("camera", **CORNELL_CAMERA)
    return g.finish()


def cornell_bunny_light():
    mesh, area = bunny(0.6)
    g = Gltf(copyright=BUNNY_CREDIT)
    add_cornell_box(g)
    # Match the classic light's emitted power: luminance(17, 12, 4) * 0.47 m * 0.38 m from one side,
    # here from both sides of the bunny's surface.
    classic = (0.2126 * 17.0 + 0.7152 * 12.0 + 0.0722 * 4.0) * 0.47 * 0.38
    color = (1.0, 0.85, 0.65)
    lum = 0.2126 * color[0] + 0.7152 * color[1] + 0.0722 * color[2]
    strength = round(classic / (2.0 * area * lum), 3)
    emitter = g.material("bunny light", color=(0.8, 0.8, 0.8), emissive=color, strength=strength,
                         double_sided=True)
    g.object("bunny light", mesh, emitter, translation=(0.0, 1.0, -0.05))
    g.camera("camera", **CORNELL_CAMERA)
    doc = g.finish()
    doc["asset"]["extras"] = {"bunny": BUNNY_CREDIT, "bunnyArea_m2": clean(area, 4)}
    return doc


def cornell_textured():
    g = Gltf()
    add_cornell_box(g, textured=True)
    add_ceiling_light(g, 0.47, 0.38)
    white = g.material("white boxes", color=WHITE)
    add_two_boxes(g, white)
    g.camera("camera", **CORNELL_CAMERA)
    return g.finish()


def cornell_dispersion():
    g = Gltf()
    dark = (0.12, 0.12, 0.12)
    # Dark box with a white floor, where the coloured caustic lands.
    add_cornell_box(g, wall_colors={"ceiling": dark, "back": dark, "left": dark, "right": dark})
    # A small, bright white light straight above a ball lens of strongly dispersive glass. The lens
    # (radius 0.3 m, centre 0.68 m above the floor) images the light onto the floor; blue light
    # focuses closer to the lens than red, so the caustic spreads into coloured rings.
    add_ceiling_light(g, 0.3, 0.3, emissive=(1.0, 1.0, 1.0), strength=40.0)
    radius = 0.3
    flint = g.material("dispersive glass", color=(1.0, 1.0, 1.0), roughness=0.0, transmission=1.0,
                       ior=1.5, thickness=2 * radius, dispersion=1.2)
    g.object("dispersive sphere", uv_sphere(radius, 64, 32), flint, translation=(0.0, 0.68, 0.0))
    # A 60-degree prism on the floor to the right bends the same light into a spectrum.
    side, length = 0.35, 0.5
    g.object("prism", prism(side, length), flint, translation=(0.55, side / (2.0 * math.sqrt(3.0)), 0.35))
    g.camera("camera", **CORNELL_CAMERA)
    return g.finish()


def classic_light_luminance_power():
    """luminance(17, 12, 4) x 0.47 m x 0.38 m: the classic ceiling light's (one-sided) power weight."""
    return (0.2126 * 17.0 + 0.7152 * 12.0 + 0.0722 * 4.0) * 0.47 * 0.38


def cornell_tube_light():
    """Cornell box lit only by a closed, smooth-shaded, non-convex emitter: a tube of radius 5 cm
    around a (2, 3) torus knot hanging under the ceiling (one-sided, fronts outward), with a glass
    sphere on the floor. Test scene for light sampling from curved emitters (naive vs mis)."""
    mesh, area = torus_knot_tube(2, 3, 0.32, 0.12, 0.05, 160, 10)
    return curved_light_box("tube light", mesh, area, False, 1.62,
                            "Test scene: Cornell box lit only by a closed, smooth-shaded torus-knot tube light "
                            "(naive vs mis light-sampling test).", "tubeArea_m2")


def cornell_sheet_light():
    """Cornell box lit only by an open, double-sided, smooth-shaded wavy sheet under the ceiling,
    with a glass sphere on the floor: the thin-shell counterpart of cornell_tube_light."""
    mesh, area = wavy_sheet(0.9, 0.5, 0.08, 1.5, 48, 6)
    return curved_light_box("sheet light", mesh, area, True, 1.7,
                            "Test scene: Cornell box lit only by an open, double-sided, smooth-shaded wavy sheet "
                            "light (naive vs mis light-sampling test).", "sheetArea_m2")


def curved_light_box(name, mesh, area, double_sided, height, description, area_key):
    """Cornell box lit only by `mesh` (area `area`, one or both sides emitting the classic light's
    power) hung at `height` under the ceiling, with a glass sphere on the floor."""
    g = Gltf()
    add_cornell_box(g)
    color = (1.0, 0.9, 0.75)
    lum = 0.2126 * color[0] + 0.7152 * color[1] + 0.0722 * color[2]
    sides = 2.0 if double_sided else 1.0
    strength = round(classic_light_luminance_power() / (sides * area * lum), 3)
    extra = {"double_sided": True} if double_sided else {}
    emitter = g.material(name, color=(0.78, 0.78, 0.78), emissive=color, strength=strength, **extra)
    g.object(name, mesh, emitter, translation=(0.0, height, -0.1))
    radius = 0.3
    glass = g.material("glass", color=(1.0, 1.0, 1.0), roughness=0.0, transmission=1.0, ior=1.5,
                       thickness=2 * radius)
    g.object("glass sphere", uv_sphere(radius, 32, 16), glass, translation=(0.3, radius, 0.25))
    g.camera("camera", **CORNELL_CAMERA)
    doc = g.finish()
    doc["asset"]["extras"] = {"description": description, area_key: clean(area, 4)}
    return doc


def look_rotation(direction):
    """Unit quaternion (x, y, z, w) turning a node's -Z towards `direction`, without roll: a yaw about
    +y, then a pitch about the node's x axis (for cameras and KHR_lights_punctual lights)."""
    d = normalize(direction)
    yaw = math.atan2(-d[0], -d[2])
    pitch = math.asin(max(-1.0, min(1.0, d[1])))
    cy, sy = math.cos(yaw / 2.0), math.sin(yaw / 2.0)
    cp, sp = math.cos(pitch / 2.0), math.sin(pitch / 2.0)
    # q_yaw * q_pitch with q_yaw = (0, sy, 0, cy), q_pitch = (sp, 0, 0, cp)
    return [clean(cy * sp, 9), clean(sy * cp, 9), clean(-sy * sp, 9), clean(cy * cp, 9)]


def add_punctual_light(g, name, light, position=None, direction=None):
    """A KHR_lights_punctual light and a root node placing it (the light shines down the node's -Z)."""
    ext = g.doc.setdefault("extensions", {}).setdefault("KHR_lights_punctual", {"lights": []})
    ext["lights"].append(dict(light, name=name))
    g.extensions.add("KHR_lights_punctual")
    node = {"name": name, "extensions": {"KHR_lights_punctual": {"light": len(ext["lights"]) - 1}}}
    if position is not None:
        node["translation"] = [clean(x) for x in position]
    if direction is not None:
        node["rotation"] = look_rotation(direction)
    g.doc["nodes"].append(node)
    g.doc["scenes"][0]["nodes"].append(len(g.doc["nodes"]) - 1)


def punctual_lights_scene():
    """A table-top stage lit only by KHR_lights_punctual lights: a warm point light, a cool spot aimed
    at a glass ball and a low sun. Intensities in the spec's units (cd; the sun in lux). The ball's
    caustic of the point and spot lights appears only with --light-radius (a delta light cannot be
    found by a bounce off the floor through the glass)."""
    g = Gltf()
    floor_mesh = MeshData()
    floor_mesh.polygon([(-3, 0, -2), (3, 0, -2), (3, 0, 3), (-3, 0, 3)], (0, 1, 0))
    wall_mesh = MeshData()
    wall_mesh.polygon([(-3, 3, -2), (3, 3, -2), (3, 0, -2), (-3, 0, -2)], (0, 0, 1))
    white = g.material("white", color=WHITE)
    g.object("floor", floor_mesh, white)
    g.object("back wall", wall_mesh, white)
    radius = 0.35
    glass = g.material("glass", color=(1.0, 1.0, 1.0), roughness=0.0, transmission=1.0, ior=1.5,
                       thickness=2 * radius)
    g.object("glass ball", uv_sphere(radius, 48, 24), glass, translation=(0.15, radius, 0.2))
    red = g.material("red", color=RED)
    g.object("box", unit_cube(), red, translation=(-0.85, 0.25, -0.45), rotation=quat_y(25.0),
             scale_=(0.5, 0.5, 0.5))
    green = g.material("green", color=GREEN)
    g.object("green ball", uv_sphere(0.25, 32, 16), green, translation=(1.0, 0.25, -0.6))
    add_punctual_light(g, "warm bulb", {"type": "point", "color": [1.0, 0.75, 0.5], "intensity": 1.5},
                       position=(-1.1, 1.1, 0.9))
    spot_at = (1.3, 2.0, 1.1)
    add_punctual_light(g, "cool spot", {"type": "spot", "color": [0.65, 0.8, 1.0], "intensity": 12.0,
                                        "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.32}},
                       position=spot_at, direction=sub((0.15, radius, 0.2), spot_at))
    add_punctual_light(g, "low sun", {"type": "directional", "color": [1.0, 0.9, 0.75], "intensity": 0.6},
                       direction=(0.6, -0.45, -0.65))
    cam_at = (0.0, 1.35, 3.3)
    g.camera("camera", cam_at, 0.75, aspect=1.0, rotation=look_rotation(sub((0.0, 0.35, 0.0), cam_at)))
    return g.finish()


def many_lights_scene(count=31, spacing=1.3, size=0.25, height=0.6):
    """A floor under a count x count grid of small emissive quads (961 lights, 1,922 emissive
    triangles), spread far apart, with boxes among them: every floor point is lit by its few nearest
    lights, while power-proportional light selection picks one of those only rarely. For measuring
    light selection (docs/path-tracer.md, "Many lights")."""
    g = Gltf()
    half = (count - 1) * spacing / 2.0 + 2.0
    floor_mesh = MeshData()
    floor_mesh.polygon([(-half, 0, -half), (half, 0, -half), (half, 0, half), (-half, 0, half)], (0, 1, 0))
    white = g.material("white", color=WHITE)
    g.object("floor", floor_mesh, white)
    lights = MeshData()
    h = size / 2.0
    for i in range(count):
        for j in range(count):
            x = (i - (count - 1) / 2.0) * spacing
            z = (j - (count - 1) / 2.0) * spacing
            lights.polygon([(x - h, height, z - h), (x + h, height, z - h), (x + h, height, z + h),
                            (x - h, height, z + h)], (0, -1, 0))
    lamp = g.material("lamp", color=(0.8, 0.8, 0.8), emissive=(1.0, 0.9, 0.75), strength=20.0)
    g.object("lights", lights, lamp)
    boxes = MeshData(with_uvs=True)
    cube = unit_cube()
    state = 12345
    for k in range(40):  # a fixed linear congruential sequence: the same boxes on every run
        vals = []
        for _ in range(3):
            state = (1103515245 * state + 12345) % 2147483648
            vals.append(state / 2147483648.0)
        cx = (vals[0] - 0.5) * 2.0 * (half - 2.0)
        cz = (vals[1] - 0.5) * 2.0 * (half - 2.0)
        s = 0.2 + 0.25 * vals[2]
        base = len(boxes.positions)
        for p, n, uv in zip(cube.positions, cube.normals, cube.uvs):
            boxes.vertex((cx + p[0] * s, s / 2.0 + p[1] * s, cz + p[2] * s), n, uv)
        boxes.indices += [base + i for i in cube.indices]
    red = g.material("red", color=RED)
    g.object("boxes", boxes, red)
    cam_at = (0.0, 2.2, 7.0)
    g.camera("camera", cam_at, 0.8, aspect=1.0, rotation=look_rotation(sub((0.0, 0.0, 0.0), cam_at)))
    return g.finish()


def far_small_cornell():
    """small_cornell with its whole node tree (camera included) moved by (1e6, -2e6, 5e5): the loader
    rebases it in double, and `caustica info` prints that origin (test scene)."""
    doc = small_cornell()
    scene = doc["scenes"][doc.get("scene", 0)]
    doc["nodes"].append({"name": "far away", "translation": [1.0e6, -2.0e6, 5.0e5], "children": scene["nodes"]})
    scene["nodes"] = [len(doc["nodes"]) - 1]
    return doc


def furnace(glass=False, albedo=0.5):
    """Closed cube room, every wall a Lambertian emitter (radiance 1, albedo `albedo`), camera inside.
    Exact radiance everywhere: 1 / (1 - albedo)."""
    g = Gltf()
    wall = g.material("furnace wall", color=(albedo, albedo, albedo), emissive=(1.0, 1.0, 1.0))
    g.object("room", box_room(1.0), wall)
    if glass:
        clear = g.material("clear glass", color=(1.0, 1.0, 1.0), roughness=0.0, transmission=1.0,
                           ior=1.5, thickness=0.8)
        g.object("glass sphere", uv_sphere(0.4, 32, 16), clear, translation=(0.1, -0.1, -0.45))
    g.camera("camera", position=(0.0, 0.0, 0.6), yfov=1.0)
    return g.finish()


def small_cornell():
    return cornell_glass(segments=16, rings=8)


def quat_look(direction):
    """Rotation (x, y, z, w) turning a camera's -Z towards `direction` with no roll: yaw about y after
    pitch about x."""
    dx, dy, dz = normalize(direction)
    yaw = math.atan2(-dx, -dz)
    pitch = math.atan2(dy, math.hypot(dx, dz))
    sy, cy = math.sin(yaw / 2.0), math.cos(yaw / 2.0)
    sx, cx = math.sin(pitch / 2.0), math.cos(pitch / 2.0)
    return [clean(cy * sx), clean(sy * cx), clean(-sy * sx), clean(cy * cx)]


def sun_glass():
    """A glass ball and a clay box on a grey floor, open to the sky: no emitters; meant for an
    environment (render with --env sun-sky: assets/env/sun-sky.hdr, written by scripts/make_sky_hdr.py;
    its sun stands 35 degrees high, in front of the camera and to the left, so the ball's shadow and
    caustic fall to its right, towards the camera)."""
    g = Gltf()
    floor = g.material("floor", color=(0.7, 0.7, 0.7))
    clay = g.material("clay", color=(0.75, 0.35, 0.2))
    glass = g.material("glass", color=(1.0, 1.0, 1.0), roughness=0.0, transmission=1.0, ior=1.5,
                       thickness=1.0)
    mesh = MeshData()
    mesh.polygon([(-6, 0, -6), (6, 0, -6), (6, 0, 6), (-6, 0, 6)], (0, 1, 0))
    g.object("floor", mesh, floor)
    g.object("glass ball", uv_sphere(0.5, 64, 32), glass, translation=(0.0, 0.5, 0.0))
    g.object("clay box", unit_cube(), clay, translation=(1.2, 0.3, -1.0), rotation=quat_y(25.0),
             scale_=(0.6, 0.6, 0.6))
    eye, target = (0.3, 1.8, 3.9), (0.45, 0.2, 0.2)
    g.camera("camera", position=eye, yfov=0.6, rotation=quat_look(sub(target, eye)))
    return g.finish()


def mirror_caustic():
    """A white floor under a small warm lamp, and a standing mirror beside it that throws the lamp's
    reflection onto the floor: a reflection caustic (found only by bouncing off the mirror) next to a
    floor that direct-light sampling makes smooth at once. Its noise is uneven: the bench scene of
    adaptive sampling (docs/benchmarks.md, "Adaptive sampling"). Open to a black sky, no walls."""
    g = Gltf()
    white = g.material("floor", color=(0.8, 0.8, 0.8))
    mirror = g.material("mirror", color=(0.95, 0.95, 0.95), metallic=1.0, roughness=0.0, double_sided=True)
    floor = MeshData()
    floor.polygon([(-4, 0, -4), (4, 0, -4), (4, 0, 4), (-4, 0, 4)], (0, 1, 0))
    g.object("floor", floor, white)
    # 1.0 m wide, 0.8 m tall, in the plane x = 0.8 facing the lamp (-x); reflects on both sides.
    panel = MeshData()
    panel.polygon([(0.8, 0, -0.5), (0.8, 0, 0.5), (0.8, 0.8, 0.5), (0.8, 0.8, -0.5)], (-1, 0, 0))
    g.object("mirror", panel, mirror)
    # A 0.25 m square lamp 1.8 m up, facing down. Its mirror image (x = 2.2) lights the floor from x ~ -0.3
    # (rays past the mirror's top edge; the lamp's size blurs it over -0.42..-0.22) to the mirror's foot at
    # x = 0.8, |z| up to 0.5 there and ~0.9 at the far edge; behind the mirror lies its shadow.
    lamp = g.material("lamp", color=(0.78, 0.78, 0.78), emissive=(1.0, 0.95, 0.85), strength=150.0)
    g.object("lamp", ceiling_light(0.25, 0.25, x=-0.6, y=1.8), lamp)
    eye, target = (-0.3, 2.4, 2.4), (0.2, 0.0, -0.3)
    g.camera("camera", position=eye, yfov=0.8, rotation=quat_look(sub(target, eye)))
    return g.finish()


# ---- bad inputs ------------------------------------------------------------------------------------
def triangle_doc(positions=None, indices=(0, 1, 2), mode=None, extra_accessor_count=None):
    """A minimal valid one-triangle scene, returned as a dict to be broken by the caller."""
    positions = positions or [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0)]
    pos = b"".join(struct.pack("<3f", *p) for p in positions)
    idx = struct.pack("<%dH" % len(indices), *indices)
    while len(idx) % 4:
        idx += b"\x00"
    data = pos + idx
    prim = {"attributes": {"POSITION": 0}, "indices": 1, "material": 0}
    if mode is not None:
        prim["mode"] = mode
    return {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [prim]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1.0],
                                                "metallicFactor": 0.0}}],
        "accessors": [
            {"bufferView": 0, "componentType": FLOAT,
             "count": extra_accessor_count or len(positions), "type": "VEC3"},
            {"bufferView": 1, "componentType": UNSIGNED_SHORT, "count": len(indices), "type": "SCALAR"},
        ],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(pos)},
                        {"buffer": 0, "byteOffset": len(pos), "byteLength": 2 * len(indices)}],
        "buffers": [{"byteLength": len(data),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
    }, data


def glb_bytes(doc, bin_data):
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * ((4 - len(text) % 4) % 4)
    bin_data = bytes(bin_data) + b"\x00" * ((4 - len(bin_data) % 4) % 4)
    total = 12 + 8 + len(text) + 8 + len(bin_data)
    return (struct.pack("<4sII", b"glTF", 2, total) + struct.pack("<I4s", len(text), b"JSON") + text
            + struct.pack("<I4s", len(bin_data), b"BIN\x00") + bin_data)


def bad_files():
    """{file name: bytes}: every one must make loadScene throw caustica::Error (see scene_test.cpp)."""
    files = {}

    def put(name, doc):
        files[name] = (json.dumps(doc, indent=1) + "\n").encode()

    def variant(edit, **kwargs):
        doc, _ = triangle_doc(**kwargs)
        edit(doc)
        return doc

    files["not-a-scene.txt"] = b"This is a text file, not a glTF scene.\n"
    good = (json.dumps(triangle_doc()[0], indent=1) + "\n").encode()
    files["truncated.gltf"] = good[: len(good) // 2]
    files["not-json.gltf"] = bytes((i * 73 + 41) % 256 for i in range(300))
    put("no-asset.gltf", variant(lambda d: d.pop("asset")))
    put("wrong-version.gltf", variant(lambda d: d["asset"].update(version="1.0")))
    put("string-for-number.gltf", variant(lambda d: d["accessors"][0].update(count="3")))
    put("string-for-index.gltf", variant(lambda d: d["nodes"][0].update(mesh="0")))
    put("unknown-required-extension.gltf", variant(lambda d: d.update(
        extensionsUsed=["EXT_caustica_unknown"], extensionsRequired=["EXT_caustica_unknown"])))
    put("lines-only.gltf", variant(lambda d: None, indices=(0, 1, 1, 2), mode=1))
    put("empty-scene.gltf", variant(lambda d: d["scenes"][0].update(nodes=[])))
    put("degenerate-only.gltf", variant(lambda d: None, positions=[(0.0, 0.0, 0.0), (1.0, 0.0, 0.0),
                                                                   (2.0, 0.0, 0.0)]))
    put("index-out-of-range.gltf", variant(lambda d: None, indices=(0, 1, 99)))
    put("accessor-overrun.gltf", variant(lambda d: None, extra_accessor_count=100))
    put("bufferview-overrun.gltf", variant(lambda d: d["bufferViews"][1].update(byteLength=4096)))
    put("bad-stride.gltf", variant(lambda d: d["bufferViews"][0].update(byteStride=4)))
    put("bad-component-type.gltf", variant(lambda d: d["accessors"][0].update(componentType=UNSIGNED_BYTE)))
    put("mesh-index-out-of-range.gltf", variant(lambda d: d["nodes"][0].update(mesh=5)))
    put("material-index-out-of-range.gltf",
        variant(lambda d: d["meshes"][0]["primitives"][0].update(material=7)))
    put("bad-alpha-mode.gltf", variant(lambda d: d["materials"][0].update(alphaMode="SEMI")))
    put("nan-position.gltf", variant(lambda d: None, positions=[(0.0, 0.0, 0.0), (float("nan"), 0.0, 0.0),
                                                                (0.0, 1.0, 0.0)]))
    put("inf-position.gltf", variant(lambda d: None, positions=[(0.0, 0.0, 0.0), (1.0, 0.0, 0.0),
                                                                (0.0, float("inf"), 0.0)]))

    def cycle(d):
        d["nodes"] = [{"mesh": 0, "children": [1]}, {"children": [0]}]
    put("cycle.gltf", variant(cycle))

    def two_parents(d):
        d["nodes"] = [{"children": [2]}, {"children": [2]}, {"mesh": 0}]
        d["scenes"][0]["nodes"] = [0, 1]
    put("two-parents.gltf", variant(two_parents))

    def camera(yfov):
        def edit(d):
            d["cameras"] = [{"type": "perspective", "perspective": {"yfov": yfov, "znear": 0.1}}]
            d["nodes"].append({"camera": 0, "translation": [0.0, 0.0, 3.0]})
            d["scenes"][0]["nodes"].append(1)
        return edit
    put("camera-yfov-zero.gltf", variant(camera(0.0)))
    put("camera-yfov-negative.gltf", variant(camera(-0.5)))

    def bad_sparse(d):
        # Sparse substitution of vertex 7 in a 3-vertex POSITION accessor.
        _, data = triangle_doc()
        views = len(data)
        data += struct.pack("<H2x3f", 7, 0.5, 0.5, 0.0)
        d["buffers"][0] = {"byteLength": len(data), "uri": "data:application/octet-stream;base64,"
                           + base64.b64encode(data).decode()}
        d["bufferViews"] += [{"buffer": 0, "byteOffset": views, "byteLength": 2},
                             {"buffer": 0, "byteOffset": views + 4, "byteLength": 12}]
        d["accessors"][0]["sparse"] = {"count": 1,
                                       "indices": {"bufferView": 2, "componentType": UNSIGNED_SHORT},
                                       "values": {"bufferView": 3}}
    put("bad-sparse-index.gltf", variant(bad_sparse))

    def external_bin(name, length_delta):
        def edit(d):
            d["buffers"][0]["uri"] = name
            d["buffers"][0]["byteLength"] += length_delta
        return edit
    put("missing-bin.gltf", variant(external_bin("missing.bin", 0)))
    put("bin-size-mismatch.gltf", variant(external_bin("bin-size-mismatch.bin", 8)))
    files["bin-size-mismatch.bin"] = triangle_doc()[1]

    def texture(uri):
        def edit(d):
            d["images"] = [{"uri": uri}]
            d["textures"] = [{"source": 0}]
            d["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
        return edit
    put("missing-image.gltf", variant(texture("missing.png")))
    garbage = base64.b64encode(b"\x89PNG but not really a PNG image at all").decode()
    put("bad-image-data.gltf", variant(texture("data:image/png;base64," + garbage)))

    # 100000 nested arrays in "extras": recursive JSON readers overflow their stack.
    text = json.dumps(triangle_doc()[0])
    files["deep-nesting.gltf"] = (text[:-1] + ', "extras": ' + "[" * 100000 + "]" * 100000 + "}\n").encode()

    doc, data = triangle_doc()
    doc["buffers"] = [{"byteLength": len(data)}]
    glb = glb_bytes(doc, data)
    files["bad-magic.glb"] = b"gltf" + glb[4:]
    files["truncated.glb"] = glb[: len(glb) - 16]
    # BIN chunk header claims 8 more bytes than the file holds (its data starts 8 bytes after the
    # chunk header, a classic off-by-eight in GLB readers).
    json_len = struct.unpack("<I", glb[12:16])[0]
    bin_at = 20 + json_len
    bin_len = struct.unpack("<I", glb[bin_at:bin_at + 4])[0]
    files["bin-chunk-overrun.glb"] = glb[:bin_at] + struct.pack("<I", bin_len + 8) + glb[bin_at + 4:]
    files.update(hostile_files(put, variant, external_bin, texture))
    return files


def hostile_files(put, variant, external_bin, texture):
    """Untrusted-input files (docs/untrusted-input.md): references out of the scene's folder and
    declared sizes over the default limits. Each must be refused before anything is read or allocated."""
    files = {}
    # References that lead outside the folder: refused by name, the target never opened.
    put("escape-dotdot-buffer.gltf", variant(external_bin("../../../../../../../../etc/passwd", 0)))
    put("escape-absolute-buffer.gltf", variant(external_bin("/etc/hostname", 0)))
    put("escape-percent-encoded-buffer.gltf", variant(external_bin("%2e%2e/%2E%2E/%2e%2e/etc/passwd", 0)))
    put("escape-dotdot-image.gltf", variant(texture("../../../../../../../../etc/passwd")))
    put("escape-absolute-image.gltf", variant(texture("/etc/passwd")))
    # Declared sizes over the default limits (LoadOptions in app/scene/scene.h).
    put("huge-buffer-length.gltf", variant(external_bin("huge.bin", 1 << 50)))

    def many_buffers(d):
        d["buffers"] += [{"byteLength": 100 << 20, "uri": "part-%d.bin" % i} for i in range(16)]
    put("many-large-buffers.gltf", variant(many_buffers))

    def many_huge_images(d):
        # PNG headers declaring 8192x8192 RGBA (256 MiB decoded each) over a few bytes of junk:
        # the fifth takes the total past the 1024 MiB default before it is decoded.
        def chunk(kind, data):
            body = kind + data
            return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)
        png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 8192, 8192, 8, 6, 0, 0, 0))
               + chunk(b"IDAT", zlib.compress(b"\0" * 64)) + chunk(b"IEND", b""))
        uri = "data:image/png;base64," + base64.b64encode(png).decode()
        d["images"] = [{"uri": uri} for _ in range(8)]
    put("many-huge-images.gltf", variant(many_huge_images))

    # 10^15 declared triangles in one index accessor: refused before any accessor is decoded.
    put("huge-accessor-count.gltf", variant(lambda d: d["accessors"][1].update(count=3 * 10 ** 15)))

    def wide(d):
        # 1000 sibling nodes instancing a mesh of 10^6 (zero, unstored) triangles: 10^9 in all.
        d["accessors"].append({"componentType": FLOAT, "count": 3000000, "type": "VEC3"})
        d["meshes"].append({"primitives": [{"attributes": {"POSITION": 2}, "material": 0}]})
        d["nodes"] = [{"mesh": 0, "children": list(range(1, 1001))}] + [{"mesh": 1}] * 1000
    files["wide-node-tree.gltf"] = (json.dumps(variant(wide), separators=(",", ":")) + "\n").encode()

    def deep(d):
        # A chain of 1100 nodes, each scaling by 2: the world transform overflows 2^1024 down the chain.
        d["nodes"] = [{"children": [i + 1], "scale": [2.0, 2.0, 2.0]} for i in range(1099)] + [{"mesh": 0}]
    files["deep-node-tree.gltf"] = (json.dumps(variant(deep), separators=(",", ":")) + "\n").encode()
    return files


def main():
    scenes = {
        os.path.join(SCENES, "cornell-box.gltf"): cornell_box(),
        os.path.join(SCENES, "cornell-glass.gltf"): cornell_glass(),
        os.path.join(SCENES, "cornell-bunny-light.gltf"): cornell_bunny_light(),
        os.path.join(SCENES, "cornell-textured.gltf"): cornell_textured(),
        os.path.join(SCENES, "cornell-dispersion.gltf"): cornell_dispersion(),
        os.path.join(SCENES, "sun-glass.gltf"): sun_glass(),
        os.path.join(SCENES, "punctual-lights.gltf"): punctual_lights_scene(),
        os.path.join(SCENES, "many-lights.gltf"): many_lights_scene(),
        os.path.join(SCENES, "cornell-materials.gltf"): cornell_materials(),
        os.path.join(SCENES, "cornell-layers.gltf"): cornell_layers(),
        os.path.join(SCENES, "mirror-caustic.gltf"): mirror_caustic(),
        os.path.join(TEST_SCENES, "furnace.gltf"): furnace(),
        os.path.join(TEST_SCENES, "furnace-glass.gltf"): furnace(glass=True),
        os.path.join(TEST_SCENES, "glass-in-white-enclosure.gltf"): furnace(glass=True, albedo=0.0),
        os.path.join(TEST_SCENES, "small-cornell.gltf"): small_cornell(),
        os.path.join(TEST_SCENES, "far-cornell.gltf"): far_small_cornell(),
        os.path.join(TEST_SCENES, "tube-light.gltf"): cornell_tube_light(),
        os.path.join(TEST_SCENES, "sheet-light.gltf"): cornell_sheet_light(),
    }
    for path, doc in scenes.items():
        write_json(path, doc)
        print("wrote %s (%d bytes)" % (os.path.relpath(path, ROOT), os.path.getsize(path)))
    os.makedirs(BAD, exist_ok=True)
    for name, data in sorted(bad_files().items()):
        with open(os.path.join(BAD, name), "wb") as f:
            f.write(data)
    print("wrote %d files in %s" % (len(bad_files()), os.path.relpath(BAD, ROOT)))


if __name__ == "__main__":
    main()
