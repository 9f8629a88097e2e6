#!/usr/bin/python3
"""Spillway benchmarks. Every figure is measured in this run, and every backend's time is also
printed as a ratio to the reference backend's time measured in the same run (these machines
are noisy; ratios travel, absolute seconds do not).

  scripts/bench.py reference   Cornell box 256x256, 64 spp, reference backend: seconds, rays/s
  scripts/bench.py pipeline    cpu vs reference on the Cornell box and the 1M-triangle scene,
                               each ray sort and hit sort setting, peak RSS, spill traffic
  scripts/bench.py all         both (default)

Options: --repeat N (best of N, default 3), --spillway PATH (default build/spillway).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def run(spillway, scene, args, repeat):
    """Best-of-N render; returns (stats json, peak RSS MiB)."""
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


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("what", nargs="?", default="all", choices=["reference", "pipeline", "all"])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--spillway", default=os.path.join(ROOT, "build", "spillway"))
    a = ap.parse_args()
    if a.what in ("reference", "all"):
        bench_reference(a.spillway, a.repeat)
    if a.what in ("pipeline", "all"):
        bench_pipeline(a.spillway, a.repeat)


if __name__ == "__main__":
    main()
