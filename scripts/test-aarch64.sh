#!/usr/bin/env bash
# Cross-builds for aarch64 and runs the unit tests under qemu-user through
# CMAKE_CROSSCOMPILING_EMULATOR. End-to-end tests (label e2e) run natively only. Built with clang
# (toolchains/aarch64-linux-gnu-clang.cmake, why: toolchains/clang.cmake);
# RECONAR_CROSS_TOOLCHAIN=toolchains/aarch64-linux-gnu.cmake builds with GCC instead.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh --cross
build=${RECONAR_CROSS_BUILD_DIR:-build-aarch64}
generator_args=()  # Ninja for a new build directory, as scripts/test.sh
if [ ! -f "$build/CMakeCache.txt" ]; then generator_args=(-G Ninja); fi
cmake -S . -B "$build" "${generator_args[@]}" -DCMAKE_BUILD_TYPE=Release -DRECONAR_WERROR=ON -DRECONAR_BUILD_E2E_TESTS=OFF \
  -DCMAKE_TOOLCHAIN_FILE="${RECONAR_CROSS_TOOLCHAIN:-toolchains/aarch64-linux-gnu-clang.cmake}" > "$build.configure.log" 2>&1 \
  || { cat "$build.configure.log"; exit 1; }
cmake --build "$build" -j"$(nproc)"
file "$build/bin/reconar" 2>/dev/null | grep -q aarch64 || { echo "not an aarch64 binary" >&2; exit 1; }
ctest --test-dir "$build" --output-on-failure -j"$(nproc)" -L unit --timeout 900
