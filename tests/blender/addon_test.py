#!/usr/bin/env python3
"""The Blender add-on (blender/spillway_render), headless, as a farm would run it.

    tests/blender/addon_test.py SPILLWAY_BINARY

Builds a .blend from a script (Blender's default cube on a plane, a camera with depth of field,
an area light, a sun, a uniform world) and renders the file with `blender -b FILE.blend
-E SPILLWAY -f 1`, the add-on registered from this tree first (an expression before -E: the
user's own add-ons are left as they are). It checks:
- the add-on's image is `spillway render` of the scene the add-on exported, bit for bit;
- what that scene carries of what glTF drops: the area light as a quad, the sun, the world as
  an environment, the camera's depth of field, the resolution and percentage;
- a feature it cannot carry (a disc area light, a subsurface, a specular above the model's 1) is
  reported by name, and the rest still renders;
- a missing binary is Blender's error report, naming it;
- a world of an equirectangular image, seen by the camera alone, is Cycles' image: relMSE
  below 0.01 and every channel's mean within 3 % (the map's orientation, strength and the field
  of view all show in it);
- a point, a spot, an area light and a sun each light a diffuse plane as Cycles' does, within
  2 % (their units);
- Blender's Principled BSDF is Cycles': a rough and a glossy dielectric, a metal, a clear coat
  and a sheen over a textured floor, under an area light, a sun and an HDR sky, through a lens
  with depth of field, 256 samples (relMSE below 0.01, every channel's mean within 3 %):
  measured relMSE 0.0037, means within 0.7 %, each sphere's within 2 %;
- depth of field is Cycles': emissive cubes before, at and behind the focus distance, through a
  wide aperture, against Cycles' image of the same .blend (relMSE below 0.01, every channel's
  mean within 3 %): measured 0.0025, where an aperture 20 % narrower reads 0.011 and a pinhole
  0.079;
- Esc (the engine's stop request, made to answer yes once the first iteration is reported) stops
  a render of 2^20 samples, and the iterations done are the image (no error report);
- a binary that fails is Blender's error report, with the binary's own message.
Prints what failed and exits 1, or exits 0; 77 (skipped) without Blender.
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

MAKE_BLEND = r"""
import bpy, math, sys
out, disc = sys.argv[sys.argv.index("--") + 1:]
scene = bpy.context.scene
bpy.ops.mesh.primitive_plane_add(size=8, location=(0, 0, -1))
cam = scene.camera
cam.location = (6, -6, 4)
cam.rotation_euler = (math.radians(63), 0, math.radians(45))
cam.data.dof.use_dof = True
cam.data.dof.focus_distance = 9.0
cam.data.dof.aperture_fstop = 2.8
for o in list(scene.objects):
    if o.type == "LIGHT":
        bpy.data.objects.remove(o)
area = bpy.data.lights.new("Panel", "AREA")
area.shape, area.size, area.size_y, area.energy = "RECTANGLE", 2.0, 1.0, 400.0
o = bpy.data.objects.new("Panel", area)
o.location = (0, 0, 4)
scene.collection.objects.link(o)
sun = bpy.data.lights.new("Sun", "SUN")
sun.energy, sun.angle = 2.0, 0.0
o = bpy.data.objects.new("Sun", sun)
o.rotation_euler = (math.radians(30), 0, math.radians(20))
scene.collection.objects.link(o)
if disc == "1":
    skin = bpy.data.materials.new("Skin")
    skin.use_nodes = True
    skin.node_tree.nodes["Principled BSDF"].inputs["Subsurface"].default_value = 0.3
    skin.node_tree.nodes["Principled BSDF"].inputs["Specular"].default_value = 1.5
    bpy.data.objects["Cube"].data.materials.append(skin)
    d = bpy.data.lights.new("Disc", "AREA")
    d.shape = "DISK"
    o = bpy.data.objects.new("Disc", d)
    o.location = (2, 2, 3)
    scene.collection.objects.link(o)
