#!/usr/bin/env bash
# Installs the Khronos glTF-Validator (npm gltf-validator, the version pinned by
# tests/gltf/package-lock.json) into DEST/node_modules with `npm ci`, for
# tests/gltf/oracle_test.py. Skipped when DEST already holds an install made from the same
# lock file. Fails (non-zero, npm's message on stderr) when npm or its registry is unreachable.
#   tests/gltf/install.sh DEST
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
dest=${1:?usage: install.sh DEST}
mkdir -p "$dest"
if [[ -f "$dest/node_modules/gltf-validator/package.json" ]] &&
   cmp -s "$here/package-lock.json" "$dest/package-lock.json"; then
  exit 0
fi
command -v npm >/dev/null || { echo "install.sh: npm not found (scripts/install-deps.sh installs it)" >&2; exit 1; }
cp "$here/package.json" "$here/package-lock.json" "$dest/"
(cd "$dest" && npm ci --no-audit --no-fund --loglevel=error)
