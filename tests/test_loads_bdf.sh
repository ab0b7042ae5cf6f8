#!/usr/bin/env bash
# test_loads_bdf.sh: mbcc run --body B --loads FILE.bdf writes the load
# export as Nastran transient loads (DLOAD -> TLOAD1 -> FORCE/MOMENT and
# TABLED1; compiler/tools/loads_bdf.c).  The deck is read back here field by
# field, by the fixed columns Nastran reads (8 small, 16 large, continuation
# marks in columns 73-80 matched), and checked against the CSV export of
# the same run:
#  1. the clamped Nastran cantilever with a tip force and a torque at
#     GRID 3, both varying in time (with the clamp: 3 loads); every
#     TLOAD1 is in the DLOAD, points at one FORCE/MOMENT (CID 0, F 1.0, a
#     unit basic axis) and one TABLED1 (LINEAR, LINEAR, pairs, ENDT); the
#     tables equal the CSV's columns to 10 digits at every time, the
#     channels zero at every time are the ones left out;
#  2. the body turned 90 degrees about z: the CSV is in body axes (the tip
#     force along body x), the deck in the FE model's basic axes (along y);
#  3. .dat and .nas are decks too.
set -u
cd "$(dirname "$0")/.."
. tests/shell_setup.sh

cp "$root"/tests/models/fe/beam.bdf "$root"/tests/models/fe/beam_elements.bdf .
model() { # orientation file
  cat > "$2" <<YAML
name: tip_loaded
bodies:
  beam: {type: flexible, fe_file: beam.bdf, reference: [1], modes: 6, orientation: $1}
joints:
  clamp: {type: fixed, bodies: [ground, beam], node: 1}
forces:
  push: {type: force, body: beam, node: 5, value: [0, 50, 20], scale: {type: sine, amplitude: 1, frequency: 5, offset: 1}}
  twist: {type: torque, body: beam, node: 3, value: [0.5, 0, 2], scale: {type: sine, amplitude: 1, frequency: 7}}
simulation: {end_time: 0.1, output_step: 0.005}
YAML
}
# the deck as channels: "name grid comp t value" lines, or a message and exit 1
read_deck() { # deck
  awk '
    function trim(s) { gsub(/^ +| +$/, "", s); return s }
    function fail(msg) { print "deck: " msg > "/dev/stderr"; bad = 1; exit 1 }
    /^\$ .* at GRID [0-9]+: [FM][xyz]$/ { note = $2; next }
    /^\$/ || /^(BEGIN BULK|ENDDATA)$/ { next }
    {
      head = substr($0, 1, 8); h = trim(head)
      large = index(head, "*") > 0
      if (h ~ /^[+*]/) { # a continuation: its mark must be the card before it
        if (h != want) fail("continuation " h " after a card marked \"" want "\"")
      } else {
        n++; name[n] = large ? substr(h, 1, length(h) - 1) : h; nf[n] = 0; label[n] = note
      }
      w = large ? 16 : 8
      for (i = 0; i < (large ? 4 : 8); i++) f[n, ++nf[n]] = trim(substr($0, 9 + w * i, w))
      want = trim(substr($0, 73, 8))
    }
    END {
      if (bad) exit 1
      for (c = 1; c <= n; c++) {
        if (name[c] == "DLOAD") { dl++; if (f[c, 1] != 1 || f[c, 2] + 0 != 1) fail("DLOAD SID/S")
          for (i = 3; i + 1 <= nf[c]; i += 2) if (f[c, i] != "") { if (f[c, i] + 0 != 1) fail("DLOAD scale"); indl[f[c, i + 1]] = 1; ndl++ } }
        else if (name[c] == "TLOAD1") { tl[f[c, 1]] = c; if (f[c, 3] != "" || f[c, 4] != 0) fail("TLOAD1 DELAY/TYPE") }
        else if (name[c] == "FORCE" || name[c] == "MOMENT") { ex[f[c, 1]] = c
          if (f[c, 3] != 0 || f[c, 4] + 0 != 1) fail(name[c] " CID/F")
          s = (f[c, 5] + 0) " " (f[c, 6] + 0) " " (f[c, 7] + 0)
          axis[c] = s == "1 0 0" ? "x" : s == "0 1 0" ? "y" : s == "0 0 1" ? "z" : ""
          if (axis[c] == "") fail(name[c] " direction " s) }
        else if (name[c] == "TABLED1") { tb[f[c, 1]] = c
          if (f[c, 2] != "LINEAR" || f[c, 3] != "LINEAR") fail("TABLED1 axes")
          for (i = 4; i <= 8; i++) if (f[c, i] != "") fail("TABLED1 field " i) }
        else fail("card " name[c])
      }
      if (dl != 1) fail(dl " DLOADs")
      for (s in tl) {
        c = tl[s]; if (!(s in indl)) fail("TLOAD1 " s " not in the DLOAD")
        if (!(f[c, 2] in ex) || !(f[c, 5] in tb)) fail("TLOAD1 " s ": no FORCE/MOMENT or TABLED1")
        e = ex[f[c, 2]]; t = tb[f[c, 5]]; ntl++
        comp = (name[e] == "FORCE" ? "F" : "M") axis[e]
        if (label[e] == "") fail("no comment naming the load of " name[e] " " f[e, 1])
        for (i = 9; f[t, i] != "ENDT"; i += 2) {
          if (i > nf[t]) fail("TABLED1 " f[t, 1] " has no ENDT")
          print label[e], f[e, 2], comp, f[t, i], f[t, i + 1] }
      }
      if (ntl != ndl) fail(ndl " DLOAD entries, " ntl " TLOAD1s")
    }' "$1"
}
# the CSV's columns as the same lines, turned by A0 (rows "a b c" of A0 in $2)
csv_channels() { # csv a0-rows
  awk -F, -v A="$2" 'BEGIN { split(A, a, " ") }
    NR == 1 { for (i = 2; i <= NF; i++) { split($i, p, /[@.]/); load[i] = p[1]; grid[i] = p[2] }; next }
    { for (i = 2; i + 5 <= NF; i += 6) for (h = 0; h < 2; h++) for (r = 0; r < 3; r++) {
        v = 0; for (k = 0; k < 3; k++) v += a[3 * r + k + 1] * $(i + 3 * h + k)
        printf "%s %s %s%s %.17g %.17g\n", load[i], grid[i], h ? "M" : "F", substr("xyz", r + 1, 1), $1, v } }' "$1"
}
compare() { # csv.lines deck.lines what: each table value against the CSV's, relative
  # to the channel's largest (or, for a channel that is rounding noise, the file's)
  awk -v what="$3" 'NR == FNR { key = $1 " " $2 " " $3; want[key, $4 + 0] = $5; seen[key] = 1
      x = $5 < 0 ? -$5 : $5; if (x > big[key]) big[key] = x; if (x > all) all = x; next }
    { key = $1 " " $2 " " $3; got[key] = 1; n++
      if (!(key SUBSEP ($4 + 0) in want)) { printf "%s: %s at t = %s is not in the CSV\n", what, key, $4; bad = 1; next }
      d = $5 - want[key, $4 + 0]; if (d < 0) d = -d; s = big[key]; if (s < 1e-6 * all) s = 1e-6 * all
      d /= s; if (d > worst) worst = d }
    END { for (k in seen) if (!(k in got) && big[k] > 0) { printf "%s: channel %s (up to %g) left out\n", what, k, big[k]; bad = 1 }
          for (k in got) if (!(big[k] > 0)) { printf "%s: channel %s is zero but written\n", what, k; bad = 1 }
          printf "%s: %d table values, largest relative difference from the CSV %.2e\n", what, n, worst
          exit bad || !(n > 0 && worst <= 2e-9) }' "$1" "$2"
}

