#!/usr/bin/python3
"""Error against run time for every backend and sampler: the convergence report.

Renders a reference once at high spp (or takes --reference), then renders the scene with each
configuration, a backend and a sampler, with --error-csv against it, and writes
  OUT/convergence.csv   config, backend, sampler, iteration, spp, seconds, relmse, relmse_estimate
  OUT/convergence.png   log-log relMSE against seconds, one line per configuration
  OUT/estimate.png      the reference-free estimate (--error-csv's relmse_estimate) against the
                        true relMSE, over spp, one colour per configuration
and prints for each configuration its last point, its efficiency 1 / (relMSE x seconds), the
convergence slope (a least-squares fit of log relMSE against log seconds over the second half
of its points: -1 is Monte Carlo's rate, steeper is better) and the equal-error time ratio: the
seconds it takes to reach the first configuration's final error, over the first configuration's
seconds (interpolated on its curve, or extrapolated along its slope, marked "~"); then the
estimate over the true relMSE at each power-of-4 spp. The true relMSE is the relMSE against the
reference less the reference's own (its half-buffer estimate, from rendering it with
--error-csv; unknown, and taken as 0, for a --reference given).

  scripts/convergence.py [SCENE] [--backends reference,cpu,vulkan] [--spp 256]
                         [--samplers Independent,Stratified,Sobol,Sobol+adaptive]
                         [--adaptive-threshold 0.02] [--adaptive-spp 1024]
                         [--reference-spp 4096 | --reference REF.exr] [--out out/convergence]

Samplers are the scene format's (Independent, Grid, Stratified, Sobol; default: the scene's
own), each optionally "+adaptive": adaptive sampling at --adaptive-threshold, allowed up to
--adaptive-spp so that its curve reaches past the others' errors (it stops earlier once every
tile is below the threshold). The curves have a point per iteration.
A backend that cannot run here (vulkan without a Vulkan device) is reported and skipped.
--replot redraws the report from OUT/convergence.csv without rendering. The plot needs
Debian's python3-matplotlib, hence /usr/bin/python3 rather than whatever python3 is first on
the PATH.
"""
import argparse
import csv
import math
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def number(cell):
    """A CSV cell as a float; an empty one (no estimate yet: one half buffer without samples) as 0,
    which the tables and plots leave out."""
    return float(cell) if cell != "" else 0.0


