# Cross-compiling for arm-linux-gnueabihf on Debian multiarch (issue #27): the compiler of
# crossbuild-essential-armhf, the target's -dev packages installed as
# :armhf (dpkg --add-architecture), binaries run by qemu-user.
#   cmake --preset embedded-armhf     (or -DCMAKE_TOOLCHAIN_FILE=this file)
set(CMAKE_SYSTEM_PROCESSOR arm)
set(RCB_TARGET_TRIPLET arm-linux-gnueabihf)
set(RCB_QEMU_ARCH arm)
include(${CMAKE_CURRENT_LIST_DIR}/debian-multiarch.cmake)
