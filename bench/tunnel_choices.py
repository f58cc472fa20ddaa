#!/usr/bin/env python3
"""The paper's Voronoi tunnel under the modelling choices where bbm may differ from
UDEC (issue 12, item 3; docs/notes/2026-11-28-calibration-history.md "The paper's
Voronoi tunnel, choice by choice").

Each variant edits `examples/tunnel_voronoi.toml` (the paper's joints as given) in
one respect, or a few for the combined rows, and runs it over `--seeds` block
generations (the seeds of both Voronoi regions offset by 0, 1, 2, ...). Printed: a
Markdown table of the measures `bbm run` writes to summary.json's `opening`, and
the share of the springline sector's broken contacts whose normal is within 30° of
radial (fractures parallel to the wall; a random network gives 1/3). Written:
`--out`/tunnel_choices.json with every run.

    PYTHONPATH=build/python /usr/bin/python3 bench/tunnel_choices.py --out out/choices
"""

import argparse
import copy
import json
import math
import os
import sys
import time
import tomllib

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(ROOT, "build", "python"))
import bbm  # noqa: E402


def stage(d, name):
    return next(s for s in d["stage"] if s["name"] == name)


def region(d, name):
    return next(r for r in d["region"] if r["name"] == name)


def sudden(d):
    stage(d, "excavation")["relax_steps"] = 0


def dynamic(d):
    # Real masses, local damping, the opening deleted in one step: UDEC's default.
    d["solver"]["mode"] = "dynamic"
    sudden(d)
    stage(d, "failure")["max_steps"] = 200000


def long_run(d):
    # Cycled until the ratio is met or 200,000 steps (the shipped file stops at 30,000).
    stage(d, "failure")["max_steps"] = 200000


def corner(radius):
    def edit(d):
        d["solver"]["corner_radius"] = radius
    return edit


def overlap_length(d):
    d["solver"]["new_contact_length"] = "overlap"


def builtin_new_contacts(d):
    d["solver"]["new_contact_property"] = ""


def no_insitu(d):
    # No stress initialization and no implicit elastic solve: the loads and gravity
    # applied to an unstressed model, cycled to equilibrium before excavating.
    d["stage"] = [s for s in d["stage"] if s["type"] not in ("initialize", "elastic")]
    d["stage"].insert(0, {"name": "equilibrium", "type": "solve", "ratio": 1e-5, "max_steps": 60000})


def insitu_explicit(d):
    # Stresses initialized (UDEC's INSITU), then cycled to equilibrium instead of the
    # implicit elastic solve.
    for s in d["stage"]:
        if s["type"] == "elastic":
            s.clear()
            s.update({"name": "equilibrium", "type": "solve", "ratio": 1e-5, "max_steps": 60000})


def area_size(d):
    for name in ("bonded", "opening"):
        region(d, name)["pattern"]["size_measure"] = "area"


def combine(*edits):
    def edit(d):
        for e in edits:
            e(d)
    return edit


VARIANTS = {
    "shipped": ("the shipped file: quasi-static, relaxed over 3,000 steps, r = 0.05 ē, edge lengths", []),
    "long": ("cycled up to 200,000 steps after excavation, not 30,000", [long_run]),
    "sudden": ("opening deleted in one step (relax_steps = 0), quasi-static", [sudden]),
    "dynamic": ("real masses, local damping 0.8, deleted in one step", [dynamic]),
    "corner_1pct": ("corner radius 1.6 mm (1% of the mean edge, UDEC's advice) instead of 8 mm", [corner(0.0016)]),
    "corner_10pct": ("corner radius 16 mm", [corner(0.016)]),
    "overlap": ("new contacts get half the overlap of the faces (UDEC), not half the edge", [overlap_length]),
    "builtin_new": ("new contacts: built-in set (kn of the stiffest set, φ 30°)", [builtin_new_contacts]),
    "no_insitu": ("no stress initialization: loads on an unstressed model, cycled to equilibrium", [no_insitu]),
    "insitu_explicit": ("stresses initialized, then cycled (no implicit solve)", [insitu_explicit]),
    "area": ("blocks sized as an equal-area 0.3 m (more, smaller cells)", [area_size]),
    "udec": ("dynamic + corner 1% + overlap lengths", [dynamic, corner(0.0016), overlap_length]),
    "udec_area": ("dynamic + corner 1% + overlap lengths + area size", [dynamic, corner(0.0016), overlap_length, area_size]),
    "all": ("dynamic + corner 1% + overlap lengths + area size + no initialization",
            [no_insitu, dynamic, corner(0.0016), overlap_length, area_size]),
}


