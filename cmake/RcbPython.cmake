# The Python package's build (pyproject.toml at the root, scikit-build-core):
# component "python" puts librcb.so and rcbtool inside the package folder,
#   <site-packages>/librcb/librcb.so      found by librcb/_lib.py with no variable
#   <site-packages>/librcb/bin/rcbtool    run by the `rcbtool` console script
#   <site-packages>/librcb/share/rcb/rcb_plots.py   (rcbtool compare --plot)
# A wheel holds no symbolic links, so the library is one file without the
# VERSION/SOVERSION chain, and rcbtool finds it through $ORIGIN/.. .
if(NOT TARGET rcb)
  message(FATAL_ERROR "RCB_PYTHON_PACKAGE needs the shared library: RCB_BUILD_SHARED=ON")
endif()
set_property(TARGET rcb PROPERTY VERSION)
set_property(TARGET rcb PROPERTY SOVERSION)
install(TARGETS rcb LIBRARY DESTINATION librcb COMPONENT python)
if(TARGET rcbtool)
  set_target_properties(rcbtool PROPERTIES INSTALL_RPATH "$ORIGIN/..")
  install(TARGETS rcbtool RUNTIME DESTINATION librcb/bin COMPONENT python)
  install(FILES ${PROJECT_SOURCE_DIR}/tools/python/rcb_plots.py
    DESTINATION librcb/share/rcb COMPONENT python)
endif()
