#!/bin/sh
# check_bad_models.sh: the reader alone (tests/check_reader.c) on
# tests/bad_models/*.yaml.  A model it rejects must get exactly one error,
# containing its "# expect:" line and, if given, at its "# expect-loc:
# LINE:COL" (or FILE:LINE:COL in a file the model names).  Models it
# accepts hold errors for later stages (assembly...): they are listed, not
# failed; tests/test_bad_models.c checks them via mbcc.
# Usage: tests/check_bad_models.sh CHECK_READER_BINARY
reader=${1:?usage: $0 path/to/check_reader}
dir=$(dirname "$0")/bad_models
# where an error is expected: LINE:COL of the model, or FILE:LINE:COL of a
# file it names (FILE relative to the model's folder)
where() {
  case $2 in *:*:*) echo "$(dirname "$1")/$2" ;; *) echo "$1:$2" ;; esac
}
failed=0
total=0
later=0
for model in "$dir"/*.yaml; do
  total=$((total + 1))
  expect=$(sed -n 's/^# expect: //p' "$model" | head -n 1)
  loc=$(sed -n 's/^# expect-loc: //p' "$model" | head -n 1)
  stderr=$("$reader" "$model" 2>&1 >/dev/null)
  status=$?
  errors=$(printf '%s\n' "$stderr" | grep -c ': error: ')
  line=$(printf '%s\n' "$stderr" | grep ': error: ' | head -n 1)
  problem=""
  if [ "$status" -eq 0 ]; then
    later=$((later + 1))
    echo "later stage: $model"
    continue
  elif [ "$status" -ne 2 ]; then
    problem="exit status $status, expected 2"
  elif [ "$errors" -ne 1 ]; then
    problem="$errors errors, expected 1"
  elif ! printf '%s\n' "$line" | grep -qF -- "$expect"; then
    problem="message does not contain: $expect"
  elif [ -n "$loc" ] && ! printf '%s\n' "$line" | grep -qF -- "$(where "$model" "$loc"): error: "; then
    problem="error not at $loc"
  fi
  if [ -n "$problem" ]; then
    failed=$((failed + 1))
    printf 'FAIL %s: %s\n%s\n' "$model" "$problem" "$stderr"
  fi
done
echo "bad models: $((total - failed - later))/$((total - later)) rejected by the reader as expected, $later left to later stages"
[ "$failed" -eq 0 ]
