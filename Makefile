# mbcc: build, test, demo.  `make` builds build/mbcc and the runtime library.
CC      ?= cc
# The simulators mbcc builds run on the machine that builds them, so their runtime
# (libmbrt.a) and the generated code are compiled for its processor when the C compiler
# can (NATIVE = -march=native): AVX's three-operand instructions make straight-line code
# a quarter smaller, and its speed is set by how fast it streams through the instruction
# cache (docs/architecture.md, "Compiled for the machine").  mbcc itself links a portable
# build of the runtime (libmbrt_portable.a), so what it computes and emits does not depend
# on the processor.  `make NATIVE=`: simulators that run on any x86-64.
CFLAGS  ?= -O2 -g
NATIVE  ?= $(shell $(CC) -march=native -x c -c /dev/null -o /dev/null 2>/dev/null && echo -march=native)
RT_CFLAGS := $(CFLAGS) $(NATIVE)
WARN    := -Wall -Wextra -Werror
# no fused multiply-adds the source does not write (clang contracts by default):
# the generic path and the generated code give the same numbers, whatever the flags
STD     := -std=c11 -ffp-contract=off
ROOT    := $(CURDIR)
LIBS    := -lyaml -lcholmod -larpack -lklu -lamd -lcolamd -lbtf -lsuitesparseconfig -llapack -lblas -lm

# the runtime: core/ is freestanding (no allocation, no I/O: kernels, model
# tables, the generic walker); hosted/ holds the integrators, solvers, CSV
# driver and benchmarks that run on an operating system
RT_INC  := -Iruntime/core -Iruntime/hosted
RT_SRC  := runtime/core/model_generic.c runtime/core/mb_step.c \
           $(addprefix runtime/hosted/,solver_select.c genalpha.c solver_klu.c solver_dense.c \
             solver_generic.c solver_ldl.c integrate.c equilibrium.c reassemble.c driver.c ida.c bench.c)
