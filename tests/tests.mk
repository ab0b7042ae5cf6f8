# tests.mk: `make test` builds mbcc and runs every test (tests/run_tests.sh);
# `make sanitize` does the same with AddressSanitizer and UBSan in build-san/;
# `make test-browser` plays animation pages in headless Chromium (tests/browser.sh,
# about 30 s: not part of make test; .ci/run runs it after make test).
.PHONY: test sanitize test-browser
test: all $(WEB)/player.js
	B=$(B) CFLAGS="$(CFLAGS)" bash tests/run_tests.sh

# SHOTS=docs/img writes the screenshots of the documentation
test-browser: all $(WEB)/player.js
	B=$(B) SHOTS=$(SHOTS) bash tests/browser.sh

SAN_FLAGS := -O1 -g -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=undefined
sanitize:
	$(MAKE) B=build-san CFLAGS="$(SAN_FLAGS)" all build-san/web/player.js
	ASAN_OPTIONS=detect_leaks=0 B=build-san CFLAGS="$(SAN_FLAGS)" bash tests/run_tests.sh
