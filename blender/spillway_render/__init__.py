"""Spillway as a Blender render engine (Blender 3.4).

Render (F12, or `blender -b FILE.blend -E SPILLWAY -f 1`) writes the scene as Spillway reads it
(scene_export.py: a glTF file of the meshes and materials, and a YAML scene that places it with
the camera, the lights, the world and the settings glTF drops), runs the `spillway` binary the
add-on's preferences name as a child process, and puts its EXR into the render result: the
image, and the passes asked for (Denoising Albedo, Normal, Depth) as Blender passes. Progress
(`--progress lines`) drives Blender's progress bar; the image is shown as it converges (from
the render's checkpoint, written every two seconds; not with passes, which a checkpoint does
not keep yet, so the image then shows at the end); Esc stops the render as Ctrl-C does, and
the work so far is kept and shown. What the export cannot carry is reported by name in the info
bar; an error from Spillway is Blender's error report, with Spillway's message.

Installed by scripts/install-blender-addon.sh. The settings are in the Render properties.
"""
import os
import re
import shutil
import signal
import subprocess
import tempfile
import threading
import time

import bpy
from bpy.props import EnumProperty, FloatProperty, IntProperty, PointerProperty, StringProperty

from . import scene_export

bl_info = {
    "name": "Spillway",
    "description": "Renders with Spillway, the sorted-deferred path tracer",
    "blender": (3, 4, 0),
    "version": (0, 1, 0),
    "location": "Render properties > Render Engine > Spillway",
    "category": "Render",
}

# The passes Spillway writes (--aov) and the Blender pass each becomes: (aov, EXR layer, Blender
# pass, channels, channel ids).
PASSES = (
    ("albedo", "Denoising Albedo", "Denoising Albedo", 3, "RGB"),
    ("normal", "Normal", "Normal", 3, "XYZ"),
    ("depth", "Depth", "Depth", 1, "Z"),
)


def binary_path(context):
    """The spillway binary: $SPILLWAY_BINARY, else the preferences', else the one on PATH."""
    if os.environ.get("SPILLWAY_BINARY"):
        return os.environ["SPILLWAY_BINARY"]
    addon = context.preferences.addons.get(__name__)
    if addon and addon.preferences.binary:
        return bpy.path.abspath(addon.preferences.binary)
    return shutil.which("spillway") or ""


class SpillwayPreferences(bpy.types.AddonPreferences):
    bl_idname = __name__
    binary: StringProperty(name="spillway binary", subtype="FILE_PATH",
                           description="The spillway executable: a build tree's build/spillway "
                           "or a release's bin/spillway (empty: the one on PATH)")

    def draw(self, context):
        self.layout.prop(self, "binary")


class SpillwaySettings(bpy.types.PropertyGroup):
    stop: EnumProperty(name="Stop", default="SAMPLES", items=(
        ("SAMPLES", "Samples", "Render a number of samples per pixel"),
        ("TARGET", "Target error", "Render until the relMSE estimate over the pixels that hold "
         "noise reaches the target"),
        ("TIME", "Time limit", "Render until the time limit")))
    samples: IntProperty(name="Samples", default=64, min=1, max=1 << 20)
    target_error: FloatProperty(name="Target error", default=2e-3, min=1e-9, max=1.0,
                                precision=5)
    max_samples: IntProperty(name="Max samples", default=1024, min=1, max=1 << 20,
                             description="The most samples a target error or time limit takes")
    time_limit: FloatProperty(name="Time limit", default=60.0, min=0.001, subtype="TIME_ABSOLUTE")
    max_depth: IntProperty(name="Max depth", default=12, min=1, max=1024)
    backend: EnumProperty(name="Backend", default="auto", items=(
        ("auto", "Auto", "A real GPU where one is usable, else the cpu backend"),
        ("cpu", "CPU", "The sorted pipeline, shading in C++"),
        ("vulkan", "Vulkan", "The sorted pipeline, shading in Vulkan compute"),
        ("reference", "Reference", "The depth-first path tracer")))
    seed: IntProperty(name="Seed", default=0, min=0)
    filter: EnumProperty(name="Filter", default="Gaussian", items=(
        ("Box", "Box", "Each sample in its own pixel"),
        ("Tent", "Tent", "A tent of radius 1 pixel"),
        ("Gaussian", "Gaussian", "A Gaussian of radius 1.5 pixels")))


