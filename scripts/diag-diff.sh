#!/usr/bin/env bash
# diag-diff.sh OLD_MBCC [MODEL...]: the diagnostics of two mbcc builds compared
# on the models and on mutants of their joints, drivers and outputs (each
# line deleted, each joint or output type swapped for every other, a
# driver's dof flipped): `mbcc check` (and each scene) with OLD_MBCC and
# build/mbcc, stdout, stderr and exit status.  For a restructuring of the
# reader or the lowering that must leave every message as it was.  Exit 1
# and the differences if any.  Default models: the tests' output models,
# spatial_joints, slider_crank, and every file in tests/bad_models.
set -u
cd "$(dirname "$0")/.." || exit 1
old=${1:?usage: scripts/diag-diff.sh OLD_MBCC [MODEL...]}; shift
new=$(pwd)/build/mbcc
[ $# -gt 0 ] || set -- tests/models/outputs_*.yaml models/spatial_joints.yaml models/slider_crank.yaml
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"; rm -f $(cat "$tmp.list" 2>/dev/null) "$tmp.list"' EXIT
# the mutants sit next to their model, so that its relative file names resolve
python3 - "$@" > "$tmp.list" <<'PY'
import os, re, sys
joints = "spherical revolute cylindrical prismatic universal fixed distance".split()
outputs = ("position orientation angle velocity angular_velocity acceleration angular_acceleration "
           "reaction effort kinetic_energy potential_energy total_energy deflection modal momentum "
           "section force relative joint center_of_mass tyre").split()
n = 0
def emit(src, lines):
    global n
    p = os.path.join(os.path.dirname(os.path.abspath(src)), ".diag_mutant_%d_%05d.yaml" % (os.getpid(), n))
    open(p, "w").write("".join(lines))
    print(p)
    n += 1
for src in sys.argv[1:]:
    L = open(src).readlines()
    section = None
    for i, l in enumerate(L):
        m = re.match(r"^([a-z_]+):", l)
        if m: section = m.group(1)
        if section not in ("joints", "drivers", "outputs"): continue
        if l.strip() and not l.startswith(section):
            emit(src, L[:i] + L[i + 1:])
        m = re.search(r"\btype: *([a-z_]+)", l)
        if m and section != "drivers":
            for t in joints if section == "joints" else outputs:
                if t != m.group(1):
                    emit(src, L[:i] + [l[:m.start(1)] + t + l[m.end(1):]] + L[i + 1:])
        if section == "drivers" and "dof:" in l:
            flipped = l.replace("rotation", "translation") if "rotation" in l else l.replace("translation", "rotation")
            emit(src, L[:i] + [flipped] + L[i + 1:])
PY
n=0 differ=0
for f in "$@" tests/bad_models/*.yaml $(cat "$tmp.list"); do
  scenes=$(awk '/^scenes:/ { s = 1; next } s && /^[^ #]/ { s = 0 } s && /^  [a-z0-9_]+:/ { sub(/:.*/, ""); print $1 }' "$f")
  for s in "" $scenes; do
    args=(check "$f"); [ -n "$s" ] && args+=(--scene "$s")
    a=$(timeout 60 "$old" "${args[@]}" 2>&1; echo "exit $?")
    b=$(timeout 60 "$new" "${args[@]}" 2>&1; echo "exit $?")
    n=$((n + 1))
    if [ "$a" != "$b" ]; then
      differ=$((differ + 1))
      echo "differs: mbcc ${args[*]}"
      diff <(echo "$a") <(echo "$b") | head -8
    fi
  done
done
echo "diag-diff: $n checks, $differ differ"
[ "$differ" = 0 ]
