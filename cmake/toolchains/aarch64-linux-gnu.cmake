# Cross-compiling for aarch64-linux-gnu on Debian multiarch (issue #27): the compiler of
# crossbuild-essential-arm64, the target's -dev packages installed as
# :arm64 (dpkg --add-architecture), binaries run by qemu-user.
#   cmake --preset embedded-aarch64     (or -DCMAKE_TOOLCHAIN_FILE=this file)
# Multiarch keeps the target's libraries in /usr/lib/aarch64-linux-gnu and shares
# /usr/include: the root path must include "/" (a root of /usr/aarch64-linux-gnu alone hides
# /usr/include, and lapacke.h is not found), and pkg-config must read the
# target's .pc files, not the host's.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(RCB_TARGET_TRIPLET aarch64-linux-gnu)
set(CMAKE_C_COMPILER ${RCB_TARGET_TRIPLET}-gcc)
set(CMAKE_LIBRARY_ARCHITECTURE ${RCB_TARGET_TRIPLET})
set(CMAKE_FIND_ROOT_PATH /usr/${RCB_TARGET_TRIPLET} /)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
set(ENV{PKG_CONFIG_LIBDIR} /usr/lib/${RCB_TARGET_TRIPLET}/pkgconfig:/usr/share/pkgconfig)
set(ENV{PKG_CONFIG_PATH} "")
# ctest and add_test commands run the target binaries through qemu-user, with
# the target's loader and libraries from /usr/${RCB_TARGET_TRIPLET} and /
find_program(RCB_QEMU qemu-aarch64)
if(RCB_QEMU)
  set(CMAKE_CROSSCOMPILING_EMULATOR ${RCB_QEMU} -L /usr/${RCB_TARGET_TRIPLET})
endif()
