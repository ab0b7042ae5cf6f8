# tests.mk: `make test` builds mbcc and runs every test (tests/run_tests.sh);
# `make sanitize` does the same with AddressSanitizer and UBSan in build-san/.
.PHONY: test sanitize
test: all
	B=$(B) CFLAGS="$(CFLAGS)" bash tests/run_tests.sh

SAN_FLAGS := -O1 -g -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=undefined
sanitize:
	$(MAKE) B=build-san CFLAGS="$(SAN_FLAGS)" all
	ASAN_OPTIONS=detect_leaks=0 B=build-san CFLAGS="$(SAN_FLAGS)" bash tests/run_tests.sh
