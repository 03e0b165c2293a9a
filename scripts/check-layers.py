#!/usr/bin/env python3
"""Checks every project #include against the layer table of docs/design.md.

Each row of the table "| folder | library | may include | ... |" names a folder and the
folders its files may include (its own always; "any" for no restriction). An
#include "X/..." whose X is a project folder outside that list is a layer violation.
Usage: scripts/check-layers.py   (exit 1 and one line per violation)
"""
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
TABLE_ROW = re.compile(r"^\|\s*(`[^|]+`)\s*\|[^|]*\|([^|]*)\|")
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"/]+)/[^"]+"', re.M)


def layer_table():
    text = (ROOT / "docs" / "design.md").read_text()
    section = text.split("## Layers and what each may know", 1)[1].split("\n## ", 1)[0]
    rules = {}
    for line in section.splitlines():
        row = TABLE_ROW.match(line)
        if not row:
            continue
        folders = re.findall(r"`([^`]+?)/?`", row.group(1))
        allowed = {a.strip() for a in row.group(2).split(",") if a.strip()}
        for folder in folders:
            rules[folder.split("/")[0]] = allowed
    return rules


def main():
    rules = layer_table()
    if not rules:
        print("check-layers: no layer table in docs/design.md", file=sys.stderr)
        return 1
    project = {p.name for p in ROOT.iterdir() if p.is_dir()} - {"build"}
    bad = 0
    for folder, allowed in sorted(rules.items()):
        if "any" in allowed:
            continue
        for path in sorted((ROOT / folder).rglob("*")):
            if path.suffix not in {".h", ".hpp", ".cpp", ".c"}:
                continue
            for target in INCLUDE.findall(path.read_text(errors="replace")):
                if target in project and target != folder and target not in allowed:
                    print(f"{path.relative_to(ROOT)}: includes {target}/, which layer "
                          f"{folder}/ may not (docs/design.md layer table)")
                    bad += 1
    unlisted = sorted(
        p.name for p in ROOT.iterdir()
        if p.is_dir() and not p.name.startswith((".", "build")) and p.name not in rules
        and any(p.rglob("*.cpp")))
    for name in unlisted:
        print(f"{name}/: holds C++ sources but has no row in docs/design.md's layer table")
        bad += 1
    print(f"check-layers: {len(rules)} layers, {bad} violations", file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
