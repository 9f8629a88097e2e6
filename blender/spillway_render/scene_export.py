"""What the add-on writes for a render: the Blender scene as Spillway reads it.

The meshes and their materials go through Blender's own glTF exporter (scene.glb, Principled
BSDFs as glTF's metallic-roughness materials, emission included); each Principled BSDF's inputs
glTF's core lacks (specular, the tints, sheen, clear coat) are then written into its material as
SPILLWAY_materials_principled, so that Spillway renders Blender's Principled BSDF, not glTF's
BRDF. What glTF does not carry, or
carries other than Cycles renders it, is written beside it into scene.yaml, which places the
file: the camera (field of view, sensor fit, depth of field), every light (point, spot, sun and
area lights with Cycles' power), the world (a colour, or an equirectangular image with its
strength), the resolution and the filter. Anything it cannot carry is listed by name in
`problems`, never dropped silently.

Axes: glTF, and so the YAML, is Y-up: Blender's (x, y, z) is (x, z, -y) there.

Units, as Cycles renders its lights (tests/blender/addon_test.py measures each against Cycles):
a point or spot light of power P watts sends P / (4 pi) W/sr; a sun's strength is its
irradiance in W/m^2; an area light of power P and area A is one-sided with radiance P / (4 A).
A spot's blend b puts its inner cone's cosine at cos(outer) + b (1 - cos(outer)): Spillway's
falloff between them is glTF's t^2, not Cycles' smoothstep. Seen from behind, an area light is
black in Spillway, where Cycles' lets the ray through, and it shadows the other lights, where
Cycles' does not.
"""
import json
import math
import os
import struct
import subprocess

import bpy
import mathutils

# Blender's Z-up world into glTF's Y-up one.
TO_GLTF = mathutils.Matrix(((1, 0, 0, 0), (0, 0, 1, 0), (0, -1, 0, 0), (0, 0, 0, 1)))


def _vec(v):
    return "[%s]" % ", ".join(repr(float(c)) for c in v)


def _point(m):
    """The translation of world matrix m, in glTF's axes."""
    return (TO_GLTF @ m).to_translation()


def _axis(m, column):
    """Column `column` of m's rotation (a local axis in the world), in glTF's axes, unit."""
    r = (TO_GLTF @ m).to_3x3()
    return mathutils.Vector((r[0][column], r[1][column], r[2][column])).normalized()


def horizontal_fov(cam, width, height):
    """The horizontal field of view, in degrees, that Blender's sensor fit gives `cam`."""
    fit = cam.sensor_fit
    if fit == "AUTO":
        fit = "HORIZONTAL" if width >= height else "VERTICAL"
    sensor = cam.sensor_width if fit == "HORIZONTAL" or cam.sensor_fit == "AUTO" else cam.sensor_height
    half = math.atan(sensor / 2.0 / cam.lens)
    if fit == "VERTICAL":
        half = math.atan(math.tan(half) * width / height)
    return math.degrees(2.0 * half)


def camera_yaml(scene, width, height, problems):
    obj = scene.camera
    if obj is None:
        raise RuntimeError("the scene has no camera")
    cam = obj.data
    if cam.type != "PERSP":
        problems.append("camera %s: a %s camera (Spillway's are perspective)" % (obj.name, cam.type))
    if cam.shift_x != 0.0 or cam.shift_y != 0.0:
        problems.append("camera %s: lens shift" % obj.name)
    m = obj.matrix_world
    eye = _point(m)
    forward, up = -_axis(m, 2), _axis(m, 1)
    lines = ["camera:"]
    dof = cam.dof
    thin = dof.use_dof and dof.aperture_fstop > 0.0
    lines.append("  type: %s" % ("ThinLens" if thin else "PinHole"))
    lines.append("  look at: {eye: %s, target: %s, up: %s}" % (_vec(eye), _vec(eye + forward), _vec(up)))
    lines.append("  fov: %r" % horizontal_fov(cam, width, height))
    if thin:
        if dof.focus_object is not None:
            to = dof.focus_object.matrix_world.to_translation() - m.to_translation()
            distance = max(to.dot(-m.to_3x3().col[2].normalized()), 1e-6)
        else:
            distance = max(dof.focus_distance, 1e-6)
        # Cycles' aperture: the lens's focal length (mm, in metres) over twice the f-number.
        radius = cam.lens * 1e-3 * scene.unit_settings.scale_length / (2.0 * dof.aperture_fstop)
        lines.append("  aperture radius: %r" % radius)
        lines.append("  focal distance: %r" % distance)
        if dof.aperture_blades > 0:
            problems.append("camera %s: %d aperture blades (Spillway's aperture is round)"
                            % (obj.name, dof.aperture_blades))
    return lines


