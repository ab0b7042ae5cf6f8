#!/usr/bin/env bash
# test_golden.sh: the emitted code of every model and scene is byte-identical
# to tests/golden/emitted.sha256 (tests/golden.sh says how to update it).
set -u
cd "$(dirname "$0")/.." || exit 1
bash tests/golden.sh
