# vehicle.mk: `make vehicle` regenerates docs/vehicle.md and docs/img/vehicle_*.png
# (scripts/vehicle.sh: the sports car's scenes run, benchmarked and plotted;
# minutes, not part of `make test`).  Included from the Makefile.
.PHONY: vehicle
vehicle: all
	MBCC=$(B)/mbcc bash scripts/vehicle.sh
