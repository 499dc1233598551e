#!/usr/bin/env bash
# Builds reconar with warnings as errors and runs every test (unit + end-to-end on ../shared/data).
#   scripts/test.sh [extra cmake args...]
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
build=${RECONAR_TEST_BUILD_DIR:-build-test}
# The glTF validator that install-deps.sh put in its cache directory, when it is there.
gltf_validator_dir=${RECONAR_GLTF_VALIDATOR_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/reconar/gltf-validator}
validator_args=()
if [ -f "$gltf_validator_dir/node_modules/gltf-validator/package.json" ]; then
  validator_args=(-DRECONAR_GLTF_VALIDATOR_DIR="$gltf_validator_dir")
fi
# A new build directory: Ninja, which schedules all targets in one job pool (the Makefile generator
# serialises per target), and clang with lld (toolchains/clang.cmake says why);
# RECONAR_TEST_TOOLCHAIN= (empty) builds with the default compiler, as the README's first command
# does. A build directory configured earlier keeps its generator and compiler.
new_build_args=()
toolchain=${RECONAR_TEST_TOOLCHAIN-toolchains/clang.cmake}
if [ ! -f "$build/CMakeCache.txt" ]; then
  new_build_args=(-G Ninja)
  if [ -n "$toolchain" ]; then new_build_args+=(-DCMAKE_TOOLCHAIN_FILE="$toolchain"); fi
fi
cmake -S . -B "$build" "${new_build_args[@]}" -DCMAKE_BUILD_TYPE=Release -DRECONAR_WERROR=ON "${validator_args[@]}" "$@" \
  > "$build.configure.log" 2>&1 \
  || { cat "$build.configure.log"; exit 1; }
cmake --build "$build" -j"$(nproc)"
# Under a virtual X server when there is one, so that the window tests (X11 presentation, the
# capture's window) run instead of skipping.
display=()
if command -v xvfb-run > /dev/null; then display=(xvfb-run -a -s "-screen 0 1280x1024x24"); fi
"${display[@]}" ctest --test-dir "$build" --output-on-failure -j"$(nproc)" --timeout 900
