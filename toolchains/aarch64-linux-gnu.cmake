# Cross-compile for 64-bit ARM Linux with Debian's g++-aarch64-linux-gnu and arm64 multiarch
# libraries (scripts/install-deps.sh --cross). Tests run through qemu-user.
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
include("${CMAKE_CURRENT_LIST_DIR}/aarch64-linux-gnu-common.cmake")
