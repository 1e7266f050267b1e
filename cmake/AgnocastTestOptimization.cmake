# The test programs of an optimized build (Release, RelWithDebInfo) are
# compiled at AGNOCAST_TEST_OPTIMIZATION instead: they are not shipped, they
# are about half of a build, and at -O3 GCC takes about 60 % longer over them
# (33 s against 21 s at -O1 for the CLI's commands_test.cpp).  What they
# test, the libraries and programs, keeps the build's own optimization.
set(AGNOCAST_TEST_OPTIMIZATION "-O1" CACHE STRING
    "Optimization of the test programs in an optimized build; empty: the build's own")

# Every executable under DIRECTORY that links GoogleTest.
function(agnocast_collect_test_programs directory out_var)
  set(found)
  get_property(targets DIRECTORY "${directory}" PROPERTY BUILDSYSTEM_TARGETS)
  foreach(target IN LISTS targets)
    get_target_property(type ${target} TYPE)
    get_target_property(libraries ${target} LINK_LIBRARIES)
    if(type STREQUAL "EXECUTABLE" AND libraries MATCHES "GTest::|gtest")
      list(APPEND found ${target})
    endif()
  endforeach()
  get_property(subdirectories DIRECTORY "${directory}" PROPERTY SUBDIRECTORIES)
  foreach(subdirectory IN LISTS subdirectories)
    agnocast_collect_test_programs("${subdirectory}" below)
    list(APPEND found ${below})
  endforeach()
  set(${out_var} ${found} PARENT_SCOPE)
endfunction()

function(agnocast_set_test_optimization)
  if(NOT AGNOCAST_TEST_OPTIMIZATION OR NOT CMAKE_BUILD_TYPE MATCHES "^(Release|RelWithDebInfo)$")
    return()
  endif()
  agnocast_collect_test_programs("${PROJECT_SOURCE_DIR}" programs)
  foreach(program IN LISTS programs)
    # After the build type's flags on the command line, so it wins.
    target_compile_options(${program} PRIVATE ${AGNOCAST_TEST_OPTIMIZATION})
  endforeach()
endfunction()
