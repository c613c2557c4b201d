#!/usr/bin/env python3
"""The one-way rule of docs/architecture.md, checked on the sources: every #include that names a file of
the tree must come from the file's own layer or a layer below it, and an engine or a variant may include
from its own folder only, never another engine's or variant's.

Layers, lowest first: core/, harness/, engines/<name>/, variants/<name>/, then the front end and the
studies (app/, bench/). tests/ and the ports' Fortran and Pascal sources are not scanned.

Usage: check_layers.py [--root DIR] [--expect FILE ...]
  Without --expect: exit 0 when no include breaks the rule, 1 (one line per include) when one does.
  With --expect: exit 0 only when the files that break the rule are exactly those named (the check of
  the checker itself, on a tree made wrong on purpose).
"""
import argparse
import re
import sys
from pathlib import Path

SOURCES = {".hpp", ".cpp", ".h", ".cu", ".cuh"}
INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]([^">]+)[">]')
FOLDED = ("engines", "variants")  # layers made of folders that must not include each other
RANK = {"core": 0, "harness": 1, "engines": 2, "variants": 3, "app": 4, "bench": 4}


def unit(root, path):
    """(layer, folder) of a file: folder is the engine's or the variant's name, else the layer."""
    parts = path.relative_to(root).parts
    if parts[0] in FOLDED and len(parts) > 2:
        return parts[0], parts[1]
    return parts[0], parts[0]


def search_dirs(root):
    """Where an include that is not beside its file is looked for: every layer's include folder and
    every variant's folder (the programs' and tests' include paths hold some of them)."""
    dirs = [root / "core" / "include", root / "harness" / "include"]
    dirs += sorted(p / "include" for p in (root / "engines").glob("*") if (p / "include").is_dir())
    dirs += sorted(p for p in (root / "variants").glob("*") if p.is_dir())
    return dirs


def resolve(root, source, name, dirs):
    for d in [source.parent] + dirs:
        candidate = d / name
        if candidate.is_file():
            return candidate.resolve()
    return None


def violations(root):
    root = root.resolve()
    dirs = search_dirs(root)
    found = []
    for layer in RANK:
        base = root / layer
        if not base.is_dir():
            continue
        for source in sorted(p for p in base.rglob("*") if p.suffix in SOURCES and p.is_file()):
            own_layer, own_folder = unit(root, source)
            for number, line in enumerate(source.read_text(errors="replace").splitlines(), 1):
                m = INCLUDE.match(line)
                if not m:
                    continue
                target = resolve(root, source, m.group(1), dirs)
                if target is None or root not in target.parents:
                    continue  # a system or third-party header
                layer_of, folder_of = unit(root, target)
                where = f"{source.relative_to(root)}:{number}: includes {target.relative_to(root)}"
                if layer_of not in RANK:
                    found.append((source, f"{where}, outside every layer"))
                elif RANK[layer_of] > RANK[own_layer]:
                    found.append((source, f"{where}, from the layer above ({layer_of}/ over {own_layer}/)"))
                elif layer_of == own_layer and layer_of in FOLDED and folder_of != own_folder:
                    found.append((source, f"{where}, another {layer_of[:-1]}'s folder"))
    return root, found


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--root", type=Path, default=Path(__file__).resolve().parent.parent)
    parser.add_argument("--expect", nargs="*", default=None, help="files (relative to ROOT) that must break the rule")
    args = parser.parse_args()
    root, found = violations(args.root)
    for _, message in found:
        print(message)
    if args.expect is None:
        if found:
            print(f"check_layers: {len(found)} include(s) against the one-way rule (docs/architecture.md)")
        return 1 if found else 0
    got = {str(source.relative_to(root)) for source, _ in found}
    want = set(args.expect)
    if got != want:
        print(f"check_layers: expected violations in {sorted(want)}, found them in {sorted(got)}")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
