#!/usr/bin/env python3
"""Names in comments resolve to code (issue 72, item 8).

A comment that names a function, a field or a file the code no longer has sends
a reader looking for nothing ("step_contacts", "stop_fraction", "core/stages.hpp
measure_opening()"). This check reads the comments of the library and the
program and refuses, with file and line:

  * a public header of a layer whose first line is not "// bbm <layer>: ...";
  * a path of the project (base/..., core/..., studies/..., docs/..., tests/...,
    examples/...) that does not exist;
  * a name written as code — `name`, name() or a::b — or a snake_case name of
    words (two letters or more each, one of four or more: "stop_fraction", not
    the subscripted x_i of a formula) that is not a word of any source file's
    code (its comments and strings aside), of a CMake file (a target), a file's
    name, nor a model-file key, flag or output field the sources spell in a string.

It knows no list of exceptions beyond the libraries' namespaces (std::, VTK::,
CLI::, toml:: ...): a name it cannot find is either stale or written as code
where it is prose. Run: python3 tests/comment_names.py [SOURCE_DIR].
"""
import os
import re
import sys

LAYERS = ["base", "meshing", "contact", "fem", "core", "io", "studies", "apps", "python", "bench", "tests"]
SOURCE_EXT = (".hpp", ".cpp", ".h")
PATH_ROOTS = ("base/", "meshing/", "contact/", "fem/", "core/", "io/", "studies/", "apps/", "python/", "bench/",
              "tests/", "docs/", "examples/", ".ci/", "cmake/")

COMMENT = re.compile(r'//[^\n]*|/\*.*?\*/', re.S)
STRING = re.compile(r'"(?:[^"\\\n]|\\.)*"')
IDENT = re.compile(r'[A-Za-z_][A-Za-z0-9_]*')
# A path: a project root, then path characters, ending in a file name with an extension or a folder's slash.
PATH = re.compile(r'(?<![\w./-])((?:' + '|'.join(re.escape(r) for r in PATH_ROOTS) + r')[\w./+-]*[\w/])')
# Names written as code: `name` (backticks), name() (called), a::b (qualified).
BACKTICK = re.compile(r'`([^`\s]+)`')
CALLED = re.compile(r'(?<![\w.:>-])([a-z_][a-z0-9_]*[a-z0-9_])\(\)')
QUALIFIED = re.compile(r'\b((?:[A-Za-z_]\w*::)+[A-Za-z_]\w*)')


def sources(top):
    for layer in LAYERS:
        for root, _, files in os.walk(os.path.join(top, layer)):
            if "/fuzz/seeds" in root or "/regressions" in root:
                continue
            for f in files:
                if f.endswith(SOURCE_EXT):
                    yield os.path.join(root, f)


SNAKE = re.compile(r'(?<![\w./:-])([a-z][a-z0-9]*(?:_[a-z0-9]+)+)(?![\w/])')


def snake_names(comment):
    """The snake_case names of words in a comment (not a formula's x_i or k_n)."""
    for w in set(SNAKE.findall(comment)):
        parts = w.split("_")
        if min(map(len, parts)) >= 2 and max(map(len, parts)) >= 4:
            yield w


def build_words(top):
    """The words of the CMake files (targets, options) and the names of the files."""
    words = set()
    for root, dirs, files in os.walk(top):
        dirs[:] = [d for d in dirs if d not in (".git", "build") and not d.startswith("build")]
        for f in files:
            words.add(os.path.splitext(f)[0])
            if f == "CMakeLists.txt" or f.endswith(".cmake"):
                with open(os.path.join(root, f), encoding="utf-8", errors="replace") as text:
                    words.update(IDENT.findall(text.read()))
    return words


def code_words(texts):
    """Every identifier of the code, and every word of its strings (keys, flags, fields)."""
    words, string_words = set(), set()
    for text in texts.values():
        code = COMMENT.sub(" ", text)
        for s in STRING.findall(code):
            string_words.update(IDENT.findall(s))
            string_words.update(re.findall(r'[\w.-]+', s))
        words.update(IDENT.findall(STRING.sub(" ", code)))
    return words, string_words


