#!/usr/bin/env bash
# test_embedded.sh: the embedded target (mbcc compile --target embedded).
# Always (host compiler only):
#   - runtime/core's step code and a float generated model compile freestanding
#     under -Wdouble-promotion -Wconversion -Werror -DMB_REAL_FLOAT;
#   - the package's RK4 (runtime/core/mb_step.c) against the hosted RK4 of
#     mbcc run (runtime/hosted/integrate.c: the same step arithmetic,
#     mb_rk4_step, but its own workspaces, solver calls, projection and
#     output timing; test_solvers checks that RK4 against DOPRI5) on the rigid
#     and the flexible slider-crank, same step: within 1e-9 of each output's
#     size (the CSV has 12 digits);
#   - the package's generalized-alpha (fixed 3 Newton iterations) converges to
#     that RK4 solution at second order: halving the step divides the error by
#     more than 3;
#   - bad options exit 2 and write nothing.
#   - inputs (tests/embedded/input_drive.yaml): a torque set by <m>_set_input
#     matches mbcc run --set (1e-9), a step change of a force on a block matches
#     the closed form (1e-12), bad inputs give MB_ERR_INVALID;
# With arm-none-eabi-gcc, newlib and qemu-system-arm (scripts/install-deps.sh):
#   - each package (rigid and flexible, double and float) cross-compiles for a
#     Cortex-M4F with -Werror, the float ones link no __aeabi_d* (nm), and the
#     flexible float one reports its flash and RAM: under 64 KiB and 8 KiB;
#   - verify.elf runs on qemu's mps2-an386 and matches the host run of the same
#     package: double within 1e-9 of each output's size, float within 1e-4
#     (measured: 0 for the rigid, 2e-6 for the flexible slider-crank; libm's
#     sinf/cosf differ between newlib and glibc by an ulp); the float package of
#     input_drive with a step change of its input, qemu against host.
# Environment: MBCC (set by tests/run_tests.sh; default build/mbcc).
set -u
cd "$(dirname "$0")/.."
# shellcheck source=tests/shell_setup.sh
. tests/shell_setup.sh

cc -std=c11 -O2 -Wall -Wextra -Werror "$root/tests/embedded/compare.c" -lm -o compare || { echo "FAIL: compare.c"; exit 1; }

# max error relative to each column's size (first field of compare's answer)
rel_error() { ./compare "$1" "$2" | awk '{ print $1 }'; }
below() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a != "" && a + 0 <= b + 0) }'; }

# --- freestanding float build of the core with a generated model ---
"$MBCC" compile "$root/models/slider_crank_flexible.yaml" --real float -o gen_float > /dev/null || err "compile --real float"
for src in "$root/runtime/core/mb_step.c" "$root/runtime/core/model_generic.c" gen_float/slider_crank_flexible.c; do
  cc -std=c11 -ffreestanding -fno-math-errno -Wall -Wextra -Wdouble-promotion -Wconversion -Werror -DMB_REAL_FLOAT \
     -I"$root/runtime/core" -Igen_float -c "$src" -o /dev/null || err "freestanding float build of $(basename "$src")"
done

# --- the core's RK4 against the hosted RK4; generalized-alpha's order ---
package() { # package DIR MODEL [mbcc options...]
  local dir=$1 model=$2; shift 2
  "$MBCC" compile "$root/models/$model.yaml" --target embedded "$@" -o "$dir" > /dev/null || { err "package $dir"; return 1; }
}
host_log() { # host_log DIR STEPS EVERY [DEFINES]: the verification run on the host
  (cd "$1" && make -s host-verify HOSTOPT=-O0 VERIFY="-DVERIFY_STEPS=$2 -DVERIFY_EVERY=$3 ${4:-}" > /dev/null && ./host-verify > host.log) ||
    err "host-verify in $1"
}
for model in slider_crank slider_crank_flexible; do
  package rk4_$model $model --integrator rk4 --step 1e-5 || continue
  host_log rk4_$model 200 20
  "$MBCC" run "$root/models/$model.yaml" --integrator rk4 --step 1e-5 --end 0.002 --output-step 2e-4 \
    -o hosted_$model.csv --plot none --quiet || err "mbcc run $model"
  e=$(rel_error rk4_$model/host.log hosted_$model.csv)
  below "$e" 1e-9 || err "$model: the core's RK4 differs from the hosted RK4 by $e (> 1e-9)"
