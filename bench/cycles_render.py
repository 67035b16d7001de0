# cycles_render.py — runs inside Blender (never at caustica's build, run or test time): imports a glTF scene
# with Blender's glTF importer, sets Cycles up as an unbiased CPU path tracer matching caustica's conventions,
# renders for a time limit (or a sample count) and writes a linear PFM plus a JSON of what it did.
"""Called by bench/cycles-compare:

    blender -b --factory-startup -noaudio --python bench/cycles_render.py -- \
        --scene assets/scenes/lamp-caustics.gltf --size 96 --seconds 8 --seed 3 --threads 2 \
        --out x.pfm --json x.json

Settings (each one chosen so that Cycles computes the same image caustica does, without bias):
- scene: an empty factory scene (no world: black background, as caustica's --env auto for a scene with
  emitters), the glTF imported as Blender's importer makes it, the glTF's first camera;
- materials: glass, metal and emission as the importer makes them (Principled BSDF: transmission 1, IOR,
  roughness, metallic; Emission strength = emissiveFactor x KHR_materials_emissive_strength). A material
  the glTF declares purely diffuse (metallic 0, no transmission, KHR_materials_specular specularFactor 0)
  becomes a Diffuse BSDF of the same colour: the glTF BRDF with no specular layer is Lambertian, while the
  importer's Principled BSDF would keep Blender's default specular layer (0.5) and Disney's diffuse;
  an emissive material that is not doubleSided emits from its front face only (caustica's rule; Cycles'
  Emission shines from both faces, which lit the Cornell box's ceiling from the lamp's back: +22 % overall);
- Cycles: CPU, path tracing, 2 threads (--threads), every bounce limit 128 (Russian roulette ends paths, as
  in caustica), reflective and refractive caustics on, Filter Glossy 0, no clamping, light threshold 0,
  no adaptive sampling, no denoising, box pixel filter 1 px wide (caustica's pixel is a box), Standard view
  transform, exposure 0, linear 32-bit EXR;
- time: Cycles' own render time limit (path tracing only, scene sync and BVH excluded, as caustica bench
  excludes shader compilation); the samples it reached are in Blender's log (cycles-compare reads them).
"""

import argparse
import array
import json
import os
import sys
import time

import bpy

try:  # Debian 12's Blender 3.4 glTF importer uses np.bool, which Debian 12's numpy 1.24 no longer has
    import numpy
    if not hasattr(numpy, "bool"):
        numpy.bool = bool
except ImportError:
    pass  # the importer then says that it needs numpy (Debian: python3-numpy)


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="cycles_render.py")
    p.add_argument("--scene", required=True)
    p.add_argument("--size", type=int, default=96)
    p.add_argument("--seconds", type=float, default=0.0, help="render time limit (0: none, --samples decides)")
    p.add_argument("--samples", type=int, default=1 << 24)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--bounces", type=int, default=128)
    p.add_argument("--principled-diffuse", action="store_true",
                   help="keep the importer's Principled BSDF on purely diffuse materials (no Lambert conversion)")
    p.add_argument("--out", required=True, help="linear PFM output")
    p.add_argument("--exr", default="", help="also keep Cycles' EXR here")
    p.add_argument("--json", required=True)
    return p.parse_args(argv)


def purely_diffuse(mat):
    """True when a glTF material has no specular layer: metallic 0, no transmission, specularFactor 0."""
    pbr = mat.get("pbrMetallicRoughness", {})
    ext = mat.get("extensions", {})
    return (pbr.get("metallicFactor", 1.0) == 0.0 and
            ext.get("KHR_materials_transmission", {}).get("transmissionFactor", 0.0) == 0.0 and
            ext.get("KHR_materials_specular", {}).get("specularFactor", 1.0) == 0.0 and
            "baseColorTexture" not in pbr)


