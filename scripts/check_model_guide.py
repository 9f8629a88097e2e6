#!/usr/bin/env python3
"""docs/adding-a-surface-model.md says what the code requires of a surface model.

The guide adds a model called Velvet (stem velvet). Read against the registry
(shaders/shared/surface_models.h) and the dispatch (shaders/shared/bsdf.h), it must:
- list the registered models by name, in registry order, with their ids ("ids 0u to Nu");
- give the next free id in its registry line (`X(Velvet, <count>u, velvet,`);
- name as the model's functions exactly those bsdf.h dispatches to (`<fn>Bsdf<Suffix>`);
- list, in its table of files, files that every registered model has with its own stem, and a
  test file holding `TEST(<Name>,` for each.
Each finding is printed as `docs/adding-a-surface-model.md: message`; exits 1 if any.

    scripts/check_model_guide.py [REPO_ROOT]
"""

import os
import re
import sys

GUIDE = "docs/adding-a-surface-model.md"


def read(root, path):
    with open(os.path.join(root, path), encoding="utf-8") as f:
        return f.read()


def problems(root):
    guide = read(root, GUIDE)
    models = re.findall(r"X\((\w+), (\d+)u, (\w+),", read(root, "shaders/shared/surface_models.h"))
    names = [name for name, _, _ in models]
    if [int(i) for _, i, _ in models] != list(range(len(models))):
        yield "the registry's ids do not count up from 0u"
    listed = re.search(r"lists them \(today ([^)]*), ids 0u to (\d+)u\)", guide)
    if not listed:
        yield "no \"lists them (today ..., ids 0u to Nu)\" sentence"
    else:
        said = [n.strip() for n in re.split(r",|\sand\s", listed.group(1)) if n.strip()]
        if said != names:
            yield "lists the models as %s; the registry has %s" % (said, names)
        if int(listed.group(2)) != len(models) - 1:
            yield "says ids 0u to %su; the last is %du" % (listed.group(2), len(models) - 1)
    line = re.search(r"`X\(Velvet, (\d+)u, velvet,", guide)
    if not line or int(line.group(1)) != len(models):
        yield "the registry line must give the next id, %du" % len(models)
    dispatched = set(re.findall(r"fn##Bsdf(\w+)\(", read(root, "shaders/shared/bsdf.h")))
    named = set(re.findall(r"`velvetBsdf(\w+)`", guide))
    if named != dispatched:
        yield "names the functions %s; bsdf.h dispatches to %s" % (
            sorted("velvetBsdf" + s for s in named), sorted("velvetBsdf" + s for s in dispatched))
    files = re.findall(r"^\| \d+ \| `([^`]*velvet[^`]*)` \|", guide, re.M)
    if len(files) < 3:
        yield "its table of files names %d files of the model (a header, a kernel, a test)" % len(
            files)
    for name, _, stem in models:
        for pattern in files:
            path = pattern.replace("velvet", stem)
            if not os.path.isfile(os.path.join(root, path)):
                yield "names %s for each model; %s has no %s" % (pattern, name, path)
            elif path.endswith("_test.cpp") and "TEST(%s," % name not in read(root, path):
                yield "says %s holds TEST(Velvet, ...); %s has no TEST(%s," % (pattern, path, name)


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..")
    found = list(problems(os.path.abspath(root)))
    for p in found:
        print("%s: %s" % (GUIDE, p))
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
