# render_figures.py — run caustica and read what it reports, for the benchmark scripts in bench/ (run-all,
# compare, gpu-bench, experiments/): one render with its --stats JSON, the process's CPU time and the
# figures of its stderr (samples/s, rays/s, the load line); PFM images; interleaved comparisons of
# command lines (CPU time per sample, the fixed cost of a 1-spp render removed); relMSE; the machine.
"""Import it from a script in bench/ or bench/experiments/:

    sys.path.insert(0, BENCH_DIR); import render_figures as rf
    r = rf.render("build/caustica", "cornell-glass", ["--size", "64", "--spp", "8"])
    r["seconds"], r["samples"], r["rays"], r["cpu"], r["sps"], r["load"]["first_sample"] ...
"""

import array
import json
import math
import os
import platform
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time

BENCH = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(BENCH)
CAUSTICA = os.path.join(ROOT, "build", "caustica")
# The bundled scenes: every assets/scenes/*.gltf, by name.
SCENES = sorted(f[:-len(".gltf")] for f in os.listdir(os.path.join(ROOT, "assets", "scenes")) if f.endswith(".gltf"))


class RenderError(Exception):
    pass


def scene_path(scene):
    """A bundled scene's file in this checkout (so that an older build, which may not know a newer scene's
    name, loads the same file); any other argument as given."""
    path = os.path.join(ROOT, "assets", "scenes", scene + ".gltf")
    return path if os.path.isfile(path) else scene


_SUMMARY = re.compile(r"caustica: ([\d.]+) s, ([\d.e+-]+) samples/s, ([\d.e+-]+) rays/s")
_GL = re.compile(r"caustica: OpenGL \((\w+)\): (.*)")
_LOAD = re.compile(r"load: parse ([\d.]+) s, BVH ([\d.]+) s, pack ([\d.]+) s, upload ([\d.]+) s, shaders ([\d.]+) s; "
                   r"first sample starts ([\d.]+) s after start \(first pass done at ([\d.]+) s\); "
                   r"host peak ([\d.]+) MiB, (\d+) B/triangle; GPU ([\d.]+) MiB, (\d+) B/triangle")


def render(exe, scene, args, output=None, env=None):
    """Runs `EXE render SCENE ARGS -o OUTPUT --stats ...` and returns its figures: the --stats fields
    (seconds: render time, samples, rays, estimated_relmse, spp_*), cpu (the process's CPU seconds, every
    thread, start-up and load included), wall (the process's wall seconds), sps and rps (samples/s and
    rays/s as it prints them), gl (the GL renderer string) and load (the load line's fields, or None).
    Raises RenderError with the command and its stderr when it fails."""
    with tempfile.TemporaryDirectory() as tmp:
        stats = os.path.join(tmp, "stats.json")
        out = output or os.path.join(tmp, "out.pfm")
        cmd = [exe, "render", scene_path(scene)] + list(args) + ["-o", out, "--stats", stats]
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.monotonic()
        p = subprocess.run(cmd, capture_output=True, text=True, env=env)
        wall = time.monotonic() - t0
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        if p.returncode != 0:
            raise RenderError("%s failed (exit %d):\n%s" % (" ".join(cmd), p.returncode, p.stderr))
        with open(stats) as f:
            st = json.load(f)
    st["cpu"] = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    st["wall"] = wall
    m = _SUMMARY.search(p.stderr)
    st["sps"] = float(m.group(2)) if m else st["samples"] / max(st["seconds"], 1e-9)
    st["rps"] = float(m.group(3)) if m else st["rays"] / max(st["seconds"], 1e-9)
    g = _GL.search(p.stderr)
    st["gl"] = g.group(2).strip() if g else "?"
    st["backend"] = g.group(1) if g else "?"
    ld = _LOAD.search(p.stderr)
    st["load"] = None if not ld else dict(zip(
        ("parse", "bvh", "pack", "upload", "shaders", "first_sample", "first_pass", "host_peak_mib", "host_bytes_per_tri",
         "gpu_mib", "gpu_bytes_per_tri"), [float(x) for x in ld.groups()]))
    st["stderr"] = p.stderr
    return st


def scene_regions(scene, extra=()):
    """[(name, (x0, y0, x1, y1))] in normalized image coordinates (x right, y down): the whole image, the scene's
    caustic region in bench/scenes.json (if it has one), then each of `extra`, a (name, box) pair or the
    text 'NAME=x0,y0,x1,y1' (a --region option)."""
    with open(os.path.join(BENCH, "scenes.json")) as f:
        caustic = json.load(f)["scenes"].get(scene, {}).get("caustic")
    regions = [("whole", (0.0, 0.0, 1.0, 1.0))] + ([("caustic", tuple(caustic))] if caustic else [])
    for r in extra:
        if isinstance(r, str):
            name, box = r.split("=", 1)
            r = (name, tuple(float(v) for v in box.split(",")))
        regions.append((r[0], tuple(r[1])))
    return regions