def _light_colour(light):
    return [float(c) for c in light.color]


def light_yaml(obj, problems):
    """The YAML light entry of light object `obj`, or None where Spillway has no such light."""
    light = obj.data
    m = obj.matrix_world
    colour = _light_colour(light)
    if light.type in ("POINT", "SPOT"):
        if light.shadow_soft_size > 0.0:
            problems.append("light %s: radius %g (Spillway's point and spot lights are points)"
                            % (obj.name, light.shadow_soft_size))
        intensity = light.energy / (4.0 * math.pi)
        if light.type == "POINT":
            return "  - {type: Point, position: %s, intensity: %r, colour: %s}" % (
                _vec(_point(m)), intensity, _vec(colour))
        outer = light.spot_size / 2.0
        cos_outer = math.cos(outer)
        inner = math.acos(min(1.0, cos_outer + light.spot_blend * (1.0 - cos_outer)))
        inner = min(inner, outer * (1.0 - 1e-6))  # Spillway's inner angle is below the outer
        return ("  - {type: Spot, position: %s, direction: %s, intensity: %r, colour: %s, "
                "inner angle: %r, outer angle: %r}" % (
                    _vec(_point(m)), _vec(-_axis(m, 2)), intensity, _vec(colour),
                    math.degrees(inner), min(math.degrees(outer), 90.0)))
    if light.type == "SUN":
        if light.angle > 0.0:
            problems.append("light %s: a sun of angle %.3g degrees (Spillway's is a direction)"
                            % (obj.name, math.degrees(light.angle)))
        return "  - {type: Directional, direction: %s, intensity: %r, colour: %s}" % (
            _vec(-_axis(m, 2)), light.energy, _vec(colour))
    if light.type == "AREA":
        if light.shape not in ("SQUARE", "RECTANGLE"):
            problems.append("light %s: a %s area light (Spillway's are rectangles)"
                            % (obj.name, light.shape.lower()))
            return None
        sx = light.size
        sy = light.size_y if light.shape == "RECTANGLE" else light.size
        scale = m.to_scale()
        sx, sy = sx * scale.x, sy * scale.y
        radiance = light.energy / (4.0 * sx * sy)  # Cycles': measured, tests/blender
        if light.spread < math.pi - 1e-6:
            problems.append("light %s: a spread of %.3g degrees (Spillway's quads spread 180)"
                            % (obj.name, math.degrees(light.spread)))
        # Spillway's quad emits along its local +Z, Blender's area light along its local -Z: turn
        # it half round its X axis (the rectangle is symmetric under it).
        r = (TO_GLTF @ m).to_3x3().normalized() @ mathutils.Matrix.Rotation(math.pi, 3, "X")
        e = r.to_euler("XYZ")
        return ("  - {type: Quad, translation: %s, rotation: %s, scale: [%r, %r], intensity: %r, "
                "colour: %s}" % (_vec(_point(m)), _vec([math.degrees(a) for a in e]), sx, sy,
                                 radiance, _vec(colour)))
    problems.append("light %s: a %s light" % (obj.name, light.type.lower()))
    return None


