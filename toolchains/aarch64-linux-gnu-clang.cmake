# Cross-compile for 64-bit ARM Linux with clang (--target) and lld against Debian's aarch64 GCC
# installation (libstdc++ and crt files of g++-aarch64-linux-gnu) and the arm64 multiarch
# libraries (scripts/install-deps.sh --cross). The CI's aarch64 leg uses it (why: clang.cmake);
# aarch64-linux-gnu.cmake is the same with GCC.
include("${CMAKE_CURRENT_LIST_DIR}/clang.cmake")
set(CMAKE_C_COMPILER_TARGET aarch64-linux-gnu)
set(CMAKE_CXX_COMPILER_TARGET aarch64-linux-gnu)
include("${CMAKE_CURRENT_LIST_DIR}/aarch64-linux-gnu-common.cmake")
