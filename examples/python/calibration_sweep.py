"""A calibration study from Python: sweep the joints' tensile strength and see
what it does to the rock's UCS and direct tensile strength (numerical lab tests
on the paper's Voronoi blocks). Plots both against sigma_t with the stress-strain
curves of the UCS tests.

    PYTHONPATH=build/python python3 examples/python/calibration_sweep.py --out out/sweep
    (--quick: a 2 m x 4 m specimen, for the tests)

Writes DIR/sweep.png, DIR/curves.png and DIR/sweep.json."""

import argparse
import json
import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import bbm  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="out/sweep")
    ap.add_argument("--tensile", type=float, nargs="+", default=[2e6, 3e6, 4e6, 5e6])
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--quick", action="store_true", help="a small specimen (a smoke run, not a result)")
    args = ap.parse_args()
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    specimen = dict(width=2.0, height=4.0) if args.quick else {}

    rows = []
    fig_c, ax_c = plt.subplots(figsize=(6, 4))
    for st in args.tensile:
        u = bbm.ucs(tensile=st, seed=args.seed, threads=args.threads, **specimen)
        t = bbm.tension(tensile=st, seed=args.seed, threads=args.threads, **specimen)
        rows.append({"joint_tensile": st, "E": u["E"], "nu": u["nu"], "ucs": u["peak_stress"],
                     "tensile_strength": t["peak_stress"], "sigma_ci": u["crack_initiation_stress"]})
        print(f"sigma_t {st / 1e6:.1f} MPa: UCS {u['peak_stress'] / 1e6:.2f} MPa, tensile "
              f"{t['peak_stress'] / 1e6:.2f} MPa, E {u['E'] / 1e9:.2f} GPa")
        c = u["curve"]
        ax_c.plot(1e3 * c["axial_strain"], c["axial_stress"] / 1e6, label=f"sigma_t {st / 1e6:g} MPa")
    ax_c.set_xlabel("axial strain (1e-3)")
    ax_c.set_ylabel("axial stress (MPa)")
    ax_c.legend()
    fig_c.tight_layout()
    fig_c.savefig(out / "curves.png", dpi=120)

    fig, ax = plt.subplots(figsize=(6, 4))
    x = [r["joint_tensile"] / 1e6 for r in rows]
    ax.plot(x, [r["ucs"] / 1e6 for r in rows], marker="o", label="UCS")
    ax.plot(x, [r["tensile_strength"] / 1e6 for r in rows], marker="s", label="direct tensile strength")
    ax.set_xlabel("joint tensile strength sigma_t (MPa)")
    ax.set_ylabel("rock strength (MPa)")
    ax.set_title("What the joints' tensile strength buys")
    ax.legend()
    fig.tight_layout()
    fig.savefig(out / "sweep.png", dpi=120)
    (out / "sweep.json").write_text(json.dumps(rows, indent=2) + "\n")
    print(f"wrote {out}/sweep.png, curves.png, sweep.json")


if __name__ == "__main__":
    main()