done
package ga1 slider_crank_flexible --integrator genalpha --step 1e-5 && host_log ga1 200 20
package ga2 slider_crank_flexible --integrator genalpha --step 5e-6 && host_log ga2 400 40
e1=$(rel_error ga1/host.log hosted_slider_crank_flexible.csv)
e2=$(rel_error ga2/host.log hosted_slider_crank_flexible.csv)
below "$e1" 1e-3 || err "generalized-alpha, step 1e-5: error $e1 against RK4 (> 1e-3)"
awk -v a="$e1" -v b="$e2" 'BEGIN { exit !(b > 0 && a / b > 3) }' ||
  err "generalized-alpha is not second order: error $e1 at 1e-5, $e2 at 5e-6"

# --- inputs (tests/embedded/input_drive.yaml: parameters with 'input: true') ---
# the torque 'drive' set through <m>_set_input before the first step against
# mbcc run --set drive=3.5 (the hosted RK4, same step): within 1e-9
inputs=$root/tests/embedded/input_drive.yaml
"$MBCC" compile "$inputs" --target embedded -o in_pkg > /dev/null || err "package input_drive"
grep -q '"push", "drive", 0' in_pkg/input_drive_api.c || err "input_drive: the input names table is not {push, drive}"
drive_defs="-DVERIFY_INPUT=1 -DVERIFY_INPUT_FIRST=3.5"
cp -r in_pkg in_drive && host_log in_drive 200 10 "$drive_defs"
for d in 3.5 0; do
  "$MBCC" run "$inputs" --integrator rk4 --step 1e-3 --end 0.2 --output-step 0.01 --set drive=$d \
    -o hosted_drive_$d.csv --plot none --quiet || err "mbcc run input_drive --set drive=$d"
done
e=$(rel_error in_drive/host.log hosted_drive_3.5.csv)
below "$e" 1e-9 || err "input_drive: set_input(drive, 3.5) differs from mbcc run --set drive=3.5 by $e (> 1e-9)"
e0=$(rel_error in_drive/host.log hosted_drive_0.csv)
below 1e-3 "$e0" || err "input_drive: the torque input changes nothing ($e0 against drive = 0)"
# a step change of the force 'push' on the 2 kg block: 4 N until t = 0.1 s,
# then -6 N; x(t) is piecewise quadratic, which RK4 integrates exactly
push_defs="-DVERIFY_INPUT=0 -DVERIFY_INPUT_FIRST=4 -DVERIFY_INPUT_AT=100 -DVERIFY_INPUT_THEN=-6"
cp -r in_pkg in_push && host_log in_push 200 10 "$push_defs"
awk 'BEGIN { print "time,x"; for (k = 0; k <= 20; k++) { t = k * 0.01; s = t - 0.1
  x = t <= 0.1 ? 0.5 + t * t : 0.51 + 0.2 * s - 1.5 * s * s; printf "%.17g,%.17g\n", t, x } }' > push_exact.csv
e=$(rel_error in_push/host.log push_exact.csv)
below "$e" 1e-12 || err "input_drive: the step change of 'push' differs from the closed form by $e (> 1e-12)"
# out of range, non-finite or unknown: MB_ERR_INVALID and nothing changed
cat > in_pkg/bad_input.c <<'CEOF'
#include <math.h>
#include "input_drive_api.h"
static input_drive_data data;
int main(void) {
  if (input_drive_init(&data)) return 1;
  if (input_drive_set_input(&data, 0, 101) != MB_ERR_INVALID) return 2;   /* max 100 */
  if (input_drive_set_input(&data, 1, NAN) != MB_ERR_INVALID) return 3;
  if (input_drive_set_input(&data, 2, 1) != MB_ERR_INVALID) return 4;     /* no input 2 */
  if (input_drive_set_input(&data, -1, 1) != MB_ERR_INVALID) return 5;
  return INPUT_DRIVE_NINPUT == 2 ? 0 : 6;
}
CEOF
(cd in_pkg && cc -std=c11 -Wall -Wextra -Werror input_drive.c input_drive_api.c mb_step.c model_generic.c bad_input.c -lm -o bad_input &&
  ./bad_input) || err "input_drive: set_input accepted a bad input (status $?)"

