#!/usr/bin/env bash
# test_fe_nastran_systems.sh: Nastran GRID displacement systems (CD) and
# CBAR/CBEAM end offsets (WA, WB), each against the same structure written
# without them:
#  1. CD: a propped cantilever (unequal bending stiffnesses) whose root PS,
#     a mid-span SPC of two rotations, the tip SPC and the orientation vector
#     are given in a system turned 90 degrees about z, and in one turned 30
#     degrees about x; frequencies and shapes (basic axes) equal the basic
#     deck's.  The tip SPC is what makes it sensitive: read in the wrong
#     system it holds the axial DOF and the frequencies change;
#  2. offsets: a cantilever whose GRIDs lie h below the beam's axis (WA = WB =
#     (0, h, 0)) against the same beam with its GRIDs on the axis: equal
#     frequencies, and each GRID moves as a point rigidly attached to the
#     axis, u = u_axis + theta x (0, -h, 0) (the offset is a rigid arm);
#  3. offsets in a frame (three directions, ends in displacement systems)
#     against the frame written with explicit GRIDs at the ends and RBE2s;
#  4. bad input: a component set skew to the basic axes, CORD2C, an
#     undefined CD, OFFT with element-system offsets: file:line:col, exit 2.
set -u
cd "$(dirname "$0")/.."
. tests/shell_setup.sh

modes() { # deck-file out-prefix [reference]
  printf 'name: sys\nbodies:\n  beam: {type: flexible, fe_file: %s, reference: %s, modes: 8, mass: consistent}\n' \
    "$1" "${3:-[1]}" > "$2.yaml"
  "$MBCC" modes "$2.yaml" --body beam --shapes "$2.csv" --write-modal "$2.modal" > "$2.log" 2>&1 ||
    { cat "$2.log"; err "mbcc modes $1"; return 1; }
}
same_freqs() { # a.modal b.modal tol what
  paste <(grep -o 'frequency: [0-9.e+-]*' "$1" | cut -d' ' -f2) <(grep -o 'frequency: [0-9.e+-]*' "$2" | cut -d' ' -f2) |
    awk -v tol="$3" -v what="$4" '{ d = ($1 - $2) / $2; if (d < 0) d = -d; if (d > w) w = d; n++ }
      END { printf "%s: %d frequencies, largest relative difference %.2e\n", what, n, w
            exit !(n == 8 && w <= tol) }'

}
# shapes of GRID rows 0..rows-1: b = a moved by a rigid arm (0, -h, 0) from a's node
# (h = 0: equal), each mode up to its sign
same_shapes() { # a.csv b.csv rows h tol what
  awk -F, -v rows="$3" -v h="$4" -v tol="$5" -v what="$6" '
    FNR == 1 { next }
    NR == FNR { for (i = 1; i <= NF; i++) a[FNR - 2, i] = $i; nf = NF; next }
    { for (i = 1; i <= NF; i++) b[FNR - 2, i] = $i }
    END {
      worst = 0
      for (c = 5; c + 5 <= nf; c += 6) {
        big = 0; dp = 0; dm = 0
        for (k = 0; k < rows; k++) {
          # a node of a plus theta x r, r = (0, -h, 0): (theta_z h, 0, -theta_x h)
          e[0] = a[k, c] + a[k, c + 5] * h; e[1] = a[k, c + 1]; e[2] = a[k, c + 2] - a[k, c + 3] * h
          for (i = 3; i < 6; i++) e[i] = a[k, c + i]
          for (i = 0; i < 6; i++) {
            x = e[i] < 0 ? -e[i] : e[i]; if (x > big) big = x
            p = b[k, c + i] - e[i]; q = b[k, c + i] + e[i]; if (p < 0) p = -p; if (q < 0) q = -q
            if (p > dp) dp = p; if (q > dm) dm = q } }
        d = (dp < dm ? dp : dm) / big; if (d > worst) worst = d }
      printf "%s: shapes, largest relative difference %.2e\n", what, worst
      exit !(worst <= tol) }' "$1" "$2"
}

