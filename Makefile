# mbcc: build, test, demo.  `make` builds build/mbcc and the runtime library.
CC      ?= cc
CFLAGS  ?= -O2 -g
WARN    := -Wall -Wextra -Werror
STD     := -std=c11
ROOT    := $(CURDIR)
LIBS    := -lyaml -lklu -lamd -lcolamd -lbtf -lsuitesparseconfig -llapack -lblas -lm

RT_SRC  := runtime/model_generic.c runtime/solver_select.c runtime/genalpha.c runtime/solver_klu.c runtime/solver_dense.c runtime/solver_generic.c runtime/solver_ldl.c \
           runtime/integrate.c runtime/driver.c runtime/ida.c runtime/bench.c
RT_HDR  := $(wildcard runtime/*.h)
CC_SRC  := compiler/main.c compiler/reader.c compiler/diag.c compiler/lower.c compiler/fe.c compiler/flex.c \
           compiler/assemble.c compiler/emit.c compiler/emit_rows.c compiler/order.c compiler/emit_ldl.c \
           compiler/trade.c compiler/trade_metric.c
CC_HDR  := $(wildcard compiler/*.h)
B       ?= build

.PHONY: all test demo clean sanitize docs bench trade extremes
all: $(B)/mbcc $(B)/libmbrt.a $(B)/libmbrt_float.a

$(B)/rt/%.o: runtime/%.c $(RT_HDR)
	@mkdir -p $(B)/rt
	$(CC) $(STD) $(WARN) $(CFLAGS) -Iruntime -c $< -o $@

$(B)/libmbrt.a: $(patsubst runtime/%.c,$(B)/rt/%.o,$(RT_SRC))
	rm -f $@ && ar rcs $@ $^

# the single-precision runtime (mbcc compile --real float): the emitted LDL^T
# only, since KLU, LAPACK and SUNDIALS work in double
RT_FLOAT_SRC := runtime/model_generic.c runtime/solver_select.c runtime/solver_ldl.c \
                runtime/integrate.c runtime/genalpha.c runtime/driver.c
$(B)/rt-float/%.o: runtime/%.c $(RT_HDR)
	@mkdir -p $(B)/rt-float
	$(CC) $(STD) $(WARN) $(CFLAGS) -DMB_REAL_FLOAT -Iruntime -c $< -o $@

$(B)/libmbrt_float.a: $(patsubst runtime/%.c,$(B)/rt-float/%.o,$(RT_FLOAT_SRC))
	rm -f $@ && ar rcs $@ $^

$(B)/mbcc: $(CC_SRC) $(CC_HDR) $(B)/libmbrt.a
	$(CC) $(STD) $(WARN) $(CFLAGS) -Icompiler -Iruntime -DMBCC_ROOT='"$(ROOT)"' \
	  -DMBCC_RTLIB='"$(ROOT)/$(B)/libmbrt.a"' -DMBCC_GEN_CFLAGS='"$(CFLAGS)"' \
	  $(CC_SRC) $(B)/libmbrt.a $(LIBS) -lcamd -o $@

demo: all
	$(B)/mbcc run models/slider_crank.yaml

# the timing comparison of every path (scripts/bench.sh): writes docs/benchmarks.md
bench: all
	MBCC=$(B)/mbcc sh scripts/bench.sh

# the speed/accuracy study (scripts/trade.sh): writes docs/trade.md and docs/img/trade_*.png
trade: all
	MBCC=$(B)/mbcc sh scripts/trade.sh

# the stability suite at the extremes (tests/extremes/run.sh): writes docs/stability.md
extremes: all
	MBCC=$(B)/mbcc bash tests/extremes/run.sh

include tests/tests.mk
include docs/results.mk

clean:
	rm -rf $(B) generated/*/ results
