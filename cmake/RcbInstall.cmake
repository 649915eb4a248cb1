# Install rules: public headers (plus the generated rcb_config.h), the shared
# and static libraries, rcbtool, the rcb::rcb export (rcbConfig.cmake +
# rcbConfigVersion.cmake) and rcb.pc for pkg-config users; the same package
# also under the project's name, librcb (librcbConfig.cmake, librcb.pc).
#
# Consumers:
#   find_package(rcb CONFIG REQUIRED)  ->  target_link_libraries(app PRIVATE rcb::rcb)
#   cc app.c $(pkg-config --cflags --libs rcb)          (shared)
#   cc app.c $(pkg-config --static --cflags --libs rcb) (static)
#   find_package(librcb ...), pkg-config librcb: the same, the same targets
# rcb::rcb is the shared library when it was built, else an alias of
# rcb::rcb_static (made by rcbConfig.cmake).
include(CMakePackageConfigHelpers)

set(RCB_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/rcb CACHE STRING
  "Where rcbConfig.cmake is installed, relative to the prefix")
mark_as_advanced(RCB_INSTALL_CMAKEDIR)

install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/rcb
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT dev
  FILES_MATCHING PATTERN "*.h")
install(FILES ${PROJECT_BINARY_DIR}/include/rcb/rcb_config.h
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/rcb COMPONENT dev)

# Consumers of the export get rcb::rcb (EXPORT_NAME of target rcb) and
# rcb::rcb_static, in two files: the static one names the dependencies as
# link items, and rcbConfig.cmake reads it only when those are found or
# wanted (a shared-library consumer needs none of them; issue #17).
if(TARGET rcb)
  install(TARGETS rcb EXPORT rcbTargets
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT runtime
      NAMELINK_COMPONENT dev
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT dev
    RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
  install(EXPORT rcbTargets NAMESPACE rcb:: FILE rcbTargets.cmake
    DESTINATION ${RCB_INSTALL_CMAKEDIR} COMPONENT dev)
endif()
if(TARGET rcb_static)
  install(TARGETS rcb_static EXPORT rcbStaticTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT dev)
  install(EXPORT rcbStaticTargets NAMESPACE rcb:: FILE rcbStaticTargets.cmake
    DESTINATION ${RCB_INSTALL_CMAKEDIR} COMPONENT dev)
endif()

if(TARGET rcbtool)
  # tools/CMakeLists.txt installs rcbtool to bin; the installed tool finds the
  # installed librcb.so through a relative rpath, wherever the prefix is.
  file(RELATIVE_PATH _rcb_bin_to_lib ${CMAKE_INSTALL_FULL_BINDIR}
    ${CMAKE_INSTALL_FULL_LIBDIR})
  set_target_properties(rcbtool PROPERTIES INSTALL_RPATH "$ORIGIN/${_rcb_bin_to_lib}")
endif()

# What the static library needs at link time, for rcbConfig.cmake.
set(RCB_CONFIG_WITH_SUITESPARSE ${RCB_WITH_SUITESPARSE})
set(RCB_CONFIG_WITH_NLOPT ${RCB_WITH_NLOPT})
set(RCB_CONFIG_WITH_SUNDIALS ${RCB_WITH_SUNDIALS})
set(RCB_CONFIG_WITH_THREADS ${RCB_WITH_THREADS})
set(RCB_CONFIG_WITH_FFTW ${RCB_WITH_FFTW})
set(RCB_CONFIG_WITH_KISSFFT ${RCB_WITH_KISSFFT})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/rcbConfig.cmake.in
  ${PROJECT_BINARY_DIR}/rcbConfig.cmake
  INSTALL_DESTINATION ${RCB_INSTALL_CMAKEDIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/rcbConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMajorVersion)
set(_rcb_cmake_files ${PROJECT_BINARY_DIR}/rcbConfig.cmake
  ${PROJECT_BINARY_DIR}/rcbConfigVersion.cmake)
if(RCB_WITH_SUITESPARSE)
  list(APPEND _rcb_cmake_files ${PROJECT_SOURCE_DIR}/cmake/FindKLU.cmake)
endif()
install(FILES ${_rcb_cmake_files} DESTINATION ${RCB_INSTALL_CMAKEDIR} COMPONENT dev)

# find_package(librcb): the same package under the project's name (issue #36;
# cmake/librcbConfig.cmake.in says why), in a librcb directory beside rcb's.
get_filename_component(_rcb_cmake_parent ${RCB_INSTALL_CMAKEDIR} DIRECTORY)
file(RELATIVE_PATH RCB_LIBRCB_TO_RCB /${_rcb_cmake_parent}/librcb /${RCB_INSTALL_CMAKEDIR})
configure_file(${PROJECT_SOURCE_DIR}/cmake/librcbConfig.cmake.in
  ${PROJECT_BINARY_DIR}/librcbConfig.cmake @ONLY)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/librcbConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMajorVersion)