FIELDS = ["config", "backend", "sampler", "iteration", "spp", "seconds", "relmse", "relmse_estimate",
          "relmse_estimate_stderr", "relmse_true"]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene", nargs="?", default=os.path.join(ROOT, "scenes", "cornell-box.yaml"))
    ap.add_argument("--backends", default="reference,cpu,vulkan")
    ap.add_argument("--samplers", default="", help="comma-separated; empty: the scene's own")
    ap.add_argument("--adaptive-threshold", type=float, default=0.02)
    ap.add_argument("--adaptive-spp", type=int, default=1024)
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--reference-spp", type=int, default=4096)
    ap.add_argument("--reference")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "convergence"))
    ap.add_argument("--spillway", default=os.path.join(ROOT, "build", "spillway"))
    ap.add_argument("--replot", action="store_true")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    out_csv = os.path.join(a.out, "convergence.csv")
    if a.replot:
        with open(out_csv) as f:
            rows = [dict(r, iteration=int(r["iteration"]), spp=int(r["spp"]), seconds=float(r["seconds"]),
                         relmse=float(r["relmse"]), relmse_estimate=number(r["relmse_estimate"]),
                         relmse_estimate_stderr=number(r.get("relmse_estimate_stderr", 0.0)),
                         relmse_true=float(r.get("relmse_true", r["relmse"])))
                    for r in csv.DictReader(f)]
        report(a, rows)
        return

    ref = a.reference
    ref_own = 0.0  # the reference's own relMSE, removed from the measured one
    if not ref:
        ref = os.path.join(a.out, "ground-truth.exr")  # not <backend>.exr: the reference backend writes that
        ref_csv = os.path.join(a.out, "ground-truth.csv")
        print("rendering the reference: %d spp on the reference backend (seed 1000003)" % a.reference_spp)
        subprocess.check_call([a.spillway, "render", a.scene, "--backend", "reference", "--spp", str(a.reference_spp),
                               "--seed", "1000003", "--quiet", "-o", ref, "--error-csv", ref_csv])
        with open(ref_csv) as f:
            ref_own = number(list(csv.DictReader(f))[-1]["relmse_estimate"])
        print("the reference's own relMSE (estimated): %.4g" % ref_own)

    rows = []
    samplers = a.samplers.split(",") if a.samplers else [""]
    for backend in a.backends.split(","):
        for sampler in samplers:
            name = backend + ("/" + sampler if sampler else "")
            label = name.replace("/", "-").replace("+", "-")
            csv_path = os.path.join(a.out, label + ".csv")
            adaptive = sampler.endswith("+adaptive")
            cmd = [a.spillway, "render", a.scene, "--backend", backend, "--quiet",
                   "--spp", str(a.adaptive_spp if adaptive else a.spp),
                   "-o", os.path.join(a.out, label + ".exr"), "--error-csv", csv_path, "--reference", ref]
            if sampler:
                cmd += ["--sampler", sampler.split("+")[0]]
            if adaptive:
                cmd += ["--adaptive-threshold", str(a.adaptive_threshold)]
            print("rendering", name)
            p = subprocess.run(cmd, capture_output=True, text=True)
            if p.returncode != 0:
                print("%s: skipped (%s)" % (name, p.stderr.strip().splitlines()[-1] if p.stderr.strip() else p.returncode))
                continue
            with open(csv_path) as f:
                for r in csv.DictReader(f):
                    rows.append({"config": name, "backend": backend, "sampler": sampler or "scene",
                                 "iteration": int(r["iteration"]), "spp": int(r["spp"]),
                                 "seconds": float(r["seconds"]), "relmse": float(r["relmse"]),
                                 "relmse_estimate": number(r["relmse_estimate"]),
                                 "relmse_estimate_stderr": number(r["relmse_estimate_stderr"]),
                                 "relmse_true": float(r["relmse"]) - ref_own})
    if not rows:
        sys.exit("no configuration rendered")

    with open(out_csv, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=FIELDS)
        w.writeheader()
        w.writerows(rows)
    report(a, rows)


