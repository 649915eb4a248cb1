# Cross-compiling for arm-linux-gnueabihf on Debian multiarch (issue #27): the compiler of
# crossbuild-essential-armhf, the target's -dev packages installed as
# :armhf (dpkg --add-architecture), binaries run by qemu-user.
#   cmake --preset embedded-armhf     (or -DCMAKE_TOOLCHAIN_FILE=this file)
# Multiarch keeps the target's libraries in /usr/lib/arm-linux-gnueabihf and shares
# /usr/include: the root path must include "/" (a root of /usr/arm-linux-gnueabihf alone hides
# /usr/include, and lapacke.h is not found), and pkg-config must read the
# target's .pc files, not the host's.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR arm)
set(RCB_TARGET_TRIPLET arm-linux-gnueabihf)
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
find_program(RCB_QEMU qemu-arm)
if(RCB_QEMU)
  set(CMAKE_CROSSCOMPILING_EMULATOR ${RCB_QEMU} -L /usr/${RCB_TARGET_TRIPLET})
endif()