# --- 1. displacement systems ---------------------------------------------------------
# cantilever along x, 10 CBARs, I1 != I2; root PS 123456, GRID 6 holds
# rotations about y and z, the tip (GRID 11) holds uy: written in basic
# (cd = 0), in CORD2R 5 (x' = y, y' = -x, z' = z) and in CORD2R 6 (30
# degrees about x: y' = (0, c, s), z' = (0, -s, c))
cantilever() { # cd root-ps mid-spc tip-cd tip-spc v1 v2 v3 file
  { echo 'CORD2R,5,,0.,0.,0.,0.,0.,1.'
    echo ',0.,1.,0.'
    echo 'CORD2R,6,,0.,0.,0.,0.,-.5,.86602540378443865'
    echo ',1.,0.,0.'
    for k in $(seq 1 11); do
      cd=$1; [ $k -eq 11 ] && cd=$4
      ps=""; [ $k -eq 1 ] && ps=$2
      printf 'GRID,%d,,%.17g,0.,0.,%s,%s\n' $k "$(awk -v k=$k 'BEGIN { print (k - 1) / 10 }')" "$cd" "$ps"
    done
    for e in $(seq 1 10); do printf 'CBAR,%d,1,%d,%d,%s,%s,%s\n' $e $e $((e + 1)) "$6" "$7" "$8"; done
    echo "SPC,1,6,$3,0.,11,$5,0."
    echo 'PBAR,1,1,1.e-4,2.e-9,5.e-9,3.e-9'
    echo 'MAT1,1,2.1e11,,.3,7850.'; } > "$9"
}
c30=0.86602540378443865
cantilever 0 123456 56 0 2 0. 1. 0. basic.bdf            # basic: v = y
cantilever 5 123456 46 5 1 1. 0. 0. turned90.bdf         # y = x', rotations y, z = 4, 6 in CD 5
cantilever 6 123456 56 0 2 0. $c30 -.5 turned30.bdf      # y in CD 6 = (0, c, -s); tip in basic
cantilever 0 123456 56 0 1 0. 1. 0. axial.bdf            # the tip holding ux instead: what CD 5 read as basic would give
modes basic.bdf basic && modes turned90.bdf t90 && modes turned30.bdf t30 && modes axial.bdf axial && {
  same_freqs basic.modal t90.modal 1e-10 "CD turned 90 degrees about z" || err "CD turned 90 degrees about z: frequencies differ"
  same_shapes basic.csv t90.csv 11 0 1e-8 "CD turned 90 degrees about z" || err "CD turned 90 degrees about z: shapes differ"
  same_freqs basic.modal t30.modal 1e-10 "CD turned 30 degrees about x" || err "CD turned 30 degrees about x: frequencies differ"
  same_shapes basic.csv t30.csv 11 0 1e-8 "CD turned 30 degrees about x" || err "CD turned 30 degrees about x: shapes differ"
  if same_freqs basic.modal axial.modal 1e-6 "tip holding ux (must differ)"; then
    err "the tip SPC's direction does not change the frequencies: the CD test could not fail"
  fi
}

# --- 2. offsets: GRIDs h below the axis ----------------------------------------------
offset_beam() { # grid-y offset-y file
  { for k in $(seq 1 11); do printf 'GRID,%d,,%.17g,%s,0.\n' $k "$(awk -v k=$k 'BEGIN { print (k - 1) / 10 }')" "$1"; done
    for e in $(seq 1 10); do printf 'CBAR,%d,1,%d,%d,0.,0.,1.,GGG\n,,,0.,%s,0.,0.,%s,0.\n' $e $e $((e + 1)) "$2" "$2"; done
    echo 'PBAR,1,1,1.e-4,2.e-9,5.e-9,3.e-9'
    echo 'MAT1,1,2.1e11,,.3,7850.'; } > "$3"
}
offset_beam 0.1 0. axis.bdf        # GRIDs on the axis at y = h
offset_beam 0. 0.1 offset.bdf      # GRIDs at y = 0, the axis h above them
modes axis.bdf axis && modes offset.bdf offset && {
  same_freqs axis.modal offset.modal 1e-10 "offsets (0, h, 0)" || err "offsets (0, h, 0): frequencies differ"
  same_shapes axis.csv offset.csv 11 0.1 1e-8 "offsets (0, h, 0): GRIDs on rigid arms" || err "offsets (0, h, 0): GRIDs on rigid arms: shapes differ"
}

