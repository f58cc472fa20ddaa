"""Figures of docs/joints.md from the runs it lists:
    python3 plot_joints.py SHEAR_DIR JAEGER_DIR OUT_DIR
SHEAR_DIR holds k0, k0.25, k0.5, k0.75, k1 (bbm shear --persistence K ... -o SHEAR_DIR/kK);
JAEGER_DIR holds b30 ... b90 (bbm biaxial --joint-set-angle B ... -o JAEGER_DIR/bB)."""
import csv, json, math, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

shear_dir, jaeger_dir, out = sys.argv[1:4]

# Rock bridges: tau mobilised up to 2 mm and 10 mm against persistence, with Jennings' line.
ks = ["0", "0.25", "0.5", "0.75", "1"]
reach = {2e-3: {}, 10e-3: {}}
for k in ks:
    rows = list(csv.DictReader(open(f"{shear_dir}/k{k}/shear.csv")))
    for u_max in reach:
        per_seed = {}
        for r in rows:
            if float(r["shear_displacement_m"]) <= u_max:
                per_seed[r["seed"]] = max(per_seed.get(r["seed"], -1e30), float(r["shear_stress_Pa"]))
        values = [v / 1e6 for v in per_seed.values()]
        reach[u_max][float(k)] = (sum(values) / len(values), values)
fig, ax = plt.subplots(figsize=(6.4, 4.4))
for (u_max, data), colour in zip(reach.items(), ["tab:blue", "tab:red"]):
    x = sorted(data)
    ax.plot(x, [data[k][0] for k in x], "o-", color=colour, label=f"bbm, largest tau up to {u_max * 1e3:g} mm")
    for k in x:
        ax.plot([k] * len(data[k][1]), data[k][1], ".", color=colour, alpha=0.4)
    ax.plot([0, 1], [data[0.0][0], data[1.0][0]], "--", color=colour, label=f"Jennings (1970), end members at {u_max * 1e3:g} mm")
ax.set_xlabel("persistence k")
ax.set_ylabel("shear stress (MPa)")
ax.set_title("non-persistent joint, sigma_n 5 MPa (CNL), 3 seeds")
ax.legend(fontsize=8)
fig.tight_layout()
fig.savefig(f"{out}/shear_rock_bridges.png", dpi=110)

# Plane of weakness: joint slip stress (or the intact peak) against beta, with Jaeger.
mu, s3 = math.tan(math.radians(30.0)), 5.0
def jaeger(beta):
    b = math.radians(beta)
    if beta <= 30.0 or beta >= 90.0:
        return float("inf")
    return s3 + 2 * mu * s3 / ((1 - mu / math.tan(b)) * math.sin(2 * b))
fig, ax = plt.subplots(figsize=(6.4, 4.4))
betas = [b / 2 for b in range(62, 180)]
ax.plot(betas, [min(jaeger(b), 80) for b in betas], "k-", label="Jaeger: slip on the plane")
slip, intact = [], []
for b in range(30, 95, 5):
    try:
        s = json.load(open(f"{jaeger_dir}/b{b}/summary.json"))
    except FileNotFoundError:
        continue
    for r in s["per_realization"]:
        if r["joint_slip_stress"] > 0:
            slip.append((b, r["joint_slip_stress"] / 1e6))
        else:
            intact.append((b, r["peak_stress"] / 1e6))
ax.plot([p[0] for p in slip], [p[1] for p in slip], "o", color="tab:blue", label="bbm: plane slides (90% of its length)")
ax.plot([p[0] for p in intact], [p[1] for p in intact], "s", color="tab:red", label="bbm: no slip, the rock fails (peak)")
ax.set_ylim(0, 50)
ax.set_xlabel("beta: angle between sigma_1 and the joint's normal (deg)")
ax.set_ylabel("sigma_1 (MPa)")
ax.set_title("one joint (phi_j 30, c_j 0) across an 8 x 16 m specimen, sigma_3 5 MPa")
ax.legend(fontsize=8)
fig.tight_layout()
fig.savefig(f"{out}/jaeger_plane_of_weakness.png", dpi=110)
