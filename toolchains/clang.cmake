# The host's clang and lld instead of the default GCC and ld (scripts/install-deps.sh). The CI's
# builds use it (scripts/test.sh, and aarch64-linux-gnu-clang.cmake for the cross build): clang
# compiles this code base in about two thirds of GCC's time, and half for the tests, whose
# precompiled header holds GoogleTest's instantiated templates under clang.
set(CMAKE_C_COMPILER clang)
set(CMAKE_CXX_COMPILER clang++)
set(CMAKE_EXE_LINKER_FLAGS_INIT "-fuse-ld=lld")
set(CMAKE_SHARED_LINKER_FLAGS_INIT "-fuse-ld=lld")
set(CMAKE_MODULE_LINKER_FLAGS_INIT "-fuse-ld=lld")
