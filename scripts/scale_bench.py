"""`scripts/bench.py scale`: production-shaped glTF scenes at increasing sizes, rendered by
Spillway and, where Blender is installed, by Cycles on the same file.

The scenes, written here as .glb files (numpy makes their arrays):
  - forest-N: one tree of T triangles (a noisy sphere of leaves on a trunk) placed by N glTF
    nodes, each turned and scaled, on a ground quad under a sun (glTF's instancing: every node
    names the one mesh);
  - unique-M: one mesh of M triangles of its own (a displaced grid), under the same sun;
  - lanterns-N: N trees of 2,000 triangles, each with an emissive lantern of 176 beside it (a
    second mesh the N nodes name: its triangles are lights at every placement);
  - textures-K-S: K quads, each with its own material whose base colour is an S x S PNG
    embedded in the file (noise: it compresses as badly as photographs do);
  - uris-K-S: the same as a .gltf, each image written out in the JSON as a data: URI and the
    buffer too (as Blender's "glTF Embedded" format writes a scene).
Each is rendered at 320x240, 16 spp, 2 threads, `--backend cpu` (Spillway; the textures scenes
under `--texture-cache 64`) and by Blender's
Cycles (its glTF importer, scripts/cycles_compare.py's settings, 16 samples, 2 threads). The
table gives, per renderer, the seconds to load the scene, to build the BVH, to render, the
whole process's wall seconds and its peak resident memory (wait4's ru_maxrss), and Spillway's
bytes of peak memory per instance and per triangle. Cycles' load is Blender's whole process less
its render call (Blender's start and its glTF importer).

--quick: small counts, no Cycles; it checks that the benchmark runs (the suite's
Bench.ScaleQuickRuns). Writes out/bench/scale.json.
"""
import base64
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import zlib
import struct

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cycles_compare as cc  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
WIDTH, HEIGHT, SPP, THREADS = 320, 240, 16, 2
TEXTURE_CACHE_MIB = 64  # Spillway's --texture-cache for the textures-K-S scenes


# --- scenes -----------------------------------------------------------------------------------

