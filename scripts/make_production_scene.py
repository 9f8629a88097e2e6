#!/usr/bin/python3
"""Writes the production workload: the performance scene of the thesis (Eisenacher et al. 2013 as
reproduced there), scaled to this machine. Its data does not fit in cache, which is the regime the
sorted pipeline exists for.

  scripts/make_production_scene.py OUT_DIR [--models N] [--triangles T] [--texture-res R]
                                           [--width W --height H --spp S --max-depth D] [--small]

OUT_DIR gets (never committed; rerunning rewrites only what the options change):
  scene.yaml     N non-instanced bumpy spheres (meshes with UVs, T triangles in all) on a floor,
                 each with its own shader (3 of 4 Lambert, every 4th a rough Conductor) whose
                 colour is 4 Standard textures layered by 3 Standard masks; one quad light; a
                 ThinLens camera
  control.yaml   the in-core control: the same scene with every image leaf replaced by a
                 Constant of that image's mean (linear) colour
  model_KK.obj, tex_KK_L.tx (colour L = 0..3, RGB) and mask_KK_M.tx (M = 0..2, one channel):
                 tiled (64 x 64), MIP-mapped, uncompressed textures made by maketx, so bytes on
                 disk are the bytes a tile read brings in
The defaults (64 models, 3.2 M triangles, 1280^2 textures: 2.1 GB of textures) are the scale
the thesis' experiment needs on a 24 GiB machine. --small is the test preset: 4 models, 256^2
textures (5.2 MB) against `texture cache: 1` (1 MiB), 64 x 64 pixels, 4 spp, rendering in seconds.

Deterministic: the same options write the same bytes. Prints what it wrote: triangles, geometry
bytes, texture bytes, seconds.
"""
import argparse
import json
import math
import os
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

COLOURS, MASKS = 4, 3


def sphere_mesh(path, centre, radius, seed, nu, nv):
    """A UV sphere with a bumpy radius (distinct per seed), its texture coordinates tiling the
    textures twice around and once pole to pole. nu x nv quads, the pole rows as triangles:
    2 nu (nv - 1) triangles."""
    rng = np.random.default_rng(seed)
    k1, k2, k3 = rng.integers(3, 11, size=3)
    p1, p2 = rng.uniform(0, 2 * math.pi, size=2)
    u = np.linspace(0.0, 1.0, nu + 1)  # the seam column is duplicated for its own UVs
    v = np.linspace(0.0, 1.0, nv + 1)
    uu, vv = np.meshgrid(u, v)
    th, ph = vv * math.pi, uu * 2 * math.pi
    bump = 1 + 0.05 * np.sin(k1 * th + p1) * np.sin(k2 * ph + p2) + 0.02 * np.sin(k3 * (th + ph))
    r = radius * bump
    x = centre[0] + r * np.sin(th) * np.cos(ph)
    y = centre[1] + r * np.cos(th)
    z = centre[2] + r * np.sin(th) * np.sin(ph)
    verts = np.stack([x, y, z], axis=-1).reshape(-1, 3)
    uvs = np.stack([2 * uu, 1 - vv], axis=-1).reshape(-1, 2)
    j, i = np.meshgrid(np.arange(nv), np.arange(nu), indexing="ij")
    a = j * (nu + 1) + i + 1
    b, c = a + 1, a + nu + 1
    d = c + 1
    upper = np.stack([a, c, b], axis=-1)[1:]  # the north pole row would be degenerate
    lower = np.stack([b, c, d], axis=-1)[:-1]  # and so would the south pole's
    faces = np.concatenate([upper.reshape(-1, 3), lower.reshape(-1, 3)])
    with open(path + ".part", "w") as f:
        f.write("".join("v %.5f %.5f %.5f\n" % tuple(p) for p in verts))
        f.write("".join("vt %.5f %.5f\n" % tuple(t) for t in uvs))
        f.write("".join("f %d/%d %d/%d %d/%d\n" % (p, p, q, q, s, s) for p, q, s in faces))
    os.replace(path + ".part", path)
    return len(faces)