world = bpy.data.worlds.new("Sky")
world.use_nodes = True
bg = world.node_tree.nodes["Background"]
bg.inputs["Color"].default_value = (0.2, 0.3, 0.5, 1.0)
bg.inputs["Strength"].default_value = 0.5
scene.world = world
scene.render.resolution_x, scene.render.resolution_y = 96, 64
scene.render.resolution_percentage = 50
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_depth = "32"
scene.render.image_settings.exr_codec = "ZIP"
scene.render.engine = "SPILLWAY"
scene.spillway.stop = "SAMPLES"
scene.spillway.samples = 8
scene.spillway.backend = "cpu"
scene.spillway.filter = "Box"
bpy.ops.wm.save_as_mainfile(filepath=out)
"""


# The end of a .blend script whose image Spillway and Cycles must agree on: 64 x 48, SAMPLES
# samples in both, no denoising or adaptive sampling in Cycles, a box filter in both (Cycles'
# of width 0.01 pixel), no view transform.
ALIKE = r"""
scene.render.resolution_x, scene.render.resolution_y = 64, 48
scene.render.resolution_percentage = 100
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_depth = "32"
scene.render.filter_size = 0.01
scene.cycles.samples = SAMPLES
scene.cycles.use_denoising = False
scene.cycles.use_adaptive_sampling = False
scene.view_settings.view_transform = "Standard"
scene.spillway.samples = SAMPLES
scene.spillway.backend = "cpu"
scene.spillway.filter = "Box"
bpy.ops.wm.save_as_mainfile(filepath=out)
"""


# A world of an equirectangular image and nothing else: the camera sees the map alone, which
# Cycles and Spillway must then show alike (no BSDF in between): the map's orientation, its
# strength and the camera's field of view all show in where its texels land.
MAKE_WORLD = r"""
import bpy, math, sys
out, image_path = sys.argv[sys.argv.index("--") + 1:]
scene = bpy.context.scene
for o in list(scene.objects):
    if o.type != "CAMERA":
        bpy.data.objects.remove(o)
w, h = 64, 32
img = bpy.data.images.new("map", w, h, float_buffer=True)
px = []
for y in range(h):
    for x in range(w):
        q = (x * 4) // w  # four quarters of azimuth, each its own colour, brighter upward
        base = ((1.0, 0.2, 0.1), (0.1, 1.0, 0.2), (0.2, 0.1, 1.0), (1.0, 1.0, 0.2))[q]
        k = 0.25 + y / h
        px += [base[0] * k, base[1] * k, base[2] * k, 1.0]
img.pixels = px
img.filepath_raw = image_path
img.file_format = "OPEN_EXR"
img.save()
world = bpy.data.worlds.new("Map")
world.use_nodes = True
nodes = world.node_tree.nodes
tex = nodes.new("ShaderNodeTexEnvironment")
tex.image = bpy.data.images.load(image_path)
tex.interpolation = "Closest"
world.node_tree.links.new(tex.outputs["Color"], nodes["Background"].inputs["Color"])
nodes["Background"].inputs["Strength"].default_value = 2.0
scene.world = world
cam = scene.camera
cam.location = (0, 0, 0)
cam.rotation_euler = (math.radians(80), 0, math.radians(-30))
cam.data.lens = 18
SAMPLES = 64
""" + ALIKE


# One light over a white diffuse plane (Principled, roughness 1, no specular), seen from where
# the light is not in view, through a narrow lens: the plane's brightness is the light's
# irradiance, which the add-on must carry in Cycles' units (at normal incidence Cycles' diffuse
# and glTF's are the same).
MAKE_LIGHT = r"""
import bpy, math, sys, mathutils
kind, out = sys.argv[sys.argv.index("--") + 1:]
scene = bpy.context.scene
for o in list(scene.objects):
    if o.type != "CAMERA":
        bpy.data.objects.remove(o)
bpy.ops.mesh.primitive_plane_add(size=20, location=(0, 0, 0))
mat = bpy.data.materials.new("white")
mat.use_nodes = True
p = mat.node_tree.nodes["Principled BSDF"]
p.inputs["Base Color"].default_value = (0.8, 0.8, 0.8, 1)
p.inputs["Roughness"].default_value = 1.0
p.inputs["Specular"].default_value = 0.0
bpy.context.active_object.data.materials.append(mat)
cam = scene.camera
cam.location = (6, 0.001, 6)
cam.rotation_euler = (-mathutils.Vector(cam.location)).to_track_quat("-Z", "Y").to_euler()
cam.data.lens = 2000
if kind == "SUN":
    light = bpy.data.lights.new("L", "SUN")
    light.energy, light.angle = 3.0, 0.0
