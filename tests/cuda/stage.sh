#!/usr/bin/env bash
# Stages a CUDA build for tests/cuda/gpu_round.sh, from the repository root:
#   tests/cuda/stage.sh BUILD_DIR [EXTRA_FILE_OR_DIR ...]
# ../shared/gpu/stage copies the executables one folder deep (snag, snag-cloth) and the
# libraries the GPU host lacks into .gpu; the test binaries are two folders deep
# (BUILD_DIR/tests/cuda/...), so they are copied into .gpu/bin here. ../shared/data is staged
# as an extra (the reports and bench steps read it through SNAG_DATA_DIR).
set -euo pipefail
[ $# -ge 1 ] || { echo "usage: tests/cuda/stage.sh BUILD_DIR [EXTRA ...]" >&2; exit 2; }
build=$1; shift
../shared/gpu/stage "$build" .gpu ../shared/data "$@"
cp "$build"/tests/*/snag_*_tests .gpu/bin/
ls .gpu/bin
