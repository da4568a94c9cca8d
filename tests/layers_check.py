#!/usr/bin/python3
"""Checks the layer rule of docs/design.md §2 on the source tree.

Every library file belongs to one target by its path; it may include project headers
(`#include "brdf/<target>/..."`) only of its own target and of the targets that table lets it
depend on, and every public header lives in `<folder>/include/brdf/<target>/` of its target's
folder. The table below is transcribed from docs/design.md §2 ("may depend on"), not derived from
the build files, so a new include that breaks the layering fails here even if CMake links it.

Usage: layers_check.py SOURCE_DIR [--control]
--control checks the checker: it injects an include of brdf::exporter into a brdf::core source
(in memory) and succeeds only if exactly that one problem is reported.
"""
import pathlib
import re
import sys

# target -> (folder that holds it, targets it may include besides itself)
TARGETS = {
    "core": ("processing", set()),
    "processing": ("processing", {"core"}),
    "fit": ("processing", {"core", "processing"}),
    "device": ("device", {"core"}),
    "device_emulation": ("device/emulation", {"core", "device"}),
    "image_io": ("export", {"core"}),
    "exporter": ("export", {"core", "image_io"}),
    "engines": ("export/engines", {"core", "image_io", "exporter"}),
    "sources": ("sources", {"core", "processing", "image_io", "exporter"}),
    "preview": ("preview", {"core", "image_io"}),
    "viewer": ("viewer", {"core", "processing", "fit", "image_io", "exporter", "sources", "preview"}),
}

# Private sources: path prefix -> target (longest prefix wins).
PRIVATE = {
    "processing/src/core/": "core",
    "processing/src/processing/": "processing",
    "processing/src/fit/": "fit",
    "device/src/": "device",
    "device/emulation/src/": "device_emulation",
    "export/src/image_io/": "image_io",
    "export/src/": "exporter",
    "export/engines/src/": "engines",
    "sources/src/": "sources",
    "preview/src/": "preview",
    "viewer/src/": "viewer",
}

INCLUDE = re.compile(r'^\s*#\s*include\s+"brdf/([a-z_0-9]+)/', re.M)


def target_of(rel):
    m = re.match(r"(.+)/include/brdf/([a-z_0-9]+)/", rel)
    if m:
        folder, target = m.group(1), m.group(2)
        if target not in TARGETS:
            return None, f"{rel}: public header under include/brdf/{target}/, which names no target"
        if TARGETS[target][0] != folder:
            return None, (f"{rel}: public header of brdf::{target} in {folder}/, "
                          f"expected {TARGETS[target][0]}/include/brdf/{target}/")
        return target, None
    best = None
    for prefix, target in PRIVATE.items():
        if rel.startswith(prefix) and (best is None or len(prefix) > len(best[0])):
            best = (prefix, target)
    return (best[1] if best else None), None


CONTROL_FILE = "processing/src/core/lut.cpp"


def check(root, inject=None):
    problems = []
    checked = 0
    for path in sorted(root.rglob("*")):
        if path.suffix not in (".h", ".cpp", ".hpp", ".inc") or not path.is_file():
            continue
        rel = path.relative_to(root).as_posix()
        if rel.startswith(("build/", "tests/", "bench/", "fuzz/", "tools/", ".git/")):
            continue
        target, problem = target_of(rel)
        if problem:
            problems.append(problem)
            continue
        if target is None:
            if "/include/" in rel or rel.split("/")[0] in {f.split("/")[0] for f, _ in TARGETS.values()}:
                problems.append(f"{rel}: belongs to no library target of docs/design.md §2")
            continue
        checked += 1
        allowed = TARGETS[target][1] | {target}
        text = path.read_text(encoding="utf-8", errors="replace")
        if inject and rel == inject[0]:
            text = inject[1] + text
        for m in INCLUDE.finditer(text):
            inc = m.group(1)
            if inc not in allowed:
                line = text.count("\n", 0, m.start()) + 1
                problems.append(f"{rel}:{line}: brdf::{target} includes a header of brdf::{inc}, "
                                f"which it may not depend on (docs/design.md §2)")
    if checked < 100:
        problems.append(f"only {checked} library files found under {root}: wrong folder?")
    return checked, problems


def main():
    root = pathlib.Path(sys.argv[1]).resolve()
    if "--control" in sys.argv[2:]:
        checked, problems = check(root, (CONTROL_FILE, '#include "brdf/exporter/ktx2.h"\n'))
        expected = f"{CONTROL_FILE}:1: brdf::core includes a header of brdf::exporter"
        ok = len(problems) == 1 and problems[0].startswith(expected)
        print(f"layers_check control: {'caught' if ok else 'MISSED'} the injected include "
              f"({len(problems)} problem(s): {problems})")
        return 0 if ok else 1
    checked, problems = check(root)
    for p in problems:
        print(p)
    print(f"layers_check: {checked} library files, {len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