def missing_paths(top, text):
    """The project paths a text names that do not exist."""
    out = []
    for m in PATH.finditer(text):
        p = m.group(1).rstrip(".")
        # A glob (examples/tunnel_*.toml) names files that start so; a module
        # (io/model_input, core/bolts.*) its .hpp and .cpp.
        glob_like = text[m.end():m.end() + 1] in ("*", "<", "{")
        found = os.path.exists(os.path.join(top, p)) or any(
            os.path.exists(os.path.join(top, p + ext)) for ext in (".hpp", ".cpp"))
        if glob_like:
            folder, stem = os.path.split(os.path.join(top, p))
            found = os.path.isdir(folder) and any(f.startswith(stem) for f in os.listdir(folder))
        if not found:
            out.append(f"{p}: no such file or folder")
    return out


def comments(text):
    """(line, comment text) of each comment."""
    for m in COMMENT.finditer(text):
        yield text.count("\n", 0, m.start()) + 1, m.group(0)


# The namespaces of the libraries bbm uses: their names are theirs to keep.
EXTERNAL = re.compile(r'^(std|VTK|vtk\w*|CLI|toml|Eigen|CGAL|nlohmann|pybind11|py|doctest|gmsh|MPI|cholmod)(::|$)')


def known(name, words, string_words):
    if EXTERNAL.match(name) or "<" in name:
        return True
    if name in words or name in string_words:
        return True
    # a::b::c: its last part a word of the code (a namespace's member, an enumerator).
    if "::" in name:
        return name.split("::")[-1] in words
    # A flag (--size), a key path (region.pattern.size), a file name: its words.
    parts = [p for p in re.split(r'[.\-/\[\]]+', name) if p]
    return bool(parts) and all(p in words or p in string_words or not IDENT.fullmatch(p) for p in parts)


def check(top):
    texts = {}
    for path in sources(top):
        with open(path, encoding="utf-8", errors="replace") as f:
            texts[path] = f.read()
    words, string_words = code_words(texts)
    words |= build_words(top)
    problems = []
    for path, text in sorted(texts.items()):
        rel = os.path.relpath(path, top)
        # A public header of a library layer starts with what it is for, tagged with its layer.
        layer = rel.split(os.sep)[0]
        if rel.endswith(".hpp") and layer in LAYERS[:8] and not re.match(r"// bbm " + layer + r"(, internal)?: ", text):
            problems.append(f"{rel}:1: its first line is not '// bbm {layer}: what it is for'")
        for line, comment in comments(text):
            problems += [f"{rel}:{line}: {p}" for p in missing_paths(top, comment)]
            named = set(BACKTICK.findall(comment)) | set(CALLED.findall(comment)) | set(QUALIFIED.findall(comment))
            named |= set(snake_names(comment))
            for name in sorted(named):
                if name.startswith(("--", "-")) or not re.search(r'[A-Za-z_]', name):
                    continue
                # Only what looks like an identifier of code: an underscore, a call or a scope.
                if not ("_" in name or "::" in name or name.endswith("()")):
                    continue
                bare = name[:-2] if name.endswith("()") else name
                if not known(bare, words, string_words):
                    problems.append(f"{rel}:{line}: '{name}' names nothing in the code")
    return problems


def check_docs(top):
    """The pages of docs/ (not its dated notes, nor the history) name files that exist."""
    problems = []
    pages = [os.path.join(top, "README.md")]
    for root, _, files in os.walk(os.path.join(top, "docs")):
        if os.sep + "notes" in root:
            continue
        pages += [os.path.join(root, f) for f in files if f.endswith(".md")]
    for page in sorted(pages):
        rel = os.path.relpath(page, top)
        with open(page, encoding="utf-8") as f:
            for number, text in enumerate(f, 1):
                problems += [f"{rel}:{number}: {p}" for p in missing_paths(top, text)]
    return problems


def main():
    top = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    problems = check(top) + check_docs(top)
    for p in problems:
        print(p)
    if problems:
        print(f"{len(problems)} name(s) in comments resolve to nothing: fix the comment (or the name)")
        return 1
    print("every name in the comments resolves")
    return 0


if __name__ == "__main__":
    sys.exit(main())