def srgb_to_linear(c):
    c = c / 255.0
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def texture_pixels(seed, res, channels):
    """Blotches of colour at three scales plus grain: structure a MIP level can average, and
    detail (so bytes do not compress away)."""
    rng = np.random.default_rng(seed)
    img = np.zeros((res, res, channels))
    for cells, weight in ((4, 0.5), (16, 0.3), (64, 0.15)):
        cells = min(cells, res)
        grid = rng.uniform(0, 1, size=(cells, cells, channels))
        img += weight * np.kron(grid, np.ones((res // cells + 1, res // cells + 1, 1)))[:res, :res]
    img += 0.05 * rng.uniform(-1, 1, size=img.shape)
    return np.clip(img * 255.0, 0, 255).astype(np.uint8)


def write_texture(out, name, seed, res, channels):
    """Writes NAME.tx (tiled, MIP-mapped, uncompressed) unless it is there; returns its mean linear
    colour and its size on disk."""
    tx = os.path.join(out, name + ".tx")
    pix = texture_pixels(seed, res, channels)
    mean = srgb_to_linear(pix.reshape(-1, channels).astype(np.float64)).mean(axis=0)
    if not os.path.exists(tx):
        src = os.path.join(out, name + (".ppm" if channels == 3 else ".pgm"))
        with open(src, "wb") as f:
            f.write(b"P%d\n%d %d\n255\n" % (6 if channels == 3 else 5, res, res))
            f.write(pix.tobytes())
        tmp = tx + ".part.tx"
        subprocess.run(["maketx", src, "-o", tmp, "--tile", "64", "64", "--compression", "none",
                        "--threads", "1"], check=True, stdout=subprocess.DEVNULL)
        os.replace(tmp, tx)
        os.remove(src)
    return mean, os.path.getsize(tx)


def layered(leaves, masks):
    """4 colours layered by 3 masks: L0 over (L1 over (L2 over L3 by M2) by M1) by M0."""
    node = leaves[3]
    for m in (2, 1, 0):
        node = "{type: Layered, upper: %s, lower: %s, mask: %s}" % (leaves[m], node, masks[m])
    return node


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out")
    ap.add_argument("--models", type=int, default=64)
    ap.add_argument("--triangles", type=int, default=3_200_000, help="in all, over the models")
    ap.add_argument("--texture-res", type=int, default=1280)
    ap.add_argument("--width", type=int, default=640)
    ap.add_argument("--height", type=int, default=360)
    ap.add_argument("--spp", type=int, default=16, help="a square: sample base sqrt(spp)")
    ap.add_argument("--max-depth", type=int, default=2)
    ap.add_argument("--texture-cache", type=float, help="MiB, written to settings (default: none)")
    ap.add_argument("--small", action="store_true", help="the test preset")
    a = ap.parse_args()
    if a.small:
        a.models, a.triangles, a.texture_res = 4, 16_000, 256
        a.width, a.height, a.spp, a.texture_cache = 64, 64, 4, a.texture_cache or 1
    base = int(round(math.sqrt(a.spp)))
    if base * base != a.spp or a.models < 1 or a.texture_res < 8:
        sys.exit("make_production_scene: --spp must be a square, --models >= 1, --texture-res >= 8")
    start = time.time()
    os.makedirs(a.out, exist_ok=True)

    # Geometry: a square grid of spheres, nu = 2 nv, 2 nu (nv - 1) ~ triangles / models each.
    side = math.ceil(math.sqrt(a.models))
    nv = max(4, int(round(math.sqrt(a.triangles / a.models / 4))))
    nu = 2 * nv
    spacing = 2.4
    triangles, geometry_bytes = 0, 0
    # What is already in OUT_DIR is kept when it was made with the same options.
    # The record is removed until this run completes, so that files left by an interrupted run
    # are never taken as made with these options.
    made = {}
    stamp_path = os.path.join(a.out, "generated.json")
    if os.path.exists(stamp_path):
        made = json.load(open(stamp_path))
        os.remove(stamp_path)
    fresh_geometry = made.get("mesh") != [nu, nv, a.models]
    if made.get("texture_res") != a.texture_res:
        for f in os.listdir(a.out):
            if f.endswith(".tx"):
                os.remove(os.path.join(a.out, f))
    objects, shaders, control = [], [], []
    jobs = []
    for k in range(a.models):
        cx = (k % side - (side - 1) / 2) * spacing
        cz = (k // side - (side - 1) / 2) * spacing
        obj = "model_%02d.obj" % k
        path = os.path.join(a.out, obj)
        if fresh_geometry or not os.path.exists(path):
            triangles += sphere_mesh(path, (cx, 1.0, cz), 1.0, 1000 + k, nu, nv)
        else:
            triangles += 2 * nu * (nv - 1)
        geometry_bytes += os.path.getsize(path)
        objects.append("  - {filename: %s, shader: %d}" % (obj, k))
        for l in range(COLOURS):
            jobs.append(("tex_%02d_%d" % (k, l), (k * 16 + l) * 7919, 3))
        for m in range(MASKS):
            jobs.append(("mask_%02d_%d" % (k, m), (k * 16 + 8 + m) * 7919, 1))

    # Textures: two at a time (maketx on one thread each), one per core of this machine kind.
    with ThreadPoolExecutor(max_workers=max(1, os.cpu_count() or 1)) as pool:
        results = dict(zip([j[0] for j in jobs],
                           pool.map(lambda j: write_texture(a.out, j[0], j[1], a.texture_res, j[2]), jobs)))
    with open(stamp_path, "w") as f:
        json.dump({"mesh": [nu, nv, a.models], "texture_res": a.texture_res}, f)
    texture_bytes = sum(size for _, size in results.values())

    def leaf(name):
        return "{type: Standard, string: %s.tx}" % name

    def constant(name):
        mean = results[name][0]
        c = mean if len(mean) == 3 else np.repeat(mean, 3)
        return "{type: Constant, colour: [%.4f, %.4f, %.4f]}" % tuple(c)

    for k in range(a.models):
        cols = ["tex_%02d_%d" % (k, l) for l in range(COLOURS)]
        masks = ["mask_%02d_%d" % (k, m) for m in range(MASKS)]
        if k % 4 == 3:
            head = "  - type: Conductor\n    alpha: %.2f\n" % (0.15 + 0.05 * (k % 3))
        else:
            head = "  - type: Lambert\n    reflectance: 0.9\n"
        shaders.append(head + "    texture: " + layered([leaf(c) for c in cols], [leaf(m) for m in masks]))
        control.append(head + "    texture: " + layered([constant(c) for c in cols], [constant(m) for m in masks]))

    with open(os.path.join(a.out, "floor.obj"), "w") as f:
        h = side * spacing
        f.write("v %g 0 %g\nv %g 0 %g\nv %g 0 %g\nv %g 0 %g\n" % (-h, -h, -h, h, h, h, h, -h))
        f.write("f 1 2 3\nf 1 3 4\n")
    floor_shader = "  - {type: Lambert, colour: [0.5, 0.5, 0.5]}"
    objects.append("  - {filename: floor.obj, shader: %d}" % a.models)
    extent = side * spacing / 2 + 1.5  # the grid's half width, and a sphere's margin
    settings = "settings: {max depth: %d, min depth: %d%s}\n" % (
        a.max_depth, min(3, a.max_depth),
        ", texture cache: %g" % a.texture_cache if a.texture_cache else "")
    for name, shader_list in (("scene.yaml", shaders), ("control.yaml", control)):
        with open(os.path.join(a.out, name), "w") as f:
            f.write("# generated by scripts/make_production_scene.py %s\n" % " ".join(sys.argv[2:]))
            f.write("image: {width: %d, height: %d, sample base: %d, iterations: 1}\n" % (a.width, a.height, base))
            f.write(settings)
            f.write("camera:\n  type: ThinLens\n  look at: {eye: [0, %.2f, %.2f], target: [0, 0.5, %.2f]}\n"
                    "  fov: 45\n  aperture radius: 0.02\n  focal distance: %.2f\n" % (
                        extent * 1.2, extent * 2.2, extent * 0.1, extent * 2.4))
            f.write("shaders:\n" + "\n".join(shader_list) + "\n" + floor_shader + "\n")
            f.write("objects:\n" + "\n".join(objects) + "\n")
            f.write("light: {type: Quad, translation: [%.2f, %.2f, %.2f], rotation: [90, 0, 0], "
                    "scale: [%.2f, %.2f], intensity: 12}\n" % (-extent * 0.4, extent * 1.5, -extent * 0.3,
                                                              extent * 0.6, extent * 0.6))
    print("%s: %d models, %d triangles, %.1f MB geometry, %d textures %d^2, %.1f MB textures, %.1f s" % (
        os.path.join(a.out, "scene.yaml"), a.models, triangles, geometry_bytes / 1e6, len(jobs),
        a.texture_res, texture_bytes / 1e6, time.time() - start))


if __name__ == "__main__":
    main()
