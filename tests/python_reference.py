"""docs/reference/python.md from the bbm module itself: every public class, method,
property and function with its signature and docstring, in the module's order.

    python3 tests/python_reference.py REFERENCE          # exits 1 if REFERENCE is stale
    python3 tests/python_reference.py REFERENCE --write  # rewrites it

Run with the built module on PYTHONPATH (ctest python.reference does, with
Debian's python3 and numpy)."""
import inspect
import sys

import bbm


def doc_of(obj):
    return inspect.cleandoc(obj.__doc__ or "")


def split_signature(name, doc):
    """pybind11 puts the signature on a docstring's first line: 'name(...) -> T'."""
    first, _, rest = doc.partition("\n")
    if first.startswith(name + "("):
        return first, inspect.cleandoc(rest)
    return None, doc


def python_signature(name, obj):
    try:
        return name + str(inspect.signature(obj))
    except (TypeError, ValueError):
        return name + "(...)"


def callable_entry(name, obj, level, shown=None):
    sig, doc = split_signature(name, doc_of(obj))
    if sig is None:
        sig = python_signature(name, obj)
    if shown:  # a constructor: shown under its class's name
        sig = shown + sig[len(name):]
    out = [f"{'#' * level} `{sig}`", ""]
    if doc:
        out += [doc, ""]
    return out


def class_entry(name, cls):
    out = [f"## class `{name}`", ""]
    doc = doc_of(cls)
    if doc:
        out += [doc, ""]
    for member, obj in cls.__dict__.items():
        if member.startswith("_") and member != "__init__":
            continue
        if isinstance(obj, property):
            out += [f"### property `{name}.{member}`", ""]
            if doc_of(obj):
                out += [doc_of(obj), ""]
        elif callable(obj) or isinstance(obj, (staticmethod, classmethod)):
            target = obj.__func__ if isinstance(obj, (staticmethod, classmethod)) else obj
            if member == "__init__":
                if doc_of(target).startswith("Initialize self"):
                    continue  # made by the module, not by the user
                out += callable_entry("__init__", target, 3, shown=name)
            else:
                out += callable_entry(member, target, 3)
    return out


def reference():
    lines = ["# The Python module `bbm`", "",
             "Generated from the module's own docstrings by tests/python_reference.py "
             "(`ctest -R python.reference` fails when this file is stale; run the script "
             "with `--write` to rewrite it). The guide is docs/running.md, \"Python\".", ""]
    lines += [doc_of(bbm), ""]
    members = [(n, o) for n, o in vars(bbm).items() if not n.startswith("_")]
    classes = sorted((n, o) for n, o in members if inspect.isclass(o) and not issubclass(o, BaseException))
    errors = sorted((n, o) for n, o in members if inspect.isclass(o) and issubclass(o, BaseException))
    functions = sorted((n, o) for n, o in members if callable(o) and not inspect.isclass(o))
    for n, o in classes:
        lines += class_entry(n, o)
    if functions:
        lines += ["## Functions", ""]
        for n, o in functions:
            lines += callable_entry(n, o, 3)
    if errors:
        lines += ["## Errors", ""]
        for n, o in errors:
            lines += [f"* `{n}` ({o.__mro__[1].__name__}): {doc_of(o).splitlines()[0] if doc_of(o) else ''}"]
        lines += [""]
    text = "\n".join(lines)
    while "\n\n\n" in text:
        text = text.replace("\n\n\n", "\n\n")
    return text.rstrip() + "\n"


def main():
    path = sys.argv[1]
    text = reference()
    if "--write" in sys.argv[2:]:
        with open(path, "w", encoding="utf-8") as f:
            f.write(text)
        return 0
    try:
        with open(path, encoding="utf-8") as f:
            current = f.read()
    except FileNotFoundError:
        current = ""
    if current != text:
        print(f"{path} is stale: rewrite it with python3 {sys.argv[0]} {path} --write", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
