#!/usr/bin/env bash
# golden-diff.sh REV: the emitted code of every golden model (tests/golden.sh),
# built by the mbcc of git revision REV and by the working tree, as a unified
# diff on stdout.  Empty output: the working tree emits byte-identical code.
set -eu
cd "$(dirname "$0")/.."
rev=${1:?usage: scripts/golden-diff.sh REV}
tmp=$(mktemp -d)
trap 'git worktree remove --force "$tmp/wt" >/dev/null 2>&1 || true; rm -rf "$tmp"' EXIT
git worktree add --detach "$tmp/wt" "$rev" >/dev/null 2>&1
make -s -C "$tmp/wt" -j2 all >/dev/null
make -s -j2 all >/dev/null
# this tree's list of models and scenes, run in both trees (the same relative paths)
script=tests/golden.sh
cp "$script" "$tmp/wt/tests/golden.sh"
(cd "$tmp/wt" && MBCC="$tmp/wt/build/mbcc" bash tests/golden.sh --out "$tmp/old" >/dev/null 2>&1) || true
bash "$script" --out "$tmp/new" >/dev/null 2>&1 || true
diff -ru "$tmp/old" "$tmp/new" | sed "s|$tmp/||g" || true
