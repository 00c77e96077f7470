#!/usr/bin/env python3
"""No include runs back up a layer: every `#include "dir/..."` of a repository file in a component's
sources names the component itself or one it may use, by the layer picture in docs/design.md (the
```layers block: "component: what it uses directly"; what those use is allowed in turn).
Usage: layering_test.py REPO_ROOT"""
import os
import re
import sys


def read_layers(design_md):
    text = open(design_md, encoding="utf-8").read()
    found = re.search(r"```layers\n(.*?)```", text, re.S)
    if not found:
        sys.exit(f"{design_md}: no ```layers block")
    direct = {}
    for line in found.group(1).splitlines():
        if not line.strip():
            continue
        name, _, uses = line.partition(":")
        direct[name.strip()] = uses.split()
    for name, uses in direct.items():
        for used in uses:
            if used not in direct:
                sys.exit(f"{design_md}: {name} uses {used}, which the picture does not list")
    return direct


def allowed(direct):
    closure = {}

    def reach(name, trail):
        if name in trail:
            sys.exit("the layer picture has a cycle: " + " -> ".join(trail + [name]))
        if name not in closure:
            out = set()
            for used in direct[name]:
                out |= {used} | reach(used, trail + [name])
            closure[name] = out
        return closure[name]

    for name in direct:
        reach(name, [])
    return closure


def component_of(path, components):
    # The longest listed prefix: surrogate/gp/x.hpp is surrogate/gp's.
    best = None
    for c in components:
        if path == c or path.startswith(c + "/"):
            if best is None or len(c) > len(best):
                best = c
    return best


def main():
    root = sys.argv[1]
    direct = read_layers(os.path.join(root, "docs", "design.md"))
    may_use = allowed(direct)
    tops = sorted({c.split("/")[0] for c in direct})
    problems = []
    for top in tops:
        for folder, _, files in os.walk(os.path.join(root, top)):
            for name in files:
                if not name.endswith((".cpp", ".hpp", ".h", ".c")):
                    continue
                path = os.path.relpath(os.path.join(folder, name), root)
                owner = component_of(path, direct)
                if owner is None:
                    problems.append(f"{path}: its folder is not in the layer picture (docs/design.md)")
                    continue
                for number, line in enumerate(open(os.path.join(root, path), encoding="utf-8"), 1):
                    m = re.match(r'\s*#\s*include\s+"([^"]+)"', line)
                    if not m or not os.path.exists(os.path.join(root, m.group(1))):
                        continue
                    target = component_of(m.group(1), direct)
                    if target is not None and target != owner and target not in may_use[owner]:
                        problems.append(f"{path}:{number}: {owner} includes {m.group(1)} ({target}), "
                                        f"above it or beside it in the layer picture")
    for p in problems:
        print(p)
    if problems:
        sys.exit(1)
    print(f"layers: {len(direct)} components, no include runs back up")


if __name__ == "__main__":
    main()
