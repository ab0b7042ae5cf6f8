#!/usr/bin/env bash
# test_generated_warnings.sh: the generated code of every model (models/ and
# tests/models/, every scene) compiles as C99 with -Wall -Wextra -Werror
# -pedantic, as users build it (exit 0 = pass).  An unread variable in one
# model's combination of joints (a marker no row reads, a massless body's
# right side without Y columns) is a build failure for them.
# tests/models/reader_example.yaml's base scene is a reader fixture whose
# driver does not assemble at t = 0 (mbcc rejects it, as it should); its
# 'slow' scene is compiled.
# Environment: MBCC (set by tests/run_tests.sh), CC (default cc).
set -u
cd "$(dirname "$0")/.." || exit 1
# shellcheck source=tests/shell_setup.sh
. tests/shell_setup.sh
CC=${CC:-cc}
n=0
for f in "$root"/models/*.yaml "$root"/tests/models/*.yaml; do
  case $(basename "$f") in _*|*.fe.yaml) continue ;; esac  # examples; FE files (fe_file)
  scenes=$(awk '/^scenes:/ { s = 1; next } s && /^[^ #]/ { s = 0 } s && /^  [a-z0-9_]+:/ { sub(/:.*/, ""); print $1 }' "$f")
  for sc in base $scenes; do
    [ "$(basename "$f")" = reader_example.yaml ] && [ "$sc" = base ] && continue
    d="$tmp/$(basename "$f" .yaml)-$sc"
    args=()
    [ "$sc" = base ] || args=(--scene "$sc")
    if ! "$MBCC" compile "$f" "${args[@]}" -o "$d" > "$tmp/log" 2>&1; then
      err "mbcc compile $(basename "$f") ${args[*]}: $(grep error "$tmp/log" | head -1)"
      continue
    fi
    for c in "$d"/*.c; do
      case $c in */main.c) continue ;; esac
      "$CC" -std=c99 -Wall -Wextra -Werror -pedantic -O1 -I"$root/runtime/core" -I"$root/runtime/hosted" -c "$c" -o "$tmp/x.o" > "$tmp/cc.log" 2>&1 ||
        err "$(basename "$f") ${args[*]}: $(grep -m1 error "$tmp/cc.log")"
      n=$((n + 1))
    done
  done
done
[ "$n" -ge 30 ] || err "only $n generated files compiled"
echo "$n generated files compiled without warnings"
exit "$fail"