def lambert(material, colour):
    """Puts a Diffuse BSDF of `colour` (and any emission the importer made) in place of the Principled BSDF."""
    nt = material.node_tree
    principled = next((n for n in nt.nodes if n.type == "BSDF_PRINCIPLED"), None)
    if principled is None:
        return False
    diffuse = nt.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = colour
    diffuse.inputs["Roughness"].default_value = 0.0  # Oren-Nayar with roughness 0 is Lambert
    emission_strength = principled.inputs["Emission Strength"].default_value
    emission_colour = tuple(principled.inputs["Emission"].default_value)
    out_links = [l.to_socket for l in nt.links if l.from_node == principled]
    shader = diffuse.outputs["BSDF"]
    if emission_strength > 0.0 and max(emission_colour[:3]) > 0.0:
        emission = nt.nodes.new("ShaderNodeEmission")
        emission.inputs["Color"].default_value = emission_colour
        emission.inputs["Strength"].default_value = emission_strength
        add = nt.nodes.new("ShaderNodeAddShader")
        nt.links.new(diffuse.outputs["BSDF"], add.inputs[0])
        nt.links.new(emission.outputs["Emission"], add.inputs[1])
        shader = add.outputs["Shader"]
    for sock in out_links:
        nt.links.new(shader, sock)
    nt.nodes.remove(principled)
    return True


def front_face_emission(material):
    """Makes an emissive material emit from its front face only (caustica's rule, and glTF's winding), where
    Cycles' Emission shines from both faces: back faces get the same material without emission."""
    nt = material.node_tree
    out = next((n for n in nt.nodes if n.type == "OUTPUT_MATERIAL"), None)
    link = next((l for l in nt.links if out is not None and l.to_node == out and l.to_socket.name == "Surface"), None)
    if link is None:
        return False
    src = link.from_node
    if src.type == "ADD_SHADER":  # lambert(): diffuse + emission
        back = next(l.from_socket for l in nt.links if l.to_node == src and l.from_node.type == "BSDF_DIFFUSE")
    elif src.type == "BSDF_PRINCIPLED":
        copy = nt.nodes.new("ShaderNodeBsdfPrincipled")
        for i, inp in enumerate(src.inputs):
            if hasattr(inp, "default_value"):
                copy.inputs[i].default_value = inp.default_value
        for l in list(nt.links):
            if l.to_node == src:
                nt.links.new(l.from_socket, copy.inputs[list(src.inputs).index(l.to_socket)])
        copy.inputs["Emission Strength"].default_value = 0.0
        back = copy.outputs["BSDF"]
    else:
        return False
    geometry = nt.nodes.new("ShaderNodeNewGeometry")
    mix = nt.nodes.new("ShaderNodeMixShader")
    nt.links.new(geometry.outputs["Backfacing"], mix.inputs["Fac"])
    nt.links.new(link.from_socket, mix.inputs[1])
    nt.links.new(back, mix.inputs[2])
    nt.links.new(mix.outputs["Shader"], out.inputs["Surface"])
    return True


def describe(material):
    """The inputs of a material's shader nodes that matter here, for the JSON log."""
    d = {}
    if not material.use_nodes:
        return d
    for n in material.node_tree.nodes:
        for name in ("Base Color", "Color", "Metallic", "Roughness", "IOR", "Transmission", "Specular",
                     "Emission", "Emission Strength", "Strength"):
            if name in n.inputs and hasattr(n.inputs[name], "default_value"):
                v = n.inputs[name].default_value
                d["%s.%s" % (n.type, name)] = [round(x, 6) for x in v] if hasattr(v, "__len__") else round(v, 6)
    return d


def set_if(obj, attr, value, log):
    if hasattr(obj, attr):
        setattr(obj, attr, value)
        log[attr] = value
    else:
        log[attr] = "absent in this Blender"


