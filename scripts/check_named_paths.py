#!/usr/bin/env python3
"""Every repository path the prose names exists.

Reads the Markdown files (README.md, docs/, each folder's README) whole and the source files'
comments only (// and /* */ in C++ and GLSL, # in Python, shell and CMake), finds the words that
look like paths into the repository (a top-level folder of it, then a file or a folder), and
prints `file:line: names PATH, which does not exist` for each one missing. Exits 1 when any is
missing, 0 otherwise. A word counts as a path when its last part has an extension, it ends in
`/`, or it is a stem followed by `.{h,cpp}` (each name of which is checked); so `host/shader
boundary` is prose. Paths with a placeholder in them (`<stem>`, `*`, `...`, an upper-case NAME)
are patterns, not names, and are skipped; so are the folders a build or an install makes
(build*/, out/, dist/, .gl/, .whl/), the history page (docs/performance-log.md, true when
written) and the files EXAMPLES lists.

    scripts/check_named_paths.py [REPO_ROOT]
"""

import os
import re
import sys

# The folders a path must start with to be read as a path into this repository.
TOP = ("host", "shaders", "embree_backend", "tests", "scripts", "docs", "scenes", "cmake", ".ci",
       "blender")
PATH = re.compile(r"(?<![\w./-])((?:%s)/[\w./-]*[\w/])" % "|".join(re.escape(t) for t in TOP))
PLACEHOLDER = re.compile(r"[<>*]|\.\.\.|/[A-Z]+(/|$)")
BRACES = re.compile(r"\.\{([\w,]+)\}")
# Names of files that a reader is told to make, or that are made elsewhere, by design.
EXAMPLES = {
    # The guide's worked example: the files of a new model called Velvet.
    "shaders/shared/velvet.h", "shaders/velvet.comp", "tests/bsdf/velvet_test.cpp",
    "host/cpu/velvet_lanes-inl.h",
    # Carried by a release only: scripts/bundle.sh writes it into the release's scenes/.
    "scenes/textured/",
}
SKIP_FILES = {"docs/performance-log.md"}
CODE = {".cpp", ".h", ".hpp", ".glsl", ".comp", ".py", ".sh", ".cmake", ".txt"}
SKIP_DIRS = {".git", ".gl", ".whl", "dist", "out", "third_party"}  # and build*: made, not written


def comment_text(path, text):
    """The file's comments, with each comment's characters at their own line (others blanked)."""
    if path.endswith((".py", ".sh", ".cmake", ".txt")) or os.path.basename(path) == "run":
        return "\n".join(line[line.index("#"):] if "#" in line else "" for line in text.split("\n"))
    out, i, n = [], 0, len(text)
    while i < n:
        if text.startswith("//", i):
            end = text.find("\n", i)
            end = n if end < 0 else end
            out.append(text[i:end])
            i = end
        elif text.startswith("/*", i):
            end = text.find("*/", i)
            end = n if end < 0 else end + 2
            out.append(text[i:end])
            i = end
        elif text[i] == '"':  # a string literal: skipped, its newlines kept
            j = i + 1
            while j < n and text[j] != '"' and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            out.append("\n" * text.count("\n", i, j))
            i = j + 1
        else:
            out.append("\n" if text[i] == "\n" else " ")
            i += 1
    return "".join(out)


def files(root):
    for folder, dirs, names in os.walk(root):
        rel = os.path.relpath(folder, root)
        dirs[:] = sorted(d for d in dirs if d not in SKIP_DIRS and not d.startswith("build"))
        for name in sorted(names):
            path = os.path.join(folder, name)
            ext = os.path.splitext(name)[1]
            if ext == ".md":
                yield path, False
            elif ext in CODE or (rel == ".ci" and name == "run"):
                yield path, True


def names(word, after):
    """The paths a matched word names: none if it is prose, several for stem.{h,cpp}."""
    braces = BRACES.match(after)
    if braces:
        return [word + "." + ext for ext in braces.group(1).split(",")]
    word = word.rstrip(".")
    last = word.rstrip("/").rsplit("/", 1)[-1]
    return [word] if word.endswith("/") or "." in last else []


def missing(root):
    for path, is_code in files(root):
        rel = os.path.relpath(path, root)
        if rel in SKIP_FILES:
            continue
        with open(path, encoding="utf-8", errors="replace") as f:
            text = f.read()
        if is_code:
            text = comment_text(path, text)
        for number, line in enumerate(text.split("\n"), 1):
            for match in PATH.finditer(line):
                for named in names(match.group(1), line[match.end():]):
                    if named in EXAMPLES or PLACEHOLDER.search(named):
                        continue
                    if not os.path.exists(os.path.join(root, named)):
                        yield "%s:%d: names %s, which does not exist" % (rel, number, named)


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..")
    problems = list(missing(os.path.abspath(root)))
    for p in problems:
        print(p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
