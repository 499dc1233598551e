#!/usr/bin/env bash
# Installs what reconar needs on Debian 12. Idempotent: re-running installs nothing new.
#   scripts/install-deps.sh            build + test dependencies (x86-64 host)
#   scripts/install-deps.sh --cross    also the aarch64 cross toolchain, arm64 libraries and qemu-user
#   scripts/install-deps.sh --bench    also the peers measured side by side in bench/ (OpenCV)
set -euo pipefail

want_cross=0
want_bench=0
for arg in "$@"; do
  case "$arg" in
    --cross) want_cross=1 ;;
    --bench) want_bench=1 ;;
    -h|--help) sed -n '2,5p' "$0"; exit 0 ;;
    *) echo "install-deps.sh: unknown option '$arg'" >&2; exit 2 ;;
  esac
done

sudo_cmd=""
if [ "$(id -u)" -ne 0 ]; then sudo_cmd="sudo"; fi
export DEBIAN_FRONTEND=noninteractive

host_packages=(build-essential clang lld cmake ninja-build pkg-config
  libjpeg62-turbo-dev libpng-dev libeigen3-dev libsuitesparse-dev
  libgtest-dev libbenchmark-dev
  libapriltag-dev libcamera-dev libegl-dev libgles-dev libegl-mesa0 libgl1-mesa-dri
  libgbm-dev libdrm-dev libx11-dev
  poppler-utils librsvg2-bin xvfb xauth libifcplusplus-dev)
cross_packages=(g++-aarch64-linux-gnu qemu-user libstdc++6:arm64 libgcc-s1:arm64
  libjpeg62-turbo-dev:arm64 libpng-dev:arm64 libgtest-dev:arm64 libsuitesparse-dev:arm64
  libapriltag3:arm64 libcamera-dev:arm64 libegl-dev:arm64 libgles-dev:arm64 libgbm-dev:arm64
  libdrm-dev:arm64 libx11-dev:arm64)
bench_packages=(libopencv-dev libceres-dev)

missing() {
  local out=()
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || out+=("$p")
  done
  echo "${out[@]:-}"
}

todo=( $(missing "${host_packages[@]}") )
if [ "$want_cross" = 1 ]; then
  if ! dpkg --print-foreign-architectures | grep -qx arm64; then
    $sudo_cmd dpkg --add-architecture arm64
  fi
  todo+=( $(missing "${cross_packages[@]}") )
fi
if [ "$want_bench" = 1 ]; then todo+=( $(missing "${bench_packages[@]}") ); fi

if [ "${#todo[@]}" -eq 0 ]; then
  echo "install-deps: all packages present"
else
  echo "install-deps: installing ${todo[*]}"
  $sudo_cmd apt-get update -qq
  $sudo_cmd apt-get install -y -qq --no-install-recommends "${todo[@]}"
fi

# The Khronos glTF validator (npm package gltf-validator, pinned) checks the .glb files the tests
# write; scripts/test.sh hands this directory to CMake as RECONAR_GLTF_VALIDATOR_DIR. Without it
# (no npm, no network) those checks are skipped, so a failure here is only a warning.
gltf_validator_version=2.0.0-dev.3.10
gltf_validator_dir=${RECONAR_GLTF_VALIDATOR_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/reconar/gltf-validator}
if [ -f "$gltf_validator_dir/node_modules/gltf-validator/package.json" ]; then
  echo "install-deps: glTF validator present in $gltf_validator_dir"
else
  if ! command -v npm >/dev/null; then
    echo "install-deps: installing nodejs npm (for the glTF validator)"
    $sudo_cmd apt-get update -qq
    $sudo_cmd apt-get install -y -qq --no-install-recommends nodejs npm
  fi
  echo "install-deps: installing gltf-validator@$gltf_validator_version into $gltf_validator_dir"
  mkdir -p "$gltf_validator_dir"
  if ! npm install --prefix "$gltf_validator_dir" --no-audit --no-fund --loglevel=error \
      "gltf-validator@$gltf_validator_version"; then
    echo "install-deps: warning: npm could not install gltf-validator; the glTF validation tests will be skipped" >&2
  fi
fi