class Glb:
    """A .glb built from numpy arrays: one buffer, a view and an accessor per array."""

    def __init__(self):
        self.doc = {"asset": {"version": "2.0"}, "scene": 0, "nodes": [], "meshes": [],
                    "accessors": [], "bufferViews": [], "materials": []}
        self.chunks, self.size = [], 0

    def view(self, data):
        pad = -self.size % 4
        if pad:
            self.chunks.append(b"\0" * pad)
            self.size += pad
        self.doc["bufferViews"].append({"buffer": 0, "byteOffset": self.size,
                                        "byteLength": len(data)})
        self.chunks.append(data)
        self.size += len(data)
        return len(self.doc["bufferViews"]) - 1

    def accessor(self, array, kind, ctype):
        a = {"bufferView": self.view(array.tobytes()), "componentType": ctype,
             "count": int(array.shape[0]), "type": kind}
        if kind == "VEC3" and ctype == 5126:
            a["min"] = array.min(axis=0).tolist()
            a["max"] = array.max(axis=0).tolist()
        self.doc["accessors"].append(a)
        return len(self.doc["accessors"]) - 1

    def mesh(self, pos, nor, idx, material, uv=None):
        attributes = {"POSITION": self.accessor(pos.astype(np.float32), "VEC3", 5126),
                      "NORMAL": self.accessor(nor.astype(np.float32), "VEC3", 5126)}
        if uv is not None:
            attributes["TEXCOORD_0"] = self.accessor(uv.astype(np.float32), "VEC2", 5126)
        prim = {"attributes": attributes, "material": material,
                "indices": self.accessor(idx.astype(np.uint32).reshape(-1), "SCALAR", 5125)}
        self.doc["meshes"].append({"primitives": [prim]})
        return len(self.doc["meshes"]) - 1

    def material(self, colour, roughness=0.8, image=None, uri=False):
        m = {"pbrMetallicRoughness": {"baseColorFactor": list(colour) + [1.0],
                                      "metallicFactor": 0.0, "roughnessFactor": roughness}}
        if image is not None:
            self.doc.setdefault("images", []).append(
                {"uri": "data:image/png;base64," + base64.b64encode(image).decode()} if uri else
                {"bufferView": self.view(image), "mimeType": "image/png"})
            self.doc.setdefault("textures", []).append({"source": len(self.doc["images"]) - 1})
            m["pbrMetallicRoughness"]["baseColorTexture"] = {"index": len(self.doc["textures"]) - 1}
        self.doc["materials"].append(m)
        return len(self.doc["materials"]) - 1

    def node(self, **n):
        self.doc["nodes"].append(n)
        return len(self.doc["nodes"]) - 1

    def camera_and_sun(self, eye, pitch):
        """A camera at `eye` looking down by `pitch` radians along -Z, and a sun from above."""
        self.doc["cameras"] = [{"type": "perspective", "perspective": {
            "yfov": 0.7, "aspectRatio": WIDTH / HEIGHT, "znear": 0.05}}]
        self.node(camera=0, translation=list(eye),
                  rotation=[-np.sin(pitch / 2), 0.0, 0.0, np.cos(pitch / 2)])
        self.doc["extensionsUsed"] = ["KHR_lights_punctual"]
        self.doc["extensions"] = {"KHR_lights_punctual": {"lights": [
            {"type": "directional", "intensity": 3.0 * 683.0}]}}
        a = -0.6
        self.node(rotation=[np.sin(a / 2), 0.0, 0.0, np.cos(a / 2)],
                  extensions={"KHR_lights_punctual": {"light": 0}})

    def write_gltf(self, path):
        """As a .gltf, its buffer a data: URI (as Blender's "glTF Embedded" writes one)."""
        self.doc["scenes"] = [{"nodes": list(range(len(self.doc["nodes"])))}]
        data = base64.b64encode(b"".join(self.chunks)).decode()
        self.doc["buffers"] = [{"byteLength": self.size,
                                "uri": "data:application/octet-stream;base64," + data}]
        with open(path, "w") as f:
            json.dump(self.doc, f)

    def write(self, path):
        if path.endswith(".gltf"):
            return self.write_gltf(path)
        self.doc["scenes"] = [{"nodes": list(range(len(self.doc["nodes"])))}]
        self.doc["buffers"] = [{"byteLength": self.size}]
        text = json.dumps(self.doc).encode()
        text += b" " * (-len(text) % 4)
        pad = b"\0" * (-self.size % 4)
        with open(path, "wb") as f:
            f.write(struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(text) + 8 + self.size + len(pad)))
            f.write(struct.pack("<II", len(text), 0x4E4F534A) + text)
            f.write(struct.pack("<II", self.size + len(pad), 0x004E4942))
            for c in self.chunks:
                f.write(c)
            f.write(pad)


def grid(n, size, height, rng):
    """An n x n grid of quads over [-size, size]^2 in y = 0, displaced up by noise."""
    x, z = np.meshgrid(np.linspace(-size, size, n + 1), np.linspace(-size, size, n + 1))
    y = height * rng.random(x.shape)
    pos = np.stack([x, y, z], axis=-1).reshape(-1, 3)
    nor = np.tile([0.0, 1.0, 0.0], (pos.shape[0], 1))
    i = np.arange(n)
    a = (i[:, None] * (n + 1) + i[None, :]).reshape(-1)
    b, c, d = a + 1, a + n + 1, a + n + 2
    idx = np.concatenate([np.stack([a, c, b], 1), np.stack([b, c, d], 1)])
    return pos, nor, idx


def tree(triangles, rng):
    """About `triangles` triangles: a crown (a sphere, its vertices pushed out by noise) on a
    trunk (an open cylinder of 32 triangles)."""
    rings = max(4, int(np.sqrt((triangles - 32) / 4)))
    segs = 2 * rings
    t = np.linspace(0, np.pi, rings + 1)[:, None]
    p = np.linspace(0, 2 * np.pi, segs + 1)[None, :]
    n = np.stack([np.sin(t) * np.cos(p), np.cos(t) * np.ones_like(p), np.sin(t) * np.sin(p)], -1)
    n = n.reshape(-1, 3)
    pos = n * (1.0 + 0.15 * rng.random((n.shape[0], 1))) + [0.0, 2.0, 0.0]
    r, s = np.meshgrid(np.arange(rings), np.arange(segs), indexing="ij")
    a = (r * (segs + 1) + s).reshape(-1)
    idx = np.concatenate([np.stack([a, a + segs + 1, a + 1], 1),
                          np.stack([a + 1, a + segs + 1, a + segs + 2], 1)])
    k = np.arange(17) * 2 * np.pi / 16
    ring = np.stack([0.15 * np.cos(k), np.zeros_like(k), 0.15 * np.sin(k)], -1)
    trunk = np.concatenate([ring, ring + [0.0, 1.2, 0.0]])
    tn = np.concatenate([ring, ring]) / 0.15
    j = np.arange(16)
    tidx = np.concatenate([np.stack([j, j + 17, j + 1], 1), np.stack([j + 1, j + 17, j + 18], 1)])
    return (np.concatenate([pos, trunk]), np.concatenate([n, tn]),
            np.concatenate([idx, tidx + pos.shape[0]]))


