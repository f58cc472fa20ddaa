#!/usr/bin/env python3
"""Runs a tutorial of docs/guide/ as a new user would and checks the figures it
promises, so the guides cannot drift from the code.

    python3 tests/guide_check.py docs/guide/first-tunnel.md --bbm build/apps/bbm \
        [--python-path build/python] [--work DIR]

What it runs: every line starting with "$ " inside a ```console block, in order,
from a fresh working directory that has the repository's examples/ (a link) and
`bbm` on its PATH (the build's); a line ending in a backslash continues on the
next. Blocks fenced ```sh are shown to the reader and not run.

What it checks, from HTML comments the reader does not see (one per line):

    <!-- check: FILE KEY = VALUE -->            a JSON value, exactly
    <!-- check: FILE KEY ~ VALUE +- TOL -->     a JSON number within TOL
    <!-- check: FILE KEY in [LOW, HIGH] -->     a JSON number in a range
    <!-- check-file: FILE -->                    the file exists and is not empty
    <!-- check-output: TEXT -->                  the commands printed TEXT
    <!-- check-same: CSV1 CSV2 COLUMN -->         a column the same, row by row, in two tables

KEY is dot-separated (list items by number: opening.failed_zone.lobes.0.depth_m).
FILE may be CSV: KEY is then COLUMN.ROW (ROW -1: the last). Exit 0 if every command
succeeded and every check holds; else 1, with each failure named.
"""

import argparse
import csv
import json
import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile

REPO = pathlib.Path(__file__).resolve().parent.parent


def commands_of(text):
    """The "$ " lines of the ```console blocks, continuation lines joined."""
    out, in_console, pending = [], False, None
    for line in text.splitlines():
        fence = line.strip()
        if fence.startswith("```"):
            in_console = fence == "```console" if not in_console else False
            continue
        if not in_console:
            continue
        if pending is not None:
            pending += " " + line.strip()
        elif line.startswith("$ "):
            pending = line[2:].strip()
        else:
            continue
        if pending.endswith("\\"):
            pending = pending[:-1].rstrip()
        else:
            out.append(pending)
            pending = None
    return out


CHECK = re.compile(r"<!--\s*(check|check-file|check-output|check-same):\s*(.*?)\s*-->")


def lookup(path, key):
    if path.suffix == ".csv":
        column, row = key.rsplit(".", 1)
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
        return float(rows[int(row)][column])
    value = json.loads(path.read_text())
    for part in key.split("."):
        value = value[int(part)] if isinstance(value, list) else value[part]
    return value


def check_value(work, spec):
    m = re.fullmatch(r"(\S+)\s+(\S+)\s+(=|~|in)\s+(.*)", spec)
    if not m:
        return f"unreadable check: {spec}"
    file, key, op, rest = m.groups()
    path = work / file
    try:
        got = lookup(path, key)
    except (OSError, KeyError, IndexError, ValueError, json.JSONDecodeError) as e:
        return f"{file} {key}: cannot read it ({type(e).__name__}: {e})"
    if op == "=":
        want = json.loads(rest)
        return None if got == want else f"{file} {key} = {got!r}, the guide says {want!r}"
    if op == "~":
        value, tol = (float(x) for x in rest.split("+-"))
        return None if abs(got - value) <= tol else f"{file} {key} = {got}, the guide says {value} +- {tol}"
    low, high = (float(x) for x in rest.strip("[] ").split(","))
    return None if low <= got <= high else f"{file} {key} = {got}, the guide says within [{low}, {high}]"


def check_same(work, spec):
    try:
        first, second, column = spec.split()
        columns = []
        for name in (first, second):
            with open(work / name, newline="") as f:
                columns.append([row[column] for row in csv.DictReader(f)])
    except (OSError, KeyError, ValueError) as e:
        return f"{spec}: cannot read it ({type(e).__name__}: {e})"
    if not columns[0] or columns[0] != columns[1]:
        return f"{column} differs between {first} and {second}: {columns[0]} against {columns[1]}"
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("guide")
    ap.add_argument("--bbm", required=True)
    ap.add_argument("--python-path", default="")
    ap.add_argument("--work", help="working directory (default: a fresh temporary one, removed on success)")
    args = ap.parse_args()
    guide = pathlib.Path(args.guide).resolve()
    text = guide.read_text()
    commands = commands_of(text)
    checks = CHECK.findall(text)
    if not commands:
        print(f"{guide.name}: no ```console command to run")
        return 1
    work = pathlib.Path(args.work or tempfile.mkdtemp(prefix="bbm-guide-"))
    work.mkdir(parents=True, exist_ok=True)
    if not (work / "examples").exists():
        (work / "examples").symlink_to(REPO / "examples")
    bin_dir = work / ".bin"
    bin_dir.mkdir(exist_ok=True)
    # `bbm` is the build's, `python3` the interpreter running this (the one with the
    # module's numpy), whatever else is on the PATH.
    for name, target in (("bbm", pathlib.Path(args.bbm).resolve()), ("python3", pathlib.Path(sys.executable))):
        link = bin_dir / name
        if link.is_symlink() or link.exists():
            link.unlink()
        link.symlink_to(target)
    env = dict(os.environ)
    # mpirun as root and with more ranks than cores (CI machines): Open MPI refuses both unless told.
    env.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
    env.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
    env.setdefault("OMPI_MCA_rmaps_base_oversubscribe", "1")
    env["PATH"] = f"{bin_dir}{os.pathsep}{env.get('PATH', '')}"
    if args.python_path:
        env["PYTHONPATH"] = str(pathlib.Path(args.python_path).resolve())
    env.setdefault("MPLBACKEND", "Agg")
    env.setdefault("OMP_WAIT_POLICY", "passive")
    failures, printed = [], []
    for cmd in commands:
        print(f"$ {cmd}", flush=True)
        run = subprocess.run(cmd, shell=True, cwd=work, env=env, text=True, capture_output=True,
                             executable="/bin/bash")
        printed.append(run.stdout + run.stderr)
        tail = (run.stdout + run.stderr).strip().splitlines()[-5:]
        for line in tail:
            print(f"    {line}")
        if run.returncode != 0:
            failures.append(f"`{cmd}` exited with status {run.returncode}")
            break
    output = "\n".join(printed)
    if not failures:
        for kind, spec in checks:
            if kind == "check":
                problem = check_value(work, spec)
            elif kind == "check-same":
                problem = check_same(work, spec)
            elif kind == "check-file":
                p = work / spec
                problem = None if p.is_file() and p.stat().st_size > 0 else f"{spec}: missing or empty"
            else:
                problem = None if spec in output else f"the commands did not print {spec!r}"
            print(f"{'FAIL' if problem else 'ok  '} {kind}: {spec}")
            if problem:
                failures.append(problem)
    print(f"{guide.name}: {len(commands)} commands, {len(checks)} checks, {len(failures)} failed")
    for f in failures:
        print(f"  - {f}")
    if not failures and not args.work:
        shutil.rmtree(work, ignore_errors=True)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