def command(binary, yaml, out, settings, passes, checkpoint):
    """The spillway command line of a render."""
    cmd = [binary, "render", yaml, "-o", out, "--progress", "lines", "--backend", settings.backend]
    if not passes:  # a checkpoint keeps no passes: with them, the image shows at the end only
        cmd += ["--checkpoint", checkpoint, "--checkpoint-interval", "2"]
    if settings.stop == "SAMPLES":
        cmd += ["--spp", str(settings.samples)]
    elif settings.stop == "TARGET":
        cmd += ["--target-error", repr(settings.target_error), "--spp", str(settings.max_samples)]
    else:
        cmd += ["--time-limit", repr(settings.time_limit), "--spp", str(settings.max_samples)]
    if passes:
        cmd += ["--aov", ",".join(passes)]
    return cmd


# `--progress lines`: "... N/M spp ..." per iteration.
PROGRESS = re.compile(r"(\d+)/(\d+) spp")


class SpillwayRenderEngine(bpy.types.RenderEngine):
    bl_idname = "SPILLWAY"
    bl_label = "Spillway"
    bl_use_preview = False
    bl_use_postprocess = True

    def update_render_passes(self, scene=None, renderlayer=None):
        self.register_pass(scene, renderlayer, "Combined", 4, "RGBA", "COLOR")
        for _, _, name, channels, chanid in PASSES:
            if self._pass_enabled(renderlayer, name):
                self.register_pass(scene, renderlayer, name, channels, chanid,
                                   "VECTOR" if channels == 3 and name == "Normal" else
                                   "COLOR" if channels == 3 else "VALUE")

    @staticmethod
    def _pass_enabled(layer, name):
        if name == "Denoising Albedo":
            return getattr(layer.cycles, "denoising_store_passes", False) if hasattr(layer, "cycles") else False
        if name == "Normal":
            return layer.use_pass_normal
        return layer.use_pass_z

    def render(self, depsgraph):
        scene = depsgraph.scene
        settings = scene.spillway
        binary = binary_path(bpy.context)
        if not binary or not os.access(binary, os.X_OK):
            self.report({"ERROR"}, "Spillway: no spillway binary (set it in the add-on's "
                        "preferences; now '%s')" % binary)
            return
        directory = tempfile.mkdtemp(prefix="spillway-blender-")
        try:
            self._render(scene, settings, binary, directory)
        finally:
            # $SPILLWAY_KEEP_EXPORT: a folder to keep what was exported in (scene.yaml, scene.glb),
            # to render it again by hand.
            keep = os.environ.get("SPILLWAY_KEEP_EXPORT")
            if keep:
                os.makedirs(keep, exist_ok=True)
                for name in os.listdir(directory):
                    if name.endswith((".yaml", ".glb")) or name == "environment.exr":
                        shutil.copy(os.path.join(directory, name), keep)
            shutil.rmtree(directory, ignore_errors=True)

    def _render(self, scene, settings, binary, directory):
        yaml, width, height, problems = scene_export.export(scene, directory, settings)
        for p in problems:
            self.report({"WARNING"}, "Spillway cannot carry: " + p)
        layer = scene.view_layers[0]
        passes = [aov for aov, _, name, _, _ in PASSES if self._pass_enabled(layer, name)]
        out = os.path.join(directory, "image.exr")
        checkpoint = os.path.join(directory, "checkpoint.exr")
        cmd = command(binary, yaml, out, settings, passes, checkpoint)
        child = subprocess.Popen(cmd, stderr=subprocess.PIPE, stdout=subprocess.DEVNULL,
                                 text=True, bufsize=1)
        messages = []
        reader = threading.Thread(target=lambda: messages.extend(iter(child.stderr.readline, "")))
        reader.start()
        read, shown, stopping = 0, 0.0, False
        while child.poll() is None:
            for line in messages[read:]:
                m = PROGRESS.search(line)
                if m and int(m.group(2)) > 0:
                    self._progress(min(1.0, int(m.group(1)) / int(m.group(2))))
            read = len(messages)
            if self._stop_requested() and not stopping:
                child.send_signal(signal.SIGINT)  # as Ctrl-C: the iterations so far are kept
                stopping = True
            if os.path.exists(checkpoint) and os.path.getmtime(checkpoint) > shown:
                shown = os.path.getmtime(checkpoint)
                self._show(checkpoint, directory, width, height, ())
            time.sleep(0.05)
        reader.join()
        if not os.path.exists(out):
            said = [m.rstrip() for m in messages if m.startswith("spillway:")]
            text = " / ".join(said) if said else "".join(messages).strip()
            self.report({"ERROR"}, "Spillway failed (exit %d): %s" % (child.returncode, text))
            return
        self._show(out, directory, width, height, passes)

    # Blender's progress bar and Esc, behind methods of the add-on's own (Blender's own methods
    # cannot be replaced on an engine: the add-on's test replaces these to press Esc).
    def _progress(self, fraction):
        self.update_progress(fraction)

    def _stop_requested(self):
        return self.test_break()

    def _show(self, exr, directory, width, height, passes):
        """The EXR `exr` into the render result: its image as Combined, and the passes named
        (Spillway's EXR layers), each taken out into an EXR of its own by oiiotool
        (OpenImageIO's, which Spillway's dependencies bring) and read by Blender."""
        result = self.begin_result(0, 0, width, height)
        try:
            layer = result.layers[0]
            layer.passes["Combined"].rect = self._channels(exr, directory, "R,G,B", 4,
                                                           width * height)
            for aov, exr_layer, name, n, chanid in PASSES:
                if aov in passes and name in layer.passes:
                    chans = ",".join("%s.%s" % (exr_layer, c) for c in chanid)
                    rows = self._channels(exr, directory, chans, n, width * height)
                    if name == "Normal":  # Spillway's is glTF's world, +Y up; Blender's +Z up
                        rows = [(x, -z, y) for x, y, z in rows]
                    layer.passes[name].rect = rows
        finally:
            self.end_result(result)

    @staticmethod
    def _channels(exr, directory, channels, n, pixels):
        """`channels` of `exr` (comma-separated) as `pixels` rows of n values, bottom row first
        (Blender's order); Combined (n = 4) takes alpha 1."""
        one = os.path.join(directory, "channels.exr")
        names = ",".join("RGB"[:channels.count(",") + 1])
        subprocess.run(["oiiotool", exr, "--ch", channels, "--chnames", names, "-o", one],
                       check=True, capture_output=True)
        image = bpy.data.images.load(one, check_existing=False)
        try:
            rgba = image.pixels[:]
            c = image.channels
        finally:
            bpy.data.images.remove(image)
        rows = []
        for i in range(pixels):
            v = rgba[i * c:i * c + 3]
            rows.append((v[0], v[1], v[2], 1.0) if n == 4 else tuple(v[:n]))
        return rows