def forest(path, count, triangles):
    rng = np.random.default_rng(1)
    g = Glb()
    leaf, soil = g.material((0.2, 0.5, 0.15)), g.material((0.4, 0.3, 0.2))
    side = int(np.ceil(np.sqrt(count)))
    spacing = 3.0
    half = spacing * side / 2
    gp, gn, gi = grid(1, half + 4, 0.0, rng)
    g.node(mesh=g.mesh(gp, gn, gi, soil))
    one = g.mesh(*tree(triangles, rng), leaf)
    for k in range(count):
        x, z = (k % side) * spacing - half, (k // side) * spacing - half
        a = rng.random() * np.pi
        s = 0.8 + 0.4 * rng.random()
        g.node(mesh=one, translation=[x, 0.0, z], scale=[s, s, s],
               rotation=[0.0, float(np.sin(a / 2)), 0.0, float(np.cos(a / 2))])
    g.camera_and_sun((0.0, 0.6 * half + 6.0, half + 8.0), 0.5)
    g.write(path)
    return {"instances": count, "triangles": count * len(tree(triangles, np.random.default_rng(1))[2])}


def lanterns(path, count, triangles):
    """forest-N's trees (of 2,000 triangles) with an emissive lantern of `triangles` beside each:
    a mesh of its own, placed by N nodes too, whose every triangle is a light at every placement."""
    rng = np.random.default_rng(4)
    g = Glb()
    leaf, soil = g.material((0.2, 0.5, 0.15)), g.material((0.4, 0.3, 0.2))
    glow = g.material((0.9, 0.8, 0.6))
    g.doc["materials"][glow]["emissiveFactor"] = [1.0, 0.8, 0.5]
    side = int(np.ceil(np.sqrt(count)))
    spacing = 3.0
    half = spacing * side / 2
    gp, gn, gi = grid(1, half + 4, 0.0, rng)
    g.node(mesh=g.mesh(gp, gn, gi, soil))
    one = g.mesh(*tree(2000, rng), leaf)
    lantern = g.mesh(*tree(triangles, rng), glow)
    emitters = len(tree(triangles, np.random.default_rng(4))[2])
    for k in range(count):
        x, z = (k % side) * spacing - half, (k // side) * spacing - half
        g.node(mesh=one, translation=[x, 0.0, z])
        g.node(mesh=lantern, translation=[x + 1.2, 0.0, z + 0.4], scale=[0.2, 0.2, 0.2])
    g.camera_and_sun((0.0, 0.6 * half + 6.0, half + 8.0), 0.5)
    g.write(path)
    return {"instances": 2 * count, "triangles": count * (2000 + emitters), "emitters": count * emitters}


def unique(path, triangles):
    rng = np.random.default_rng(2)
    g = Glb()
    n = max(1, int(np.sqrt(triangles / 2)))
    pos, nor, idx = grid(n, 10.0, 0.3, rng)
    g.node(mesh=g.mesh(pos, nor, idx, g.material((0.6, 0.6, 0.6))))
    g.camera_and_sun((0.0, 8.0, 16.0), 0.5)
    g.write(path)
    return {"instances": 0, "triangles": int(idx.shape[0])}


def noise_png(size, rng):
    rows = rng.integers(0, 256, (size, 3 * size + 1), dtype=np.uint8)
    rows[:, 0] = 0

    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data +
                struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))
    header = struct.pack(">IIBBBBB", size, size, 8, 2, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) +
            chunk(b"IDAT", zlib.compress(rows.tobytes(), 1)) + chunk(b"IEND", b""))