model '[1, 0, 0, 0]' tip.yaml
"$MBCC" run tip.yaml --body beam --loads loads.csv > run1.log 2>&1 || { cat run1.log; err "run --loads csv"; }
"$MBCC" run tip.yaml --body beam --loads loads.bdf > run2.log 2>&1 || { cat run2.log; err "run --loads bdf"; }
read_deck loads.bdf > deck.txt || err "the deck's cards"
csv_channels loads.csv "1 0 0 0 1 0 0 0 1" > csv.txt
compare csv.txt deck.txt "unturned body" || err "the deck's tables differ from the CSV"

# --- the body turned 90 degrees about z: body x = global y ------------------------------
model '{axis: [0, 0, 1], angle: 1.5707963267948966}' rot.yaml
"$MBCC" run rot.yaml --body beam --loads rot.csv > run3.log 2>&1 || { cat run3.log; err "run turned, csv"; }
"$MBCC" run rot.yaml --body beam --loads rot.bdf > run4.log 2>&1 || { cat run4.log; err "run turned, bdf"; }
read_deck rot.bdf > rdeck.txt || err "the turned deck's cards"
csv_channels rot.csv "0 -1 0 1 0 0 0 0 1" > rcsv.txt # A0: columns the body axes x = y, y = -x
compare rcsv.txt rdeck.txt "turned body" || err "the turned deck is not the CSV turned into basic axes"
# the push (0, 50, 20) (1 + sin(10 pi t)) global: at t = 0.1
# (sin = 0) (0, 50, 20) global = (50, 0, 20) in body axes: Fx in the CSV, Fy in the deck
awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "push@5.Fx") c = i; next } $1 + 0 == 0.1 { v = $c } END { exit !(c && v > 49.99 && v < 50.01) }' rot.csv ||
  err "the turned body's CSV does not have the push along body x"
awk '$1 == "push" && $3 == "Fy" && $4 + 0 == 0.1 { found = 1; exit !($5 > 49.99 && $5 < 50.01) } END { if (!found) exit 1 }' rdeck.txt ||
  err "the turned body's deck does not have the push along basic y"

# --- other deck extensions --------------------------------------------------------------
for ext in dat nas; do
  "$MBCC" run tip.yaml --body beam --loads "loads.$ext" > run5.log 2>&1 && grep -q '^TLOAD1' "loads.$ext" ||
    { cat run5.log; err "--loads FILE.$ext"; }
done
exit $fail
