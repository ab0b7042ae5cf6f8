#!/usr/bin/env bash
# test_docs_fresh.sh: scripts/docs-fresh.sh (make release-check) finds a stale
# generated document (exit 0 = pass).  In a scratch git repository holding the
# script, a docs/results.md and the code it describes:
#   - right after the document is committed: fresh (exit 0);
#   - after a later commit that changes compiler/: stale (exit 1), naming
#     docs/results.md and `make results`; a change of unrelated files does not;
#   - an uncommitted change of the code counts as well;
#   - regenerated and committed again: fresh.
# The real repository's documents are checked by make release-check, not here
# (see the script: they lag by design between releases).
set -u
cd "$(dirname "$0")/.."
# shellcheck source=tests/shell_setup.sh
. tests/shell_setup.sh

mkdir -p repo/scripts repo/docs repo/compiler repo/runtime repo/templates repo/models
cp "$root/scripts/docs-fresh.sh" repo/scripts/
cd repo || exit 1
g() { git -c user.name=t -c user.email=t@t "$@" > /dev/null 2>&1; }
g init -q
echo code > compiler/a.c; echo gen > scripts/results.sh; echo unrelated > README.md
g add -A; g commit -qm code
echo "results v1" > docs/results.md; g add -A; g commit -qm results
bash scripts/docs-fresh.sh docs/results.md > o1 2>&1 || err "fresh document reported stale: $(cat o1)"
echo more >> README.md; g commit -qam readme
bash scripts/docs-fresh.sh docs/results.md > o2 2>&1 || err "an unrelated change made it stale: $(cat o2)"
echo changed >> compiler/a.c
bash scripts/docs-fresh.sh docs/results.md > o3 2>&1 && err "an uncommitted code change went unnoticed"
g commit -qam "compiler change"
bash scripts/docs-fresh.sh docs/results.md > o4 2>&1
[ $? = 1 ] || err "a later code commit did not make docs/results.md stale"
grep -q 'docs/results.md: stale.*make results' o4 || err "the stale report does not say what to run: $(cat o4)"
echo "results v2" > docs/results.md; g commit -qam regenerated
bash scripts/docs-fresh.sh docs/results.md > o5 2>&1 || err "regenerated document reported stale: $(cat o5)"
exit $fail
