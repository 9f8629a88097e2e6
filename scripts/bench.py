#!/usr/bin/python3
"""Spillway benchmarks. Every figure is measured in this run, and every backend's time is also
printed as a ratio to the reference backend's time measured in the same run (these machines
are noisy; ratios travel, absolute seconds do not).

  scripts/bench.py reference   Cornell box 256x256, 64 spp, reference backend: seconds, rays/s
  scripts/bench.py pipeline    cpu vs reference on the Cornell box and the 1M-triangle scene,
                               each ray sort and hit sort setting, peak RSS, spill traffic
  scripts/bench.py production  the thesis' Table 6.1 on this machine: the generated production
                               scene (scripts/make_production_scene.py, in out/production) with a
                               texture cache of 1/4 of its texture bytes; cpu at bin exponents
                               8, 11, 14, 17 and the reference, at max depth 1, 2, 3; vulkan at
                               2^17; the in-core control (Constant colours). Wall, user and system
                               seconds, peak RSS, texture tiles and bytes read, ratio to the
                               reference at the same depth; all of it twice, with
                               --texture-filter finest (the thesis' regime: every lookup at the
                               finest level) and cone (the default). Writes
                               out/production/bench.json.
  scripts/bench.py incore      in-core speed: the Cornell box at 64 and 256 spp, and at 64 spp
                               with a Tent and a Gaussian filter; the 1M-triangle scene; 64
                               shaders over layered image textures (the production generator at
                               an in-core size, out/incore-textured) and its Constant-colour
                               control; reference, cpu (fused stages, SIMD shading),
                               cpu with separate stages, cpu with scalar shading
                               (--simd-shading off), vulkan; runs alternate between configurations and
                               the best of N is kept. Per configuration: render seconds, ratio to
                               the reference, rays per second per core, and Embree's own rate on
                               the same rays (the cpu backend's traverse and shadow stages, which
                               do nothing but Embree calls), the share of the render in Embree,
                               and the stage seconds. --baseline PATH adds another build's
                               reference, cpu and vulkan (before/after in one run). Writes
                               out/bench/incore.json.
  scripts/bench.py mpi         distributed rendering: 1 process x 2 threads against mpirun -np 2
                               x 1 thread (--threads T: the process's; --ranks R1,R2,...: rank
                               counts, each rank with T/R threads or --threads-per-rank) on the
                               Cornell box (64 spp) and the 1M-triangle scene, cpu and reference;
                               alternating, best of N. Per configuration: the launch's wall time
                               (MPI start-up included), rank 0's render seconds, the seconds the
                               ranks spent in the film's reduction and in the agreements around
                               each iteration (waiting for the slowest rank, mostly; the most of
                               any rank), and the ratios to one process.
                               Writes out/bench/mpi.json.
  scripts/bench.py large       large images: the Cornell box at 4000x4000, 1 spp, on every
                               backend (and --baseline's): peak RSS above the same render at
                               16x16 (the fixed costs), in bytes per pixel; the seconds to write
                               the 16-Mpixel EXR; render and wall seconds. Best of N, alternating.
                               Writes out/bench/large.json.
  scripts/bench.py cycles      time to Cycles' error at 256 spp on five kinds of scene (the Cornell
                               box, a glossy box lit by a small light, a textured glTF file, 128
                               lamps, an environment map with a sun), each renderer against its
                               own 4096-spp reference: scripts/cycles_bench.py says how.
                               --backends cpu,reference (default), --scenes NAME,... (default
                               all; `holdout`: five of the same kinds laid out by other draws),
                               --quick (tiny, for the suite). Writes out/bench/cycles.json
                               (cycles-holdout.json).
  scripts/bench.py scale       production-shaped glTF scenes at increasing sizes (an instanced
                               forest, unique geometry, many embedded images), Spillway beside
                               Cycles on each file: load, BVH, render and wall seconds, peak RSS,
                               bytes per instance and per triangle (scripts/scale_bench.py says
                               how). --quick (small, no Cycles, for the suite), --scenes NAME,...,
                               --no-cycles.
                               Writes out/bench/scale.json.
  scripts/bench.py all         reference and pipeline (default)

Options: --repeat N (best of N, default 3; production: 1), --spillway PATH (default
build/spillway), --baseline PATH (incore, large), --depths 1,2,3 and --exponents 8,11,14,17 (production), --scene-args "..."
(production: options for make_production_scene.py).
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def run(spillway, scene, args, repeat):
    """Best-of-N render; returns (stats json, peak RSS MiB). The stats get "user_seconds" and
    "system_seconds" of the best run."""
    best, rss = None, 0
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(repeat):
            stats = os.path.join(tmp, "s.json")
            cmd = [spillway, "render", scene, "-o", os.path.join(tmp, "o.exr"), "--quiet", "--stats", stats] + args
            p = subprocess.Popen(cmd)
            _, status, ru = os.wait4(p.pid, 0)
            if status != 0:
                return None, 0
            s = json.load(open(stats))
            s["user_seconds"], s["system_seconds"] = ru.ru_utime, ru.ru_stime
            rss = max(rss, ru.ru_maxrss / 1024)
            if best is None or s["wall_seconds"] < best["wall_seconds"]:
                best = s
    return best, rss


def core_seconds(s):
    """Render time without start-up and output: the iterations' wall time (stage times can
    overlap, device work under host work, so they are not summed)."""
    return s["render_seconds"]


def bench_reference(spillway, repeat):
    scene = os.path.join(ROOT, "scenes", "cornell-box.yaml")
    s, rss = run(spillway, scene, ["--backend", "reference", "--spp", "64"], repeat)
    print("reference, Cornell box 256x256, 64 spp, %d threads on %s" % (s["threads"], s["device"]))
    print("  %.2f s wall, %.2f s rendering, %.1f M rays/s, peak RSS %.0f MiB" % (
        s["wall_seconds"], core_seconds(s), s["rays"]["total"] / core_seconds(s) / 1e6, rss))


def bench_pipeline(spillway, repeat):
    heavy = subprocess.check_output([sys.executable, os.path.join(ROOT, "scripts", "make_heavy_scene.py"),
                                     os.path.join(ROOT, "out", "heavy")], text=True).strip()
    scenes = [("Cornell box 256x256, 64 spp", os.path.join(ROOT, "scenes", "cornell-box.yaml"), ["--spp", "64"]),
              ("1M triangles, 17 shaders, 640x480, 16 spp", heavy, [])]
    configs = [("reference", ["--backend", "reference"]),
               ("cpu (auto sort)", ["--backend", "cpu"]),
               ("cpu, ray sort morton", ["--backend", "cpu", "--ray-sort", "morton"]),
               ("cpu, ray sort median", ["--backend", "cpu", "--ray-sort", "median"]),
               ("cpu, ray sort off", ["--backend", "cpu", "--ray-sort", "off"]),
               ("cpu, hit sort on", ["--backend", "cpu", "--hit-sort", "on"]),
               ("cpu, hit sort off", ["--backend", "cpu", "--hit-sort", "off"]),
               ("cpu, 1 MiB budget (spills)", ["--backend", "cpu", "--memory-budget", "1"]),
               ("vulkan (lavapipe or GPU)", ["--backend", "vulkan"]),
               ("vulkan, megakernel", ["--backend", "vulkan", "--shading", "megakernel"])]
    for title, scene, extra in scenes:
        print("\n%s" % title)
        print("  %-30s %8s %8s %9s %8s %9s %10s" % ("config", "wall s", "core s", "Mrays/s", "vs ref", "RSS MiB",
                                                  "spilled MB"))
        ref_core = None
        for name, args in configs:
            s, rss = run(spillway, scene, args + extra, repeat)
            if s is None:
                print("  %-30s (could not run here)" % name)
                continue
            core = core_seconds(s)
            ref_core = ref_core or core
            print("  %-30s %8.2f %8.2f %9.2f %7.2fx %9.0f %10.1f" % (
                name, s["wall_seconds"], core, s["rays"]["total"] / core / 1e6, core / ref_core, rss,
                s.get("bytes_spilled_written", 0) / 1e6))
            if name in ("cpu (auto sort)", "vulkan (lavapipe or GPU)"):
                stages = ", ".join("%s %.2f" % (k, v) for k, v in s["stage_seconds"].items())
                print("    stages: " + stages)
                print("    batches: %d processed, %d ray-sorted; device: %s" % (
                    s["batches_processed"], s["batches_ray_sorted"], s["device"]))


def embree_seconds(s):
    """The sorted backends' time in Embree: traversal, and the shadow stage (occlusion calls and
    the gathering of their rays)."""
    st = s["stage_seconds"]
    return st.get("traverse", 0.0) + st.get("shadow", 0.0)


def bench_incore(spillway, repeat, baseline):
    heavy = subprocess.check_output([sys.executable, os.path.join(ROOT, "scripts", "make_heavy_scene.py"),
                                     os.path.join(ROOT, "out", "heavy")], text=True).strip()
    box = os.path.join(ROOT, "scenes", "cornell-box.yaml")
    # The scenes users bring that the others miss: many shaders reading image textures (the
    # production generator's 64 models, each a Lambert or Conductor over a Layered tree of 7
    # tiled MIP-mapped images, at an in-core size, cone filter), its Constant-colour control, and
    # the Cornell box with a wide pixel filter.
    textured_dir = os.path.join(ROOT, "out", "incore-textured")
    subprocess.check_output([sys.executable, os.path.join(ROOT, "scripts", "make_production_scene.py"),
                             textured_dir, "--models", "64", "--triangles", "400000",
                             "--texture-res", "256", "--width", "320", "--height", "180",
                             "--spp", "16", "--max-depth", "2"], text=True)
    def with_filter(kind):
        path = os.path.join(ROOT, "out", "bench", "cornell-%s.yaml" % kind.lower())
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "w") as f:
            f.write(open(box).read().replace("filter: {type: Box}", "filter: {type: %s}" % kind)
                    .replace("filename: cornell-box/", "filename: %s/" % os.path.join(ROOT, "scenes", "cornell-box")))
        return path
    scenes = [("Cornell box 256x256, 64 spp", box, ["--spp", "64"]),
              ("Cornell box 256x256, 256 spp", box, ["--spp", "256"]),
              ("Cornell box 256x256, 64 spp, Tent filter", with_filter("Tent"), ["--spp", "64"]),
              ("Cornell box 256x256, 64 spp, Gaussian filter", with_filter("Gaussian"), ["--spp", "64"]),
              ("1M triangles, 17 shaders, 640x480, 16 spp", heavy, []),
              ("64 textured shaders (7 images each, 256^2), 320x180, 16 spp, depth 2",
               os.path.join(textured_dir, "scene.yaml"), []),
              ("the same, every image a Constant of its mean", os.path.join(textured_dir, "control.yaml"), [])]
    configs = [("reference", spillway, ["--backend", "reference"]),
               ("cpu", spillway, ["--backend", "cpu"]),
               ("cpu, separate stages", spillway, ["--backend", "cpu", "--stages", "separate"]),
               ("cpu, scalar shading", spillway, ["--backend", "cpu", "--simd-shading", "off"]),
               ("vulkan", spillway, ["--backend", "vulkan"])]
    if baseline:
        configs += [("baseline reference", baseline, ["--backend", "reference"]),
                    ("baseline cpu", baseline, ["--backend", "cpu"]),
                    ("baseline vulkan", baseline, ["--backend", "vulkan"])]
    results = []
    for title, scene, extra in scenes:
        best = {}
        for _ in range(repeat):  # alternate: every configuration once per round
            for name, binary, args in configs:
                s, rss = run(binary, scene, args + extra, 1)
                if s is not None and (name not in best or s["render_seconds"] < best[name]["render_seconds"]):
                    best[name] = s
        print("\n%s (best of %d, alternating)" % (title, repeat))
        print("  %-22s %8s %8s %14s %16s %8s" % ("config", "core s", "vs ref", "Mrays/s/core",
                                                 "Embree Mr/s/core", "Embree"))
        for name, _, _ in configs:
            if name not in best:
                print("  %-22s (could not run here)" % name)
                continue
            s = best[name]
            ref = best["baseline reference" if name.startswith("baseline") else "reference"]
            core, rays, threads = s["render_seconds"], s["rays"]["total"], s["threads"]
            emb = embree_seconds(s)
            raw = "%16.2f" % (rays / emb / threads / 1e6) if emb > 0 else "%16s" % "-"
            share = "%7.0f%%" % (100 * emb / core) if emb > 0 else "%8s" % "-"
            print("  %-22s %8.2f %7.2fx %14.2f %s %s" % (name, core, core / ref["render_seconds"],
                                                         rays / core / threads / 1e6, raw, share))
            if name != "reference" and name != "baseline reference":
                print("    stages: " + ", ".join("%s %.2f" % (k, v) for k, v in s["stage_seconds"].items()
                                                 if v >= 0.005))
            results.append({"scene": title, "config": name, "render_seconds": core,
                            "vs_reference": core / ref["render_seconds"], "rays": rays, "threads": threads,
                            "embree_seconds": emb, "device": s["device"], "stage_seconds": s["stage_seconds"]})
    folder = os.path.join(ROOT, "out", "bench")
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "incore.json"), "w") as f:
        json.dump(results, f, indent=1)


def with_depth(scene, depth):
    """A copy of a generated scene file beside it (its files are relative) with max depth set."""
    text = open(scene).read()
    text = re.sub(r"max depth: \d+", "max depth: %d" % depth, text)
    text = re.sub(r"min depth: \d+", "min depth: %d" % min(depth, 3), text)
    out = scene.replace(".yaml", "-d%d.yaml" % depth)
    with open(out, "w") as f:
        f.write(text)
    return out


def bench_production(spillway, repeat, depths, exponents, scene_args):
    folder = os.path.join(ROOT, "out", "production")
    made = subprocess.check_output([sys.executable, os.path.join(ROOT, "scripts", "make_production_scene.py"),
                                    folder] + scene_args, text=True).strip()
    print(made)
    texture_bytes = sum(os.path.getsize(os.path.join(folder, f)) for f in os.listdir(folder) if f.endswith(".tx"))
    geometry_bytes = sum(os.path.getsize(os.path.join(folder, f)) for f in os.listdir(folder) if f.endswith(".obj"))
    cache = texture_bytes / 4 / 2**20
    common = ["--texture-cache", "%.1f" % cache]
    print("textures %.0f MiB on disk, cache %.0f MiB (1/4); geometry %.0f MiB of OBJ text" % (
        texture_bytes / 2**20, cache, geometry_bytes / 2**20))
    header = "  %-26s %8s %8s %7s %7s %8s %9s %10s %10s %9s" % (
        "config", "wall s", "core s", "user s", "sys s", "vs ref", "RSS MiB", "tiles", "MB read", "B/ray")
    rows = []
    for texture_filter in ("finest", "cone"):
        print("\n== --texture-filter %s ==" % texture_filter)
        for depth in depths:
            scene = with_depth(os.path.join(folder, "scene.yaml"), depth)
            control = with_depth(os.path.join(folder, "control.yaml"), depth)
            top = str(max(exponents))
            configs = [("reference", scene, ["--backend", "reference"])]
            configs += [("cpu 2^%d" % e, scene, ["--backend", "cpu", "--bin-exponent", str(e)]) for e in exponents]
            configs += [("vulkan 2^" + top, scene, ["--backend", "vulkan", "--bin-exponent", top]),
                        ("control: reference", control, ["--backend", "reference"]),
                        ("control: cpu 2^" + top, control, ["--backend", "cpu", "--bin-exponent", top])]
            print("\nmax depth %d\n%s" % (depth, header))
            ref = None
            for name, path, args in configs:
                s, rss = run(spillway, path, args + common + ["--texture-filter", texture_filter], repeat)
                if s is None:
                    print("  %-26s (could not run here)" % name)
                    continue
                core = core_seconds(s)
                if name == "reference":
                    ref = core
                t = s.get("textures", {})
                rays = s["rays"]["total"]
                print("  %-26s %8.2f %8.2f %7.1f %7.1f %7.2fx %9.0f %10d %10.1f %9.1f" % (
                    name, s["wall_seconds"], core, s["user_seconds"], s["system_seconds"], core / ref, rss,
                    t.get("tiles_read", 0), t.get("bytes_read", 0) / 1e6, t.get("bytes_read", 0) / rays),
                    flush=True)
                if name.startswith("cpu") or name.startswith("vulkan"):
                    print("    stages: " + ", ".join("%s %.2f" % (k, v) for k, v in s["stage_seconds"].items()))
                rows.append({"filter": texture_filter, "depth": depth, "config": name,
                             "wall_seconds": s["wall_seconds"], "core_seconds": core,
                             "user_seconds": s["user_seconds"], "system_seconds": s["system_seconds"],
                             "vs_reference": core / ref, "peak_rss_mib": rss, "rays": rays, "textures": t,
                             "stage_seconds": s["stage_seconds"]})
    bound = 512 + cache + geometry_bytes / 2**20 + 200
    print("\npeak RSS bound: memory budget 512 + cache %.0f + geometry %.0f + 200 = %.0f MiB" % (
        cache, geometry_bytes / 2**20, bound))
    with open(os.path.join(folder, "bench.json"), "w") as f:
        json.dump({"texture_bytes": texture_bytes, "geometry_bytes": geometry_bytes, "cache_mib": cache,
                   "rss_bound_mib": bound, "rows": rows}, f, indent=1)
    plot_production(rows, os.path.join(folder, "production.png"))


def plot_production(rows, path):
    """Run time against bin exponent per max depth, one panel per texture filter, the reference
    as a dashed line at its depth (as the thesis' figures 6.5 and 6.6)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    filters = sorted({r["filter"] for r in rows}, key=["finest", "cone"].index)
    fig, axes = plt.subplots(1, len(filters), figsize=(5.5 * len(filters), 4), sharey=True)
    for ax, f in zip(axes if len(filters) > 1 else [axes], filters):
        for i, depth in enumerate(sorted({r["depth"] for r in rows})):
            colour = "C%d" % i
            pts = sorted((int(r["config"].split("^")[1]), r["core_seconds"]) for r in rows
                         if r["filter"] == f and r["depth"] == depth and r["config"].startswith("cpu"))
            ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-", color=colour, label="cpu, depth %d" % depth)
            for r in rows:
                if r["filter"] == f and r["depth"] == depth and r["config"] == "reference":
                    ax.axhline(r["core_seconds"], color=colour, ls="--", lw=1,
                               label="reference, depth %d" % depth)
        ax.set_title("--texture-filter %s" % f)
        ax.set_xlabel("bin exponent (batch = 2^E rays)")
        ax.grid(alpha=0.3)
    (axes[0] if len(filters) > 1 else axes).set_ylabel("render seconds")
    (axes[0] if len(filters) > 1 else axes).legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    print("plot: " + path)


def bench_mpi(spillway, repeat, ranks_list, threads_per_rank, one_process_threads):
    import time
    heavy = subprocess.check_output([sys.executable, os.path.join(ROOT, "scripts", "make_heavy_scene.py"),
                                     os.path.join(ROOT, "out", "heavy")], text=True).strip()
    box = os.path.join(ROOT, "scenes", "cornell-box.yaml")
    scenes = [("Cornell box 256x256, 64 spp", box, ["--spp", "64"]),
              ("1M triangles, 17 shaders, 640x480, 16 spp", heavy, [])]
    mpirun = ["mpirun", "--oversubscribe", "--bind-to", "none"]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    configs = [("1 process x %d threads" % one_process_threads, 1, one_process_threads)]
    for r in ranks_list:
        t = threads_per_rank or max(1, one_process_threads // r)  # default: the same cores in all
        configs.append(("%d rank%s x %d thread%s" % (r, "s" if r > 1 else "", t, "s" if t > 1 else ""), r, t))
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        for title, scene, extra in scenes:
            for backend in ("cpu", "reference"):
                best = {}
                for _ in range(repeat):  # alternate: every configuration once per round
                    for name, n, threads in configs:
                        stats = os.path.join(tmp, "s.json")
                        cmd = [spillway, "render", scene, "--backend", backend, "--threads", str(threads),
                               "-o", os.path.join(tmp, "o.exr"), "--quiet", "--stats", stats] + extra
                        if n > 1:
                            cmd = mpirun + ["-np", str(n)] + cmd
                        start = time.monotonic()
                        subprocess.run(cmd, check=True, env=env)
                        s = json.load(open(stats))
                        s["launch_seconds"] = time.monotonic() - start
                        if name not in best or s["launch_seconds"] < best[name]["launch_seconds"]:
                            best[name] = s
                one = best[configs[0][0]]
                print("\n%s, %s backend (best of %d, alternating)" % (title, backend, repeat))
                print("  %-22s %9s %9s %9s %9s %10s %10s" % ("config", "launch s", "render s", "reduce s",
                                                             "wait s", "vs 1 proc", "render vs"))
                for name, n, threads in configs:
                    s = best[name]
                    reduce_s = max((r["reduce_seconds"] for r in s.get("ranks", [])), default=0.0)
                    wait_s = max((r["agree_seconds"] for r in s.get("ranks", [])), default=0.0)
                    print("  %-22s %9.2f %9.2f %9.3f %9.3f %9.2fx %9.2fx" % (
                        name, s["launch_seconds"], s["render_seconds"], reduce_s, wait_s,
                        s["launch_seconds"] / one["launch_seconds"], s["render_seconds"] / one["render_seconds"]))
                    results.append({"scene": title, "backend": backend, "config": name, "ranks": n,
                                    "threads_per_rank": threads, "launch_seconds": s["launch_seconds"],
                                    "render_seconds": s["render_seconds"], "reduce_seconds": reduce_s, "wait_seconds": wait_s,
                                    "wall_seconds": s["wall_seconds"], "rays": s["rays"]["total"]})
    folder = os.path.join(ROOT, "out", "bench")
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "mpi.json"), "w") as f:
        json.dump(results, f, indent=1)


