#!/bin/sh
# check_bad_models.sh: every tests/bad_models/*.yaml must be rejected with
# exactly one error whose text contains its "# expect:" line and, if given,
# at its "# expect-loc: LINE:COL".
# Usage: tests/check_bad_models.sh CHECK_READER_BINARY
reader=${1:?usage: $0 path/to/check_reader}
dir=$(dirname "$0")/bad_models
failed=0
total=0
for model in "$dir"/*.yaml; do
  total=$((total + 1))
  expect=$(sed -n 's/^# expect: //p' "$model" | head -n 1)
  loc=$(sed -n 's/^# expect-loc: //p' "$model" | head -n 1)
  stderr=$("$reader" "$model" 2>&1 >/dev/null)
  status=$?
  errors=$(printf '%s\n' "$stderr" | grep -c ': error: ')
  line=$(printf '%s\n' "$stderr" | grep ': error: ' | head -n 1)
  problem=""
  if [ "$status" -ne 2 ]; then
    problem="exit status $status, expected 2"
  elif [ "$errors" -ne 1 ]; then
    problem="$errors errors, expected 1"
  elif ! printf '%s\n' "$line" | grep -qF -- "$expect"; then
    problem="message does not contain: $expect"
  elif [ -n "$loc" ] && ! printf '%s\n' "$line" | grep -qF -- "$model:$loc: error: "; then
    problem="error not at $loc"
  fi
  if [ -n "$problem" ]; then
    failed=$((failed + 1))
    printf 'FAIL %s: %s\n%s\n' "$model" "$problem" "$stderr"
  fi
done
echo "bad models: $((total - failed))/$total passed"
[ "$failed" -eq 0 ]
