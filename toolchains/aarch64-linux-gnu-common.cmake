# What the aarch64 toolchains share (aarch64-linux-gnu.cmake with GCC, -clang.cmake with clang):
# the target, where its libraries are found, and qemu-user to run its tests.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)

# Headers and architecture-independent configs (Eigen) live in /usr; libraries in the multiarch dir.
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY BOTH)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE BOTH)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE BOTH)
set(ENV{PKG_CONFIG_LIBDIR} "/usr/lib/aarch64-linux-gnu/pkgconfig:/usr/share/pkgconfig")

# With the multiarch libc6:arm64 installed, qemu must use / as its sysroot: the cross loader in
# /usr/aarch64-linux-gnu mismatches that libc and hangs in pthread_create.
if(EXISTS "/lib/ld-linux-aarch64.so.1")
  set(CMAKE_CROSSCOMPILING_EMULATOR "qemu-aarch64;-L;/" CACHE STRING "" FORCE)
else()
  set(CMAKE_CROSSCOMPILING_EMULATOR "qemu-aarch64;-L;/usr/aarch64-linux-gnu" CACHE STRING "" FORCE)
endif()
