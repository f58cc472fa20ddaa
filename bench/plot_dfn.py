#!/usr/bin/env python3
"""Draws bench/results_dfn.json (bench_dfn): the time to cut a region by a fracture
network against the number of fractures, on log axes, beside n log n through the
10,000-fracture point. Usage: python3 bench/plot_dfn.py [results_dfn.json] [out.png]"""
import json
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

src = sys.argv[1] if len(sys.argv) > 1 else "bench/results_dfn.json"
out = sys.argv[2] if len(sys.argv) > 2 else "bench/dfn_scaling.png"
runs = json.load(open(src))["runs"]
n = [r["fractures"] for r in runs]
s = [r["seconds"] for r in runs]
mb = [r["peak_rss_mb"] for r in runs]
ref = next((r for r in runs if r["fractures"] == 10000), runs[len(runs) // 2])
k = ref["seconds"] / (ref["fractures"] * math.log(ref["fractures"]))
fig, ax = plt.subplots(figsize=(6, 4.2))
ax.loglog(n, s, "o-", label="bbm mesh: cutting (1 thread)")
ax.loglog(n, [k * x * math.log(x) for x in n], "--", color="grey", label="n log n through 10,000")
for x, y, m in zip(n, s, mb):
    ax.annotate(f"{y:.1f} s, {m:.0f} MB", (x, y), textcoords="offset points", xytext=(6, -10), fontsize=8)
ax.set_xlabel("fractures (0.5 m Voronoi blocks, 6.25 fracture centres per m²)")
ax.set_ylabel("seconds")
ax.set_title("DFN cutting: time against the number of fractures")
ax.legend(loc="upper left", fontsize=8)
ax.grid(True, which="both", alpha=0.3)
fig.tight_layout()
fig.savefig(out, dpi=120)
print(f"wrote {out}")
