"""bbm under mpirun gives what the serial program gives (CTest: mpi.*).

    mpi_check.py BBM MPIEXEC DIR labtest|sweep|calibrate|errors

    mpi_check.py ... studies: calibrate and compare on 2 ranks as serially

labtest: `bbm ucs --realizations 4` on 2 and 3 ranks writes the summary of the
serial run (wall times aside). sweep: a sweep over 2 values x 2 seeds, with a run
that fails (a load no stiffness carries), on 2 ranks gives the serial table; the
failed run is reported and the others complete; --resume keeps finished runs.
Only the standard library: it runs without the Python module."""

import csv
import json
import os
import pathlib
import shutil
import subprocess
import sys

BBM, MPIEXEC, DIR, WHAT = sys.argv[1], sys.argv[2], pathlib.Path(sys.argv[3]), sys.argv[4]
SOURCE = pathlib.Path(__file__).resolve().parents[1]
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_rmaps_base_oversubscribe="1", OMP_WAIT_POLICY="passive")


def run(args, ranks=0, expect=0):
    cmd = ([MPIEXEC, "--oversubscribe", "-n", str(ranks)] if ranks else []) + [BBM, *map(str, args)]
    done = subprocess.run(cmd, capture_output=True, text=True, env=ENV)
    if done.returncode != expect:
        sys.exit(f"{' '.join(cmd)}: exit {done.returncode}, expected {expect}\n{done.stdout}{done.stderr}")
    return done


def without_times(x):
    if isinstance(x, dict):
        return {k: without_times(v) for k, v in x.items() if k not in ("wall_seconds", "seconds", "meshing_seconds")}
    if isinstance(x, list):
        return [without_times(v) for v in x]
    return x


def labtest():
    args = ["ucs", "--realizations", 4, "--width", 2, "--height", 4, "--threads", 2, "--quiet"]
    run(args + ["--out", DIR / "serial"])
    serial = json.loads((DIR / "serial/summary.json").read_text())
    assert serial["realizations"] == 4
    for ranks in (2, 3):
        run(args + ["--out", DIR / f"ranks{ranks}"], ranks)
        got = json.loads((DIR / f"ranks{ranks}/summary.json").read_text())
        if without_times(got) != without_times(serial):
            sys.exit(f"{ranks} ranks: the summary differs from the serial run's")
        # Every realization's folder is there, written by whichever rank ran it.
        for k in range(1, 5):
            assert (DIR / f"ranks{ranks}/realization_{k}/summary.json").exists()
    print("ucs --realizations 4: 2 and 3 ranks give the serial summary; peak mean",
          serial["peak_stress"]["mean"])


def sweep_table(out):
    rows = list(csv.DictReader(open(out / "sweep.csv")))
    for r in rows:
        r.pop("wall_seconds")
    return rows


def sweep():
    model = SOURCE / "examples/verification/insitu_voronoi.toml"
    args = ["sweep", model, "--set", "joint_property[0].tensile=2e6,4e6", "--set", "stage[0].syy=-20e6,-1e300",
            "--seeds", 2, "--plot", "cracks.tensile", "--quiet"]
    # -1e300 cannot be carried: those runs stop (exit 3 inside), the table says so.
    run(args + ["--out", DIR / "serial"], expect=1)
    serial = sweep_table(DIR / "serial")
    assert len(serial) == 8, serial
    bad = [r for r in serial if r["stage[0].syy"] == "-1e300"]
    good = [r for r in serial if r["stage[0].syy"] == "-20e6"]
    assert all(r["status"] != "done" and r["error"] for r in bad), bad
    assert all(r["status"] == "done" and r["steps"] == "100" for r in good), good
    # Two seeds give two patterns, the same seed the same state for either strength (no crack).
    assert good[0]["state_hash"] != good[1]["state_hash"] and good[0]["state_hash"] == good[2]["state_hash"]
    run(args + ["--out", DIR / "ranks2"], 2, expect=1)
    if sweep_table(DIR / "ranks2") != serial:
        sys.exit("sweep on 2 ranks: the table differs from the serial one")
    table = json.loads((DIR / "ranks2/sweep.json").read_text())
    assert table["ranks"] == 2 and len(table["runs"]) == 8
    # --resume keeps the finished runs and redoes the others.
    again = run(args[:-1] + ["--out", DIR / "serial", "--resume"], expect=1)
    resumed = json.loads((DIR / "serial/sweep.json").read_text())["runs"]
    assert sum(1 for r in resumed if r.get("resumed")) == 4, again.stderr
    print("sweep: 8 runs, 4 stopped and reported, the same table on 2 ranks; --resume kept 4")


def studies():
    # calibrate: its UCS and tension runs over 2 ranks, the same iterations.
    args = ["calibrate", "--width", 2, "--height", 4, "--realizations", 2, "--iterations", 2, "--quiet"]
    run(args + ["--out", DIR / "cal_serial", "--threads", 2])
    run(args + ["--out", DIR / "cal_ranks2", "--threads", 1], 2)
    a = json.loads((DIR / "cal_serial/calibration.json").read_text())
    b = json.loads((DIR / "cal_ranks2/calibration.json").read_text())
    if without_times(a) != without_times(b):
        sys.exit("calibrate on 2 ranks: calibration.json differs from the serial one")
    assert (DIR / "cal_ranks2/joint_property.toml").read_text() == (DIR / "cal_serial/joint_property.toml").read_text()
    # compare: one model per rank, one table.
    models = [SOURCE / "examples/verification/insitu_voronoi.toml", SOURCE / "examples/verification/hybrid_elastic.toml"]
    run(["compare", *models, "--out", DIR / "cmp_serial", "--quiet"])
    run(["compare", *models, "--out", DIR / "cmp_ranks2", "--quiet"], 2)

    def table(d):
        rows = list(csv.DictReader(open(d / "comparison.csv")))
        for r in rows:
            r.pop("wall_seconds")
        return rows

    assert table(DIR / "cmp_serial") == table(DIR / "cmp_ranks2")
    for m in models:
        a = json.loads((DIR / "cmp_serial" / m.stem / "summary.json").read_text())
        b = json.loads((DIR / "cmp_ranks2" / m.stem / "summary.json").read_text())
        assert a["state_hash"] == b["state_hash"]
    print("calibrate and compare on 2 ranks: the serial results")


def errors():
    # Bad input under mpirun: exit 2 from every rank, one message.
    done = run(["ucs", "--kn", "nan", "--quiet"], 2, expect=2)
    assert done.stderr.count("--kn") == 1, done.stderr
    model = SOURCE / "examples/verification/insitu_voronoi.toml"
    done = run(["sweep", model, "--set", "joint_propery[0].tensile=2e6", "--out", DIR / "bad"], expect=2)
    assert "joint_propery" in done.stderr, done.stderr
    assert not (DIR / "bad").exists()
    print("errors: named once, exit 2")


shutil.rmtree(DIR, ignore_errors=True)
DIR.mkdir(parents=True)
{"labtest": labtest, "sweep": sweep, "studies": studies, "errors": errors}[WHAT]()
