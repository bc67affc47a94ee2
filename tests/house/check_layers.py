#!/usr/bin/env python3
"""The layering rule of docs/architecture.md, checked on every source file.

Each layer (a folder of src/, its public headers under include/lcsim/<layer>/,
and python/src for the Python module) may include the public headers of the
layers below it in LAYERS and its own headers, nothing else of lcsim's. A
layer's private headers (src/<layer>/*.hpp, included as "<layer>/x.hpp") are
its own: another layer including them is reported too, except the pairs in
PRIVATE_EXCEPTIONS, each with its reason.

Usage: check_layers.py SOURCE_DIR. Exit 0 when the rule holds, 1 with one line
per offending include (file:line: what it includes and why that is not allowed).
"""
import pathlib
import re
import sys

# Bottom to top. A layer may include any layer listed before it (its "below"),
# as long as the dependency is also in its DEPS below (the link order of
# CMakeLists.txt): ipopt and sim are siblings, as are bullet and study.
LAYERS = {
    "core": set(),
    "lcp": {"core"},
    "lcs": {"core", "lcp"},
    "mech": {"core", "lcp", "lcs"},
    "impact": {"core", "lcp", "lcs", "mech"},
    "ipopt": {"core", "lcp", "lcs", "mech", "impact"},
    "sim": {"core", "lcp", "lcs", "mech", "impact"},
    "io": {"core", "lcp", "lcs", "mech", "impact", "sim"},
    "circuit": {"core", "lcp", "lcs", "mech", "impact", "sim", "io"},
    "scene": {"core", "lcp", "lcs", "mech", "impact", "sim", "io", "circuit"},
    "bullet": {"core", "lcp", "lcs", "mech", "impact", "sim", "io", "circuit", "scene"},
    "mujoco": {"core", "lcp", "lcs", "mech", "impact", "sim", "io", "circuit", "scene"},
    "study": {"core", "lcp", "lcs", "mech", "impact", "sim", "io", "circuit", "scene"},
    "app": {"core", "lcp", "lcs", "mech", "impact", "sim", "io", "circuit", "scene", "study"},
    "cli": {"core", "lcp", "lcs", "mech", "impact", "ipopt", "sim", "io", "circuit", "scene",
            "bullet", "mujoco", "study", "app"},
    "python": {"core", "lcp", "lcs", "mech", "impact", "ipopt", "sim", "io", "circuit", "scene",
               "bullet", "mujoco", "study", "app"},
}

# (includer, private header's layer): why it is tolerated.
PRIVATE_EXCEPTIONS = {
    ("ipopt", "impact"): "moreau-qp is an impact law built outside the impact layer only to "
    "keep Ipopt optional; it shares the laws' preparation and finish (src/impact/detail.hpp)",
}

INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]')


def layer_of(path: pathlib.Path, root: pathlib.Path):
    rel = path.relative_to(root).parts
    if rel[0] == "src" and len(rel) > 2:
        return rel[1]
    if rel[0] == "include" and len(rel) > 3 and rel[1] == "lcsim":
        return rel[2]
    if rel[:2] == ("python", "src"):
        return "python"
    return None


def check_file(path, root, layer):
    problems = []
    for n, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
        m = INCLUDE.match(line)
        if not m:
            continue
        target = m.group(2)
        parts = target.split("/")
        if parts[0] == "lcsim" and len(parts) > 2:
            other, private = parts[1], False
        elif m.group(1) == '"' and len(parts) > 1 and parts[0] in LAYERS:
            other, private = parts[0], True
        else:
            continue
        if other == layer:
            continue
        where = f"{path.relative_to(root)}:{n}"
        if other not in LAYERS:
            problems.append(f"{where}: includes {target}: '{other}' is not a layer")
        elif other not in LAYERS[layer]:
            problems.append(f"{where}: layer '{layer}' includes {target} of layer '{other}', "
                            f"which is not below it")
        elif private and (layer, other) not in PRIVATE_EXCEPTIONS:
            problems.append(f"{where}: layer '{layer}' includes {target}, a private header of "
                            f"layer '{other}' (include its public header under lcsim/{other}/)")
    return problems


def main(argv):
    root = pathlib.Path(argv[1] if len(argv) > 1 else ".").resolve()
    problems, files = [], 0
    for sub in ("src", "include/lcsim", "python/src"):
        for path in sorted((root / sub).rglob("*")):
            if path.suffix not in (".cpp", ".hpp", ".h") or not path.is_file():
                continue
            layer = layer_of(path, root)
            if layer is None:
                continue
            if layer not in LAYERS:
                problems.append(f"{path.relative_to(root)}: folder '{layer}' is not a known layer "
                                f"(add it to LAYERS in tests/house/check_layers.py and docs/architecture.md)")
                continue
            files += 1
            problems += check_file(path, root, layer)
    for p in problems:
        print(p)
    print(f"check_layers: {files} files, {len(problems)} includes against the layering")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
