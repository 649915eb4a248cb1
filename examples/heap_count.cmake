# rcb_example_count_heap(TARGET): on Linux (GNU ld, lld), TARGET's calls of
# the C heap from what it links statically go through examples/heap_count.h,
# which counts them (RCB_EXAMPLE_COUNT_HEAP); issue #36. Used by
# examples/consumer and examples/firmware when built on their own.
function(rcb_example_count_heap target)
  if(CMAKE_SYSTEM_NAME STREQUAL "Linux")
    target_compile_definitions(${target} PRIVATE RCB_EXAMPLE_COUNT_HEAP)
    target_link_options(${target} PRIVATE
      "LINKER:--wrap=malloc,--wrap=calloc,--wrap=realloc,--wrap=free")
  endif()
endfunction()