class RENDER_PT_spillway(bpy.types.Panel):
    bl_label = "Spillway"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"
    COMPAT_ENGINES = {"SPILLWAY"}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES

    def draw(self, context):
        s = context.scene.spillway
        col = self.layout.column()
        col.use_property_split = True
        col.prop(s, "stop")
        if s.stop == "SAMPLES":
            col.prop(s, "samples")
        elif s.stop == "TARGET":
            col.prop(s, "target_error")
            col.prop(s, "max_samples")
        else:
            col.prop(s, "time_limit")
            col.prop(s, "max_samples")
        col.prop(s, "max_depth")
        col.prop(s, "backend")
        col.prop(s, "seed")
        col.prop(s, "filter")


def _panels():
    """Blender's own panels that apply to this engine: output, dimensions, passes."""
    wanted = ("RENDER_PT_format", "RENDER_PT_output", "RENDER_PT_color_management",
              "VIEWLAYER_PT_layer_passes", "VIEWLAYER_PT_layer_passes_data", "DATA_PT_camera_dof",
              "DATA_PT_lens", "DATA_PT_light", "DATA_PT_EEVEE_light", "WORLD_PT_context_world")
    return [getattr(bpy.types, n) for n in wanted if hasattr(bpy.types, n)]


CLASSES = (SpillwayPreferences, SpillwaySettings, SpillwayRenderEngine, RENDER_PT_spillway)


def register():
    for c in CLASSES:
        bpy.utils.register_class(c)
    bpy.types.Scene.spillway = PointerProperty(type=SpillwaySettings)
    for p in _panels():
        p.COMPAT_ENGINES.add("SPILLWAY")


def unregister():
    for p in _panels():
        p.COMPAT_ENGINES.discard("SPILLWAY")
    del bpy.types.Scene.spillway
    for c in reversed(CLASSES):
        bpy.utils.unregister_class(c)
