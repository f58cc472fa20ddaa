"""Rock bridges at several normal stresses (docs/joints.md):
    python3 plot_jennings_normal_stress.py SHEAR_DIR OUT_DIR
SHEAR_DIR holds k0, k0.25, k0.5, k0.75, k1, each from
    bbm shear --persistence K --bridges 1 --max-displacement 10e-3 --shear-rate 1e-7 \\
              --normal-stress 2e6,10e6 --realizations 3 --out SHEAR_DIR/kK
Plots the largest shear stress up to 2 mm against persistence, per normal stress, with
Jennings' (1970) line between the end members measured at the same displacement."""
import csv, statistics, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

shear_dir, out = sys.argv[1:3]
ks = [0.0, 0.25, 0.5, 0.75, 1.0]
u_max = 2e-3
tau = {}  # (normal stress, k) -> per-seed largest tau up to u_max, MPa
for k in ks:
    for r in csv.DictReader(open(f"{shear_dir}/k{k:g}/shear.csv")):
        if float(r["shear_displacement_m"]) > u_max:
            continue
        key = (float(r["normal_stress_Pa"]), k)
        seeds = tau.setdefault(key, {})
        seeds[r["seed"]] = max(seeds.get(r["seed"], -1e30), float(r["shear_stress_Pa"]) / 1e6)
fig, ax = plt.subplots(figsize=(6.4, 4.4))
for sn, colour in zip(sorted({key[0] for key in tau}), ["tab:blue", "tab:red", "tab:green"]):
    mean = [statistics.mean(tau[(sn, k)].values()) for k in ks]
    ax.plot(ks, mean, "o-", color=colour, label=f"bbm, sigma_n {sn / 1e6:g} MPa")
    for k in ks:
        ax.plot([k] * len(tau[(sn, k)]), list(tau[(sn, k)].values()), ".", color=colour, alpha=0.4)
    ax.plot([0, 1], [mean[0], mean[-1]], "--", color=colour, label=f"Jennings (1970), sigma_n {sn / 1e6:g} MPa")
ax.set_xlabel("persistence k")
ax.set_ylabel(f"largest shear stress up to {u_max * 1e3:g} mm (MPa)")
ax.set_title("non-persistent joint at two normal stresses (CNL), 3 seeds")
ax.legend(fontsize=8)
fig.tight_layout()
fig.savefig(f"{out}/shear_rock_bridges_normal_stress.png", dpi=110)
