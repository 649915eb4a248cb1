# The serial OpenBLAS for rcbtool, the tests and the benchmarks (issue #26, item 5).
#
# librcb runs its own threads (the FRF sweep, the diagnosis); a threaded BLAS under
# it only oversubscribes the cores, and its start-up threads (made before main, in
# the library's constructor) kill the process when pthread_create fails. Debian
# ships OpenBLAS in three builds side by side (libopenblas0-pthread, -openmp,
# -serial), each in /usr/lib/<triplet>/openblas-<variant>/ with the same sonames
# (libopenblas.so.0, libblas.so.3, liblapack.so.3); the system picks one through
# update-alternatives. RCB_SERIAL_BLAS puts the serial directory first in the
# executables' search path (DT_RPATH, which also applies to the libraries they
# load, so librcb and liblapacke find the same libopenblas.so.0):
#   AUTO (default): when RCB_OPENBLAS_SERIAL_DIR holds libopenblas.so.0
#   ON: required (configure fails without it)   OFF: the system's choice
# librcb itself is not changed: a program linking it keeps its own BLAS.
set(RCB_SERIAL_BLAS AUTO CACHE STRING
  "Link rcbtool, tests and benchmarks against the serial OpenBLAS: AUTO, ON or OFF")
set_property(CACHE RCB_SERIAL_BLAS PROPERTY STRINGS AUTO ON OFF)
set(RCB_OPENBLAS_SERIAL_DIR "/usr/lib/${CMAKE_LIBRARY_ARCHITECTURE}/openblas-serial" CACHE PATH
  "Directory of the serial OpenBLAS (Debian: apt-get install libopenblas0-serial)")

set(RCB_USE_SERIAL_BLAS OFF)
if(NOT RCB_SERIAL_BLAS STREQUAL "OFF")
  if(EXISTS "${RCB_OPENBLAS_SERIAL_DIR}/libopenblas.so.0")
    set(RCB_USE_SERIAL_BLAS ON)
    message(STATUS "rcbtool, tests, benchmarks: serial OpenBLAS from ${RCB_OPENBLAS_SERIAL_DIR}")
  elseif(RCB_SERIAL_BLAS STREQUAL "ON")
    message(FATAL_ERROR "RCB_SERIAL_BLAS=ON: no libopenblas.so.0 in ${RCB_OPENBLAS_SERIAL_DIR} "
      "(Debian: apt-get install libopenblas0-serial, or set RCB_OPENBLAS_SERIAL_DIR)")
  else()
    message(STATUS "rcbtool, tests, benchmarks: the system's BLAS (no serial OpenBLAS in "
      "${RCB_OPENBLAS_SERIAL_DIR}; apt-get install libopenblas0-serial to use it)")
  endif()
endif()

# Called in a directory that makes executables only (tools/, tests/): every target
# made after it there searches the serial directory first, in the build tree and
# installed.
macro(rcb_serial_blas_link_options)
  if(RCB_USE_SERIAL_BLAS)
    add_link_options("LINKER:--disable-new-dtags") # DT_RPATH: also for the libraries loaded
    list(APPEND CMAKE_BUILD_RPATH "${RCB_OPENBLAS_SERIAL_DIR}")
    list(APPEND CMAKE_INSTALL_RPATH "${RCB_OPENBLAS_SERIAL_DIR}")
  endif()
endmacro()