def bench_large(spillway, repeat, baseline):
    box = os.path.join(ROOT, "scenes", "cornell-box.yaml")
    os.makedirs(os.path.join(ROOT, "out", "bench"), exist_ok=True)
    scenes = {}
    for size in (16, 4000):
        path = os.path.join(ROOT, "out", "bench", "cornell-%d.yaml" % size)
        with open(path, "w") as f:
            f.write(open(box).read()
                    .replace("image: {width: 256, height: 256, sample base: 2, iterations: 16}",
                             "image: {width: %d, height: %d, sample base: 1, iterations: 1}" % (size, size))
                    .replace("filename: cornell-box/", "filename: %s/" % os.path.join(ROOT, "scenes", "cornell-box")))
        scenes[size] = path
    builds = [("", spillway)] + ([("baseline ", baseline)] if baseline else [])
    configs = [(label + backend, binary, backend) for label, binary in builds
               for backend in ("reference", "cpu", "vulkan")]
    best = {}
    for _ in range(repeat):  # alternating: one run of every configuration per round
        for name, binary, backend in configs:
            small, small_rss = run(binary, scenes[16], ["--backend", backend], 1)
            big, big_rss = run(binary, scenes[4000], ["--backend", backend], 1)
            if small is None or big is None:
                continue
            row = {"bytes_per_pixel": (big_rss - small_rss) * 1048576 / 16e6,
                   "peak_rss_mib": big_rss, "fixed_rss_mib": small_rss,
                   "write_image_seconds": big["stage_seconds"].get("write image", 0.0),
                   "render_seconds": big["render_seconds"], "wall_seconds": big["wall_seconds"]}
            if name not in best or row["wall_seconds"] < best[name]["wall_seconds"]:
                best[name] = row
    print("Cornell box 4000x4000, 1 spp (16 Mpixels), best of %d, alternating" % repeat)
    print("%-22s %14s %10s %12s %10s %8s" % ("", "bytes/pixel", "peak MiB", "write image", "render", "wall"))
    for name, _, _ in configs:
        r = best.get(name)
        if r is None:
            print("%-22s (did not run)" % name)
            continue
        print("%-22s %14.1f %10.0f %11.2fs %9.2fs %7.2fs" % (
            name, r["bytes_per_pixel"], r["peak_rss_mib"], r["write_image_seconds"],
            r["render_seconds"], r["wall_seconds"]))
    json.dump(best, open(os.path.join(ROOT, "out", "bench", "large.json"), "w"), indent=2)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("what", nargs="?", default="all",
                    choices=["reference", "pipeline", "production", "incore", "mpi", "large", "cycles",
                             "scale", "all"])
    ap.add_argument("--repeat", type=int)
    ap.add_argument("--depths", default="1,2,3")
    ap.add_argument("--exponents", default="8,11,14,17")
    ap.add_argument("--scene-args", default="")
    ap.add_argument("--spillway", default=os.path.join(ROOT, "build", "spillway"))
    ap.add_argument("--baseline", help="another build's spillway binary (incore, large: before/after)")
    ap.add_argument("--ranks", default="2", help="mpi: rank counts to run, e.g. 2,4,8,16")
    ap.add_argument("--threads-per-rank", type=int, default=0,
                    help="mpi: threads of each rank (default: --threads / ranks)")
    ap.add_argument("--threads", type=int, default=2, help="mpi: threads of the single process")
    ap.add_argument("--backends", default="cpu,reference", help="cycles: Spillway's backends")
    ap.add_argument("--scenes", default="", help="cycles, scale: the scenes to run (default all)")
    ap.add_argument("--quick", action="store_true", help="cycles, scale: small, to check it runs")
    ap.add_argument("--no-cycles", action="store_true", help="scale: Spillway alone")
    a = ap.parse_args()
    if a.what == "scale":
        import scale_bench
        sys.exit(scale_bench.main(a.spillway, a.quick, [s for s in a.scenes.split(",") if s],
                                  cycles=not a.no_cycles))
    if a.what == "cycles":
        import cycles_bench
        sys.exit(cycles_bench.main(a.spillway, a.backends.split(","), a.quick, a.repeat or 1,
                                   [s for s in a.scenes.split(",") if s]))
    if a.what == "production":
        bench_production(a.spillway, a.repeat or 1, [int(d) for d in a.depths.split(",")],
                         [int(e) for e in a.exponents.split(",")], a.scene_args.split())
        return
    a.repeat = a.repeat or 3
    if a.what == "incore":
        bench_incore(a.spillway, a.repeat, a.baseline)
        return
    if a.what == "large":
        bench_large(a.spillway, a.repeat, a.baseline)
        return
    if a.what == "mpi":
        bench_mpi(a.spillway, a.repeat, [int(r) for r in a.ranks.split(",")], a.threads_per_rank, a.threads)
        return
    if a.what in ("reference", "all"):
        bench_reference(a.spillway, a.repeat)
    if a.what in ("pipeline", "all"):
        bench_pipeline(a.spillway, a.repeat)


if __name__ == "__main__":
    main()