# --- bad options: exit 2, nothing written ---
"$MBCC" compile "$root/models/slider_crank.yaml" --target mcu -o bad1 > out 2>&1; st=$?
[ $st = 2 ] && [ ! -e bad1 ] || err "--target mcu: exit $st (want 2, nothing written)"
"$MBCC" compile "$root/models/slider_crank.yaml" --target embedded --integrator dopri5 -o bad2 > out 2>&1; st=$?
[ $st = 2 ] && [ ! -e bad2 ] || err "--target embedded --integrator dopri5: exit $st (want 2, nothing written)"

# --- on the emulated Cortex-M4F ---
if ! command -v arm-none-eabi-gcc > /dev/null || ! command -v qemu-system-arm > /dev/null; then
  echo "test_embedded: no arm-none-eabi-gcc or qemu-system-arm: the ARM part is skipped (scripts/install-deps.sh)"
  exit $fail
fi
for model in slider_crank slider_crank_flexible; do
  for real in double float; do
    d=arm_${model}_$real
    package $d $model --real $real || continue
    (cd $d && make -s lib$model.a verify.elf example.elf > build.log 2>&1) || { err "$d: cross build"; cat $d/build.log; continue; }
    ! grep -q warning $d/build.log || err "$d: warnings in the cross build"
    if [ $real = float ]; then
      (cd $d && make -s check-double > /dev/null) || err "$d: __aeabi_d* linked in the float build"
    fi
    if [ "$model-$real" = slider_crank_flexible-float ]; then
      size=$(cd $d && make -s size | tr '\n' ' ')
      echo "$model float on Cortex-M4F: $size"
      # the aim: under 64 KiB of flash and 8 KiB of RAM (data block included);
      # measured 64,940 B and 7,824 B.  This guards the looped LDL^T with short
      # tables, no powf, no tyre (asinf), builtin sqrtf, one integrator and the
      # frames sharing the LDL^T workspace (without them 100 KB and 11.5 KB)
      flash=$(echo "$size" | awk '{ print $2 }')
      ram=$(echo "$size" | sed 's/.*ram \([0-9]*\).*/\1/')
      [ "${flash:-999999}" -lt 65536 ] || err "$d: flash $flash B (> 64 KiB; measured 64,940 B)"
      [ "${ram:-999999}" -lt 8192 ] || err "$d: RAM $ram B (> 8 KiB; measured 7,824 B)"
    fi
    host_log $d 200 20
    (cd $d && timeout 60 make -s run-qemu > arm.log 2>&1) || { err "$d: qemu run failed"; tail -3 $d/arm.log; continue; }
    e=$(rel_error $d/arm.log $d/host.log)
    bound=$([ $real = double ] && echo 1e-9 || echo 1e-4)
    below "$e" $bound || err "$d: qemu and host differ by $e (> $bound)"
    echo "$model $real: qemu against host $e"
  done
done
# inputs on the Cortex-M4F: the float package of input_drive with the step
# change of 'push', qemu against host (its set_params computes in float: no
# __aeabi_d*), and the host's float run against the closed form
d=arm_input_float
"$MBCC" compile "$inputs" --target embedded --real float -o $d > /dev/null || err "package $d"
(cd $d && make -s verify.elf example.elf VERIFY="-DVERIFY_STEPS=200 -DVERIFY_EVERY=10 $push_defs" > build.log 2>&1 &&
  make -s check-double > /dev/null) || { err "$d: cross build or __aeabi_d* linked"; cat $d/build.log; }
host_log $d 200 10 "$push_defs"
(cd $d && timeout 60 make -s run-qemu > arm.log 2>&1) || { err "$d: qemu run failed"; tail -3 $d/arm.log; }
eq=$(rel_error $d/arm.log $d/host.log)
below "$eq" 1e-4 || err "$d: qemu and host differ by $eq (> 1e-4)"
# measured 1.1e-6: float round-off of 200 steps
e=$(rel_error $d/host.log push_exact.csv)
below "$e" 1e-5 || err "$d: the float run's step change of 'push' differs from the closed form by $e (> 1e-5)"
echo "input_drive float (step change of an input): qemu against host $eq, against the closed form $e"
exit $fail