elif kind == "AREA":
    light = bpy.data.lights.new("L", "AREA")
    light.size, light.energy = 0.5, 50.0
else:
    light = bpy.data.lights.new("L", kind)
    light.energy, light.shadow_soft_size = 50.0, 0.0
    if kind == "SPOT":
        light.spot_size, light.spot_blend = math.radians(60), 0.1
o = bpy.data.objects.new("L", light)
o.location = (0, 0, 2)
scene.collection.objects.link(o)
world = bpy.data.worlds.new("Dark")
world.use_nodes = True
world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
scene.world = world
scene.render.resolution_x = scene.render.resolution_y = 16
scene.render.resolution_percentage = 100
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_depth = "32"
scene.cycles.samples = 64
scene.cycles.use_denoising = False
scene.view_settings.view_transform = "Standard"
scene.spillway.samples = 64
scene.spillway.backend = "cpu"
bpy.ops.wm.save_as_mainfile(filepath=out)
"""


# Emissive cubes (black, unreflecting, in a black world: what the camera sees is their emission
# alone) at three depths, the middle one in focus, through a 100 mm lens at f/0.5: the near one
# blurs over about 9 pixels, the far one 4, by the aperture's radius and the focus distance.
MAKE_DOF = r"""
import bpy, math, sys
out = sys.argv[sys.argv.index("--") + 1]
scene = bpy.context.scene
for o in list(scene.objects):
    if o.type != "CAMERA":
        bpy.data.objects.remove(o)
mat = bpy.data.materials.new("glow")
mat.use_nodes = True
p = mat.node_tree.nodes["Principled BSDF"]
p.inputs["Base Color"].default_value = (0, 0, 0, 1)
p.inputs["Specular"].default_value = 0.0
p.inputs["Roughness"].default_value = 1.0
p.inputs["Emission"].default_value = (1.0, 0.6, 0.3, 1)
p.inputs["Emission Strength"].default_value = 2.0
for x, y, size in ((-0.25, 2.0, 0.2), (0.0, 6.0, 0.5), (0.7, 12.0, 0.8)):
    bpy.ops.mesh.primitive_cube_add(size=size, location=(x, y, 0))
    bpy.context.active_object.data.materials.append(mat)
cam = scene.camera
cam.location = (0, -0.5, 0)
cam.rotation_euler = (math.radians(90), 0, 0)
cam.data.lens = 100
cam.data.dof.use_dof = True
cam.data.dof.focus_distance = 6.5
cam.data.dof.aperture_fstop = 0.5
world = bpy.data.worlds.new("Dark")
world.use_nodes = True
world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
scene.world = world
SAMPLES = 256
""" + ALIKE


# Blender's Principled BSDF in five kinds on spheres over a textured floor (a rough and a glossy
# dielectric, the second with a specular tint, a metal, a clear coat, a sheen), lit by an area
# light, a sun and an HDR sky, through a lens with depth of field, at 8 bounces in both
# renderers and with Cycles' glossy filter and indirect clamp off (they bias its image). The
# area light stands where the sun's rays to the spheres do not cross it: Spillway's quad lights
# shadow other lights, Cycles' do not.
MAKE_PRINCIPLED = r"""
import bpy, math, sys, mathutils
out, image_path, tex_path = sys.argv[sys.argv.index("--") + 1:]
scene = bpy.context.scene
for o in list(scene.objects):
    if o.type != "CAMERA":
        bpy.data.objects.remove(o)
def principled(name, colour, **inputs):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    p = mat.node_tree.nodes["Principled BSDF"]
    p.inputs["Base Color"].default_value = colour + (1.0,)
    for k, v in inputs.items():
        p.inputs[k.replace("_", " ")].default_value = v
    return mat, p
