"""A seed study of the paper's tunnel from Python: three Voronoi patterns of the
calibrated bonded-block region, run to failure; plots the hoop stress against
distance from the side wall and the cracks against step, one curve per seed.

    PYTHONPATH=build/python python3 examples/python/tunnel_seeds.py --out out/tunnel_seeds
    (--quick: short stages, for the tests)

Writes DIR/hoop_stress.png, DIR/cracks.png and DIR/seeds.json."""

import argparse
import json
import pathlib
import tomllib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import bbm  # noqa: E402

HERE = pathlib.Path(__file__).resolve().parent
MODEL = HERE.parent / "tunnel_voronoi_calibrated.toml"


def hoop_stress_profile(model, radius=4.0, band=0.4, bins=np.arange(0.0, 3.01, 0.25)):
    """Mean hoop stress (MPa, compression positive) of the blocks beside the
    springline (|y| < band), binned by distance from the wall x - radius. At the
    springline the hoop direction is vertical: sigma_theta = syy."""
    b = model.blocks
    xy, stress, keep = b.centroid, b.stress, ~b.removed
    near = keep & (np.abs(xy[:, 1]) < band) & (xy[:, 0] > radius)
    distance = xy[near, 0] - radius
    hoop = -stress[near, 1] / 1e6
    which = np.digitize(distance, bins)
    centres, means = [], []
    for k in range(1, len(bins)):
        sel = which == k
        if sel.any():
            centres.append(0.5 * (bins[k - 1] + bins[k]))
            means.append(hoop[sel].mean())
    return np.array(centres), np.array(means)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="out/tunnel_seeds")
    ap.add_argument("--seeds", type=int, nargs="+", default=[7, 17, 27])
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--quick", action="store_true", help="short stages (a smoke run, not a result)")
    args = ap.parse_args()
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    base = tomllib.loads(MODEL.read_text())
    fig_h, ax_h = plt.subplots(figsize=(6, 4))
    fig_c, ax_c = plt.subplots(figsize=(6, 4))
    table = []
    for seed in args.seeds:
        d = json.loads(json.dumps(base))  # a deep copy
        for region in d["region"]:
            if region["name"] == "bonded":
                region["pattern"]["seed"] = seed
        if args.quick:
            for stage in d["stage"]:
                if stage["type"] == "excavate":
                    stage["relax_steps"] = 300
                if stage["type"] == "solve":
                    stage["max_steps"] = 600
        model = bbm.Model.from_dict(d, name=f"{MODEL.name} (seed {seed})", threads=args.threads)
        steps, cracks = [], []

        def record(m):
            steps.append(m.steps)
            cracks.append(m.cracks["tensile"] + m.cracks["shear"])

        model.run(callback=record, every=100)
        record(model)
        r, hoop = hoop_stress_profile(model)
        s = model.summary()
        table.append({"seed": seed, "cracks": s["cracks"], "opening": s["opening"], "steps": s["steps"],
                      "state_hash": s["state_hash"]})
        print(f"seed {seed}: {s['steps']} steps, cracks {s['cracks']}, springline sector "
              f"{s['opening']['cracks_springline_sector']}, failed depth {s['opening']['failed_depth_springline']:.2f} m")
        ax_h.plot(r, hoop, marker="o", label=f"seed {seed}")
        ax_c.plot(steps, cracks, label=f"seed {seed}")
    ax_h.set_xlabel("distance from the side wall (m)")
    ax_h.set_ylabel("hoop stress (MPa, compression +)")
    ax_h.set_title("Hoop stress beside the springline")
    ax_h.legend()
    fig_h.tight_layout()
    fig_h.savefig(out / "hoop_stress.png", dpi=120)
    ax_c.set_xlabel("step")
    ax_c.set_ylabel("broken contacts")
    ax_c.set_title("Cracks during excavation and failure")
    ax_c.legend()
    fig_c.tight_layout()
    fig_c.savefig(out / "cracks.png", dpi=120)
    (out / "seeds.json").write_text(json.dumps(table, indent=2) + "\n")
    print(f"wrote {out}/hoop_stress.png, cracks.png, seeds.json")


if __name__ == "__main__":
    main()
