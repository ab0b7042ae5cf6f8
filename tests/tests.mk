# tests.mk: `make test` builds mbcc and runs every test (tests/run_tests.sh);
# `make sanitize` does the same with AddressSanitizer, LeakSanitizer and UBSan
# (with float-cast-overflow) in build-san/;
# `make test-browser` plays animation pages in headless Chromium (tests/browser.sh,
# about 30 s: not part of make test; .ci/run runs it after make test).
.PHONY: test sanitize test-browser
test: all $(WEB)/player.js
	B=$(B) CFLAGS="$(RT_CFLAGS)" bash tests/run_tests.sh

# SHOTS=docs/img writes the screenshots of the documentation
test-browser: all $(WEB)/player.js
	B=$(B) SHOTS=$(SHOTS) bash tests/browser.sh

# float-cast-overflow: a double converted to an int it does not fit (not
# part of -fsanitize=undefined); leaks are errors too (detect_leaks=1)
SAN_FLAGS := -O1 -g -fno-omit-frame-pointer -fsanitize=address,undefined,float-cast-overflow \
             -fno-sanitize-recover=undefined,float-cast-overflow
sanitize:
	$(MAKE) B=build-san CFLAGS="$(SAN_FLAGS)" all build-san/web/player.js
	ASAN_OPTIONS=detect_leaks=1 B=build-san CFLAGS="$(SAN_FLAGS)" bash -c 'set -o pipefail; bash tests/run_tests.sh 2>&1 | tee build-san/sanitize.log'

# `make fuzz FUZZ_SECONDS=N`: the libFuzzer harness of the front end
# (tests/fuzz/fuzz_front.c: YAML -> IR -> checks -> lowering and pattern ->
# assembly analysis) built with clang's AddressSanitizer, UBSan with
# float-cast-overflow, and LeakSanitizer; seeded with models/, tests/models/
# and tests/bad_models/ (its modal/ files fuzzed as a flexible body's modal
# data file), with tests/fuzz/yaml.dict.  tests/fuzz/run.sh prints
# the executions and findings; a finding is copied to tests/fuzz_regressions/
# (replayed by tests/test_fuzz_regressions.sh).
.PHONY: fuzz
FUZZ_B       ?= build-fuzz
FUZZ_SECONDS ?= 60
FUZZ_CC      ?= clang
FUZZ_FLAGS   := -O1 -g -fno-omit-frame-pointer \
                -fsanitize=fuzzer,address,undefined,float-cast-overflow \
                -fno-sanitize-recover=undefined,float-cast-overflow
FUZZ_SRC     := tests/fuzz/fuzz_front.c runtime/core/model_generic.c \
                $(filter-out compiler/main.c compiler/tools/%,$(CC_SRC))
$(FUZZ_B)/fuzz_front: $(FUZZ_SRC) $(wildcard compiler/*/*.h runtime/*/*.h)
	@mkdir -p $(@D)
	$(FUZZ_CC) $(STD) $(FUZZ_FLAGS) $(CC_INC) -DMBCC_ROOT='"$(ROOT)"' $(FUZZ_SRC) -lspqr $(LIBS) -lcamd -o $@
fuzz: $(FUZZ_B)/fuzz_front
	bash tests/fuzz/run.sh $(FUZZ_B) $(FUZZ_SECONDS)

# `make reliability`: docs/reliability.md (scripts/reliability.sh): fuzzing,
# limits, the fault suite, the sanitizer runs
.PHONY: reliability
reliability: all
	MBCC=$(B)/mbcc FUZZ_SECONDS=$(FUZZ_SECONDS) bash scripts/reliability.sh
