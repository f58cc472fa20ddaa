#!/usr/bin/env python3
"""docs/validation.md from the tests' own records (tests/validation_record.hpp).

    validation_report.py RECORDS_DIR docs/validation.md           # check: exit 1 if stale
    validation_report.py RECORDS_DIR docs/validation.md --write   # rewrite the page

Each test that checks a figure against a reference writes one JSON record into
RECORDS_DIR when it runs (CTest sets BBM_VALIDATION_DIR). The page is the union of
the rows already on it and the records: a record replaces its row (same test and
quantity), rows of tests not run this time stay as they were. The check fails
when the records change the page: a figure moved, a row is new, or a check that
held no longer does.
"""
import json
import pathlib
import sys

GROUPS = [("closed form", "Against closed forms (verification)"),
          ("paper", "Against the paper (Lemos)"),
          ("laboratory", "Against laboratory records"),
          ("field", "Against field measurements")]
HEADER = "| what | reference | tolerance asserted | measured | held | test |"
RULE = "|---|---|---|---|---|---|"

INTRO = """# Verification and validation

Every figure bbm is checked against, the tolerance its test asserts, what the
test measured and whether it held. Generated from the tests' own records by
tests/validation_report.py (the test `validation.report` fails when this page
differs from what the tests measured; `python3 tests/validation_report.py
build/validation docs/validation.md --write` rewrites it). The default suite
(`ctest -LE long`) records the closed forms and the quick cases; the long suite
(`ctest -L long`) the laboratory and field cases of minutes. How each reference is
derived: [theory.md](theory.md); the field case: [field.md](field.md); the
laboratory calibrations: [calibration.md](calibration.md).
"""


def cell(text):
    return str(text).replace("|", "\\|").replace("\n", " ")


def split_row(line):
    cells, current, escaped = [], "", False
    for ch in line.strip()[1:-1]:
        if escaped:
            current += ch
            escaped = False
        elif ch == "\\":
            current += ch
            escaped = True
        elif ch == "|":
            cells.append(current.strip())
            current = ""
        else:
            current += ch
    cells.append(current.strip())
    return cells


def read_page(path):
    """The rows already on the page: {(group, test, what): row cells}."""
    rows = {}
    if not path.exists():
        return rows
    group = None
    titles = {title: key for key, title in GROUPS}
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.startswith("## "):
            group = titles.get(line[3:].strip())
        elif group and line.startswith("| ") and line != HEADER and not line.startswith("|---"):
            cells = split_row(line)
            if len(cells) == 6:
                rows[(group, cells[5], cells[0])] = cells
    return rows


def read_records(directory):
    rows = {}
    for f in sorted(pathlib.Path(directory).glob("*.json")):
        r = json.loads(f.read_text(encoding="utf-8"))
        test = cell(f"{r['file']}: {r['test']}")
        what = cell(r["what"])
        rows[(r["against"], test, what)] = [what, cell(r["reference"]), cell(r["tolerance"]),
                                            cell(r["measured"]), "yes" if r["within"] else "**no**", test]
    return rows


def render(rows):
    out = [INTRO]
    for key, title in GROUPS:
        group = sorted((k, v) for k, v in rows.items() if k[0] == key)
        if not group:
            continue
        held = sum(1 for _, v in group if v[4] == "yes")
        out += [f"## {title}", "", f"{len(group)} checks, {held} held.", "", HEADER, RULE]
        out += ["| " + " | ".join(v) + " |" for _, v in group]
        out.append("")
    return "\n".join(out)


def main():
    records_dir, page = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
    write = "--write" in sys.argv[3:]
    old_rows = read_page(page)
    records = read_records(records_dir) if records_dir.is_dir() else {}
    rows = dict(old_rows)
    rows.update(records)
    text = render(rows)
    if write:
        page.write_text(text, encoding="utf-8")
        print(f"{page}: {len(rows)} rows, {len(records)} from this run's records")
        return 0
    old = page.read_text(encoding="utf-8") if page.exists() else ""
    if text == old:
        print(f"{page}: up to date ({len(records)} records checked)")
        return 0
    for k, v in sorted(records.items()):
        if old_rows.get(k) != v:
            print(f"changed: {k[1]} / {k[0]}: {old_rows.get(k, ['(no row)'])[3:5]} -> {v[3:5]}")
    print(f"{page} is stale: run python3 tests/validation_report.py {records_dir} {page} --write and commit it")
    return 1


if __name__ == "__main__":
    sys.exit(main())
