#!/usr/bin/env python3
"""Checks the project's size rules on production code: a function at most 80 lines, a file at
most 600, a unit (a header and its source: X.h + X.cpp, also .hpp and .c) at most 800.

Production code is every top-level folder with C/C++ sources except tests/, bench/, fuzz/ and
examples/ (and build folders). Functions are found as scripts/function-lengths.py finds them.
A violation listed in ALLOWED is reported but does not fail; an ALLOWED entry that no longer
violates fails, so the list only shrinks.
Usage: scripts/check-lengths.py   (exit 1 and one line per violation; a summary on stderr)
"""
import importlib.util
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
MAX_FUNCTION, MAX_FILE, MAX_UNIT = 80, 600, 800
NOT_PRODUCTION = {"tests", "bench", "fuzz", "examples"}
SOURCES = {".h", ".hpp", ".cpp", ".c"}

# Violations in files being reshaped elsewhere, allowed until that work lands: "unit X",
# "file X" or "function FILE:NAME". Each line says why; remove it when its code is split.
ALLOWED: set[str] = set()

_spec = importlib.util.spec_from_file_location("function_lengths",
                                               ROOT / "scripts" / "function-lengths.py")
_lengths = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_lengths)


def production_files():
    for folder in sorted(p for p in ROOT.iterdir() if p.is_dir()):
        if folder.name.startswith((".", "build")) or folder.name in NOT_PRODUCTION:
            continue
        yield from sorted(p for p in folder.rglob("*") if p.suffix in SOURCES and p.is_file())


def violations():
    """(key, message) of every rule broken, key as ALLOWED spells it."""
    found, units = [], {}
    for path in production_files():
        rel = path.relative_to(ROOT)
        lines = len(path.read_text(errors="replace").splitlines())
        units.setdefault(str(rel.with_suffix("")), []).append((str(rel), lines))
        if lines > MAX_FILE:
            found.append((f"file {rel}", f"{rel}: {lines} lines (a file at most {MAX_FILE})"))
        for name, first, length in _lengths.functions(path):
            if length > MAX_FUNCTION:
                found.append((f"function {rel}:{name}", f"{rel}:{first}: {name} is {length} "
                              f"lines (a function at most {MAX_FUNCTION})"))
    for unit, files in sorted(units.items()):
        total = sum(lines for _, lines in files)
        if len(files) > 1 and total > MAX_UNIT:
            parts = " + ".join(f"{name} {lines}" for name, lines in files)
            found.append((f"unit {unit}", f"{unit}: {total} lines ({parts}; a header and its "
                          f"source at most {MAX_UNIT})"))
    return found, len(units)


def main():
    found, unitCount = violations()
    keys = {key for key, _ in found}
    allowed = bad = 0
    for key, message in found:
        if key in ALLOWED:
            print(f"allowed: {message}")
            allowed += 1
        else:
            print(message)
            bad += 1
    for key in sorted(ALLOWED - keys):
        print(f"scripts/check-lengths.py: ALLOWED lists \"{key}\", which no longer breaks a "
              "rule: remove it")
        bad += 1
    print(f"check-lengths: {unitCount} units, {len(found)} over the limits ({allowed} allowed), "
          f"{bad} failing", file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
