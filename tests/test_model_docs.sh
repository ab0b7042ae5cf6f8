#!/usr/bin/env bash
# test_model_docs.sh: docs/model-format.md documents the whole model format
# (exit 0 = pass).
#   - every key and every choice the reader knows (the string lists named
#     *keys[] and *_names[] in compiler/front/*.c and the force elements'
#     compiler/elements/*.c) appears in the page in backquotes;
#   - every complete model in the page (a ```yaml block that starts with
#     `name:`) passes `mbcc check`;
#   - the beam-and-field example runs, and its physics holds: the tip of the
#     cantilever, loaded suddenly by its weight P, swings to twice the static
#     deflection P L^3 / (3 E I) (to 3%), and the mount whose preload carries
#     the block keeps it at rest (to 1e-9 m).
# Environment: MBCC (set by tests/run_tests.sh; default build/mbcc).
set -u
cd "$(dirname "$0")/.."
# shellcheck source=tests/shell_setup.sh
. tests/shell_setup.sh
doc="$root/docs/model-format.md"

# 1. keys and choices: the reader's string lists, one literal a line
words=$(awk '/(keys|_names)\[\] *= *\{/ { on = 1 } on { print } on && /\}/ { on = 0 }' \
    "$root"/compiler/front/*.c "$root"/compiler/elements/*.c |
  grep -o '"[^"]*"' | tr -d '"' | sort -u)
[ -n "$words" ] || err "found no key lists in compiler/front/ and compiler/elements/"
for w in $words; do
  grep -qF "\`$w\`" "$doc" || grep -qF "\`$w:" "$doc" || grep -qF "{$w:" "$doc" ||
    err "docs/model-format.md does not document '$w'"
done

# 2. every complete model in the page checks
awk '/^```yaml/ { n++; f = sprintf("doc_%d.yaml", n); inb = 1; next } /^```/ { inb = 0 } inb { print > f }' "$doc"
found=0
for f in doc_*.yaml; do
  [ -e "$f" ] || continue
  head -1 "$f" | grep -q '^name:' || continue
  found=$((found + 1))
  # relative paths in an example (modal files) are the repository's
  (cd "$root" && "$MBCC" check "$tmp/$f") > "$f.log" 2>&1 || err "the example $(head -1 "$f") does not check: $(head -3 "$f.log")"
done
[ "$found" -ge 3 ] || err "only $found complete models in docs/model-format.md"

# 3. the beam and field example, against closed forms
ex=$(grep -l '^name: beam_and_field' doc_*.yaml | head -1)
if [ -n "$ex" ] && "$MBCC" run "$ex" --plot none -o bf.csv --quiet > bf.log 2>&1; then
  # P = 0.5 kg * 9.81, L = 0.3 m, E = 7e10 Pa, I = A^2/(4 pi) with A = 3e-5 m^2
  awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
    { y = $c["tip_y"]; if (y < lo) lo = y
      for (k = 0; k < 3; k++) { n = "block_position." substr("xyz", k + 1, 1); d = $c[n] - (k == 1 ? -0.2 : 0)
        if (d < 0) d = -d; if (d > drift) drift = d } }
    END { pi = atan2(0, -1); I = 3e-5 ^ 2 / (4 * pi); st = 0.5 * 9.81 * 0.3 ^ 3 / (3 * 7e10 * I)
      r = -lo / (2 * st)
      if (r < 0.97 || r > 1.03) printf "tip swings to %.4g m, expected twice %.4g m (ratio %.3f)\n", -lo, st, r
      if (drift > 1e-9) printf "the preloaded mount moved by %.3g m\n", drift }' bf.csv > bf.out
  [ -s bf.out ] && err "beam_and_field: $(cat bf.out)"
else
  err "the beam_and_field example does not run: $(tail -3 bf.log 2>/dev/null)"
fi

exit $fail
