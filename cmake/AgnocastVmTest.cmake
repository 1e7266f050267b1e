# In-VM tests: each component registers its kernel-side and end-to-end tests
# here; tests/CMakeLists.txt turns them into one VM boot and one ctest result
# per test (vm.<NAME>).
#
#   agnocast_add_vm_test(NAME name COMMAND program [args...]
#                        [TIMEOUT seconds] [TARGETS target...] [FILES path...]
#                        [OWN_FILES path...] [TREES "path[|exclude...]"...])
#
# COMMAND's program is a target (its binary is copied into the VM) or a file
# path (copied too); either is run by its file name from /opt/agnocast/bin,
# which is on PATH.  TARGETS (targets, also ones defined later) and FILES are
# further programs or data the test needs, copied to the same place with every
# shared library they link.  OWN_FILES are copied likewise, but only into the
# boots that run this test (large files, such as node, that no other kernel's
# boot should carry).
# TREES are host files or folders the test needs at the same absolute path in
# the VM (an interpreter and its modules), each optionally followed by "|" and
# space-separated tar --exclude patterns; every ELF file in them brings the
# shared libraries it links.  Like OWN_FILES, they go only where the test runs.
# The VM runs each test as root in a fresh /tmp/vm-tests/<NAME> directory with
# agnocast.ko freshly loaded with default parameters, default mqueue limits
# and empty /dev/mqueue and /dev/shm (the module path is $AGNOCAST_MODULE),
# one after another;
# TIMEOUT (default 120 s) bounds one test.
function(agnocast_add_vm_test)
  cmake_parse_arguments(PARSE_ARGV 0 arg "" "NAME;TIMEOUT" "COMMAND;TARGETS;FILES;OWN_FILES;TREES")
  if(NOT arg_NAME OR NOT arg_COMMAND)
    message(FATAL_ERROR "agnocast_add_vm_test needs NAME and COMMAND")
  endif()
  if(NOT arg_NAME MATCHES "^[A-Za-z0-9_.-]+$")
    message(FATAL_ERROR "agnocast_add_vm_test: NAME '${arg_NAME}' may use only [A-Za-z0-9_.-]")
  endif()
  if(NOT arg_TIMEOUT)
    set(arg_TIMEOUT 120)
  endif()

  list(POP_FRONT arg_COMMAND program)
  # TARGETS may name targets defined later (resolved when the build is generated).
  set(files)
  foreach(item IN LISTS arg_TARGETS)
    list(APPEND files "$<TARGET_FILE:${item}>")
  endforeach()
  foreach(item IN LISTS program arg_FILES)
    if(TARGET ${item})
      list(APPEND files "$<TARGET_FILE:${item}>")
    else()
      get_filename_component(item "${item}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
      list(APPEND files "${item}")
    endif()
  endforeach()
  if(TARGET ${program})
    set(program_name "$<TARGET_FILE_NAME:${program}>")
  else()
    get_filename_component(program_name "${program}" NAME)
  endif()

  string(JOIN " " args ${arg_COMMAND})
  set(lines)
  foreach(file IN LISTS files)
    string(APPEND lines "file\t${file}\n")
  endforeach()
  foreach(file IN LISTS arg_OWN_FILES)
    get_filename_component(file "${file}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
    string(APPEND lines "file\t${file}\t${arg_NAME}\n")
  endforeach()
  foreach(tree IN LISTS arg_TREES)
    string(REPLACE "|" "\t" tree "${tree}")
    string(APPEND lines "tree\t${tree}\n")
  endforeach()
  string(APPEND lines "test\t${arg_NAME}\t${arg_TIMEOUT}\t${program_name} ${args}\n")
  set_property(GLOBAL APPEND_STRING PROPERTY AGNOCAST_VM_MANIFEST "${lines}")
  set_property(GLOBAL APPEND PROPERTY AGNOCAST_VM_TEST_NAMES "${arg_NAME}")
endfunction()