def _rolled_environment(image, directory):
    """The file of `image`, an equirectangular map as Blender lays it out (its centre looks
    along +X), rolled a quarter turn so that its centre looks along -Z in glTF's axes, as
    Spillway's does: OpenImageIO's circular shift, into an EXR in `directory` (values as they
    are: no colour transform). Returns (path, whether the width is not a multiple of 4), or None
    where the image is not a file."""
    source = bpy.path.abspath(image.filepath, library=image.library)
    if image.packed_file is not None or not os.path.isfile(source):
        return None
    width = image.size[0]
    path = os.path.join(directory, "environment.exr")
    subprocess.run(["oiiotool", source, "--cshift", "+%d+0" % (width // 4), "-d", "float", "-o",
                    path], check=True, capture_output=True)
    return path, width % 4 != 0


def world_yaml(scene, directory, problems):
    world = scene.world
    if world is None:
        return None
    if not world.use_nodes:
        return "  - {type: Environment, colour: %s}" % _vec(world.color)
    output = next((n for n in world.node_tree.nodes
                   if n.type == "OUTPUT_WORLD" and n.is_active_output), None)
    if output is None or not output.inputs["Surface"].is_linked:
        return None
    background = output.inputs["Surface"].links[0].from_node
    if background.type != "BACKGROUND":
        problems.append("world %s: a %s node as its surface" % (world.name, background.bl_idname))
        return None
    strength = background.inputs["Strength"]
    if strength.is_linked:
        problems.append("world %s: a linked Strength" % world.name)
    colour = background.inputs["Color"]
    if not colour.is_linked:
        return "  - {type: Environment, colour: %s, intensity: %r}" % (
            _vec(list(colour.default_value)[:3]), strength.default_value)
    source = colour.links[0].from_node
    if source.type != "TEX_ENVIRONMENT" or source.image is None:
        problems.append("world %s: a %s node as its colour" % (world.name, source.bl_idname))
        return None
    if source.inputs["Vector"].is_linked:
        problems.append("world %s: a mapped environment texture (Vector input)" % world.name)
    if source.projection != "EQUIRECTANGULAR":
        problems.append("world %s: a %s environment texture" % (world.name, source.projection))
    rolled = _rolled_environment(source.image, directory)
    if rolled is None:
        problems.append("world %s: the image %s is packed or generated, not a file (save it)"
                        % (world.name, source.image.name))
        return None
    path, off = rolled
    if off:
        problems.append("world %s: an environment map %d wide (not a multiple of 4: turned a "
                        "quarter round to the nearest texel)" % (world.name, source.image.size[0]))
    return "  - {type: Environment, string: %s, intensity: %r}" % (json.dumps(os.path.basename(path)),
                                                               strength.default_value)


# The Principled BSDF's inputs glTF's core lacks, as SPILLWAY_materials_principled names them
# (docs/scene-format.md): Spillway's Principled model renders them as Cycles does.
PRINCIPLED_FACTORS = (("Specular", "specular"), ("Specular Tint", "specularTint"),
                      ("Sheen", "sheen"), ("Sheen Tint", "sheenTint"), ("Clearcoat", "clearcoat"),
                      ("Clearcoat Roughness", "clearcoatRoughness"))
PRINCIPLED_EXTENSION = "SPILLWAY_materials_principled"


def _surface(mat):
    """The node a material's active output takes its surface from, or None."""
    if not mat.use_nodes:
        return None
    out = next((n for n in mat.node_tree.nodes
                if n.type == "OUTPUT_MATERIAL" and n.is_active_output), None)
    if out is None or not out.inputs["Surface"].is_linked:
        return None
    return out.inputs["Surface"].links[0].from_node


def principled_factors(mat, problems):
    """SPILLWAY_materials_principled's factors of `mat`'s Principled BSDF (None where its surface
    is not one); what the model leaves out is added to `problems` by name."""
    node = _surface(mat)
    if node is None or node.type != "BSDF_PRINCIPLED":
        return None
    factors = {}
    for socket, key in PRINCIPLED_FACTORS:
        value = node.inputs[socket]
        if value.is_linked:
            problems.append("material %s: a linked %s (its value %g is rendered)"
                            % (mat.name, socket, value.default_value))
        factor = float(value.default_value)
        factors[key] = min(max(factor, 0.0), 1.0)
        if factors[key] != factor:
            problems.append("material %s: %s %g (rendered as %g)"
                            % (mat.name, socket, factor, factors[key]))
    for socket in ("Subsurface", "Anisotropic", "Transmission"):
        value = node.inputs[socket]
        if value.is_linked or value.default_value > 0.0:
            what = {"Subsurface": "rendered as its diffuse", "Anisotropic": "rendered isotropic",
                    "Transmission": "rendered as glTF's glass, not the Principled BSDF's"}[socket]
            problems.append("material %s: %s (%s)" % (mat.name, socket.lower(), what))
    if node.distribution != "GGX":
        problems.append("material %s: the %s distribution (rendered as GGX)"
                        % (mat.name, node.distribution))
    return factors


def add_principled_extension(glb, factors):
    """Writes SPILLWAY_materials_principled into the materials of the .glb at `glb` that
    `factors` names (a material's name: its factors), rewriting the file's JSON chunk."""
    with open(glb, "rb") as f:
        data = f.read()
    magic, version, _ = struct.unpack_from("<4sII", data, 0)
    length, kind = struct.unpack_from("<II", data, 12)
    if magic != b"glTF" or version != 2 or kind != 0x4E4F534A:
        raise RuntimeError("%s: not a glTF 2.0 binary file" % glb)
    doc = json.loads(data[20:20 + length].decode("utf-8"))
    rest = data[20 + length:]
    used = False
    for m in doc.get("materials", []):
        if m.get("name") in factors:
            m.setdefault("extensions", {})[PRINCIPLED_EXTENSION] = factors[m["name"]]
            used = True
    if not used:
        return
    doc.setdefault("extensionsUsed", []).append(PRINCIPLED_EXTENSION)
    text = json.dumps(doc, separators=(",", ":")).encode("utf-8")
    text += b" " * (-len(text) % 4)
    with open(glb, "wb") as f:
        f.write(struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(text) + len(rest)))
        f.write(struct.pack("<II", len(text), 0x4E4F534A))
        f.write(text)
        f.write(rest)