def textures(path, count, size, uri=False):
    """`count` quads, each with its own `size`^2 PNG of noise: in the .glb's buffer, or (uri)
    written out in a .gltf as data: URIs."""
    rng = np.random.default_rng(3)
    g = Glb()
    side = int(np.ceil(np.sqrt(count)))
    pos = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float) * 0.9
    nor = np.tile([0.0, 0.0, 1.0], (4, 1))
    uv = np.array([[0, 1], [1, 1], [1, 0], [0, 0]], float)
    idx = np.array([[0, 1, 2], [0, 2, 3]])
    for k in range(count):
        material = g.material((1.0, 1.0, 1.0), image=noise_png(size, rng), uri=uri)
        m = g.mesh(pos, nor, idx, material, uv)
        g.node(mesh=m, translation=[k % side - side / 2, k // side - side / 2, 0.0])
    g.camera_and_sun((0.0, 0.0, 1.3 * side + 1.0), 0.0)
    g.write(path)
    return {"instances": 0, "triangles": 2 * count, "texels": count * size * size}


def scenes(quick):
    if quick:
        return [("forest-10", forest, (10, 2000)), ("forest-100", forest, (100, 2000)),
                ("unique-20k", unique, (20000,)), ("lanterns-100", lanterns, (100, 200)),
                ("textures-4-256", textures, (4, 256)),
                ("uris-4-256", textures, (4, 256, True))]
    return [("forest-100", forest, (100, 20000)), ("forest-1000", forest, (1000, 20000)),
            ("forest-10000", forest, (10000, 20000)), ("forest-100000", forest, (100000, 20000)),
            ("unique-1M", unique, (1_000_000,)), ("unique-5M", unique, (5_000_000,)),
            ("unique-20M", unique, (20_000_000,)), ("forest-1000000", forest, (1_000_000, 20000)),
            ("lanterns-10000", lanterns, (10000, 200)), ("lanterns-100000", lanterns, (100000, 200)),
            ("textures-64-2048", textures, (64, 2048)), ("textures-256-2048", textures, (256, 2048)),
            ("textures-64-4096", textures, (64, 4096)), ("uris-64-2048", textures, (64, 2048, True))]


# --- renders ----------------------------------------------------------------------------------

def timed(cmd, env=None):
    """Runs cmd; returns (exit status, wall seconds, peak RSS MiB, output tail)."""
    start = time.perf_counter()
    with tempfile.TemporaryFile() as log:
        p = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, env=env)
        _, status, ru = os.wait4(p.pid, 0)
        log.seek(0)
        tail = log.read()[-2000:].decode(errors="replace")
    return os.waitstatus_to_exitcode(status), time.perf_counter() - start, ru.ru_maxrss / 1024, tail


def spillway_row(spillway, glb, folder, extra=()):
    stats = os.path.join(folder, "stats.json")
    status, wall, rss, tail = timed([spillway, "render", glb, "--backend", "cpu", "--spp", str(SPP),
                                     "--threads", str(THREADS), "--width", str(WIDTH), "--quiet",
                                     "-o", os.path.join(folder, "spillway.exr"), "--stats", stats,
                                     *extra])
    if status != 0:
        return {"failed": tail.strip().splitlines()[-1] if tail.strip() else "exit %d" % status,
                "wall_seconds": wall, "peak_rss_mib": rss}
    with open(stats) as f:
        s = json.load(f)
    stages = s["stage_seconds"]
    return {"load_seconds": stages.get("load scene", 0.0), "bvh_seconds": stages.get("build bvh", 0.0),
            "render_seconds": s["render_seconds"], "wall_seconds": wall, "peak_rss_mib": rss,
            # Loading, then the session's work before its first iteration (BVH, lights, images).
            "first_ray_seconds": stages.get("load scene", 0.0) + s["wall_seconds"] - s["render_seconds"],
            "geometry": s.get("geometry", {})}


def cycles_row(glb, folder):
    out, seconds = os.path.join(folder, "cycles.exr"), os.path.join(folder, "cycles-seconds.json")
    args = {"file": os.path.abspath(glb), "width": WIDTH, "height": HEIGHT,
            "fov_x": cc.horizontal_fov(glb), "lit": True, "threads": THREADS, "seconds": seconds,
            "renders": [{"spp": SPP, "out": out}], "environment": None}
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PYTHON", "PYENV", "VIRTUAL_ENV"))}
    env["PATH"] = "/usr/bin:/bin:" + env.get("PATH", "")
    status, wall, rss, tail = timed([shutil.which("blender"), "-b", "--factory-startup",
                                     "--python-exit-code", "1", "--python-expr", cc.BLENDER_SCRIPT,
                                     "--", json.dumps(args)], env=env)
    if status != 0 or not os.path.exists(seconds):
        return {"failed": "exit %d" % status, "wall_seconds": wall, "peak_rss_mib": rss}
    with open(seconds) as f:
        render = json.load(f)[0]
    return {"load_seconds": wall - render, "render_seconds": render, "wall_seconds": wall,
            "peak_rss_mib": rss}


def print_row(name, who, r):
    if "failed" in r:
        print("%-18s %-9s failed after %.1f s at %.0f MiB: %s" % (
            name, who, r["wall_seconds"], r["peak_rss_mib"], r["failed"]))
        return
    print("%-18s %-9s load %7.2f  bvh %7.2f  first ray %7.2f  render %7.2f  wall %7.2f  "
          "peak %8.0f MiB" % (
              name, who, r["load_seconds"], r.get("bvh_seconds", float("nan")),
              r.get("first_ray_seconds", float("nan")), r["render_seconds"], r["wall_seconds"],
              r["peak_rss_mib"]))


def print_costs(rows):
    """Spillway's peak memory per instance (the growth from one forest to the next, over the
    instances added) and per triangle (the whole peak over the unique triangles)."""
    ok = [r for r in rows if "failed" not in r["spillway"]]
    forests = [r for r in ok if r["instances"]]
    for a, b in zip(forests, forests[1:]):
        grow = (b["spillway"]["peak_rss_mib"] - a["spillway"]["peak_rss_mib"]) * 2 ** 20
        b["bytes_per_instance"] = grow / (b["instances"] - a["instances"])
        print("%-18s spillway  %.0f bytes of peak memory per instance added" % (
            b["scene"], b["bytes_per_instance"]))
    for r in ok:
        if r["scene"].startswith("unique"):
            r["bytes_per_triangle"] = r["spillway"]["peak_rss_mib"] * 2 ** 20 / r["triangles"]
            print("%-18s spillway  %.0f bytes of peak memory per triangle, all told" % (
                r["scene"], r["bytes_per_triangle"]))


def make_apart(name, path, quick):
    """Scene `name` written to `path` by a Python process of its own, whose info it returns. A
    child's peak RSS starts from its parent's at the fork (Linux keeps it through exec): made
    here, a million nodes' Python objects would count in every render's figure."""
    r = subprocess.run([sys.executable, os.path.abspath(__file__), name, path, str(int(quick))],
                       capture_output=True, text=True, check=True)
    return json.loads(r.stdout)


def main(spillway, quick, only=(), cycles=True):
    with_cycles = cycles and not quick and shutil.which("blender") is not None
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for name, _, _ in scenes(quick):
            if only and name not in only:
                continue
            glb = os.path.join(folder, name + (".gltf" if name.startswith("uris-") else ".glb"))
            info = make_apart(name, glb, quick)
            info["file_mib"] = os.path.getsize(glb) / 2 ** 20
            # Textures under a budget far below their texels: the cache's, not the images'.
            extra = ("--texture-cache", str(TEXTURE_CACHE_MIB)) if "texels" in info else ()
            row = {"scene": name, **info, "spillway": spillway_row(spillway, glb, folder, extra)}
            print_row(name, "spillway", row["spillway"])
            if "failed" in row["spillway"] and quick:
                return 1
            if with_cycles:
                row["cycles"] = cycles_row(glb, folder)
                print_row(name, "cycles", row["cycles"])
            sys.stdout.flush()
            rows.append(row)
            os.remove(glb)
    print_costs(rows)
    os.makedirs(os.path.join(ROOT, "out", "bench"), exist_ok=True)
    with open(os.path.join(ROOT, "out", "bench", "scale-quick.json" if quick else "scale.json"), "w") as f:
        json.dump(rows, f, indent=2)
    return 0


if __name__ == "__main__":  # make_apart's child: scripts/scale_bench.py NAME PATH QUICK
    for scene, make, params in scenes(sys.argv[3] == "1"):
        if scene == sys.argv[1]:
            print(json.dumps(make(sys.argv[2], *params)))
            break
    else:
        sys.exit("no scene named " + sys.argv[1])
