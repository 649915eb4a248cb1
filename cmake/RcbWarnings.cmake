# Compiler warnings and sanitizers for every librcb target (never -ffast-math:
# it breaks the NaN checks of the input validation).
add_library(rcb_warnings INTERFACE)
if(CMAKE_C_COMPILER_ID MATCHES "GNU|Clang")
  target_compile_options(rcb_warnings INTERFACE
    -Wall -Wextra -Wshadow -Wconversion -Wdouble-promotion -Wstrict-prototypes
    -Wmissing-prototypes -Wno-sign-conversion)
  if(RCB_WARNINGS_AS_ERRORS)
    target_compile_options(rcb_warnings INTERFACE -Werror)
  endif()
  if(RCB_ENABLE_SANITIZERS)
    # -O1 over the Debug build's -O0 (ASan's own advice for reasonable speed;
    # asserts stay on): the sanitizer stage of ./scripts/dev.sh test ran
    # minutes of time integration and fits at -O0
    target_compile_options(rcb_warnings INTERFACE -fsanitize=address,undefined
                           -fno-omit-frame-pointer -fno-sanitize-recover=undefined -O1)
    target_link_options(rcb_warnings INTERFACE -fsanitize=address,undefined)
  endif()
endif()
