#!/usr/bin/env bash
# test_install.sh: mbcc installs like a C library (exit 0 = pass).
#   - make install PREFIX=P (into a scratch P) installs bin/mbcc, lib/libmbrt.a
#     and libmbrt_float.a, include/mbcc/, share/mbcc/templates, the pkg-config
#     file, the man page and the docs;
#   - the installed mbcc runs `mbcc run pendulum.yaml` from another
#     directory, and its C compiler calls use the installed headers and
#     library, not the checkout's that were compiled into it (seen through a
#     CC wrapper that logs its arguments);
#   - a user's own program, built with `pkg-config --cflags --libs mbcc`
#     against an emitted pendulum, simulates it with the installed runtime:
#     the bob stays on its unit circle (1e-9) and the energy is conserved
#     (1e-7 J), which the program checks from q and v itself.
# Environment: B (the build directory to install from), CFLAGS (those it was
# built with); MBCC is unused: this test installs its own.
set -u
cd "$(dirname "$0")/.."
# shellcheck source=tests/shell_setup.sh
. tests/shell_setup.sh
unset MBCC_ROOT MBCC_RTLIB
command -v pkg-config > /dev/null || { echo "FAIL: no pkg-config"; exit 1; }
B=${B:-build}

P="$tmp/prefix"
make -s -C "$root" B="$B" install PREFIX="$P" > install.log 2>&1 || { err "make install failed: $(tail -5 install.log)"; exit 1; }
for f in bin/mbcc lib/libmbrt.a lib/libmbrt_float.a include/mbcc/mb_model.h include/mbcc/mb_driver.h \
         share/mbcc/templates/main.c.in lib/pkgconfig/mbcc.pc share/man/man1/mbcc.1 share/doc/mbcc/model-format.md; do
  [ -s "$P/$f" ] || err "not installed: $f"
done

# the installed mbcc, moved, from another directory, with a CC that logs
mkdir -p elsewhere
cat > cc-log <<EOS
#!/bin/sh
echo "\$@" >> "$tmp/cc.args"
exec cc "\$@"
EOS
chmod +x cc-log
cp "$root/models/pendulum.yaml" elsewhere/
(cd elsewhere && CC="$tmp/cc-log" "$P/bin/mbcc" run pendulum.yaml --end 0.5 --quiet) > run.log 2>&1 ||
  err "the installed mbcc run failed: $(tail -5 run.log)"
[ -s elsewhere/results/pendulum.csv ] && [ -s elsewhere/results/pendulum.png ] || err "the installed mbcc wrote no results"
if [ -s cc.args ]; then
  grep -q -- "-I$P/include/mbcc" cc.args || err "the generated code was not compiled against the installed headers: $(cat cc.args)"
  grep -q "$P/lib/libmbrt.a" cc.args || err "not linked with the installed runtime: $(cat cc.args)"
  grep -q "$root" cc.args && err "the installed mbcc still uses the checkout: $(cat cc.args)"
else
  err "the CC wrapper was never called"
fi

# a user's program, built with pkg-config
(cd elsewhere && "$P/bin/mbcc" compile pendulum.yaml -o gen) > compile.log 2>&1 || err "mbcc compile failed: $(cat compile.log)"
cat > user.c <<'EOS'
/* a user's program: the emitted pendulum, simulated by the installed runtime */
#include <math.h>
#include <stdio.h>
#include "pendulum.h"
#include "mb_sim.h"

typedef struct { double e0, de, dr; int rows; double t; } check;

static int row(void *user, double t, const mb_real *q, const mb_real *v, const mb_real *vd, const mb_real *lambda) {
  check *c = user;
  (void)vd; (void)lambda;
  double w2 = v[3] * v[3] + v[4] * v[4] + v[5] * v[5];
  double e = 0.5 * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) + 0.5 * 1e-4 * w2 + 9.81 * q[1];
  if (c->rows++ == 0) c->e0 = e;
  if (fabs(e - c->e0) > c->de) c->de = fabs(e - c->e0);
  double r = fabs(q[0] * q[0] + q[1] * q[1] - 1);
  if (r > c->dr) c->dr = r;
  c->t = t;
  return 0;
}

int main(void) {
  mb_settings s;
  mb_settings_default(&s);
  s.end_time = 1; s.output_step = 0.01; s.max_step = 0.01; s.rtol = 1e-10; s.atol = 1e-12;
  mb_solver *ls = mb_solver_new("ldl", &pendulum_model);
  mb_sim sim;
  check c = {0, 0, 0, 0, 0};
  if (!ls || mb_sim_init(&sim, &pendulum_model, ls, &s) || mb_sim_run(&sim, row, &c)) return 1;
  printf("rows %d t %.9g energy drift %.3g radius error %.3g\n", c.rows, c.t, c.de, c.dr);
  mb_sim_free(&sim);
  ls->destroy(ls);
  return !(c.rows == 101 && fabs(c.t - 1) < 1e-9 && c.de < 1e-7 && c.dr < 1e-9);
}
EOS
flags=$(PKG_CONFIG_PATH="$P/lib/pkgconfig" pkg-config --cflags --libs mbcc) || err "pkg-config --cflags --libs mbcc failed"
case $flags in *"-I$P/include/mbcc"*"-lmbrt"*) ;; *) err "pkg-config gives: $flags" ;; esac
# the C flags the runtime was built with (make sanitize: the sanitizers)
# shellcheck disable=SC2086  # flags are words
if cc -std=c99 ${CFLAGS:--O2} -Ielsewhere/gen -o user user.c elsewhere/gen/pendulum.c $flags > cc.log 2>&1; then
  ./user > user.out 2>&1 || err "the user's program failed its own checks: $(cat user.out)"
  echo "user program: $(cat user.out)"
else
  err "the user's program does not build with pkg-config: $(tail -5 cc.log)"
fi

exit $fail
