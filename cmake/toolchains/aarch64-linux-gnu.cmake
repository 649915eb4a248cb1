# Cross-compiling for aarch64-linux-gnu on Debian multiarch (issue #27): the compiler of
# crossbuild-essential-arm64, the target's -dev packages installed as
# :arm64 (dpkg --add-architecture), binaries run by qemu-user.
#   cmake --preset embedded-aarch64     (or -DCMAKE_TOOLCHAIN_FILE=this file)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(RCB_TARGET_TRIPLET aarch64-linux-gnu)
set(RCB_QEMU_ARCH aarch64)
include(${CMAKE_CURRENT_LIST_DIR}/debian-multiarch.cmake)