def materials(scene, problems):
    """The visible objects' materials: what glTF cannot carry of them (a surface that is not a
    Principled BSDF or an Emission, a volume, a displacement) added to `problems`, and the
    Principled BSDFs' factors returned, by material name."""
    seen = set()
    factors = {}
    for obj in scene.objects:
        if obj.type != "MESH" or not obj.visible_get():
            continue
        for slot in obj.material_slots:
            mat = slot.material
            if mat is None or mat.name in seen or not mat.use_nodes:
                continue
            seen.add(mat.name)
            node = _surface(mat)
            if node is not None and node.type not in ("BSDF_PRINCIPLED", "EMISSION"):
                problems.append("material %s: a %s surface (glTF carries the Principled "
                                "BSDF)" % (mat.name, node.bl_idname))
            principled = principled_factors(mat, problems)
            if principled is not None:
                factors[mat.name] = principled
            out = next((n for n in mat.node_tree.nodes
                        if n.type == "OUTPUT_MATERIAL" and n.is_active_output), None)
            for socket in ("Volume", "Displacement"):
                if out is not None and out.inputs[socket].is_linked:
                    problems.append("material %s: a %s" % (mat.name, socket.lower()))
    return factors


def export(scene, directory, settings):
    """Writes scene.glb and scene.yaml into `directory`; returns (yaml path, width, height,
    problems)."""
    problems = []
    render = scene.render
    width = int(render.resolution_x * render.resolution_percentage / 100)
    height = int(render.resolution_y * render.resolution_percentage / 100)
    glb = os.path.join(directory, "scene.glb")
    try:
        import warnings
        import numpy as np
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            if not hasattr(np, "bool"):
                np.bool = bool  # Blender 3.4's glTF add-on on NumPy 1.24 and later
    except ImportError:
        pass
    # A render engine's context is a render's, without the window, view layer and active object
    # the exporter asks for: give it the first window's and the scene's.
    view_layer = scene.view_layers[0]
    windows = bpy.context.window_manager.windows
    override = dict(scene=scene, view_layer=view_layer, active_object=view_layer.objects.active,
                    selected_objects=[], object=view_layer.objects.active)
    if windows:
        override["window"] = windows[0]
    with bpy.context.temp_override(**override):
        bpy.ops.export_scene.gltf(filepath=glb, export_format="GLB", export_cameras=False,
                                  export_lights=False, export_apply=True, export_yup=True,
                                  use_visible=True)
    lines = ["# Written by the Spillway add-on for Blender: the scene %s." % scene.name,
             "image: {width: %d, height: %d}" % (width, height),
             "settings: {max depth: %d, seed: %d}" % (settings.max_depth, settings.seed)]
    lines += camera_yaml(scene, width, height, problems)
    lines.append("filter: {type: %s}" % settings.filter)
    lines.append("objects:")
    lines.append("  - {type: Gltf, filename: %s}" % json.dumps(os.path.basename(glb)))
    lights = []
    for obj in scene.objects:
        if obj.type == "LIGHT" and obj.visible_get():
            entry = light_yaml(obj, problems)
            if entry:
                lights.append(entry)
        elif obj.type == "VOLUME":
            problems.append("volume %s" % obj.name)
    add_principled_extension(glb, materials(scene, problems))
    environment = world_yaml(scene, directory, problems)
    if environment:
        lights.append(environment)
    if lights:
        lines.append("lights:")
        lines += lights
    path = os.path.join(directory, "scene.yaml")
    with open(path, "w", encoding="utf-8") as f:
        f.write("\n".join(lines) + "\n")
    return path, width, height, problems
