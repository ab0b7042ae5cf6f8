#!/usr/bin/env bash
# grillage-deck.sh N > grid.bdf: a Nastran deck of a square grillage, 1 m,
# (N+1) x (N+1) GRIDs joined by CBARs along x and y (aluminium tubes, PBARL
# TUBE 5/4 mm), the edge x = 0 fixed by SPC1: 6 (N+1)^2 DOFs (N = 128:
# 99846).  For measuring the sparse modal analysis (docs/model-format.md,
# "Large bodies"):
#   scripts/grillage-deck.sh 128 > /tmp/grid.bdf
#   printf 'name: grid\nbodies:\n  plate: {type: flexible, fe_file: grid.bdf, reference: [], modes: 20}\n' > /tmp/grid.yaml
#   build/mbcc modes /tmp/grid.yaml --body plate
set -eu
n=${1:?usage: grillage-deck.sh N}
awk -v n="$n" 'BEGIN {
  h = 1.0 / n
  for (j = 0; j <= n; j++) for (i = 0; i <= n; i++) printf "GRID,%d,,%.17g,%.17g,0.\n", j * (n + 1) + i + 1, i * h, j * h
  e = 0
  for (j = 0; j <= n; j++) for (i = 0; i < n; i++) printf "CBAR,%d,5,%d,%d,0.,0.,1.\n", ++e, j * (n + 1) + i + 1, j * (n + 1) + i + 2
  for (j = 0; j < n; j++) for (i = 0; i <= n; i++) printf "CBAR,%d,5,%d,%d,0.,0.,1.\n", ++e, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1
  for (j = 0; j <= n; j++) printf "SPC1,1,123456,%d\n", j * (n + 1) + 1
  print "PBARL,5,8,,TUBE"; print ",5.e-3,4.e-3"; print "MAT1,8,7.e10,,.33,2700."
}'
