"""`scripts/bench.py cycles`: the time Spillway needs to reach the error Cycles reaches at 256
samples a pixel, on five kinds of scene users bring, each renderer judged against its own
reference image (their BRDFs differ; on the Cornell box, where they nearly agree, Spillway is
also judged against Cycles' reference).

For each scene the script writes a glTF file (and, for the environment-lit one, a lat-long
map and a YAML scene that places the file under it), then
  - Cycles (Blender's glTF importer, scripts/cycles_compare.py's matched settings, 2 threads)
    renders it at --cycles-spp (256) and at 16, 32, ... below, and once at --reference-spp
    (4096) with another seed: its reference;
  - each Spillway backend (--backends, default cpu and reference; default settings: the
    Sobol sampler a glTF file gets, 2 threads) renders its own reference at --reference-spp
    with another seed, and then 4, 8, 16, ... samples a pixel until its relMSE against that
    reference is below the one Cycles reached at --cycles-spp.
The time to reach that error is interpolated between the two bracketing renders (log time
against log error); a render's time is Spillway's whole process (loading the scene included)
and Cycles' render call (Blender's start and the import left out). The table prints, per
scene: Cycles' seconds and relMSE at 256 spp, and per backend the samples and seconds it took,
the ratio to Cycles' seconds, and that ratio less Spillway's process start (`spillway
--version`: loading its shared libraries), which Cycles' figure does not pay. Writes out/bench/cycles.json.

Spillway renders the scene Cycles renders: where a glTF file's emitters are too dim for Spillway
to let them light it alone (it would add a white world, as it says on stderr), it gets a black
world (`--environment 0,0,0`), as Cycles has. `--scenes holdout` runs five scenes of the same
kinds that nothing was tuned on: the Cornell box's room with two boxes and its light drawn anew,
the glossy one likewise, the spheres, lamps, panel and sun of the others drawn from
HOLDOUT_SEED (out/bench/cycles-holdout.json).

--quick renders small images and few samples: it checks that the comparison runs (the
suite's Bench.CyclesQuickRuns), its figures mean nothing.
"""
import json
import math
import os
import random
import shutil
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cycles_compare as cc  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
THREADS = 2


# --- scenes -----------------------------------------------------------------------------------

def obj_triangles(path):
    """The triangles of a (polygon) OBJ file, as lists of three vertices."""
    verts, tris = [], []
    with open(path) as f:
        for line in f:
            t = line.split()
            if t and t[0] == "v":
                verts.append(tuple(float(x) for x in t[1:4]))
            elif t and t[0] == "f":
                face = [verts[int(x.split("/")[0]) - 1] for x in t[1:]]
                tris += [(face[0], face[k], face[k + 1]) for k in range(1, len(face) - 1)]
    return tris


