#!/usr/bin/env python3
"""Blender's Principled BSDF lobe by lobe, Spillway's `Principled` model against Cycles 3.4, in a
white furnace: spheres each showing one lobe (Burley's diffuse, a white and a gold metal, a clear
coat alone, a sheen alone, the specular lobe alone), a uniform world of radiance 1, one bounce,
512 samples, rendered through the Blender add-on with both engines from the same .blend.

  scripts/principled_furnace.py [--spillway build/spillway] [--keep DIR]

Prints, per sphere, the mean of its central pixels and of the whole sphere in each renderer and
their ratio (Spillway / Cycles). The figures blender/README.md gives came from this script. A
measurement, not a test: where the two differ by design (Cycles' clear coat draws its directions
from GGX's visible normals and weights them with GTR1's density) it says by how much.
"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# (name, base colour, Principled inputs); the spheres stand 1.2 apart along X, centred.
SPHERES = (
    ("diffuse", (0.8, 0.8, 0.8), {"Roughness": 0.7, "Specular": 0.0}),
    ("white metal", (1.0, 1.0, 1.0), {"Metallic": 1.0, "Roughness": 0.3}),
    ("gold", (0.95, 0.7, 0.3), {"Metallic": 1.0, "Roughness": 0.3}),
    ("coat alone", (0.0, 0.0, 0.0), {"Specular": 0.0, "Clearcoat": 1.0,
                                     "Clearcoat Roughness": 0.05}),
    ("sheen alone", (0.0, 0.0, 0.0), {"Specular": 0.0, "Sheen": 1.0, "Sheen Tint": 0.0}),
    ("specular alone", (0.0, 0.0, 0.0), {"Specular": 0.5, "Roughness": 0.4}),
)
WIDTH, HEIGHT = 144, 24

MAKE = r"""
import bpy, math, sys
out = sys.argv[sys.argv.index("--") + 1]
spheres = %r
scene = bpy.context.scene
for o in list(scene.objects):
    if o.type != "CAMERA":
        bpy.data.objects.remove(o)
for k, (name, colour, inputs) in enumerate(spheres):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    p = mat.node_tree.nodes["Principled BSDF"]
    p.inputs["Base Color"].default_value = tuple(colour) + (1.0,)
    for socket, value in inputs.items():
        p.inputs[socket].default_value = value
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, segments=64, ring_count=32,
                                         location=(-3.0 + 1.2 * k, 0, 0))
    bpy.ops.object.shade_smooth()
    bpy.context.active_object.data.materials.append(mat)
world = bpy.data.worlds.new("White")
world.use_nodes = True
world.node_tree.nodes["Background"].inputs["Color"].default_value = (1, 1, 1, 1)
scene.world = world
cam = scene.camera
cam.location = (0, -12, 0)
cam.rotation_euler = (math.radians(90), 0, 0)
cam.data.lens = 50
scene.cycles.blur_glossy = 0.0
scene.cycles.sample_clamp_indirect = 0.0
scene.cycles.max_bounces = scene.cycles.diffuse_bounces = scene.cycles.glossy_bounces = 1
scene.spillway.max_depth = 1
scene.render.resolution_x, scene.render.resolution_y = %d, %d
scene.render.resolution_percentage = 100
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_depth = "32"
scene.render.filter_size = 0.01
scene.cycles.samples = scene.spillway.samples = 512
scene.cycles.use_denoising = False
scene.cycles.use_adaptive_sampling = False
scene.view_settings.view_transform = "Standard"
scene.spillway.backend = "cpu"
scene.spillway.filter = "Box"
bpy.ops.wm.save_as_mainfile(filepath=out)
""" % (SPHERES, WIDTH, HEIGHT)


def pixels(path):
    """The image's RGB rows, from oiiotool's dump."""
    out = subprocess.run(["oiiotool", "--dumpdata", "--info", path], capture_output=True,
                         text=True, check=True).stdout
    img = [[None] * WIDTH for _ in range(HEIGHT)]
    for x, y, values in re.findall(r"Pixel \((\d+), (\d+)\): ([-\d.e+ ]+)", out):
        img[int(y)][int(x)] = [float(v) for v in values.split()[:3]]
    return img


def mean(img, xs, ys):
    cells = [img[y][x] for y in ys for x in xs]
    return [sum(c[k] for c in cells) / len(cells) for k in range(3)]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--spillway", default=os.path.join(ROOT, "build", "spillway"))
    ap.add_argument("--keep", help="a folder to keep the .blend and the images in")
    args = ap.parse_args()
    if not shutil.which("blender"):
        raise SystemExit("principled_furnace.py: needs Blender (Debian's blender package)")
    tmp = args.keep or tempfile.mkdtemp(prefix="spillway-furnace-")
    os.makedirs(tmp, exist_ok=True)
    # Blender's Python finds its standard library from the first python3 on PATH (not pyenv's).
    path = os.pathsep.join(p for p in os.environ.get("PATH", "").split(os.pathsep)
                           if ".pyenv" not in p)
    env = dict(os.environ, SPILLWAY_BINARY=os.path.abspath(args.spillway), PATH=path)
    addon = ["--python-expr", "import sys; sys.path.insert(0, %r); import spillway_render; "
             "spillway_render.register()" % os.path.join(ROOT, "blender")]
    blend = os.path.join(tmp, "furnace.blend")
    try:
        subprocess.run(["blender", "-b", "--factory-startup"] + addon +
                       ["--python-expr", MAKE, "--", blend], env=env, check=True,
                       capture_output=True)
        images = {}
        for engine in ("SPILLWAY", "CYCLES"):
            subprocess.run(["blender", "-b", "--factory-startup", blend] + addon +
                           ["-E", engine, "-o", os.path.join(tmp, engine + "_"), "-F",
                            "OPEN_EXR", "-f", "1"], env=env, check=True, capture_output=True)
            images[engine] = pixels(os.path.join(tmp, engine + "_0001.exr"))
        # Sphere k's centre: its X over the view's half width at 12 m (36 mm sensor, 50 mm lens).
        half = 12.0 * 18.0 / 50.0
        for k, (name, _, _) in enumerate(SPHERES):
            cx = int(round(WIDTH / 2 + (-3.0 + 1.2 * k) / (2 * half) * WIDTH))
            for label, xs, ys in (("centre", range(cx - 1, cx + 1), range(11, 13)),
                                  ("sphere", range(cx - 4, cx + 4), range(7, 17))):
                a = mean(images["SPILLWAY"], xs, ys)
                b = mean(images["CYCLES"], xs, ys)
                print("%-15s %-6s Spillway %s  Cycles %s  ratio %s" % (
                    name, label, " ".join("%.4f" % v for v in a),
                    " ".join("%.4f" % v for v in b),
                    " ".join("%.3f" % (x / y) if y else "-" for x, y in zip(a, b))))
    finally:
        if not args.keep:
            shutil.rmtree(tmp, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
