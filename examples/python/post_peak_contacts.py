"""Who carries the load after the peak? A UCS test watched contact by contact.

Runs `bbm.ucs` with a callback every --every steps of loading and, for each
frame, splits the compressive load the contacts carry (sum of sigma_n * L over
contacts in compression) by what the contacts are:

  intact      bonded, undamaged           softening  bonded, 0 < D < 1
  broken      original joints whose bond broke (cracks closed again)
  new         contacts formed by detection during the run ("unbonded" set)
and, across those, the share carried at rounded corners (the vertex past the end
of its edge: vertex-vertex contacts) and the overlap depths of unbonded contacts
in compression. Plots the stress-strain curve with these shares, and the force
chains (block centroid to block centroid, width ~ force) at the peak and at the
end. Writes DIR/contacts.png, DIR/chains.png and DIR/frames.json.

    PYTHONPATH=build/python python3 examples/python/post_peak_contacts.py \\
        --out out/post_peak -- --width 2 --height 4 --seed 1
(options after -- go to bbm.ucs as --key value)."""

import argparse
import json
import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
import numpy as np  # noqa: E402

import bbm  # noqa: E402

KINDS = ("intact", "softening", "broken", "new")


def classify(frame):
    c = frame["contacts"]
    names = frame["property_names"]
    new = np.isin(c["property"], [k for k, n in enumerate(names) if n == "unbonded"])
    bonded = c["bonded"]
    damaged = c["damage"] > 0
    kind = np.where(new, 3, np.where(~bonded, 2, np.where(damaged, 1, 0)))
    return kind


def measure(frame):
    c = frame["contacts"]
    kind = classify(frame)
    force = np.clip(c["normal_stress"], 0.0, None) * c["length"]  # N/m, compression
    total = force.sum()
    s = c["edge_parameter"]
    # A vertex past the end of its edge: the rounded-corner contact (unbonded only;
    # a bond keeps its original geometry however far it has sheared).
    corner = ~c["bonded"] & ((s < 0.0) | (s > 1.0))
    share = {k: float(force[kind == i].sum() / total) if total > 0 else 0.0 for i, k in enumerate(KINDS)}
    loaded = (kind >= 2) & (c["normal_stress"] > 0)
    overlap = -c["normal_displacement"][loaded]
    return {
        "step": int(frame["step"]), "axial_strain": float(frame["axial_strain"]),
        "axial_stress": float(frame["axial_stress"]),
        "cracks": int(frame["cracks_tensile"] + frame["cracks_shear"]),
        "share": share,
        "corner_share": float(force[corner].sum() / total) if total > 0 else 0.0,
        "contacts": {k: int((kind == i).sum()) for i, k in enumerate(KINDS)},
        "unbonded_in_compression": int(loaded.sum()),
        "overlap_median": float(np.median(overlap)) if overlap.size else 0.0,
        "overlap_max": float(overlap.max()) if overlap.size else 0.0,
    }


def draw_chains(ax, frame, title):
    c, b = frame["contacts"], frame["blocks"]
    kind = classify(frame)
    force = np.clip(c["normal_stress"], 0.0, None) * c["length"]
    pairs = c["block_pair"]
    xy = b["centroid"]
    keep = force > 0.02 * force.max()
    segs = np.stack([xy[pairs[keep, 0]], xy[pairs[keep, 1]]], axis=1)
    colours = np.array(["0.6", "tab:orange", "tab:red", "tab:blue"])[kind[keep]]
    widths = 4.0 * force[keep] / force.max()
    ax.add_collection(LineCollection(segs, colors=colours, linewidths=widths))
    ax.set_aspect("equal")
    ax.autoscale()
    ax.set_title(title, fontsize=9)
    ax.set_xticks([]), ax.set_yticks([])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="out/post_peak")
    ap.add_argument("--every", type=int, default=500, help="steps between frames")
    ap.add_argument("ucs", nargs=argparse.REMAINDER, help="-- then bbm ucs options, e.g. --width 2 --height 4")
    args = ap.parse_args()
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    options = {}
    rest = [a for a in args.ucs if a != "--"]
    for key, value in zip(rest[::2], rest[1::2]):
        options[key.lstrip("-").replace("-", "_")] = value
    frames, states = [], []

    def on_frame(frame):
        frames.append(measure(frame))
        states.append(frame)

    result = bbm.ucs(callback=on_frame, frame_every=args.every, **options)
    # The state nearest the reported peak (the curve's maximum before failure), and the last.
    at_peak = min(states, key=lambda f: abs(f["axial_strain"] - result["strain_at_peak"]))
    kept = {"peak": at_peak, "last": states[-1]}
    (out / "frames.json").write_text(json.dumps({"summary": {k: v for k, v in result.items() if k != "curve"},
                                                 "frames": frames}, indent=1, default=float) + "\n")
    strain = np.array([f["axial_strain"] for f in frames]) * 1e3
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7, 7), sharex=True)
    ax1.plot(1e3 * result["curve"]["axial_strain"], result["curve"]["axial_stress"] / 1e6, "k")
    ax1.set_ylabel("axial stress (MPa)")
    ax1.set_title(f"peak {result['peak_stress'] / 1e6:.2f} MPa, locking {result['post_peak_locking']}")
    bottom = np.zeros_like(strain)
    for k, colour in zip(KINDS, ("0.6", "tab:orange", "tab:red", "tab:blue")):
        share = np.array([f["share"][k] for f in frames])
        ax2.fill_between(strain, bottom, bottom + share, color=colour, label=k, step="mid")
        bottom += share
    ax2.plot(strain, [f["corner_share"] for f in frames], "k--", label="at corners")
    ax2.set_xlabel("axial strain (1e-3)")
    ax2.set_ylabel("share of contact compression")
    ax2.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "contacts.png", dpi=110)
    fig, axes = plt.subplots(1, 2, figsize=(8, 8))
    draw_chains(axes[0], kept["peak"], f"at the peak (step {kept['peak']['step']})")
    draw_chains(axes[1], kept["last"], f"at the end (step {kept['last']['step']})")
    fig.suptitle("force chains: grey intact, orange softening, red broken, blue new contacts")
    fig.tight_layout()
    fig.savefig(out / "chains.png", dpi=110)
    last, peak = frames[-1], frames[states.index(at_peak)]
    for name, f in (("peak", peak), ("end", last)):
        print(f"{name}: strain {f['axial_strain']:.3e} stress {f['axial_stress'] / 1e6:.2f} MPa cracks {f['cracks']} "
              f"shares " + " ".join(f"{k} {v:.2f}" for k, v in f["share"].items()) +
              f" corners {f['corner_share']:.2f}; unbonded in compression {f['unbonded_in_compression']}, "
              f"overlap median {f['overlap_median']:.2e} max {f['overlap_max']:.2e} m")
    print(f"wrote {out}/contacts.png, chains.png, frames.json")


if __name__ == "__main__":
    main()
