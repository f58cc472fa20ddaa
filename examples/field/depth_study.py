#!/usr/bin/env python3
"""Depth of failure against stress around the Mine-by tunnel (docs/field.md).

The in-situ stress of examples/field/mineby.toml (60 and 11 MPa, 14 degrees) is
scaled by each factor, every component in the boundaries and the initial state
together, and each model is run over seeds with `bbm sweep`. For every run the
largest elastic hoop stress sigma_max = 3 sigma1 - sigma3 is set against the
rock's laboratory UCS (--ucs: the model rock's own for the peak-calibrated
mineby.toml; the record's 213 MPa for mineby_in_situ.toml, whose bonds are
calibrated on crack initiation), and the failed zone's depth across the largest
stress (the notch, roof and floor, +/-15 degrees) gives r_f / a. The field's
trend (Martin, Kaiser & McCreath 1999, Can. Geotech. J. 36: failure starts near
sigma_max / UCS = 0.4, r_f / a = 1.25 sigma_max / UCS + 0.51) is drawn beside it.

    python3 examples/field/depth_study.py --bbm build/apps/bbm --out out/depth_study
    python3 examples/field/depth_study.py --bbm build/apps/bbm --model examples/field/mineby_in_situ.toml \
        --ucs 213e6 --out out/depth_study_in_situ
"""
import argparse
import csv
import json
import math
import pathlib
import re
import subprocess

RADIUS = 1.75          # m, the Mine-by tunnel
SIGMA1, SIGMA3 = 60e6, 11e6
UCS_PEAK_MODEL = 229.7e6  # the peak-calibrated bonds' UCS (docs/notes/2026-11-28-calibration-history.md, Lac du Bonnet, iteration 2)
NOTCH_DEG = (104.0, 284.0)  # across the largest stress: roof and floor
SIDEWALL_DEG = (14.0, 194.0)  # along it: the side walls, where the hoop stress is least (tension)


def scaled_model(text, f):
    """The model file with every in-situ stress component multiplied by f."""
    def scale(m):
        return f"{m.group(1)} = {float(m.group(2)) * f:.6e}"
    return re.sub(r"^(s[xy][xy]) = (-?[0-9.e+-]+)", scale, text, flags=re.M)


def zone_depth(summary, directions):
    """The failed zone's depth within +/-15 degrees of each direction, m."""
    zone = summary["opening"]["failed_zone"]
    depths, width = zone["depth_by_sector_m"], zone["sector_deg"]
    best = [0.0] * len(directions)
    for i, d in enumerate(depths):
        centre = (i + 0.5) * width
        for k, target in enumerate(directions):
            if abs((centre - target + 180.0) % 360.0 - 180.0) <= 15.0:
                best[k] = max(best[k], d)
    return best


