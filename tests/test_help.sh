#!/usr/bin/env bash
# test_help.sh: help everywhere (exit 0 = pass).
#   - `mbcc help` lists every command; `mbcc CMD --help` and `mbcc help CMD`
#     print the same text, starting with that command's usage, and exit 0
#     (`mbcc run --help` once failed: "option '--help' needs a value");
#   - `mbcc --version` prints MBCC_VERSION of compiler/version.h;
#   - the committed man page docs/mbcc.1 is what `mbcc help --man` prints
#     (regenerate with `make man`), and man formats it without warnings;
#   - `mbcc help NOSUCH` and `mbcc` alone exit 2.
# Environment: MBCC (set by tests/run_tests.sh; default build/mbcc).
set -u
cd "$(dirname "$0")/.."
# shellcheck source=tests/shell_setup.sh
. tests/shell_setup.sh

"$MBCC" help > help.txt 2> help.err || err "mbcc help exited $?"
[ -s help.err ] && err "mbcc help wrote to stderr: $(head -3 help.err)"
for c in check compile run bench modes plot animate trade help; do
  grep -q "^  $c " help.txt || err "mbcc help does not list '$c'"
  "$MBCC" "$c" --help > "a_$c.txt" 2>&1 || err "mbcc $c --help exited $?: $(head -3 "a_$c.txt")"
  "$MBCC" help "$c" > "b_$c.txt" 2>&1 || err "mbcc help $c exited $?"
  head -1 "a_$c.txt" | grep -q "^usage: mbcc $c" || err "mbcc $c --help: $(head -1 "a_$c.txt")"
  cmp -s "a_$c.txt" "b_$c.txt" || err "mbcc $c --help and mbcc help $c differ"
done
# --help wins wherever it stands, even after a model and options
"$MBCC" run "$root/models/pendulum.yaml" --end 1 --help > c.txt 2>&1 || err "mbcc run M --end 1 --help exited $?"
cmp -s c.txt a_run.txt || err "mbcc run M --end 1 --help is not the run help: $(head -2 c.txt)"

want=$(sed -n 's/^#define MBCC_VERSION "\(.*\)"$/\1/p' "$root/compiler/version.h")
[ -n "$want" ] || err "no MBCC_VERSION in compiler/version.h"
got=$("$MBCC" --version 2>&1)
[ "$got" = "mbcc $want" ] || err "mbcc --version printed '$got', expected 'mbcc $want'"

"$MBCC" help --man > mbcc.1 || err "mbcc help --man exited $?"
cmp -s mbcc.1 "$root/docs/mbcc.1" || err "docs/mbcc.1 is not current: run make man"
if command -v man > /dev/null && command -v groff > /dev/null; then
  warn=$(MANWIDTH=80 man --warnings -l mbcc.1 2>&1 > /dev/null)
  [ -z "$warn" ] || err "man warns about docs/mbcc.1: $warn"
  MANWIDTH=80 man -l mbcc.1 2> /dev/null | grep -q 'mbcc run M.yaml' || err "the man page has no run synopsis"
fi

"$MBCC" help nosuch > n.txt 2>&1
[ $? = 2 ] || err "mbcc help nosuch did not exit 2"
"$MBCC" > n.txt 2>&1
[ $? = 2 ] || err "mbcc alone did not exit 2"
grep -q '^usage:' n.txt || err "mbcc alone printed no usage"

exit $fail