def main():
    a = parse_args()
    log = {"blender": bpy.app.version_string, "scene": a.scene, "size": a.size, "seed": a.seed,
           "threads": a.threads, "settings": {}, "materials": {}}
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=os.path.abspath(a.scene))
    scene = bpy.context.scene
    cams = [o for o in scene.objects if o.type == "CAMERA"]
    if not cams:
        raise SystemExit("cycles_render.py: %s has no camera" % a.scene)
    scene.camera = sorted(cams, key=lambda o: o.name)[0]

    with open(a.scene) as f:
        gltf = json.load(f)
    converted = []
    for gm in gltf.get("materials", []):
        bm = bpy.data.materials.get(gm.get("name", ""))
        if bm is None or not purely_diffuse(gm) or a.principled_diffuse:
            continue
        colour = tuple(gm.get("pbrMetallicRoughness", {}).get("baseColorFactor", [1, 1, 1, 1]))
        if lambert(bm, colour):
            converted.append(bm.name)
    log["lambert"] = converted
    front = []
    for gm in gltf.get("materials", []):
        bm = bpy.data.materials.get(gm.get("name", ""))
        if bm is not None and max(gm.get("emissiveFactor", [0, 0, 0])) > 0 and not gm.get("doubleSided", False):
            if front_face_emission(bm):
                front.append(bm.name)
    log["front_face_emission"] = front
    for m in bpy.data.materials:
        log["materials"][m.name] = describe(m)

    r = scene.render
    r.engine = "CYCLES"
    r.resolution_x = r.resolution_y = a.size
    r.resolution_percentage = 100
    r.threads_mode = "FIXED"
    r.threads = a.threads
    r.use_persistent_data = False
    r.image_settings.file_format = "OPEN_EXR"
    r.image_settings.color_depth = "32"
    r.image_settings.color_mode = "RGB"
    r.image_settings.exr_codec = "NONE"
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    c = scene.cycles
    s = log["settings"]
    set_if(c, "device", "CPU", s)
    set_if(c, "samples", a.samples, s)
    set_if(c, "time_limit", a.seconds, s)
    set_if(c, "seed", a.seed, s)
    set_if(c, "use_animated_seed", False, s)
    set_if(c, "use_adaptive_sampling", False, s)
    set_if(c, "use_denoising", False, s)
    set_if(c, "use_preview_denoising", False, s)
    for attr in ("max_bounces", "diffuse_bounces", "glossy_bounces", "transmission_bounces", "volume_bounces",
                 "transparent_max_bounces"):
        set_if(c, attr, a.bounces, s)
    set_if(c, "min_light_bounces", 0, s)
    set_if(c, "min_transparent_bounces", 0, s)
    set_if(c, "caustics_reflective", True, s)
    set_if(c, "caustics_refractive", True, s)
    set_if(c, "blur_glossy", 0.0, s)
    set_if(c, "sample_clamp_direct", 0.0, s)
    set_if(c, "sample_clamp_indirect", 0.0, s)
    set_if(c, "light_sampling_threshold", 0.0, s)
    set_if(c, "pixel_filter_type", "BOX", s)
    set_if(c, "filter_width", 1.0, s)
    set_if(c, "film_exposure", 1.0, s)
    set_if(c, "film_transparent", False, s)
    set_if(c, "use_auto_scrambling_distance", False, s)
    set_if(c, "scrambling_distance", 1.0, s)


    exr = a.exr or a.out + ".exr"
    r.filepath = exr
    t0 = time.monotonic()
    bpy.ops.render.render(write_still=True)
    log["wall_seconds"] = time.monotonic() - t0
    log["time_limit"] = a.seconds

    img = bpy.data.images.load(exr)
    w, h = img.size
    ch = img.channels
    px = array.array("f", bytes(4 * w * h * ch))
    img.pixels.foreach_get(px)
    rgb = array.array("f", (px[i * ch + k] for i in range(w * h) for k in range(3)))
    if sys.byteorder == "big":
        rgb.byteswap()
    with open(a.out, "wb") as f:  # Blender's rows run bottom to top, as PFM's do
        f.write(b"PF\n%d %d\n-1.0\n" % (w, h))
        f.write(rgb.tobytes())
    if not a.exr:
        os.remove(exr)
    with open(a.json, "w") as f:
        json.dump(log, f, indent=1)


main()