# the compiler, one folder a stage: front (YAML -> IR), flex (FE models and
# modal reduction), lower (IR -> coordinates, rows, pattern, assembly),
# back (ordering, LDL^T plan, C emission), tools (trade)
CC_DIRS := compiler/front compiler/elements compiler/flex compiler/lower compiler/back compiler/tools
CC_INC  := -Icompiler $(addprefix -I,$(CC_DIRS)) $(RT_INC)
CC_SRC  := $(wildcard compiler/*.c) $(foreach d,$(CC_DIRS),$(wildcard $(d)/*.c))
B       ?= build
DEPFLAGS = -MMD -MP

.PHONY: FORCE all test demo clean sanitize docs bench peers ldl-profile trade extremes web test-browser embedded man release-check  install scaling chassis vehicle sweeps slurm-check
all: $(B)/mbcc $(B)/libmbrt.a $(B)/libmbrt_float.a

# every object depends on the compiler and flags it was built with: a change of CC or
# CFLAGS (say, a portable build after a native one) rebuilds everything
BUILD_FLAGS := $(CC) $(STD) $(WARN) $(CFLAGS) / $(NATIVE)
$(B)/flags: FORCE
	@mkdir -p $(B)
	@echo '$(BUILD_FLAGS)' | cmp -s - $@ || echo '$(BUILD_FLAGS)' > $@
FORCE:

# objects keep the source's folders: $(B)/rt/core/x.o, $(B)/cc/front/x.o
$(B)/rt/%.o: runtime/%.c $(B)/flags
	@mkdir -p $(@D)
	$(CC) $(STD) $(WARN) $(RT_CFLAGS) $(DEPFLAGS) $(RT_INC) -c $< -o $@
$(B)/rt-portable/%.o: runtime/%.c $(B)/flags
	@mkdir -p $(@D)
	$(CC) $(STD) $(WARN) $(CFLAGS) $(DEPFLAGS) $(RT_INC) -c $< -o $@

# SUNDIALS' KLU header includes <klu.h>, which Debian keeps in suitesparse/
$(B)/rt/hosted/ida.o $(B)/rt-portable/hosted/ida.o: RT_INC += -I/usr/include/suitesparse

$(B)/libmbrt.a: $(patsubst runtime/%.c,$(B)/rt/%.o,$(RT_SRC))
	rm -f $@ && ar rcs $@ $^
$(B)/libmbrt_portable.a: $(patsubst runtime/%.c,$(B)/rt-portable/%.o,$(RT_SRC))
	rm -f $@ && ar rcs $@ $^

# the single-precision runtime (mbcc compile --real float): the emitted LDL^T
# only, since KLU, LAPACK and SUNDIALS work in double
RT_FLOAT_SRC := runtime/core/model_generic.c runtime/core/mb_step.c \
                $(addprefix runtime/hosted/,solver_select.c solver_ldl.c integrate.c equilibrium.c reassemble.c genalpha.c driver.c)
$(B)/rt-float/%.o: runtime/%.c $(B)/flags
	@mkdir -p $(@D)
	$(CC) $(STD) $(WARN) $(RT_CFLAGS) $(DEPFLAGS) -DMB_REAL_FLOAT $(RT_INC) -c $< -o $@

$(B)/libmbrt_float.a: $(patsubst runtime/%.c,$(B)/rt-float/%.o,$(RT_FLOAT_SRC))
	rm -f $@ && ar rcs $@ $^

# where the built mbcc finds its templates, runtime headers and library
CC_DEFS := -DMBCC_ROOT='"$(ROOT)"' -DMBCC_RTLIB='"$(abspath $(B))/libmbrt.a"' -DMBCC_GEN_CFLAGS='"$(RT_CFLAGS)"' \
           -DMBCC_PLAYER_JS='"$(abspath $(B))/web/player.js"'
$(B)/cc/%.o: compiler/%.c $(B)/flags
	@mkdir -p $(@D)
	$(CC) $(STD) $(WARN) $(CFLAGS) $(DEPFLAGS) $(CC_INC) $(CC_DEFS) -c $< -o $@

CC_OBJ := $(patsubst compiler/%.c,$(B)/cc/%.o,$(CC_SRC))
# the assembly analysis (compiler/lower/assemble.c) uses SuiteSparseQR and CHOLMOD
$(B)/mbcc: $(CC_OBJ) $(B)/libmbrt_portable.a
	$(CC) $(CFLAGS) $(CC_OBJ) $(B)/libmbrt_portable.a -lspqr $(LIBS) -lcamd -o $@

-include $(CC_OBJ:.o=.d) $(patsubst runtime/%.c,$(B)/rt/%.d,$(RT_SRC)) $(patsubst runtime/%.c,$(B)/rt-portable/%.d,$(RT_SRC)) \
         $(patsubst runtime/%.c,$(B)/rt-float/%.d,$(RT_FLOAT_SRC))

demo: all
	$(B)/mbcc run models/slider_crank.yaml

# the sports car's chassis FE model from the vehicle spec's recipe (section 10.2);
# tests/test_chassis.sh checks that the committed file is what this writes
chassis:
	python3 scripts/sports_car_chassis.py models/sports_car_chassis.fe.yaml

# the timing comparison of every path (scripts/bench.sh): writes docs/benchmarks.md
bench: all
	MBCC=$(B)/mbcc GEN_CFLAGS="$(filter-out -g,$(RT_CFLAGS))" sh scripts/bench.sh

# only the MuJoCo peer of make bench (scripts/peers.sh): writes docs/peers.md
peers: all
	MBCC=$(B)/mbcc GEN_CFLAGS="$(filter-out -g,$(RT_CFLAGS))" PEER_DOC=docs/peers.md sh scripts/peers.sh

# the emitted LDL^T's factor and solve alone, straight-line against looped
# (scripts/ldl-profile.sh; docs/architecture.md): prints a Markdown table
ldl-profile: all
	MBCC=$(B)/mbcc GEN_CFLAGS="$(filter-out -g,$(RT_CFLAGS))" sh scripts/ldl-profile.sh

# build and run time against model size on pendulum chains and fleets of the
# sports car (scripts/scaling.sh): writes docs/scaling.md; SIZES="5 10 20"
# FLEET_SIZES="1 2" for a quick one
scaling: all
	MBCC=$(B)/mbcc bash scripts/scaling.sh

# the speed/accuracy study (scripts/trade.sh): writes docs/trade.md and docs/img/trade_*.png
trade: all
	MBCC=$(B)/mbcc sh scripts/trade.sh

# the stability suite at the extremes (tests/extremes/run.sh): writes docs/stability.md
extremes: all
	MBCC=$(B)/mbcc bash tests/extremes/run.sh

# the browser animation's player (mbcc animate): web/player.js with three.js and
# OrbitControls bundled by esbuild into one script that mbcc inlines into each
# page; the npm packages are pinned by web/package-lock.json (npm ci)
WEB := $(B)/web
web: $(WEB)/player.js
$(WEB)/node_modules/.installed: web/package.json web/package-lock.json
	@command -v npm >/dev/null || { echo "make web: npm is missing (bash scripts/install-deps.sh installs it)"; exit 1; }
	@mkdir -p $(WEB)
	cp web/package.json web/package-lock.json $(WEB)/
	cd $(WEB) && npm ci --no-audit --no-fund --loglevel=error
	touch $@
$(WEB)/player.js: web/player.js $(WEB)/node_modules/.installed
	NODE_PATH=$(ROOT)/$(WEB)/node_modules $(WEB)/node_modules/.bin/esbuild web/player.js \
	  --bundle --minify --format=iife --log-level=warning --outfile=$@
# the embedded target on qemu's Cortex-M4F (scripts/embedded.sh): writes docs/embedded.md
embedded: all
	MBCC=$(B)/mbcc bash scripts/embedded.sh

# before a release: the measured documents are current (scripts/docs-fresh.sh)
release-check:
	bash scripts/docs-fresh.sh

# the man page, from the same text as mbcc help (compiler/help.c)
man: $(B)/mbcc
	$(B)/mbcc help --man > docs/mbcc.1

# make install PREFIX=DIR [DESTDIR=STAGE]: the command, the runtime library
# (double and float) and its headers, the templates, pkg-config's mbcc.pc, the
# man page and the docs.  The installed mbcc finds the rest relative to
# itself (compiler/paths.c), so the tree can be moved as a whole.
PREFIX  ?= /usr/local
VERSION := $(shell sed -n 's/^\#define MBCC_VERSION "\(.*\)"/\1/p' compiler/version.h)
RT_HDR  := $(wildcard runtime/core/*.h runtime/hosted/*.h)
install: all
	install -d $(DESTDIR)$(PREFIX)/bin $(DESTDIR)$(PREFIX)/lib/pkgconfig $(DESTDIR)$(PREFIX)/include/mbcc \
	  $(DESTDIR)$(PREFIX)/share/mbcc/templates $(DESTDIR)$(PREFIX)/share/man/man1 $(DESTDIR)$(PREFIX)/share/doc/mbcc
	install -m 755 $(B)/mbcc $(DESTDIR)$(PREFIX)/bin/mbcc
	install -m 644 $(B)/libmbrt.a $(B)/libmbrt_float.a $(DESTDIR)$(PREFIX)/lib/
	install -m 644 $(RT_HDR) $(DESTDIR)$(PREFIX)/include/mbcc/
	install -d $(DESTDIR)$(PREFIX)/include/mbcc/elements
	install -m 644 $(wildcard runtime/core/elements/*.h) $(DESTDIR)$(PREFIX)/include/mbcc/elements/
	install -m 644 templates/*.in $(DESTDIR)$(PREFIX)/share/mbcc/templates/
	if [ -f $(WEB)/player.js ]; then install -m 644 $(WEB)/player.js $(DESTDIR)$(PREFIX)/share/mbcc/; fi
	install -m 644 docs/mbcc.1 $(DESTDIR)$(PREFIX)/share/man/man1/
	install -m 644 README.md docs/*.md $(DESTDIR)$(PREFIX)/share/doc/mbcc/
	sed -e 's|@PREFIX@|$(PREFIX)|' -e 's|@VERSION@|$(VERSION)|' -e 's|@LIBS@|$(filter-out -lyaml -lcholmod -larpack,$(LIBS))|' mbcc.pc.in \
	  > $(DESTDIR)$(PREFIX)/lib/pkgconfig/mbcc.pc

include tests/tests.mk
include docs/results.mk
include docs/vehicle.mk

clean:
	rm -rf $(B) generated/*/ results

# a sweep's Slurm job array on a single-node Slurm started here (munge, slurmctld, slurmd), against
# GNU parallel (scripts/slurm-check.sh; needs Debian slurm-wlm and munge, not part of make test)
slurm-check: all
	MBCC=$(B)/mbcc bash scripts/slurm-check.sh

# the design-of-experiments study (scripts/sweeps.sh): writes docs/sweeps.md and docs/img/sweep_*.png
sweeps: all
	MBCC=$(B)/mbcc bash scripts/sweeps.sh
