#!/usr/bin/env bash
# Checks that the working tree renders every shipped scene byte-identically to revision REV
# (default: the merge base with origin/main, else HEAD~1). REV is built in a temporary git
# worktree (ccache, when installed, shares the compiled objects); both builds render with
# scripts/render-all.sh and their SHA-256 manifests are compared. Exit 1 names each file
# that differs.
# Usage: scripts/check-identical.sh [REV] [DURATION_S]
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
rev=${1:-$(git merge-base HEAD origin/main 2>/dev/null || git rev-parse HEAD~1)}
duration=${2:-1}
work=${DPC_IDENTICAL_WORK:-$(mktemp -d)}
ref=$work/ref-src
if [[ ! -d $ref ]]; then
  git worktree add --detach "$ref" "$rev" >/dev/null
  trap 'git -C "$root" worktree remove --force "$ref" >/dev/null 2>&1 || true' EXIT
fi
echo "check-identical: building $rev in $ref" >&2
(cd "$ref" && scripts/build.sh dpc-demo >/dev/null)
echo "check-identical: building the working tree" >&2
scripts/build.sh dpc-demo >/dev/null
scripts/render-all.sh "$ref/build" "$work/ref" "$duration"
scripts/render-all.sh build "$work/new" "$duration"
if diff "$work/ref/SHA256SUMS" "$work/new/SHA256SUMS" >"$work/diff"; then
  echo "check-identical: $(wc -l <"$work/new/SHA256SUMS") files byte-identical to $rev"
else
  echo "check-identical: files differ from $rev:" >&2
  grep '^>' "$work/diff" | awk '{print "  " $3}' >&2
  exit 1
fi
