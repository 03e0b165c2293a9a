#!/usr/bin/env python3
"""Lists the longest C++ functions and the longest files of the given folders.

A function is a brace block opened outside any other function whose head (the text since the
previous ';', '{' or '}') has a parameter list and is not a namespace, class, struct, enum,
union or initialiser; its length counts the lines from the head's first line to the closing
brace. Lambdas and local classes count toward their enclosing function. Strings, character
literals and comments are skipped, so braces inside them do not count.

Usage: scripts/function-lengths.py [--top N] [--max-function L] [--max-file L] FOLDER...
With --max-function / --max-file it exits 1 when a function or file is longer (one line each).
"""
import argparse
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
NOT_FUNCTION = re.compile(r"\b(namespace|class|struct|enum|union|extern\s+\"C\")\b[^()]*$")
CONTROL = re.compile(r"^\s*(if|for|while|switch|catch|do|else)\b")


def strip_code(text):
    """The text with comments, strings and char literals blanked (newlines kept)."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append("".join(ch if ch == "\n" else " " for ch in text[i:j]))
            i = j
        elif c == "'" and i > 0 and text[i - 1].isalnum() and text[i - 1] != "L":
            out.append(c)  # a digit separator (100'000), not a character literal
            i += 1
        elif c in "\"'":
            raw = c == '"' and i > 0 and text[i - 1] == "R"
            if raw:
                m = re.match(r'"([^(]*)\(', text[i:])
                end = text.find(")" + m.group(1) + '"', i) if m else -1
                j = n if end < 0 else end + len(m.group(1)) + 2
            else:
                j = i + 1
                while j < n and text[j] != c:
                    j += 2 if text[j] == "\\" else 1
                j += 1
            out.append(c + "".join(ch if ch == "\n" else " " for ch in text[i + 1:j - 1]) + c)
            i = j
        else:
            out.append(c)
            i += 1
    return "".join(out)


def functions(path):
    """(name, first line, length) of every function defined in the file."""
    code = strip_code(path.read_text(errors="replace"))
    code = re.sub(r"^\s*#.*$", "", code, flags=re.M)
    found, stack, head_start = [], [], 0
    for i, c in enumerate(code):
        if c in ";":
            if not any(kind == "function" for kind, _, _ in stack):
                head_start = i + 1
        elif c == "{":
            inside = any(kind == "function" for kind, _, _ in stack)
            head = code[head_start:i]
            is_function = (not inside and ")" in head and not NOT_FUNCTION.search(head)
                           and not CONTROL.match(head) and not head.rstrip().endswith("="))
            start = head_start + len(head) - len(head.lstrip())
            stack.append(("function" if is_function else "block", start, head))
            if not inside:
                head_start = i + 1
        elif c == "}" and stack:
            kind, start, head = stack.pop()
            if kind == "function":
                first = code.count("\n", 0, start) + 1
                last = code.count("\n", 0, i) + 1
                name = re.findall(r"([~\w:]+)\s*\(", head)
                found.append((name[0] if name else "?", first, last - first + 1))
            if not any(k == "function" for k, _, _ in stack):
                head_start = i + 1
    return found


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folders", nargs="+")
    parser.add_argument("--top", type=int, default=10)
    parser.add_argument("--max-function", type=int)
    parser.add_argument("--max-file", type=int)
    args = parser.parse_args()
    rows, files = [], []
    for folder in args.folders:
        for path in sorted((ROOT / folder).rglob("*")):
            if path.suffix in {".cpp", ".h", ".hpp", ".c"}:
                rel = path.relative_to(ROOT)
                files.append((len(path.read_text(errors="replace").splitlines()), str(rel)))
                rows += [(length, f"{rel}:{line}", name) for name, line, length in functions(path)]
    rows.sort(reverse=True)
    files.sort(reverse=True)
    print(f"{len(rows)} functions: {sum(r[0] > 40 for r in rows)} over 40 lines, "
          f"{sum(r[0] > 80 for r in rows)} over 80; {len(files)} files, "
          f"{sum(lines for lines, _ in files)} lines, {sum(f[0] > 600 for f in files)} over 600")
    for length, where, name in rows[:args.top]:
        print(f"  {length:5d}  {where}  {name}")
    bad = 0
    if args.max_function is not None:
        for length, where, name in rows:
            if length > args.max_function:
                print(f"{where}: {name} is {length} lines (at most {args.max_function})",
                      file=sys.stderr)
                bad += 1
    if args.max_file is not None:
        for lines, rel in files:
            if lines > args.max_file:
                print(f"{rel}: {lines} lines (at most {args.max_file})", file=sys.stderr)
                bad += 1
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
