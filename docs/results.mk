# results.mk: `make results` regenerates docs/results.md and docs/img/*.png
# from scratch (scripts/results.sh: mbcc, POSIX sh, awk, gnuplot).
# Included from the Makefile with:  include docs/results.mk
.PHONY: results
results: all
	MBCC=$(B)/mbcc sh scripts/results.sh
