#!/usr/bin/env bash
# Builds reconar with warnings as errors and runs every test (unit + end-to-end on ../shared/data).
#   scripts/test.sh [extra cmake args...]
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
build=${RECONAR_TEST_BUILD_DIR:-build-test}
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DRECONAR_WERROR=ON "$@" > "$build.configure.log" 2>&1 \
  || { cat "$build.configure.log"; exit 1; }
cmake --build "$build" -j"$(nproc)"
ctest --test-dir "$build" --output-on-failure -j"$(nproc)" --timeout 900