install(FILES ${PROJECT_BINARY_DIR}/librcbConfig.cmake
  ${PROJECT_BINARY_DIR}/librcbConfigVersion.cmake
  DESTINATION ${_rcb_cmake_parent}/librcb COMPONENT dev)

# pkg-config: the shared library by default; --static adds Libs.private.
set(RCB_PC_LIBS_PRIVATE "-llapacke -llapack -lblas")
set(RCB_PC_REQUIRES_PRIVATE "inih")
if(RCB_WITH_SUITESPARSE)
  string(APPEND RCB_PC_LIBS_PRIVATE " -lklu -lamd -lcolamd -lbtf -lsuitesparseconfig")
endif()
if(RCB_WITH_NLOPT)
  string(APPEND RCB_PC_REQUIRES_PRIVATE " nlopt")
endif()
if(RCB_WITH_FFTW)
  string(APPEND RCB_PC_REQUIRES_PRIVATE " fftw3")
elseif(RCB_WITH_KISSFFT)
  string(APPEND RCB_PC_REQUIRES_PRIVATE " kissfft-float")
endif()
if(RCB_WITH_SUNDIALS)
  string(APPEND RCB_PC_LIBS_PRIVATE
    " -lsundials_cvode -lsundials_sunmatrixdense -lsundials_nvecserial")
endif()
if(RCB_WITH_THREADS)
  string(APPEND RCB_PC_LIBS_PRIVATE " -lpthread")
endif()
string(APPEND RCB_PC_LIBS_PRIVATE " -lm")
# prefix is found from the .pc file's own place (${pcfiledir}), so the package
# stays right when installed with `cmake --install --prefix DIR` or moved.
file(RELATIVE_PATH _rcb_pc_to_prefix ${CMAKE_INSTALL_FULL_LIBDIR}/pkgconfig
  ${CMAKE_INSTALL_PREFIX})
string(REGEX REPLACE "/$" "" _rcb_pc_to_prefix "${_rcb_pc_to_prefix}")
set(RCB_PC_PREFIX "\${pcfiledir}/${_rcb_pc_to_prefix}")
# Absolute install dirs are kept as given.
foreach(_d LIBDIR INCLUDEDIR)
  if(IS_ABSOLUTE "${CMAKE_INSTALL_${_d}}")
    set(RCB_PC_${_d} "${CMAKE_INSTALL_${_d}}")
  else()
    set(RCB_PC_${_d} "\${prefix}/${CMAKE_INSTALL_${_d}}")
  endif()
endforeach()
configure_file(${PROJECT_SOURCE_DIR}/cmake/rcb.pc.in ${PROJECT_BINARY_DIR}/rcb.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/rcb.pc
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig COMPONENT dev)
# pkg-config librcb: the same file under the project's name (issue #36)
install(FILES ${PROJECT_BINARY_DIR}/rcb.pc
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig RENAME librcb.pc COMPONENT dev)
