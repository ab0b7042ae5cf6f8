#!/usr/bin/env bash
# test_modal_file.sh: a flexible body read from a modal data file (written by
# `mbcc modes --write-modal` from the FE model) moves exactly as the FE body;
# the file read and written again is the same file (numbers bit for bit); a
# file over MBCC_MAX_INPUT is refused at the model's 'modal_file'.  (The
# errors in a modal data file: tests/bad_models/1NN_modal_NAME.yaml.)
set -eu
MBCC=${MBCC:-build/mbcc}
MBCC=$(cd "$(dirname "$MBCC")" && pwd)/$(basename "$MBCC")
root=$(pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$MBCC" modes models/slider_crank_flexible.yaml --body rod --write-modal "$tmp/rod.modal.yaml" >/dev/null
# the same model with the rod from the file (joint points given: the reader
# does not know the file's nodes)
sed -e 's|    line: {from: \[0.1524, 0, 0\], to: \[0.4572, 0, 0\], elements: 8}|    modal_file: rod.modal.yaml\n    position: [0.1524, 0, 0]|' \
    -e '/    section: {area: 3.16e-5}/d' -e '/    material: /d' -e '/    interface: /d' \
    -e 's|    modes: {count: 4}.*|    modes: all|' \
    -e 's|    node: 0$|    node: 0\n    point: [0.1524, 0, 0]|' -e 's|    node: 8$|    node: 8\n    point: [0.4572, 0, 0]|' \
    -e 's|^name: slider_crank_flexible|name: scf_modal|' \
    "$root/models/slider_crank_flexible.yaml" > "$tmp/scf_modal.yaml"
cd "$tmp"
"$MBCC" check scf_modal.yaml > check.txt
grep -q "frequencies (Hz): 48.7275 48.7275 298.777" check.txt
"$MBCC" modes scf_modal.yaml --body rod --write-modal back.modal.yaml > /dev/null
grep -v '^description:' rod.modal.yaml > written.txt
grep -v '^description:' back.modal.yaml > read_back.txt
[ "$(grep -c '^  - frequency:' written.txt)" -ge 4 ]
cmp written.txt read_back.txt
# a hand-written file: diagonal inertias [Jxx, Jyy, Jzz] (node 1: 1, 2, 3)
# are the tensor's diagonal: the modes rotating node 1 about x, y, z are
# mass-normalized only so (rx^2 Jxx = 1, ry^2 Jyy = 1, rz^2 Jzz = 1)
cat > diag.modal <<'EOF2'
format: mbcc-modal-1
nodes:
  - {position: [0, 0, 0], mass: 1}
  - {position: [1, 0, 0], mass: 4, inertia: [1, 2, 3]}
modes:
  - {frequency: 3, shape: [[1, 0, 0, 0, 0, 0], [0, 0, 0, 0, 0, 0]]}
  - {frequency: 5, shape: [[0, 0, 0, 0, 0, 0], [0, 0.5, 0, 0, 0, 0]]}
  - {frequency: 6, shape: [[0, 0, 0, 0, 0, 0], [0, 0, 0, 1, 0, 0]]}
  - {frequency: 7, shape: [[0, 0, 0, 0, 0, 0], [0, 0, 0, 0, 0.70710678118654757, 0]]}
  - {frequency: 8, shape: [[0, 0, 0, 0, 0, 0], [0, 0, 0, 0, 0, 0.57735026918962573]]}
EOF2
printf 'name: diag\nbodies:\n  plate:\n    type: flexible\n    modal_file: diag.modal\n' > diag.yaml
"$MBCC" modes diag.yaml --body plate --write-modal diag_back.modal > diag.txt
grep -q 'inertia: \[1, 0, 0, 0, 2, 0, 0, 0, 3\]' diag_back.modal || { cat diag_back.modal; exit 1; }
[ "$(grep -c '^  - frequency:' diag_back.modal)" = 5 ]
limit=$(wc -c < scf_modal.yaml)
[ "$(wc -c < rod.modal.yaml)" -gt "$limit" ]
if MBCC_MAX_INPUT=$limit "$MBCC" check scf_modal.yaml > big.txt 2>&1; then cat big.txt; exit 1; fi
grep -q "^scf_modal.yaml:[0-9]*:[0-9]*: error: the modal data file 'rod.modal.yaml' is larger than the limit of $limit bytes" big.txt ||
  { cat big.txt; exit 1; }
"$MBCC" run scf_modal.yaml -o modal.csv --plot none --quiet --end 0.02
"$MBCC" run "$root/models/slider_crank_flexible.yaml" -o fe.csv --plot none --quiet --end 0.02
# same midspan deflection history (column 4)
paste -d, fe.csv modal.csv | awk -F, 'NR > 1 { d = $4 - $9; if (d < 0) d = -d; if (d > m) m = d; p = $4 < 0 ? -$4 : $4; if (p > pk) pk = p }
  END { printf "max difference %g of peak %g\n", m, pk; exit !(pk > 1e-3 && m < 1e-9 * pk + 1e-15) }'