def notch_centre(summary, direction):
    """The centre (degrees) of the failed zone's largest lobe within 45 degrees of
    a direction, or None: where the notch is, whatever its depth."""
    best = None
    for lobe in summary["opening"]["failed_zone"].get("lobes", []):
        if abs((lobe["centre_deg"] - direction + 180.0) % 360.0 - 180.0) <= 45.0:
            if best is None or lobe["area_m2"] > best["area_m2"]:
                best = lobe
    return None if best is None else best["centre_deg"]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bbm", default="bbm")
    ap.add_argument("--model", default=str(pathlib.Path(__file__).with_name("mineby.toml")))
    ap.add_argument("--out", default="out/depth_study")
    ap.add_argument("--factors", default="0.3,0.6,1.0,1.4,1.7,2.0")
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--ucs", type=float, default=UCS_PEAK_MODEL,
                    help="the laboratory UCS that sigma_max is divided by, Pa")
    ap.add_argument("--replot", nargs="+", metavar="CSV",
                    help="run nothing: draw OUT/depth_study.png from these studies' depth_study.csv files "
                         "(e.g. low stresses in one region size, high ones in a larger)")
    args = ap.parse_args()
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.replot:
        plot(read_rows(args.replot), out / "depth_study.png")
        return
    text = pathlib.Path(args.model).read_text()
    rows = []
    for f in [float(v) for v in args.factors.split(",")]:
        case = out / f"factor_{f:g}"
        case.mkdir(exist_ok=True)
        model = case / "model.toml"
        model.write_text(scaled_model(text, f))
        subprocess.run([args.bbm, "sweep", str(model), "--seeds", str(args.seeds), "--threads", str(args.threads),
                        "--out", str(case / "runs"), "--plot", "opening.failed_zone.depth_crown", "--resume", "-q"],
                       check=False)
        for run in sorted((case / "runs").glob("run_*")):
            summary = json.loads((run / "summary.json").read_text())
            roof, floor = zone_depth(summary, NOTCH_DEG)
            side = max(zone_depth(summary, SIDEWALL_DEG))
            smax = (3 * SIGMA1 - SIGMA3) * f
            rows.append({"factor": f, "run": run.name, "sigma_max_MPa": smax / 1e6,
                         "sigma_max_over_ucs": smax / args.ucs, "roof_depth_m": roof, "floor_depth_m": floor,
                         "sidewall_depth_m": side,
                         "roof_notch_deg": notch_centre(summary, NOTCH_DEG[0]),
                         "floor_notch_deg": notch_centre(summary, NOTCH_DEG[1]),
                         "rf_over_a": (RADIUS + max(roof, floor)) / RADIUS,
                         "reaches_region_edge": summary["opening"]["failed_zone"]["reaches_region_edge"],
                         "cracks": summary["cracks"]["tensile"] + summary["cracks"]["shear"],
                         "verdict": summary["verdict"]["kind"],
                         "steps": summary["steps"]})
            print(f"factor {f:4.2f} {run.name}: sigma_max/UCS {rows[-1]['sigma_max_over_ucs']:.2f}  "
                  f"notch roof {roof:.2f} m floor {floor:.2f} m  r_f/a {rows[-1]['rf_over_a']:.2f}  "
                  f"side walls {side:.2f} m  "
                  f"cracks {rows[-1]['cracks']}  {rows[-1]['verdict']}")
    with open(out / "depth_study.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    plot(rows, out / "depth_study.png")


def read_rows(paths):
    """Rows of earlier studies' depth_study.csv files (--replot)."""
    rows = []
    for path in paths:
        with open(path, newline="") as fh:
            for r in csv.DictReader(fh):
                for key in ("sigma_max_over_ucs", "rf_over_a", "sidewall_depth_m"):
                    r[key] = float(r[key])
                r["reaches_region_edge"] = r["reaches_region_edge"] == "True"
                rows.append(r)
    return rows


def plot(rows, path):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print(f"matplotlib is not installed: {path} not drawn (the CSV has every figure)")
        return
    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    x = [r["sigma_max_over_ucs"] for r in rows]
    inside = [r for r in rows if not r["reaches_region_edge"]]
    edge = [r for r in rows if r["reaches_region_edge"]]
    ax.plot([r["sigma_max_over_ucs"] for r in inside], [r["rf_over_a"] for r in inside], "o", color="C3",
            label="bbm: roof and floor (each seed)")
    if edge:
        ax.plot([r["sigma_max_over_ucs"] for r in edge], [r["rf_over_a"] for r in edge], "x", color="C3",
                label="bbm: zone reaches the bonded region's edge")
    ax.plot(x, [(RADIUS + r["sidewall_depth_m"]) / RADIUS for r in rows], "^", mfc="none", color="C0",
            label="bbm: side walls, in tension (each seed)")
    xs = [0.4 + 0.01 * i for i in range(111)]
    ax.plot(xs, [1.25 * v + 0.51 for v in xs], "-", color="k", label="field trend (Martin et al. 1999)")
    ax.fill_between(xs, [1.25 * v + 0.41 for v in xs], [1.25 * v + 0.61 for v in xs], color="0.85",
                    label="±0.1 about it")
    ax.axvline(0.4, ls=":", color="0.4")
    ax.set_xlabel("largest elastic hoop stress / laboratory UCS")
    ax.set_ylabel("failed radius / tunnel radius, r_f / a")
    ax.set_xlim(0, 1.6)
    ax.set_ylim(0.95, max(2.6, 0.1 + max(r["rf_over_a"] for r in rows)))
    ax.legend(loc="upper left", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


if __name__ == "__main__":
    main()