def wall_parallel_share(model, center, springline):
    c = model.contacts
    state = c.state
    broken = (state == 2) | (state == 3)
    pos = c.position[broken]
    nrm = c.normal[broken]
    ds = np.asarray(springline) - np.asarray(center)
    ds /= np.linalg.norm(ds)
    r = pos - np.asarray(center)
    d = np.linalg.norm(r, axis=1)
    in_sector = (r @ ds) >= math.cos(math.radians(30.0)) * d
    if not in_sector.any():
        return float("nan"), 0
    radial = r[in_sector] / d[in_sector, None]
    cosang = np.abs(np.sum(nrm[in_sector] * radial, axis=1))
    return float(np.mean(cosang >= math.cos(math.radians(30.0)))), int(in_sector.sum())


def run_one(base, edits, seed_offset, threads):
    d = copy.deepcopy(base)
    for e in edits:
        e(d)
    for r in d["region"]:
        if "seed" in r.get("pattern", {}):
            r["pattern"]["seed"] += seed_offset
    t0 = time.perf_counter()
    model = bbm.Model.from_dict(d, threads=threads)
    error = ""
    try:
        model.run()
    except bbm.NumericalError as e:  # reported in the table; the state is measured as it stood
        error = str(e).split(":")[0]
    wall = time.perf_counter() - t0
    s = model.summary()
    o = s["opening"]
    share, n = wall_parallel_share(model, d["report"]["center"], d["report"]["springline"])
    return {
        "seed_offset": seed_offset,
        "steps": model.steps,
        "wall_seconds": wall,
        "cracks": model.cracks,
        "springline_sector": o["cracks_springline_sector"],
        "crown_sector": o["cracks_crown_sector"],
        "failed_depth_springline": o["failed_depth_springline"],
        "springline_convergence_mm": 1e3 * o["springline_convergence"],
        "crown_convergence_mm": 1e3 * o["crown_convergence"],
        "wall_parallel_share": share,
        "error": error,
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--model", default=os.path.join(ROOT, "examples", "tunnel_voronoi.toml"))
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--only", nargs="*", default=None, help="variant names (default: all)")
    ap.add_argument("--out", default="out/tunnel_choices")
    args = ap.parse_args()
    with open(args.model, "rb") as f:
        base = tomllib.load(f)
    os.makedirs(args.out, exist_ok=True)
    names = args.only or list(VARIANTS)
    results = {}
    for name in names:
        what, edits = VARIANTS[name]
        runs = []
        for k in range(args.seeds):
            r = run_one(base, edits, k, args.threads)
            runs.append(r)
            print(f"  {name} seed +{k}: {r['springline_sector']} / {r['crown_sector']} sector cracks, "
                  f"{r['failed_depth_springline']:.2f} m, {r['steps']} steps, {r['wall_seconds']:.1f} s",
                  file=sys.stderr, flush=True)
        results[name] = {"what": what, "runs": runs}
        with open(os.path.join(args.out, "tunnel_choices.json"), "w") as f:
            json.dump(results, f, indent=1)

    def per_seed(runs, key, fmt):
        return " / ".join(fmt.format(r[key]) for r in runs)

    print("| variant | springline / crown sector cracks | failed depth springline m | "
          "convergence springline / crown mm | wall-parallel share | steps |")
    print("|---|---|---|---|---|---|")
    for name, res in results.items():
        runs = res["runs"]
        cracks = " / ".join(f"{r['springline_sector']}:{r['crown_sector']}" for r in runs)
        conv = " / ".join(f"{r['springline_convergence_mm']:.2f}:{r['crown_convergence_mm']:.2f}" for r in runs)
        cracks += "".join(f" (seed +{r['seed_offset']}: {r['error']})" for r in runs if r["error"])
        print(f"| {name} | {cracks} | {per_seed(runs, 'failed_depth_springline', '{:.2f}')} | {conv} | "
              f"{per_seed(runs, 'wall_parallel_share', '{:.2f}')} | {per_seed(runs, 'steps', '{}')} |")


if __name__ == "__main__":
    main()
