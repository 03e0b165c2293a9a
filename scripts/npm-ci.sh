#!/usr/bin/env bash
# Installs the npm packages pinned by SRC/package-lock.json into DEST/node_modules with
# `npm ci` (nothing is committed under node_modules). Skipped when DEST already holds an install
# made from the same lock file. Fails (non-zero, npm's message on stderr) when npm or its
# registry is unreachable.
#   scripts/npm-ci.sh SRC DEST      e.g. studio/web build/studio/npm (three.js for dpc studio)
set -euo pipefail
src=${1:?usage: npm-ci.sh SRC DEST}
dest=${2:?usage: npm-ci.sh SRC DEST}
mkdir -p "$dest"
if [[ -d "$dest/node_modules" ]] && cmp -s "$src/package-lock.json" "$dest/package-lock.json"; then
  exit 0
fi
command -v npm >/dev/null || { echo "npm-ci.sh: npm not found (scripts/install-deps.sh installs it)" >&2; exit 1; }
cp "$src/package.json" "$src/package-lock.json" "$dest/"
(cd "$dest" && npm ci --no-audit --no-fund --loglevel=error)
