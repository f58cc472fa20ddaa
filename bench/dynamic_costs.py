#!/usr/bin/env python3
"""The cost per step of the dynamic mode's pieces (issue 73, item 7).

The trigon tunnel (examples/tunnel_trigon.toml) made dynamic: real masses, its
opening excavated at once and 0.1 s of model time run with viscous edges (the
wall time item 7 asks for); and, for the cost per step, the model at rest in its
in-situ state stepped 4,000 times in each of four forms that add one piece at a
time (the best of three runs), `bbm run --profile` on 2 threads:
    plain      the dynamic mode alone (no local damping)
    viscous    + viscous boundaries on the far field's top and right edges
    rayleigh   + Rayleigh damping, 2% at 20 Hz
    events     + the events catalogue ([events])
The profile's rows (µs a step over the run), the cycle stage's wall time, each
piece's share of the plain dynamic step, and each form's time step against the
plain one's (Rayleigh's stiffness part shortens it): bench/results_dynamics.json.
Usage: python3 bench/dynamic_costs.py [path/to/bbm] [out.json]  (from the repository root)
"""
import json
import os
import subprocess
import sys
import tempfile

bbm = sys.argv[1] if len(sys.argv) > 1 else "build/apps/bbm"
out_path = sys.argv[2] if len(sys.argv) > 2 else "bench/results_dynamics.json"
base = open("examples/tunnel_trigon.toml").read()


def dynamic(text: str, run: str, excavate: bool) -> str:
    text = text.replace('mode = "quasi_static"', 'mode = "dynamic"')
    # The opening removed at once (a sudden excavation), or left in place (the
    # model at rest in its in-situ state: every form steps the same state), then
    # the cycle stage.
    stages = text[text.index('[[stage]]\nname = "excavation"'):]
    excavation = '[[stage]]\nname = "excavation"\ntype = "excavate"\nregions = ["opening"]\nrelax_steps = 1\n\n'
    text = text.replace(stages, (excavation if excavate else "") + '[[stage]]\nname = "wave"\ntype = "cycle"\n' + run + "\n")
    return text.replace("output_every = 2000", "output_every = 0")


VISCOUS = '''
[[boundary]]
name = "top absorbing"
type = "viscous"
box = { min = [-0.01, 19.99], max = [20.01, 20.01] }

[[boundary]]
name = "right absorbing"
type = "viscous"
box = { min = [19.99, -20.01], max = [20.01, 20.01] }
'''


def forms():
    plain = dynamic(base, "steps = 4000", excavate=False)
    viscous = plain.replace("[solver]", VISCOUS + "\n[solver]", 1)
    rayleigh = viscous.replace('mode = "dynamic"', 'mode = "dynamic"\nrayleigh_ratio = 0.02\nrayleigh_frequency = 20.0')
    events = rayleigh + "\n[events]\n"
    return [("plain", plain), ("viscous", viscous), ("rayleigh", rayleigh), ("events", events)]


def model_time_run(work: str) -> dict:
    """The plain form through 0.1 s of model time, with viscous edges (no Rayleigh:
    its stiffness part cuts the step of stiff contacts by the factor it reports)."""
    text = dynamic(base, "time = 0.1", excavate=True).replace("[solver]", VISCOUS + "\n[solver]", 1)
    return run("model_time", text, work)


def run(name: str, text: str, work: str) -> dict:
    model = os.path.join(work, name + ".toml")
    with open(model, "w") as f:
        f.write(text)
    out = os.path.join(work, name)
    cmd = [bbm, "run", model, "--out", out, "--profile", "--threads", "2", "--quiet"]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    summary = json.load(open(os.path.join(out, "summary.json")))
    wave = next(s for s in summary["stages"] if s["name"] == "wave")
    prof = summary["profile"]
    rows = {k: 1e6 * v / prof["steps"] for k, v in prof["seconds"].items()}
    return {"form": name, "wave_stage": wave, "us_per_step_by_row": rows, "time_step_s": summary["timestep"],
            "contacts": summary["contacts"], "wall_s": summary["wall_seconds"]}


def main():
    results = []
    with tempfile.TemporaryDirectory() as work:
        timed = model_time_run(work)
        print(f"0.1 s of model time: {timed['wave_stage']['steps']} steps in {timed['wave_stage']['seconds']:.1f} s "
              f"(run {timed['wall_s']:.1f} s)", flush=True)
        for name, text in forms():
            runs = [run(name, text, work) for _ in range(3)]
            r = min(runs, key=lambda x: x["wave_stage"]["seconds"])
            print(f"{name:9s} {r['wave_stage']['steps']:7d} steps  {r['wave_stage']['seconds']:7.1f} s  "
                  f"{1e6 * r['wave_stage']['seconds'] / r['wave_stage']['steps']:7.1f} us/step", flush=True)
            results.append(r)
    plain = results[0]["wave_stage"]
    per_step = lambda r: r["wave_stage"]["seconds"] / r["wave_stage"]["steps"]
    for prev, r in zip(results, results[1:]):
        r["added_us_per_step"] = 1e6 * (per_step(r) - per_step(prev))
        r["added_share_of_plain_step"] = (per_step(r) - per_step(prev)) / per_step(results[0])
    total = (per_step(results[-1]) - per_step(results[0])) / per_step(results[0])
    for r in results:
        r["time_step_over_plain"] = r["time_step_s"] / results[0]["time_step_s"]
    doc = {"what": __doc__.strip().splitlines()[0], "model": "examples/tunnel_trigon.toml, dynamic", "threads": 2,
           "model_time_run": timed, "forms": results, "boundaries_damping_events_share_of_step": total,
           "machine": os.uname().machine, "cpus": os.cpu_count()}
    with open(out_path, "w") as f:
        json.dump(doc, f, indent=2)
    print(f"boundaries + damping + events: {100 * total:.1f}% of the plain dynamic step; {out_path}")


if __name__ == "__main__":
    main()
