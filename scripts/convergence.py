#!/usr/bin/python3
"""Error against run time for every backend: the convergence report.

Renders a reference once at high spp (or takes --reference), then renders the scene on each
backend with --error-csv against it, and writes
  OUT/convergence.csv   backend, iteration, spp, seconds, relmse, relmse_estimate
  OUT/convergence.png   log-log relMSE against seconds, one line per backend
and prints each backend's efficiency 1 / (relMSE x seconds) at its last iteration (higher is
better; for an unbiased estimator it stays roughly constant along the curve).

  scripts/convergence.py [SCENE] [--backends reference,cpu,vulkan] [--spp 256]
                         [--reference-spp 4096 | --reference REF.exr] [--out out/convergence]

A backend that cannot run here (vulkan without a Vulkan device) is reported and skipped.
--replot redraws OUT/convergence.png from OUT/convergence.csv without rendering. The plot needs
Debian's python3-matplotlib, hence /usr/bin/python3 rather than whatever python3 is first on
the PATH.
"""
import argparse
import csv
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene", nargs="?", default=os.path.join(ROOT, "scenes", "cornell-box.yaml"))
    ap.add_argument("--backends", default="reference,cpu,vulkan")
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
            rows = [{"backend": r["backend"], "iteration": int(r["iteration"]), "spp": int(r["spp"]),
                     "seconds": float(r["seconds"]), "relmse": float(r["relmse"]),
                     "relmse_estimate": float(r["relmse_estimate"])} for r in csv.DictReader(f)]
        report(a, rows)
        return

    ref = a.reference
    if not ref:
        ref = os.path.join(a.out, "ground-truth.exr")  # not <backend>.exr: the reference backend writes that
        print("rendering the reference: %d spp on the reference backend (seed 1000003)" % a.reference_spp)
        subprocess.check_call([a.spillway, "render", a.scene, "--backend", "reference", "--spp", str(a.reference_spp),
                               "--seed", "1000003", "--quiet", "-o", ref])

    rows = []
    for backend in a.backends.split(","):
        csv_path = os.path.join(a.out, backend + ".csv")
        cmd = [a.spillway, "render", a.scene, "--backend", backend, "--spp", str(a.spp), "--quiet",
               "-o", os.path.join(a.out, backend + ".exr"), "--error-csv", csv_path, "--reference", ref]
        p = subprocess.run(cmd, capture_output=True, text=True)
        if p.returncode != 0:
            print("%s: skipped (%s)" % (backend, p.stderr.strip().splitlines()[-1] if p.stderr.strip() else p.returncode))
            continue
        with open(csv_path) as f:
            for r in csv.DictReader(f):
                rows.append({"backend": backend, "iteration": int(r["iteration"]), "spp": int(r["spp"]),
                             "seconds": float(r["seconds"]), "relmse": float(r["relmse"]),
                             "relmse_estimate": float(r["relmse_estimate"])})
    if not rows:
        sys.exit("no backend rendered")

    with open(out_csv, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=["backend", "iteration", "spp", "seconds", "relmse", "relmse_estimate"])
        w.writeheader()
        w.writerows(rows)
    report(a, rows)


def report(a, rows):
    """Prints each backend's last point and efficiency, and draws the log-log plot."""
    out_csv = os.path.join(a.out, "convergence.csv")
    backends = [b for b in a.backends.split(",") if any(r["backend"] == b for r in rows)]
    print("\n%-10s %6s %10s %12s %14s" % ("backend", "spp", "seconds", "relMSE", "efficiency"))
    for b in backends:
        last = [r for r in rows if r["backend"] == b][-1]
        print("%-10s %6d %10.3f %12.4g %14.4g" % (b, last["spp"], last["seconds"], last["relmse"],
                                                  1.0 / (last["relmse"] * last["seconds"])))

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4.2), dpi=120)
    for b in backends:
        pts = [r for r in rows if r["backend"] == b]
        ax.loglog([r["seconds"] for r in pts], [r["relmse"] for r in pts], marker=".", markersize=3, label=b)
    xs = [r["seconds"] for r in rows]
    ys = [r["relmse"] for r in rows]
    x0, y0 = min(xs), max(ys)
    ax.loglog([x0, x0 * 100], [y0, y0 / 100], "k:", linewidth=0.8, label="slope -1")
    ax.set_xlabel("render seconds")
    ax.set_ylabel("relMSE against the reference")
    ax.set_title(os.path.basename(a.scene) + ": error against time")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    png = os.path.join(a.out, "convergence.png")
    fig.savefig(png)
    print("\nwrote %s and %s" % (out_csv, png))


if __name__ == "__main__":
    main()
