# Debian multiarch cross-compiling, shared by the toolchain files beside it
# (issue #27), which set CMAKE_SYSTEM_PROCESSOR, RCB_TARGET_TRIPLET and
# RCB_QEMU_ARCH first. Multiarch keeps the target's libraries in
# /usr/lib/<triplet> and shares /usr/include: the root path must include "/" (a
# root of /usr/<triplet> alone hides /usr/include, and lapacke.h is not found),
# and pkg-config must read the target's .pc files, not the host's.
set(CMAKE_SYSTEM_NAME Linux)
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
find_program(RCB_QEMU qemu-${RCB_QEMU_ARCH})
if(RCB_QEMU)
  set(CMAKE_CROSSCOMPILING_EMULATOR ${RCB_QEMU} -L /usr/${RCB_TARGET_TRIPLET})
endif()
