#!/usr/bin/env bash
# The README's test command. Installs what is missing, checks the layer table and the size
# rules, builds, runs every test (ctest) and the install test.
#   scripts/test.sh          the quick run (its ctest about 12 minutes on 2 cores; a cold build as long)
#   scripts/test.sh --full   adds the Monte Carlo [statistics] tests, the 60 s live JACK run,
#                            ThreadSanitizer, AddressSanitizer +
#                            UBSan and libFuzzer runs (what CI runs: .ci/run)
set -euo pipefail
cd "$(dirname "$0")/.."
full=0
case "${1:-}" in
  --full) full=1 ;;
  "") ;;
  *) echo "usage: scripts/test.sh [--full]" >&2; exit 2 ;;
esac
scripts/install-deps.sh
# Every #include against docs/design.md's layer table.
python3 scripts/check-layers.py
# The size rules on production code: a function <= 80 lines, a file <= 600, a header + source
# unit <= 800 (its allow-list names the exceptions still being split).
python3 scripts/check-lengths.py
scripts/build.sh
# Tests labelled "full" (the 60 s live JACK run) and "statistics" (Monte Carlo checks over many
# rays, frames or seeds; tests/CMakeLists.txt) only with --full.
(cd build && ctest --output-on-failure -j"$(nproc 2>/dev/null || echo 2)" --timeout 600 \
   -LE 'full|statistics')
# The installed package: both examples built out of tree against a fresh prefix and run.
scripts/test-install.sh
if ((full)); then
  (cd build && ctest --output-on-failure -j"$(nproc 2>/dev/null || echo 2)" --timeout 600 \
     -L statistics)
  (cd build && ctest --output-on-failure --timeout 600 -L full)
  # The queue and live-pipeline threads under ThreadSanitizer (separate build in build-tsan).
  scripts/tsan.sh
  # AddressSanitizer + UBSan build of everything and the whole ctest (build-asan; the JACK and
  # LV2-host tests excepted, see the script), and a 15 s libFuzzer run per fuzz target
  # (build-fuzz, clang).
  scripts/asan.sh
  scripts/fuzz.sh 15
fi