# a checker image for the floor's base colour
w = 32
img = bpy.data.images.new("checker", w, w)
px = []
for y in range(w):
    for x in range(w):
        on = ((x // 8) + (y // 8)) % 2
        px += [0.7, 0.7, 0.65, 1.0] if on else [0.25, 0.3, 0.35, 1.0]
img.pixels = px
img.filepath_raw = tex_path
img.file_format = "PNG"
img.save()
floor, p = principled("floor", (0.5, 0.5, 0.5), Roughness=0.6)
tex = floor.node_tree.nodes.new("ShaderNodeTexImage")
tex.image = bpy.data.images.load(tex_path)
floor.node_tree.links.new(tex.outputs["Color"], p.inputs["Base Color"])
bpy.ops.mesh.primitive_plane_add(size=12, location=(0, 0, 0))
bpy.context.active_object.data.materials.append(floor)
spheres = [
    principled("rough", (0.8, 0.2, 0.1), Roughness=0.7),
    principled("glossy", (0.1, 0.3, 0.8), Roughness=0.15, Specular_Tint=0.5),
    principled("metal", (0.95, 0.7, 0.3), Metallic=1.0, Roughness=0.3),
    principled("coat", (0.6, 0.05, 0.05), Roughness=0.5, Clearcoat=1.0, Clearcoat_Roughness=0.05),
    principled("sheen", (0.2, 0.5, 0.2), Roughness=0.8, Sheen=1.0),
]
for k, (mat, _) in enumerate(spheres):
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, segments=48, ring_count=24,
                                         location=(-2.4 + 1.2 * k, 0, 0.5))
    bpy.ops.object.shade_smooth()
    bpy.context.active_object.data.materials.append(mat)
area = bpy.data.lights.new("Panel", "AREA")
area.shape, area.size, area.size_y, area.energy = "RECTANGLE", 2.0, 1.0, 150.0
o = bpy.data.objects.new("Panel", area)
o.location = (2.5, 2.0, 4.5)
o.rotation_euler = (-mathutils.Vector(o.location)).to_track_quat("-Z", "Y").to_euler()
scene.collection.objects.link(o)
sun = bpy.data.lights.new("Sun", "SUN")
sun.energy, sun.angle = 2.0, 0.0
o = bpy.data.objects.new("Sun", sun)
o.rotation_euler = (math.radians(40), 0, math.radians(-30))
scene.collection.objects.link(o)
# an HDR world: a sky brighter upward, values above 1
wm, hm = 64, 32
sky = bpy.data.images.new("sky", wm, hm, float_buffer=True)
px = []
for y in range(hm):
    for x in range(wm):
        k = 0.2 + 1.8 * (y / hm) ** 2
        px += [0.4 * k, 0.5 * k, 0.7 * k, 1.0]
sky.pixels = px
sky.filepath_raw = image_path
sky.file_format = "OPEN_EXR"
sky.save()
world = bpy.data.worlds.new("Sky")
world.use_nodes = True
nodes = world.node_tree.nodes
env = nodes.new("ShaderNodeTexEnvironment")
env.image = bpy.data.images.load(image_path)
world.node_tree.links.new(env.outputs["Color"], nodes["Background"].inputs["Color"])
scene.world = world
cam = scene.camera
cam.location = (0, -7, 2.2)
cam.rotation_euler = (math.radians(78), 0, 0)
cam.data.lens = 45
cam.data.dof.use_dof = True
cam.data.dof.focus_distance = 7.0
cam.data.dof.aperture_fstop = 4.0
scene.cycles.blur_glossy = 0.0
scene.cycles.sample_clamp_indirect = 0.0
scene.cycles.max_bounces = scene.cycles.diffuse_bounces = scene.cycles.glossy_bounces = 8
scene.spillway.max_depth = 8
SAMPLES = 256
""" + ALIKE

# Registered after the add-on: its engine's Esc answers yes once a first iteration is reported,
# as a user pressing Esc while the image converges.
PRESS_ESC = r"""
import bpy, spillway_render
E = spillway_render.SpillwayRenderEngine
E.escaped = False
def progress(self, fraction):
    E.escaped = True
    self.update_progress(fraction)
E._progress = progress
E._stop_requested = lambda self: E.escaped
bpy.context.scene.spillway.samples = 1 << 20
"""

# A spillway binary that refuses its scene, as spillway does a bad one.
FAILING_BINARY = """#!/bin/sh
echo "spillway: scene.yaml:3: 'shaders' is not a list" >&2
exit 2
"""


def blender(args, env=None, check=True, timeout=600):
    r = subprocess.run(["blender", "-b", "--factory-startup"] + args, capture_output=True,
                       text=True, env=env, timeout=timeout)
    if check and r.returncode != 0:
        raise SystemExit("blender %s failed (%d):\n%s%s" % (args, r.returncode, r.stdout, r.stderr))
    return r


def both_engines(blend, addon, tmp, prefix, env):
    """Renders `blend` with Spillway and with Cycles; returns the two images' paths."""
    out = []
    for engine in ("SPILLWAY", "CYCLES"):
        blender([blend] + addon + ["-E", engine, "-o", os.path.join(tmp, prefix + engine + "_"),
                                   "-F", "OPEN_EXR", "-f", "1"], env=env)
        out.append(os.path.join(tmp, prefix + engine + "_0001.exr"))
    return out


def agreement(what, spillway, ours, cycles):
    """Spillway's image `ours` against Cycles' `cycles`: relMSE below 0.01 and every channel's
    mean within 3 %; the failures, described."""
    c = subprocess.run([spillway, "compare", ours, cycles, "--json"], capture_output=True,
                       text=True, check=True)
    metrics = json.loads(c.stdout)
    print("%s, Spillway against Cycles: %s" % (what, json.dumps(metrics)))
    failures = []
    if not metrics["relmse"] < 0.01:
        failures.append("%s differs from Cycles': relMSE %g" % (what, metrics["relmse"]))
    for channel in range(3):
        a, b = metrics["mean_a"][channel], metrics["mean_b"][channel]
        if not abs(a / b - 1.0) <= 0.03:
            failures.append("%s: channel %d's mean %g where Cycles' is %g" % (what, channel, a, b))
    return failures


def main():
    if len(sys.argv) != 2:
        raise SystemExit(__doc__)
    spillway = os.path.abspath(sys.argv[1])
    if not shutil.which("blender"):
        print("no Blender: skipped")
        return 77
    failures = []
    tmp = tempfile.mkdtemp(prefix="spillway-addon-test-")
    try:
        # Blender's Python finds its standard library from the first python3 on PATH: a
        # pyenv one (a developer's shell) would hide Debian's, and numpy, which the glTF
        # exporter imports.
        path = os.pathsep.join(p for p in os.environ.get("PATH", "").split(os.pathsep)
                               if ".pyenv" not in p)
        env = dict(os.environ, SPILLWAY_BINARY=spillway, PATH=path)
        addon = ["--python-expr", "import sys; sys.path.insert(0, %r); import spillway_render; "
                 "spillway_render.register()" % os.path.join(ROOT, "blender")]
        for disc in ("0", "1"):
            blend = os.path.join(tmp, "scene%s.blend" % disc)
            blender(addon + ["--python-expr", MAKE_BLEND, "--", blend, disc], env=env)
            keep = os.path.join(tmp, "export" + disc)
            r = blender([blend] + addon + ["-E", "SPILLWAY", "-o",
                         os.path.join(tmp, "out%s_" % disc), "-F", "OPEN_EXR", "-f", "1"],
                        env=dict(env, SPILLWAY_KEEP_EXPORT=keep))
            said = r.stdout + r.stderr
            if disc == "1":
                for what in ("light Disc: a disk area light",
                             "material Skin: subsurface (rendered as its diffuse)",
                             "material Skin: Specular 1.5 (rendered as 1)"):
                    if "Spillway cannot carry: " + what not in said:
                        failures.append("%r is not reported by name:\n%s" % (what, said))
                continue
            image = os.path.join(tmp, "out0_0001.exr")
            if not os.path.exists(image):
                failures.append("no image from the add-on:\n" + said)
                continue
            yaml = open(os.path.join(keep, "scene.yaml"), encoding="utf-8").read()
            for what in ("type: Quad", "type: Directional", "type: Environment", "ThinLens",
                         "aperture radius", "focal distance: 9.0", "width: 48, height: 32",
                         "type: Gltf"):
                if what not in yaml:
                    failures.append("the exported scene lacks %r:\n%s" % (what, yaml))
            direct = os.path.join(tmp, "direct.exr")
            subprocess.run([spillway, "render", os.path.join(keep, "scene.yaml"), "--spp", "8",
                            "--backend", "cpu", "--quiet", "-o", direct], check=True)
            c = subprocess.run([spillway, "compare", image, direct], capture_output=True,
                               text=True)
            if "images identical" not in c.stdout:
                failures.append("the add-on's image is not spillway render's:\n" + c.stdout)
        world = os.path.join(tmp, "world.blend")
        blender(addon + ["--python-expr", MAKE_WORLD, "--", world, os.path.join(tmp, "map.exr")],
                env=env)
        failures += agreement("the world map", spillway,
                              *both_engines(world, addon, tmp, "", env))
        for kind in ("POINT", "SPOT", "AREA", "SUN"):
            blend = os.path.join(tmp, kind + ".blend")
            blender(addon + ["--python-expr", MAKE_LIGHT, "--", kind, blend], env=env)
            ours, cycles = both_engines(blend, addon, tmp, kind, env)
            c = subprocess.run([spillway, "compare", ours, cycles, "--json"],
                               capture_output=True, text=True, check=True)
            a, b = json.loads(c.stdout)["mean_a"][0], json.loads(c.stdout)["mean_b"][0]
            print("%s light, Spillway against Cycles: %.5f and %.5f" % (kind.lower(), a, b))
            if abs(a / b - 1.0) > 0.02:
                failures.append("a %s light lights the plane %.5f where Cycles' does %.5f"
                                % (kind.lower(), a, b))
        principled = os.path.join(tmp, "principled.blend")
        blender(addon + ["--python-expr", MAKE_PRINCIPLED, "--", principled,
                         os.path.join(tmp, "sky.exr"), os.path.join(tmp, "checker.png")], env=env)
        keep = os.path.join(tmp, "principled-export")
        images = both_engines(principled, addon, tmp, "principled",
                              dict(env, SPILLWAY_KEEP_EXPORT=keep))
        with open(os.path.join(keep, "scene.glb"), "rb") as f:
            if b'"SPILLWAY_materials_principled":{"specular":0.5,"specularTint":0.5' not in f.read():
                failures.append("the glossy material's Principled factors are not in scene.glb")
        failures += agreement("Principled materials", spillway, *images)
        dof = os.path.join(tmp, "dof.blend")
        blender(addon + ["--python-expr", MAKE_DOF, "--", dof], env=env)
        failures += agreement("depth of field", spillway, *both_engines(dof, addon, tmp, "dof", env))
        r = blender([os.path.join(tmp, "scene0.blend")] + addon +
                    ["--python-expr", PRESS_ESC, "-E", "SPILLWAY", "-o",
                     os.path.join(tmp, "esc_"), "-F", "OPEN_EXR", "-f", "1"], env=env, timeout=120)
        escaped = os.path.join(tmp, "esc_0001.exr")
        if "Spillway failed" in r.stdout + r.stderr or not os.path.exists(escaped):
            failures.append("Esc did not keep the image:\n" + r.stdout + r.stderr)
        else:
            c = subprocess.run([spillway, "compare", escaped, os.path.join(tmp, "out0_0001.exr"),
                                "--json"], capture_output=True, text=True, check=True)
            a, b = json.loads(c.stdout)["mean_a"], json.loads(c.stdout)["mean_b"]
            print("after Esc: the image's mean %s, the 8-spp render's %s" % (a, b))
            if any(not abs(x / y - 1.0) < 0.1 for x, y in zip(a, b)):
                failures.append("the image Esc kept is not the scene's: mean %s where the "
                                "8-spp render's is %s" % (a, b))
        failing = os.path.join(tmp, "failing-spillway")
        with open(failing, "w", encoding="utf-8") as f:
            f.write(FAILING_BINARY)
        os.chmod(failing, 0o755)
        r = blender([os.path.join(tmp, "scene0.blend")] + addon +
                    ["-E", "SPILLWAY", "-o", os.path.join(tmp, "failing_"), "-f", "1"],
                    env=dict(env, SPILLWAY_BINARY=failing), check=False)
        if "Spillway failed (exit 2): spillway: scene.yaml:3: 'shaders' is not a list" \
                not in r.stdout + r.stderr:
            failures.append("a failing binary is not reported with its message:\n" +
                            r.stdout + r.stderr)
        r = blender([os.path.join(tmp, "scene0.blend")] + addon +
                    ["-E", "SPILLWAY", "-o", os.path.join(tmp, "missing_"), "-f", "1"],
                    env=dict(env, SPILLWAY_BINARY="/nonexistent/spillway"), check=False)
        if "no spillway binary" not in r.stdout + r.stderr or \
                "/nonexistent/spillway" not in r.stdout + r.stderr:
            failures.append("a missing binary is not reported:\n" + r.stdout + r.stderr)
    finally:
        if not os.environ.get("SPILLWAY_ADDON_TEST_KEEP"):
            shutil.rmtree(tmp, ignore_errors=True)
    for f in failures:
        print("FAIL:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