def flat_mesh(tris, material):
    """A glTF mesh of flat-shaded triangles (each its own three vertices)."""
    pos, nor = [], []
    for a, b, c in tris:
        e1 = [b[k] - a[k] for k in range(3)]
        e2 = [c[k] - a[k] for k in range(3)]
        n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
             e1[0] * e2[1] - e1[1] * e2[0]]
        length = math.sqrt(sum(x * x for x in n)) or 1.0
        for p in (a, b, c):
            pos += p
            nor += [x / length for x in n]
    return pos, nor, list(range(len(pos) // 3)), None, material


def quad(centre, half_x, half_z, material, facing=-1.0):
    """A horizontal square light facing down (facing -1) or up, as two triangles."""
    x, y, z = centre
    a, b = (x - half_x, y, z - half_z), (x + half_x, y, z - half_z)
    c, d = (x + half_x, y, z + half_z), (x - half_x, y, z + half_z)
    return flat_mesh([(a, b, c), (a, c, d)] if facing < 0 else [(a, c, b), (a, d, c)], material)


def emissive(colour, strength):
    m = cc.material((0.0, 0.0, 0.0), 0.0, 1.0)
    peak = max(colour)
    m["emissiveFactor"] = [c / peak for c in colour]
    m["extensions"] = {"KHR_materials_emissive_strength": {"emissiveStrength": strength * peak}}
    m["doubleSided"] = True  # as Cycles' emission, which leaves both faces
    return m


def box(x, z, width, depth, height, yaw):
    """A box standing on the floor (y = 0) of the Cornell box's millimetres, centred on (x, z),
    turned by yaw radians about the vertical: 12 triangles wound outward."""
    c, s = math.cos(yaw), math.sin(yaw)

    def corner(i, j, k):  # i, j, k in {0, 1}: -x/+x, floor/top, -z/+z
        u, v = (i - 0.5) * width, (k - 0.5) * depth
        return (x + c * u - s * v, j * height, z + s * u + c * v)
    faces = [((0, 0, 0), (1, 0, 0), (1, 0, 1), (0, 0, 1)),  # floor, facing down
             ((0, 1, 0), (0, 1, 1), (1, 1, 1), (1, 1, 0)),  # top, facing up
             ((0, 0, 0), (0, 1, 0), (1, 1, 0), (1, 0, 0)),  # -z
             ((0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)),  # +z
             ((0, 0, 0), (0, 0, 1), (0, 1, 1), (0, 1, 0)),  # -x
             ((1, 0, 0), (1, 1, 0), (1, 1, 1), (1, 0, 1))]  # +x
    tris = []
    for a, b, d, e in faces:
        a, b, d, e = (corner(*q) for q in (a, b, d, e))
        tris += [(a, b, d), (a, d, e)]
    return tris


def cornell(path, light_scale, blocks_material, rng=None):
    """The Cornell box (scenes/cornell-box), metres, turned to face the glTF camera on +Z: its
    ceiling light scaled by light_scale in each direction, radiance 1 / light_scale^2 times, the
    same power. With rng (the held-out set): the room alone, two boxes of rng's sizes, turns and
    places, and the light moved and reshaped on the ceiling, its power kept."""
    def place(p):  # the scene's camera at (278, 273, -800) mm comes to (0, 0.3, 0.8) m
        return ((278.0 - p[0]) / 1000, (p[1] - 273.0) / 1000 + 0.3, -p[2] / 1000)

    folder = os.path.join(ROOT, "scenes", "cornell-box")
    materials = [cc.material(c, 0.0, 1.0) for c in
                 ((0.725, 0.71, 0.68), (0.63, 0.065, 0.05), (0.14, 0.45, 0.091))]
    materials += [blocks_material, emissive((17, 12, 4), 1.0 / light_scale ** 2)]
    parts = (("white.obj", 0), ("red.obj", 1), ("green.obj", 2))
    if rng is None:
        parts += (("blocks.obj", 3),)
    meshes = [flat_mesh([tuple(place(p) for p in t) for t in obj_triangles(os.path.join(folder, f))], m)
              for f, m in parts]
    light_at, half_x, half_z = (278.0, 279.5), 0.065 * light_scale, 0.0525 * light_scale
    if rng is not None:
        blocks = []
        for x0, x1 in ((90.0, 250.0), (306.0, 466.0)):  # one box in each half of the room
            blocks += box(rng.uniform(x0, x1), rng.uniform(130.0, 420.0), rng.uniform(90.0, 170.0),
                          rng.uniform(90.0, 170.0), rng.uniform(100.0, 360.0),
                          rng.uniform(0.0, math.pi / 2))
        meshes.append(flat_mesh([tuple(place(p) for p in t) for t in blocks], 3))
        light_at = (rng.uniform(170.0, 386.0), rng.uniform(170.0, 390.0))
        aspect = rng.uniform(0.6, 1.6)
        half_x, half_z = half_x * math.sqrt(aspect), half_z / math.sqrt(aspect)
    centre = place((light_at[0], 548.7, light_at[1]))
    meshes.append(quad(centre, half_x, half_z, 4))
    fov_x = math.radians(39.3)
    cc.write_glb(path, meshes, materials, camera_z=0.8, yfov=fov_x, aspect=1.0,
                 extensions=["KHR_materials_emissive_strength"])


def sphere_layout(rng, fixed):
    """Three spheres' (x, z, radius) on the floor: `fixed`, or with rng (the held-out set) a
    sphere in each third of the frame at rng's depth and size."""
    if rng is None:
        return fixed
    return [(rng.uniform(x - 0.35, x + 0.35), rng.uniform(-1.0, 0.5), rng.uniform(0.35, 0.75))
            for x in (-1.3, 0.1, 1.4)]


def many_lights(path, count=128, rng=None):
    """Spheres on a floor before a wall, lit by `count` small square lamps of many colours and
    powers (a 40:1 range) at many heights: a glTF file's dozens of lamps and emissive meshes.
    rng (the held-out set) places the spheres and draws the lamps; else seed 7 draws them."""
    spheres = sphere_layout(rng, ((-1.2, -0.6, 0.5), (0.1, 0.3, 0.45), (1.3, -0.9, 0.55)))
    rng = rng or random.Random(7)
    s = cc.sphere()
    materials = [cc.material((0.6, 0.6, 0.6), 0.0, 0.8), cc.material((0.9, 0.6, 0.3), 1.0, 0.35),
                 cc.material((0.3, 0.5, 0.8), 0.0, 0.3)]
    meshes = [cc.floor(8.0) + (0,), cc.panel(-4.0, 4.0, -1.0, 3.0, -2.5) + (0,)]
    for k, (x, z, r) in enumerate(spheres):
        meshes.append(([c * r + o for c, o in zip(s[0], [x, -1.0 + r, z] * (len(s[0]) // 3))],
                       s[1], s[2], None, 1 + k % 2))
    for _ in range(count):
        colour = [rng.uniform(0.2, 1.0) for _ in range(3)]
        materials.append(emissive(colour, rng.choice((2.0, 8.0, 80.0)) * rng.uniform(0.5, 1.0)))
        centre = (rng.uniform(-3.5, 3.5), rng.uniform(-0.5, 2.5), rng.uniform(-2.3, 2.0))
        meshes.append(quad(centre, 0.04, 0.04, len(materials) - 1))
    cc.write_glb(path, meshes, materials, camera_z=5.5, yfov=0.7,
                 extensions=["KHR_materials_emissive_strength"])


def textured(path, rng=None):
    """Textured spheres (base colour, metallic-roughness and normal images) on a checker floor
    before a checker wall, under a sun and a wide emissive panel overhead: image lookups on
    every bounce and light bouncing between the objects. rng (the held-out set) places the
    spheres, the panel and the sun."""
    s = cc.sphere()
    images = cc.textured_images()
    textured_material = cc.material((1.0, 1.0, 1.0), 1.0, 1.0)
    textured_material["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
    textured_material["pbrMetallicRoughness"]["metallicRoughnessTexture"] = {"index": 1}
    textured_material["normalTexture"] = {"index": 2}
    checker = cc.material((0.8, 0.8, 0.8), 0.0, 0.7)
    checker["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
    materials = [textured_material, checker, emissive((1.0, 0.95, 0.9), 1.5)]
    size = 4.0
    floor = ([-size, -1.0, -size, size, -1.0, -size, size, -1.0, size, -size, -1.0, size],
             [0, 1, 0] * 4, [0, 2, 1, 0, 3, 2], [0, 0, 4, 0, 4, 4, 0, 4], 1)
    meshes = [floor, cc.panel(-4.0, 4.0, -1.0, 3.0, -2.5) + (1,)]
    for x, z, r in sphere_layout(rng, ((-1.3, -0.4, 0.6), (0.2, 0.3, 0.5), (1.5, -0.7, 0.7))):
        meshes.append(([c * r + o for c, o in zip(s[0], [x, -1.0 + r, z] * (len(s[0]) // 3))],
                       s[1], s[2], s[3], 0))
    panel_at, sun = (0.0, 3.0, 0.0), (0.5, -0.7, -0.5)
    if rng is not None:
        panel_at = (rng.uniform(-1.5, 1.5), rng.uniform(2.5, 3.5), rng.uniform(-1.0, 1.0))
        sun = (rng.uniform(-0.8, 0.8), -rng.uniform(0.5, 1.0), -rng.uniform(0.2, 0.8))
    meshes.append(quad(panel_at, 2.0, 1.5, 2))
    cc.write_glb(path, meshes, materials, camera_z=5.5, yfov=0.7, images=images,
                 sun=(sun, 2.0 * 683), extensions=["KHR_materials_emissive_strength"])


def write_hdr(path, width, height, texel):
    """A Radiance RGBE image (flat scanlines), texel(x, y) -> linear RGB."""
    rows = bytearray()
    for y in range(height):
        for x in range(width):
            rgb = texel(x, y)
            peak = max(rgb)
            if peak < 1e-32:
                rows += b"\0\0\0\0"
                continue
            mantissa, exponent = math.frexp(peak)
            scale = mantissa * 256.0 / peak
            rows += bytes([min(255, int(c * scale)) for c in rgb] + [exponent + 128])
    with open(path, "wb") as f:
        f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (height, width))
        f.write(bytes(rows))


def sky(x, y, width, height, sun_theta=math.radians(55), sun_phi=math.radians(230)):
    """A blue sky brightening to the horizon, a dim brown ground, and a sun 2 degrees across
    (by default at 35 degrees of elevation, off to the camera's right), 4000 times the sky's
    radiance."""
    theta = math.pi * (y + 0.5) / height  # from straight up
    phi = 2 * math.pi * (x + 0.5) / width
    cos_angle = (math.cos(theta) * math.cos(sun_theta) +
                 math.sin(theta) * math.sin(sun_theta) * math.cos(phi - sun_phi))
    if cos_angle > math.cos(math.radians(1.0)):
        return (4000.0, 3600.0, 3000.0)
    if theta > math.pi / 2:
        return (0.12, 0.09, 0.06)
    t = theta / (math.pi / 2)
    return (0.25 + 0.6 * t, 0.45 + 0.45 * t, 1.0)


def environment_lit(folder, quick, rng=None):
    """Spheres on a floor under a sky with a sun (a lat-long map): a glTF file for Cycles, and
    the YAML scene Spillway renders, which places it under the map with the file's camera.
    rng (the held-out set) places the spheres and the sun (20 to 60 degrees up, anywhere round)."""
    glb, hdr, yaml = (os.path.join(folder, n) for n in ("outdoor.glb", "sky.hdr", "outdoor.yaml"))
    s = cc.sphere()
    materials = [cc.material((0.5, 0.5, 0.5), 0.0, 0.9), cc.material((0.95, 0.64, 0.54), 1.0, 0.3),
                 cc.material((0.8, 0.3, 0.2), 0.0, 0.4)]
    meshes = [cc.floor(12.0) + (0,)]
    spheres = sphere_layout(rng, ((-1.3, -0.5, 0.6), (0.2, 0.2, 0.5), (1.4, -0.6, 0.7)))
    for k, (x, z, r) in enumerate(spheres):
        meshes.append(([c * r + o for c, o in zip(s[0], [x, -1.0 + r, z] * (len(s[0]) // 3))],
                       s[1], s[2], None, 1 + k % 2))
    cc.write_glb(glb, meshes, materials, camera_z=5.0, yfov=0.6)
    width = 128 if quick else 512
    sun = (math.radians(55), math.radians(230))
    if rng is not None:
        sun = (math.radians(rng.uniform(30.0, 70.0)), math.radians(rng.uniform(0.0, 360.0)))
    write_hdr(hdr, width, width // 2, lambda x, y: sky(x, y, width, width // 2, *sun))
    fov_x = math.degrees(cc.horizontal_fov(glb))
    with open(yaml, "w") as f:
        f.write("image: {width: 640, height: 480, sample base: 1, iterations: 1}\n"
                "camera:\n  type: PinHole\n"
                "  look at: {eye: [0, 0.3, 5.0], target: [0, 0.3, 0], up: [0, 1, 0]}\n"
                "  fov: %.6f\n"
                "sampler: {type: Sobol}\n"
                "shaders: []\n"
                "objects:\n  - {type: Gltf, filename: outdoor.glb}\n"
                "light: {type: Environment, filename: sky.hdr}\n" % fov_x)
    return glb, yaml, hdr


# The held-out set's seeds (--scenes holdout): scenes of the same five kinds, laid out by these
# draws, on which nothing was tuned.
HOLDOUT_SEED = 20261207


def make_scenes(folder, quick, holdout=False):
    """[(name, glTF file for Cycles, file for Spillway, environment map or None)]: the
    benchmark's own five, or with holdout five of the same kinds laid out by HOLDOUT_SEED's
    draws (each kind its own stream)."""
    os.makedirs(folder, exist_ok=True)
    p = lambda n: os.path.join(folder, n)  # noqa: E731
    rng = (lambda k: random.Random(HOLDOUT_SEED + k)) if holdout else (lambda k: None)
    cornell(p("cornell.glb"), 1.0, cc.material((0.725, 0.71, 0.68), 0.0, 1.0), rng(0))
    cornell(p("glossy-small-light.glb"), 0.1, cc.material((0.95, 0.64, 0.54), 1.0, 0.28), rng(1))
    textured(p("textured.glb"), rng(2))
    many_lights(p("many-lights.glb"), rng=rng(3))
    glb, yaml, hdr = environment_lit(folder, quick, rng(4))
    return [("cornell", p("cornell.glb"), p("cornell.glb"), None),
            ("glossy-small-light", p("glossy-small-light.glb"), p("glossy-small-light.glb"), None),
            ("textured", p("textured.glb"), p("textured.glb"), None),
            ("many-lights", p("many-lights.glb"), p("many-lights.glb"), None),
            ("environment", glb, yaml, hdr)]


# --- renders ----------------------------------------------------------------------------------

def relmse(spillway, image, reference):
    r = subprocess.run([spillway, "compare", image, reference, "--json"], capture_output=True,
                       text=True, check=True)
    return json.loads(r.stdout)["relmse"]


def spillway_render(spillway, backend, file, width, spp, seed, out, extra=()):
    """Seconds of the whole process (best of the repeats), and the image written."""
    cmd = [spillway, "render", file, "--backend", backend, "--width", str(width), "--spp",
           str(spp), "--seed", str(seed), "--threads", str(THREADS), "--quiet", "-o", out]
    cmd += list(extra)
    start = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if r.returncode != 0:
        sys.exit("%s failed (%d): %s" % (" ".join(cmd), r.returncode, r.stderr[-2000:]))
    return seconds


def same_scene_args(spillway, file, work):
    """What Spillway needs to render the scene Cycles renders: where its emitters are too dim to
    light a glTF file alone, Spillway adds a white world (and says so) where Cycles, given the
    file's own lights, has a black one; then a black world for Spillway too."""
    probe = os.path.join(work, "probe.exr")
    r = subprocess.run([spillway, "render", file, "--spp", "1", "--width", "8", "--quiet", "-o",
                        probe], capture_output=True, text=True, check=True)
    os.remove(probe)
    return ["--environment", "0,0,0"] if "lit by that environment as well" in r.stderr else []


def start_seconds(spillway):
    """The least of three `spillway --version` runs: the process's start (loading its shared
    libraries), which every render's time includes."""
    def once():
        start = time.perf_counter()
        subprocess.run([spillway, "--version"], capture_output=True, check=True)
        return time.perf_counter() - start
    return min(once() for _ in range(3))


def cycles_renders(glb, env, width, height, levels, ref_spp, folder):
    """Cycles at each of `levels` (seed 0) and its reference (seed 1): {spp: (seconds, image)},
    and the reference's path."""
    renders = [{"spp": n, "seed": 0, "out": os.path.join(folder, "cycles-%d.exr" % n)}
               for n in levels]
    ref = os.path.join(folder, "cycles-reference.exr")
    renders.append({"spp": ref_spp, "seed": 1, "out": ref})
    seconds_file = os.path.join(folder, "cycles-seconds.json")
    cc.render_in_cycles(glb, width, height, renders, environment=env, threads=THREADS,
                        seconds=seconds_file)
    with open(seconds_file) as f:
        seconds = json.load(f)
    return {r["spp"]: (t, r["out"]) for r, t in zip(renders[:-1], seconds)}, ref


def interpolate_time(points, target):
    """The seconds at which error reaches `target`, from (spp, seconds, error) in increasing
    spp: log-log between the first render at or below the target and the one before it."""
    for k, (spp, seconds, error) in enumerate(points):
        if error > target:
            continue
        if k == 0 or error == target:
            return seconds, spp
        s0, t0, e0 = points[k - 1]
        f = math.log(e0 / target) / math.log(e0 / error) if e0 > error else 1.0
        return math.exp(math.log(t0) + f * (math.log(seconds) - math.log(t0))), \
            math.exp(math.log(s0) + f * (math.log(spp) - math.log(s0)))
    return None, None


def bench_scene(spillway, backends, scene, width, cycles_spp, ref_spp, repeat, max_spp, folder):
    name, glb, ours, env = scene
    work = os.path.join(folder, name)
    os.makedirs(work, exist_ok=True)
    height = int(round(width / (1.0 if name.startswith(("cornell", "glossy")) else 4 / 3)))
    levels = [n for n in (16, 32, 64, 128) if n < cycles_spp] + [cycles_spp]
    cycles, cycles_ref = cycles_renders(glb, env, width, height, levels, ref_spp, work)
    target = relmse(spillway, cycles[cycles_spp][1], cycles_ref)
    row = {"scene": name, "width": width, "height": height, "cycles_spp": cycles_spp,
           "cycles_seconds": cycles[cycles_spp][0], "cycles_relmse": target,
           "cycles_curve": [(n, cycles[n][0], relmse(spillway, cycles[n][1], cycles_ref))
                            for n in levels], "backends": {}}
    same = same_scene_args(spillway, ours, work) if env is None else []
    row["spillway_args"] = same
    for backend in backends:
        ref = os.path.join(work, "%s-reference.exr" % backend)
        spillway_render(spillway, backend, ours, width, ref_spp, 1, ref, same)
        points, spp = [], 4
        while spp <= max_spp:
            out = os.path.join(work, "%s-%d.exr" % (backend, spp))
            seconds = min(spillway_render(spillway, backend, ours, width, spp, 0, out, same)
                          for _ in range(repeat))
            points.append((spp, seconds, relmse(spillway, out, ref)))
            if points[-1][2] <= target:
                break
            spp *= 2
        seconds, at_spp = interpolate_time(points, target)
        start = start_seconds(spillway)
        b = {"curve": points, "seconds": seconds, "spp": at_spp, "start_seconds": start,
             "ratio": seconds / row["cycles_seconds"] if seconds else None,
             "ratio_without_start": (seconds - start) / row["cycles_seconds"] if seconds else None,
             "against_cycles_reference": relmse(spillway, ref, cycles_ref)}
        # As a user asks for an error: --target-error at twice, once and half Cycles' error
        # (adaptive sampling toward it, the default), timed to the true error by interpolation.
        asked = []
        for k, factor in enumerate((2.0, 1.0, 0.5)):
            out = os.path.join(work, "%s-target-%d.exr" % (backend, k))
            t = min(spillway_render(spillway, backend, ours, width, max_spp, 0, out,
                                    same + ["--target-error", "%g" % (factor * target)])
                    for _ in range(repeat))
            asked.append((factor, t, relmse(spillway, out, ref)))
        asked.sort(key=lambda p: -p[2])
        b["target_curve"] = asked
        b["target_seconds"], _ = interpolate_time(asked, target)
        b["target_ratio"] = b["target_seconds"] / row["cycles_seconds"] \
            if b["target_seconds"] else None
        if name == "cornell":
            # The same error against Cycles' reference (the BRDFs nearly agree here).
            b["curve_against_cycles"] = [(n, t, relmse(spillway, os.path.join(
                work, "%s-%d.exr" % (backend, n)), cycles_ref)) for n, t, _ in points]
        row["backends"][backend] = b
    return row


def print_row(row):
    print("%-19s Cycles %4d spp %7.2f s relMSE %.3g" % (
        row["scene"], row["cycles_spp"], row["cycles_seconds"], row["cycles_relmse"]))
    for backend, b in row["backends"].items():
        if b["seconds"] is None:
            print("  %-10s did not reach it by %d spp (relMSE %.3g)" % (
                backend, b["curve"][-1][0], b["curve"][-1][2]))
            continue
        print("  %-10s %6.0f spp %7.2f s  %.2fx Cycles' time, %.2fx without the %.2f s process "
              "start   (its reference vs Cycles': relMSE %.3g)" % (
                  backend, b["spp"], b["seconds"], b["ratio"], b["ratio_without_start"],
                  b["start_seconds"], b["against_cycles_reference"]))
        if b.get("target_seconds"):
            print("  %-10s --target-error: %7.2f s  %.2fx Cycles' time" % (
                "", b["target_seconds"], b["target_ratio"]))
        else:
            print("  %-10s --target-error: did not reach it (%s)" % ("", b.get("target_curve")))
    sys.stdout.flush()


def main(spillway, backends, quick, repeat, scenes=None):
    """scenes: names of the benchmark's scenes to run (default all); "holdout" among them runs
    the held-out set instead (the names beside it choose among its scenes), into
    out/bench/cycles-holdout/ and out/bench/cycles-holdout.json."""
    width, cycles_spp, ref_spp, max_spp = (32, 16, 64, 256) if quick else (128, 256, 4096, 8192)
    holdout = "holdout" in (scenes or [])
    scenes = [n for n in (scenes or []) if n != "holdout"]
    tag = "cycles-holdout" if holdout else "cycles"
    folder = tempfile.mkdtemp(prefix="bench-cycles-") if quick else \
        os.path.join(ROOT, "out", "bench", tag)
    rows = []
    for scene in make_scenes(os.path.join(folder, "scenes"), quick, holdout):
        if scenes and scene[0] not in scenes:
            continue
        rows.append(bench_scene(spillway, backends, scene, width, cycles_spp, ref_spp, repeat,
                                max_spp, folder))
        print_row(rows[-1])
    if not quick:
        with open(os.path.join(ROOT, "out", "bench", tag + ".json"), "w") as f:
            json.dump(rows, f, indent=2)
    else:
        shutil.rmtree(folder)
    # Every scene measured: each render's seconds and error positive and finite.
    def measured(points):
        return all(0 < t < math.inf and 0 < e < math.inf for _, t, e in points)
    bad = [r["scene"] for r in rows if not (measured(r["cycles_curve"]) and all(
        measured(b["curve"]) and measured(b["target_curve"]) for b in r["backends"].values()))]
    if bad:
        print("FAIL: no usable measurement on %s" % ", ".join(bad))
    return 1 if bad else 0
