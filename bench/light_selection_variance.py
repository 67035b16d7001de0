#!/usr/bin/env python3
# light_selection_variance.py — how much a light tree (Conty & Kulla 2018; pbrt-v4's BVHLightSampler)
# could reduce the variance of next-event estimation on assets/scenes/many-lights.gltf, against the
# power-proportional choice caustica makes. Standard library only; no GPU.
"""Usage: python3 bench/light_selection_variance.py [POINTS]

For POINTS floor points seen by the scene's camera (default 400), with each light's unoccluded
contribution c_i = L A cos(theta_x) cos(theta_l) / d^2 (the lights are small: one point each), the
relative variance of a one-light estimate that picks light i with probability p_i is
    sum_i c_i^2 / p_i / (sum_i c_i)^2 - 1.
It is printed, averaged over the points, for: power-proportional p_i (caustica), a binary light BVH
traversed with pbrt-v4's importance (power x bounded cosines / squared distance, clamped by the node
size), and the ideal p_i proportional to c_i (zero). Occlusion by the boxes is ignored, as a light tree
ignores it too."""

import math
import os
import random
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scripts"))
import make_assets  # noqa: E402  (the scene's own parameters)

COUNT, SPACING, SIZE, HEIGHT = 31, 1.3, 0.25, 0.6  # make_assets.many_lights_scene defaults


def lights():
    out = []
    for i in range(COUNT):
        for j in range(COUNT):
            out.append(((i - (COUNT - 1) / 2.0) * SPACING, HEIGHT, (j - (COUNT - 1) / 2.0) * SPACING))
    return out


def contribution(x, l):
    """Unoccluded irradiance at floor point x (normal +y) from a small downward-facing light at l
    (radiance 1, area SIZE^2)."""
    d = (l[0] - x[0], l[1] - x[1], l[2] - x[2])
    d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
    cos_x = d[1] / math.sqrt(d2)   # receiver normal +y
    cos_l = d[1] / math.sqrt(d2)   # emitter normal -y, seen from below
    return SIZE * SIZE * cos_x * cos_l / d2


class Node:
    def __init__(self, items):
        self.items = items
        xs = [p[0] for p in items]
        zs = [p[2] for p in items]
        self.lo = (min(xs) - SIZE / 2, HEIGHT, min(zs) - SIZE / 2)
        self.hi = (max(xs) + SIZE / 2, HEIGHT, max(zs) + SIZE / 2)
        self.power = float(len(items))  # equal lights
        self.children = []
        if len(items) > 1:
            axis = 0 if self.hi[0] - self.lo[0] >= self.hi[2] - self.lo[2] else 2
            items = sorted(items, key=lambda p: p[axis])
            half = len(items) // 2
            self.children = [Node(items[:half]), Node(items[half:])]

    def importance(self, x):
        """pbrt-v4's LightBounds::Importance for emitters facing -y (normal cone of angle 0), a
        receiver with normal +y, without the cone clamping (all lights face straight down)."""
        c = tuple((a + b) / 2 for a, b in zip(self.lo, self.hi))
        d = tuple(ci - xi for ci, xi in zip(c, x))
        d2 = sum(v * v for v in d)
        diag = math.sqrt(sum((b - a) ** 2 for a, b in zip(self.lo, self.hi)))
        d2 = max(d2, diag / 2.0)
        dist = math.sqrt(d2)
        w = tuple(v / dist for v in d)
        # Angle bound of the box seen from x: sin(theta_b) = radius / distance.
        r = diag / 2.0
        sin_b = min(1.0, r / dist) if dist > 0 else 1.0
        cos_b = math.sqrt(max(0.0, 1.0 - sin_b * sin_b))
        def widen(cos_t):  # cos(max(0, theta - theta_b))
            t = math.acos(max(-1.0, min(1.0, cos_t)))
            return math.cos(max(0.0, t - math.asin(sin_b)))
        cos_light = widen(w[1])     # emitter normal -y against -w: cos = w_y
        cos_recv = widen(w[1])      # receiver normal +y against w
        if cos_light <= 0.0 or cos_recv <= 0.0:
            return 0.0
        del cos_b
        return self.power * cos_light * cos_recv / d2


def tree_probabilities(root, x):
    probs = {}
    stack = [(root, 1.0)]
    while stack:
        node, p = stack.pop()
        if not node.children:
            probs[node.items[0]] = p
            continue
        a, b = node.children
        ia, ib = a.importance(x), b.importance(x)
        if ia + ib <= 0.0:
            ia = ib = 1.0
        stack.append((a, p * ia / (ia + ib)))
        stack.append((b, p * ib / (ia + ib)))
    return probs


def floor_points(n, rng):
    """Floor points the camera sees (pinhole, the scene's camera)."""
    eye, target, yfov = (0.0, 2.2, 7.0), (0.0, 0.0, 0.0), 0.8
    f = make_assets.normalize(make_assets.sub(target, eye))
    right = make_assets.normalize(make_assets.cross(f, (0.0, 1.0, 0.0)))
    up = make_assets.cross(right, f)
    t = math.tan(yfov / 2.0)
    pts = []
    while len(pts) < n:
        u, v = rng.uniform(-1, 1), rng.uniform(-1, 1)
        d = tuple(f[k] + u * t * right[k] + v * t * up[k] for k in range(3))
        if d[1] >= -1e-6:
            continue  # sky
        s = -eye[1] / d[1]
        p = tuple(eye[k] + s * d[k] for k in range(3))
        half = (COUNT - 1) * SPACING / 2.0 + 2.0
        if abs(p[0]) <= half and abs(p[2]) <= half:
            pts.append(p)
    return pts


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 400
    rng = random.Random(1)
    ls = lights()
    root = Node(ls)
    rel_power, rel_tree, share_near = [], [], []
    for x in floor_points(n, rng):
        c = {l: contribution(x, l) for l in ls}
        total = sum(c.values())
        second = sum(v * v for v in c.values())
        rel_power.append(len(ls) * second / total ** 2 - 1.0)
        probs = tree_probabilities(root, x)
        rel_tree.append(sum(c[l] ** 2 / probs[l] for l in ls if probs[l] > 0) / total ** 2 - 1.0)
        top = sorted(c.values(), reverse=True)
        share_near.append(sum(top[:9]) / total)
    mean = lambda v: sum(v) / len(v)
    print("lights: %d, floor points: %d" % (len(ls), n))
    print("share of a point's direct light from its 9 nearest lights: %.2f" % mean(share_near))
    print("relative variance of one light sample, power-proportional: %.1f" % mean(rel_power))
    print("relative variance of one light sample, light tree (pbrt-v4 importance): %.2f" % mean(rel_tree))
    print("variance ratio power / tree: %.0f" % (mean(rel_power) / mean(rel_tree)))


if __name__ == "__main__":
    main()
