#!/usr/bin/env bash
# test_generated_cxx.sh: the generated <model>.c of every golden model and
# scene (tests/golden.sh: double and float, straight-line and looped LDL^T)
# also compiles as C++: g++ -x c++ -std=c++11 -fsyntax-only -Wall -Wextra
# -Werror, and the same with clang++ when it is installed.  That needs the
# generated header's extern "C" guards, MB_RESTRICT (runtime/core/mb_types.h)
# instead of a bare restrict, designated initializers in field order and no
# narrowing in braced initializers.  The element tables' designated
# initializers leave zero fields out on purpose (they are zero-initialized in
# C and C++ alike): g++'s -Wmissing-field-initializers, which flags that in
# C++ only, is off.  Files with the same content are checked once (exit 0 =
# pass).
# Environment: MBCC (set by tests/run_tests.sh), CXX (default g++).
set -u
cd "$(dirname "$0")/.." || exit 1
# shellcheck source=tests/shell_setup.sh
. tests/shell_setup.sh
CXX=${CXX:-g++}
command -v "$CXX" >/dev/null || { echo "FAIL: no C++ compiler '$CXX' (install g++)"; exit 1; }
compilers=$CXX
command -v clang++ >/dev/null && [ "$CXX" != clang++ ] && compilers="$compilers clang++"
(cd "$root" && MBCC="$MBCC" bash tests/golden.sh --out "$tmp/gen" > "$tmp/golden.log" 2>&1)
# one file per distinct content
find "$tmp/gen" -name '*.c' ! -name main.c | LC_ALL=C sort | xargs sha256sum | sort -k1,1 -u | awk '{print $2}' > files
n=$(wc -l < files)
[ "$n" -ge 20 ] || err "only $n generated files (tests/golden.sh: $(tail -1 "$tmp/golden.log"))"
for cxx in $compilers; do
  # two at a time; a failing file prints its name and the compiler's messages
  xargs -P 2 -I{} sh -c '"$0" -x c++ -std=c++11 -fsyntax-only -Wall -Wextra -Werror \
      -Wno-missing-field-initializers -I"$1/runtime/core" -I"$1/runtime/hosted" "$2" > "$2.$3.log" 2>&1 ||
      { echo "FAIL: $0: $2"; head -20 "$2.$3.log"; }' "$cxx" "$root" {} "$(basename "$cxx")" < files > "cxx-$(basename "$cxx").log"
  if grep -q '^FAIL' "cxx-$(basename "$cxx").log"; then
    err "$cxx rejects generated code:"
    head -60 "cxx-$(basename "$cxx").log"
  else
    echo "$cxx: $n generated files compile as C++11"
  fi
done
exit $fail