# --- 3. a frame with offsets against explicit RBE2 arms ---------------------------------
cat > frame_off.bdf <<'BDF'
CORD2R,7,,0.,0.,0.,0.,0.,1.
,0.,1.,0.
GRID,1,,0.,0.,0.
GRID,2,,1.,0.,0.,7
GRID,3,,1.,.5,0.
GRID,4,,1.,.5,.4
CBAR,1,1,1,2,0.,1.,0.,GGG
,,,0.,0.,.05,.1,0.,.05
CBAR,2,1,2,3,0.,0.,1.,BGG
,,,.1,0.,0.,.02,0.,0.
CBEAM,3,2,3,4,1.,0.,0.
,,,.02,0.,0.,0.,-.03,0.
PBAR,1,1,1.e-4,2.e-9,5.e-9,3.e-9
PBEAM,2,1,2.e-4,3.e-9,4.e-9,,5.e-9
MAT1,1,2.1e11,,.3,7850.
BDF
# the same with the element ends as GRIDs: CBAR 1's end B offset in CD 7
# (x' = y, y' = -x): (.1, 0, .05) in CD 7 = (0, .1, .05) basic; CBAR 2's end A
# in CD 7 too: (.1, 0, 0) = (0, .1, 0) basic
cat > frame_rbe.bdf <<'BDF'
GRID,1,,0.,0.,0.
GRID,2,,1.,0.,0.
GRID,3,,1.,.5,0.
GRID,4,,1.,.5,.4
GRID,11,,0.,0.,.05
GRID,12,,1.,.1,.05
GRID,21,,1.,.1,0.
GRID,22,,1.02,.5,0.
GRID,31,,1.,.47,.4
CBAR,1,1,11,12,0.,1.,0.
CBAR,2,1,21,22,0.,0.,1.
CBEAM,3,2,22,31,1.,0.,0.
RBE2,101,1,123456,11
RBE2,102,2,123456,12
RBE2,103,2,123456,21
RBE2,104,3,123456,22
RBE2,105,4,123456,31
PBAR,1,1,1.e-4,2.e-9,5.e-9,3.e-9
PBEAM,2,1,2.e-4,3.e-9,4.e-9,,5.e-9
MAT1,1,2.1e11,,.3,7850.
BDF
modes frame_off.bdf foff && modes frame_rbe.bdf frbe && {
  same_freqs foff.modal frbe.modal 1e-9 "frame with offsets vs explicit RBE2 arms" || err "frame with offsets vs explicit RBE2 arms: frequencies differ"
  same_shapes foff.csv frbe.csv 4 0 1e-7 "frame with offsets vs explicit RBE2 arms (GRIDs 1-4)" || err "frame with offsets vs explicit RBE2 arms (GRIDs 1-4): shapes differ"
}

# --- 4. bad input -----------------------------------------------------------------------
bad() { # deck-text expected-message what
  printf '%s\n' "$1" > bad.bdf
  printf 'name: bad\nbodies:\n  beam: {type: flexible, fe_file: bad.bdf, reference: [1]}\n' > bad.yaml
  "$MBCC" check bad.yaml > bad.log 2>&1; rc=$?
  if [ $rc -eq 2 ] && grep -q "bad.bdf:[0-9]*:[0-9]*: error: .*$2" bad.log; then
    echo "$3: $(grep -m1 error: bad.log)"
  else
    cat bad.log; err "$3: exit $rc"
  fi
}
BEAM='GRID,1,,0.,0.,0.
GRID,2,,1.,0.,0.
PBAR,1,1,1.e-4,2.e-9,5.e-9,3.e-9
MAT1,1,2.1e11,,.3,7850.'
bad "$BEAM
CORD2R,6,,0.,0.,0.,0.,-.5,.86602540378443865
,1.,0.,0.
GRID,3,,2.,0.,0.,6
SPC,1,3,2,0.
CBAR,1,1,1,2,0.,1.,0.
CBAR,2,1,2,3,0.,1.,0." "components 2 of GRID 3 are in its displacement system CD 6, whose axes are skew" "a skew SPC"
bad "$BEAM
CORD2C,6,,0.,0.,0.,0.,0.,1.
,1.,0.,0.
CBAR,1,1,1,2,0.,1.,0." "CORD2C: only rectangular systems" "CORD2C"
bad "$BEAM
GRID,3,,2.,0.,0.,9
CBAR,1,1,1,2,0.,1.,0.
CBAR,2,1,2,3,0.,1.,0." "GRID 3: displacement coordinate system 9 is not defined" "an undefined CD"
bad "$BEAM
CBAR,1,1,1,2,0.,1.,0.,GOO
,,,0.,.1,0.,0.,.1,0." "OFFT 'GOO' is not supported" "offsets in the element system"
bad "$BEAM
CBAR,1,1,1,2,0.,1.,0.
,,,1.,0.,0.,0.,0.,0." "its two ends coincide" "offsets that make the element zero-length"
exit $fail
