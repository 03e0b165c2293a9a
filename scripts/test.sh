#!/usr/bin/env bash
# Installs what is missing, builds everything, and runs every test (ctest).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
(cd build && ctest --output-on-failure -j"$(nproc 2>/dev/null || echo 2)" --timeout 600)
# The installed package: both examples built out of tree against a fresh prefix and run.
scripts/test-install.sh
# The queue and live-pipeline threads under ThreadSanitizer (separate build in build-tsan).
scripts/tsan.sh
# AddressSanitizer + UBSan build of everything and the whole ctest (build-asan; the JACK and
# LV2-host tests excepted, see the script), and a 15 s libFuzzer run per fuzz target
# (build-fuzz, clang).
scripts/asan.sh
scripts/fuzz.sh 15
