#!/usr/bin/env python3
"""docs/adding-a-surface-model.md says what the code requires of a surface model.

The guide adds a model called Velvet (stem velvet). Read against the registry
(shaders/shared/surface_models.h) and the dispatch (shaders/shared/bsdf.h), it must:
- list the registered models by name, in registry order, with their ids ("ids 0u to Nu");
- give the next free id in its registry line (`X(Velvet, <count>u, velvet,`);
- name as the model's functions exactly those bsdf.h dispatches to (`<fn>Bsdf<Suffix>`);
- list, in its table of files, files that every registered model has with its own stem, and a
  test file holding `TEST(<Name>,` for each;
- have every registered model's line in docs/scene-format.md's table of shaders, as it tells
  a model's author to write one;
- give the line of host/cpu/wide_models.h (`X(Velvet, velvet)`) and the one lanes file of a SIMD
  twin, which every model that list names has, holding its `struct <Name>LanesModel`.
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


def models_stems(models):
    return [(name, stem) for name, _, stem in models]


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
    files = [f for f in re.findall(r"^\| \d+ \| `([^`]*velvet[^`]*)` \|", guide, re.M)
             if not f.startswith("host/cpu/")]  # a SIMD twin's, checked above
    if len(files) < 3:
        yield "its table of files names %d files of the model (a header, a kernel, a test)" % len(
            files)
    wide = re.findall(r"^\s*X\((\w+), (\w+)\)", read(root, "host/cpu/wide_models.h"), re.M)
    if not wide or [n for n, _ in wide] != [n for n in names if n in dict(wide)]:
        yield "host/cpu/wide_models.h lists %s: models of the registry, in its order" % wide
    if "`X(Velvet, velvet)`" not in guide:
        yield "no `X(Velvet, velvet)` line for host/cpu/wide_models.h"
    lanes = re.findall(r"^\| \d+ \| `(host/cpu/velvet[^`]*)` \|", guide, re.M)
    if len(lanes) != 1:
        yield "its table of a twin's files names %d lanes files (one: host/cpu/velvet_lanes-inl.h)" % (
            len(lanes))
    stems = dict(models_stems(models))
    for name, stem in wide:
        if stems.get(name) != stem:
            yield "host/cpu/wide_models.h gives %s the stem %s; the registry %s" % (
                name, stem, stems.get(name))
        for pattern in lanes:
            path = pattern.replace("velvet", stem)
            if not os.path.isfile(os.path.join(root, path)):
                yield "names %s for each SIMD-wide model; %s has no %s" % (pattern, name, path)
            elif "struct %sLanesModel" % name not in read(root, path):
                yield "%s holds no struct %sLanesModel" % (path, name)
    shader_table = re.findall(r"^\| `(\w+)` \|", read(root, "docs/scene-format.md"), re.M)
    for name in names:
        if name not in shader_table:
            yield ("tells a model's author to give it a line in docs/scene-format.md; %s has none "
                   "(| `%s` | its keys | what it is |)" % (name, name))
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