def read_pfm(path):
    """A PFM image: (width, height, channels, float array of rows top to bottom as stored, channels interleaved)."""
    with open(path, "rb") as f:
        kind = f.readline().strip()
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        px = array.array("f")
        px.frombytes(f.read(4 * w * h * (3 if kind == b"PF" else 1)))
    if (scale > 0) != (sys.byteorder == "big"):  # a positive scale means big-endian data
        px.byteswap()
    return w, h, (3 if kind == b"PF" else 1), px


def rel_mse(x, ref):
    """relMSE = mean over values of (x - ref)^2 / (ref^2 + 0.01), the measure every benchmark here reports."""
    return sum((a - b) ** 2 / (b * b + 0.01) for a, b in zip(x, ref)) / len(ref)


class Variant:
    """One command line to compare: a label, the caustica program and extra render arguments."""

    def __init__(self, label, exe=CAUSTICA, args=(), env=None):
        self.label, self.exe, self.args, self.env = label, exe, list(args), env

    @staticmethod
    def parse(text):
        """'LABEL=EXE|ARG|ARG...' (the form bench/compare takes on its command line)."""
        label, rest = text.split("=", 1)
        parts = rest.split("|")
        return Variant(label, parts[0] or CAUSTICA, parts[1:])


def compare(variants, scene, integrator, size, spp, repeats, extra=()):
    """Renders SCENE with every variant, interleaved round by round (A, B, C, A, B, C, ...) so that the
    load of other processes hits all alike. Per variant: one 1-spp render to warm Mesa's shader cache,
    one whose CPU time is the fixed cost (start-up, load, compile, one sample per pixel), then REPEATS
    renders of SPP. Returns {label: [round, ...]} where a round has cpu_per_msample (process CPU seconds
    per million samples beyond the fixed cost), sps and rps (render wall time only), rays_per_sample,
    estimated_relmse and seconds."""
    base = ["--integrator", integrator, "--size", str(size)] + list(extra)
    fixed = {}
    for v in variants:
        render(v.exe, scene, base + ["--spp", "1"] + v.args, env=v.env)
        fixed[v.label] = render(v.exe, scene, base + ["--spp", "1"] + v.args, env=v.env)
    rounds = {v.label: [] for v in variants}
    for _ in range(repeats):
        for v in variants:
            r = render(v.exe, scene, base + ["--spp", str(spp)] + v.args, env=v.env)
            f = fixed[v.label]
            r["cpu_per_msample"] = (r["cpu"] - f["cpu"]) / max(r["samples"] - f["samples"], 1) * 1e6
            r["rays_per_sample"] = r["rays"] / max(r["samples"], 1)
            rounds[v.label].append(r)
    return rounds


def gain(rounds, a, b, key="cpu_per_msample"):
    """How many times less KEY variant B needs than A: (median, lowest, highest) of the per-round ratios
    A/B (each round's renders ran back to back, so a ratio sees one load)."""
    ratios = [ra[key] / rb[key] for ra, rb in zip(rounds[a], rounds[b])]
    return statistics.median(ratios), min(ratios), max(ratios)


def median(rounds, key):
    return statistics.median(r[key] for r in rounds)


def time_to(threshold, times, errors):
    """Time at which ERRORS (falling over TIMES) reach THRESHOLD, interpolated on log-log axes between
    checkpoints as `caustica bench` does: (seconds, mark) with mark '' (interpolated), '~' (extrapolated
    as 1/time past the last checkpoint) or '<=' (already reached at the first); (None, '') without data."""
    pts = [(t, e) for t, e in zip(times, errors) if t > 0 and e > 0 and math.isfinite(e)]
    if not pts:
        return None, ""
    if pts[0][1] <= threshold:
        return pts[0][0], "<="
    for (t0, e0), (t1, e1) in zip(pts, pts[1:]):
        if e1 <= threshold < e0:
            f = (math.log(threshold) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(t0) + f * (math.log(t1) - math.log(t0))), ""
    t, e = pts[-1]
    return t * e / threshold, "~"


def load_average():
    try:
        with open("/proc/loadavg") as f:
            return float(f.read().split()[0])
    except OSError:
        return float("nan")


def machine():
    """A line naming the machine: CPU model, cores, memory, OS."""
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    mem = ""
    try:
        with open("/proc/meminfo") as f:
            kib = int(f.readline().split()[1])
            mem = ", %.0f GiB" % (kib / 2 ** 20)
    except (OSError, ValueError, IndexError):
        pass
    osname = platform.platform(terse=True)
    try:
        with open("/etc/os-release") as f:
            for line in f:
                if line.startswith("PRETTY_NAME="):
                    osname = line.split("=", 1)[1].strip().strip('"')
    except OSError:
        pass
    return "%s, %d cores%s, %s" % (cpu, os.cpu_count() or 0, mem, osname)


def fmt(x, digits=3):
    """A number in `digits` significant figures, as the tables print them."""
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "–"
    return "%.*g" % (digits, x)


def fmt_seconds(x, mark=""):
    if x is None:
        return "–"
    return "%s%s s" % (mark, fmt(x))