def slope(pts):
    """Least-squares slope of log relMSE against log seconds over the second half of the points."""
    pts = [p for p in pts[len(pts) // 2:] if p["seconds"] > 0 and p["relmse"] > 0]
    if len(pts) < 2:
        return float("nan")
    xs = [math.log(p["seconds"]) for p in pts]
    ys = [math.log(p["relmse"]) for p in pts]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    sxx = sum((x - mx) ** 2 for x in xs)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx if sxx > 0 else float("nan")


def time_to_reach(pts, target, k):
    """Seconds at which a curve first reaches relMSE `target`: interpolated in log-log between the
    points around the crossing, or extrapolated from the last point along slope k. Returns
    (seconds, extrapolated)."""
    for prev, cur in zip(pts, pts[1:]):
        if cur["relmse"] <= target < prev["relmse"]:
            t = (math.log(target) - math.log(prev["relmse"])) / (math.log(cur["relmse"]) - math.log(prev["relmse"]))
            return math.exp(math.log(prev["seconds"]) + t * (math.log(cur["seconds"]) - math.log(prev["seconds"]))), False
    if pts and pts[0]["relmse"] <= target:
        return pts[0]["seconds"], False
    last = pts[-1]
    if not (k < 0):
        return float("nan"), True
    return last["seconds"] * (target / last["relmse"]) ** (1.0 / k), True


def report(a, rows):
    """Prints each configuration's last point, efficiency, slope and equal-error time ratio, and
    draws the log-log plot."""
    out_csv = os.path.join(a.out, "convergence.csv")
    configs = []
    for r in rows:
        if r["config"] not in configs:
            configs.append(r["config"])
    curves = {c: [r for r in rows if r["config"] == c] for c in configs}
    base = curves[configs[0]]
    target, base_seconds = base[-1]["relmse"], base[-1]["seconds"]
    print("\nequal-error time: the seconds to reach %s's final relMSE %.4g (%.3f s)" % (configs[0], target, base_seconds))
    print("%-28s %6s %10s %12s %12s %8s %12s" % ("config", "spp", "seconds", "relMSE", "efficiency", "slope",
                                                "time ratio"))
    for c in configs:
        pts = curves[c]
        last, k = pts[-1], slope(pts)
        t, extrapolated = time_to_reach(pts, target, k)
        print("%-28s %6d %10.3f %12.4g %12.4g %8.2f %11s%s" % (
            c, last["spp"], last["seconds"], last["relmse"], 1.0 / (last["relmse"] * last["seconds"]), k,
            "~" if extrapolated else "", "%.3f" % (t / base_seconds)))

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4.2), dpi=120)
    for c in configs:
        pts = curves[c]
        ax.loglog([r["seconds"] for r in pts], [r["relmse"] for r in pts], marker=".", markersize=2, label=c)
    xs = [r["seconds"] for r in rows]
    ys = [r["relmse"] for r in rows]
    x0, y0 = min(xs), max(ys)
    ax.loglog([x0, x0 * 100], [y0, y0 / 100], "k:", linewidth=0.8, label="slope -1")
    ax.axhline(target, color="grey", linewidth=0.6, linestyle="--")
    ax.set_xlabel("render seconds")
    ax.set_ylabel("relMSE against the reference")
    ax.set_title(os.path.basename(a.scene) + ": error against time")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    png = os.path.join(a.out, "convergence.png")
    fig.savefig(png)
    estimate_png = report_estimate(a, configs, curves)
    print("\nwrote %s, %s and %s" % (out_csv, png, estimate_png))


def report_estimate(a, configs, curves):
    """Prints the estimate over the true relMSE at 16, 64, 256, 1024 ... spp and plots both."""
    import matplotlib.pyplot as plt
    print("\nthe reference-free estimate over the true relMSE")
    print("%-28s %s" % ("config", " ".join("%8s" % ("%d spp" % (4 ** k)) for k in range(2, 6))))
    for c in configs:
        by_spp = {r["spp"]: r for r in curves[c]}
        cells = []
        for k in range(2, 6):
            r = by_spp.get(4 ** k)
            ok = r and r["relmse_true"] > 0 and r["relmse_estimate"] > 0
            cells.append("%8.3f" % (r["relmse_estimate"] / r["relmse_true"]) if ok else "%8s" % "-")
        print("%-28s %s" % (c, " ".join(cells)))
    fig, ax = plt.subplots(figsize=(6, 4.2), dpi=120)
    for i, c in enumerate(configs):
        pts = [r for r in curves[c] if r["relmse_true"] > 0 and r["relmse_estimate"] > 0]
        colour = "C%d" % (i % 10)
        ax.loglog([r["spp"] for r in pts], [r["relmse_true"] for r in pts], color=colour, label=c + ": true")
        ax.loglog([r["spp"] for r in pts], [r["relmse_estimate"] for r in pts], color=colour, linestyle="--",
                  label=c + ": estimate")
        # The estimate's standard error (from its own tiles) as a band of +- 2.
        ax.fill_between([r["spp"] for r in pts],
                        [max(r["relmse_estimate"] - 2 * r["relmse_estimate_stderr"], 1e-12) for r in pts],
                        [r["relmse_estimate"] + 2 * r["relmse_estimate_stderr"] for r in pts],
                        color=colour, alpha=0.2, linewidth=0)
    ax.set_xlabel("samples per pixel")
    ax.set_ylabel("relMSE")
    ax.set_title(os.path.basename(a.scene) + ": estimate (dashed, band: 2 s.e.) against truth", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=6)
    fig.tight_layout()
    png = os.path.join(a.out, "estimate.png")
    fig.savefig(png)
    return png


if __name__ == "__main__":
    main()
