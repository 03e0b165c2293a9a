#!/usr/bin/env bash
# dpc studio in a real browser (tests/studio/browser_test.mjs): installs puppeteer-core from
# npm into the build (scripts/npm-ci.sh; fails when npm cannot), then runs the test with
# Debian's chromium. Exit 77 (ctest's SKIP_RETURN_CODE) only when chromium is missing or
# cannot start here.
#   tests/studio/browser_test.sh BUILD SOURCE [--live] [--python PY] [--screenshot PNG]
#                                [--bake-screenshot PNG] [--bake-only]
# --python: a Python with h5py, the oracle of the bake view's check (skipped without it).
# --bake-only: the bake view's checks alone.
set -euo pipefail
build=${1:?usage: browser_test.sh BUILD SOURCE}
src=${2:?usage: browser_test.sh BUILD SOURCE}
chromium=$(command -v chromium || true)
if [[ -z "$chromium" ]]; then
  echo "browser_test: chromium not installed (scripts/install-deps.sh installs it): skipped" >&2
  exit 77
fi
if ! timeout 60 "$chromium" --headless --no-sandbox --disable-gpu --dump-dom about:blank \
       >/dev/null 2>&1; then
  echo "browser_test: chromium cannot start here: skipped" >&2
  exit 77
fi
npm_dir="$build/tests/studio-npm"
"$src/scripts/npm-ci.sh" "$src/tests/studio" "$npm_dir"
test=(node "$src/tests/studio/browser_test.mjs" --build "$build" --source "$src"
      --chromium "$chromium" --npm "$npm_dir" "${@:3}")
# --live: dpc-demo plays through a JACK server of the dummy backend for the test's length.
for a in "${@:3}"; do
  if [[ $a == --live ]]; then exec "$src/scripts/jack-headless.sh" "${test[@]}"; fi
done
exec "${test[@]}"
