#!/usr/bin/env bash
# docs-fresh.sh: are the generated documents current?  A document that a make
# target writes from measurements (docs/results.md: make results, ...) is
# stale when a commit after the one that last wrote it changed the code it
# measures.  "After" is git's history order (rev-list DOC_COMMIT..HEAD), not
# the commit timestamps, which a rebase rewrites.  Prints one line per stale
# document with the target that regenerates it; exits 1 if any is stale.
# Run before a release (make release-check), not by `make test`: with several
# people changing the code every day the measured pages lag by design, and
# regenerating them takes tens of minutes.
# Usage: scripts/docs-fresh.sh [DOC ...]   (default: every document below)
set -u
cd "$(dirname "$0")/.." || exit 2

# document | make target | the code it describes (paths for git)
table='docs/results.md|results|scripts/results.sh scripts/lib.sh compiler runtime templates models/pendulum.yaml models/slider_crank.yaml models/slider_crank_flexible.yaml
docs/benchmarks.md|bench|scripts/bench.sh scripts/peers.sh scripts/lib.sh scripts/mjcf_from_yaml.py bench compiler runtime templates models
docs/peers.md|peers|scripts/peers.sh scripts/lib.sh scripts/mjcf_from_yaml.py bench/peers compiler runtime templates
docs/trade.md|trade|scripts/trade.sh scripts/lib.sh compiler runtime templates models/slider_crank_flexible.yaml
docs/stability.md|extremes|tests/extremes compiler runtime templates
docs/vehicle.md|vehicle|scripts/vehicle.sh scripts/lib.sh compiler runtime templates models/sports_car.yaml models/sports_car models/subsystems models/sports_car_chassis.fe.yaml
docs/sweeps.md|sweeps|scripts/sweeps.sh scripts/lib.sh compiler/tools/sweep.c runtime models/quarter_car.yaml'

stale=0
while IFS='|' read -r doc target sources; do
  if [ $# -gt 0 ]; then
    want=0
    for d in "$@"; do [ "$d" = "$doc" ] && want=1; done
    [ $want = 1 ] || continue
  fi
  [ -e "$doc" ] || continue
  written=$(git log -1 --format=%H -- "$doc")
  [ -n "$written" ] || { echo "$doc: not committed (make $target, then commit it)"; stale=1; continue; }
  # shellcheck disable=SC2086  # sources is a list of paths
  newer=$(git rev-list "$written..HEAD" -- $sources | wc -l)
  # uncommitted changes of the sources count too
  # shellcheck disable=SC2086
  dirty=$(git status --porcelain -- $sources | wc -l)
  if [ "$newer" -gt 0 ] || [ "$dirty" -gt 0 ]; then
    extra=""
    [ "$dirty" -gt 0 ] && extra=" and $dirty uncommitted change(s)"
    echo "$doc: stale: $newer later commit(s)$extra touch what it measures; regenerate with make $target"
    stale=1
  fi
done <<< "$table"
exit $stale
