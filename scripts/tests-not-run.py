#!/usr/bin/env python3
"""Prints a ctest -I list ("0,0,0,N,M,...") of the tests in BUILD (those ctest selects with
the extra ctest arguments given) whose names are not in RUN_LIST, one name per line (the list
scripts/asan.sh writes of the tests it ran), and those whose names match --also REGEX
(tests that check something else when sanitized), less those whose names match --skip REGEX.
scripts/test.sh --full runs these unsanitized, so that each test runs once. Prints "0,0,0" and
nothing else when there are none. The selection must not use ctest's -E: with it, ctest -N
numbers the tests after an excluded one afresh, while -I takes the numbers of the whole list
(-L and -LE keep them).

    scripts/tests-not-run.py [--also REGEX] [--skip REGEX] BUILD RUN_LIST [ctest selection...]
"""
import re
import subprocess
import sys


def main() -> int:
    args = sys.argv[1:]
    options = {"--also": None, "--skip": None}
    while args[:1] and args[0] in options and len(args) >= 2:
        options[args[0]], args = re.compile(args[1]), args[2:]
    also, skip = options["--also"], options["--skip"]
    if len(args) < 2:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    build, run_list, selection = args[0], args[1], args[2:]
    with open(run_list, encoding="utf-8") as f:
        ran = {line.rstrip("\n") for line in f}
    listing = subprocess.run(["ctest", "-N", *selection], cwd=build, check=True,
                             capture_output=True, text=True).stdout
    numbers = [m.group(1) for m in re.finditer(r"^\s*Test\s+#(\d+): (.*)$", listing, re.M)
               if (m.group(2) not in ran or (also and also.search(m.group(2))))
               and not (skip and skip.search(m.group(2)))]
    print(",".join(["0", "0", "0", *numbers]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
