# The kernels the module is built for and the VM suite boots, as listed by
# tests/vm/kernels (stock, rt, 6.12, debug: whichever is ready).  For each
# name in AGNOCAST_KERNELS: AGNOCAST_KERNEL_<name>_RELEASE, _IMAGE and _KDIR.
# KDIR (cache or environment) overrides the stock kernel's headers.  KDIR,
# AGNOCAST_KERNEL_RELEASE and AGNOCAST_VM_KERNEL_IMAGE describe the stock
# kernel, which the native build and the single-kernel tests use.
set(KDIR "$ENV{KDIR}" CACHE PATH "Kernel build directory the module is built against")
# OFF: user space only (scripts/make-packages): no
# agnocast.ko, no VM suite.
option(AGNOCAST_BUILD_MODULE "Build agnocast.ko and register the VM suite" ON)
# Empty: every kernel tests/vm/kernels lists as ready.  A list (e.g. "stock")
# keeps only those: scripts/test --quick.
set(AGNOCAST_VM_KERNELS "" CACHE STRING "Kernels the VM suite boots (empty: every ready kernel)")
if(NOT AGNOCAST_BUILD_MODULE)
  set(AGNOCAST_KERNELS)
  set(AGNOCAST_KERNEL_RELEASE "")
  set(KDIR "")
  message(STATUS "AGNOCAST_BUILD_MODULE is OFF: user space only, no module and no VM suite")
  return()
endif()

execute_process(COMMAND "${PROJECT_SOURCE_DIR}/tests/vm/kernels" list
                OUTPUT_VARIABLE _agnocast_kernel_lines RESULT_VARIABLE _agnocast_kernels_rc)
if(NOT _agnocast_kernels_rc EQUAL 0)
  message(FATAL_ERROR "tests/vm/kernels list failed")
endif()
set(AGNOCAST_KERNELS)
string(REPLACE "\n" ";" _agnocast_kernel_lines "${_agnocast_kernel_lines}")
foreach(_line IN LISTS _agnocast_kernel_lines)
  if(_line STREQUAL "")
    continue()
  endif()
  string(REPLACE "\t" ";" _fields "${_line}")
  list(GET _fields 0 _name)
  list(GET _fields 1 AGNOCAST_KERNEL_${_name}_RELEASE)
  list(GET _fields 2 AGNOCAST_KERNEL_${_name}_IMAGE)
  list(GET _fields 3 AGNOCAST_KERNEL_${_name}_KDIR)
  if(AGNOCAST_VM_KERNELS AND NOT _name IN_LIST AGNOCAST_VM_KERNELS)
    continue()
  endif()
  list(APPEND AGNOCAST_KERNELS ${_name})
endforeach()

set(AGNOCAST_KERNEL_RELEASE "")
if("stock" IN_LIST AGNOCAST_KERNELS)
  set(AGNOCAST_KERNEL_RELEASE "${AGNOCAST_KERNEL_stock_RELEASE}")
  set(AGNOCAST_VM_KERNEL_IMAGE "${AGNOCAST_KERNEL_stock_IMAGE}")
  if(NOT KDIR)
    set(KDIR "${AGNOCAST_KERNEL_stock_KDIR}" CACHE PATH
        "Kernel build directory the module is built against" FORCE)
  endif()
  set(AGNOCAST_KERNEL_stock_KDIR "${KDIR}")
endif()
message(STATUS "VM suite kernels: ${AGNOCAST_KERNELS}")

if(NOT KDIR)
  message(WARNING "No kernel headers found: install linux-image-amd64 and "
                  "linux-headers-amd64 (scripts/test does) or pass -DKDIR=. "
                  "The module and the VM suite are skipped.")
endif()

# agnocast_add_kernel_module(TARGET name SOURCE_DIR dir MODULE_NAME name
#                            [KDIR dir] [COVERAGE] [UNTRACED])
# Builds the Kbuild module in SOURCE_DIR (its Kbuild file, *.c, *.h and
# include/) out of tree with W=1 against KDIR (default: the stock kernel's).
# COVERAGE passes AGNOCAST_COVERAGE=1, which the module's Kbuild turns into
# gcov and kcov instrumentation (for a kernel built with both).  UNTRACED
# passes AGNOCAST_UNTRACED=1 (a module without its trace events), and leaves
# the target out of the default build.
# Sets <name>_KO in the caller's scope to the resulting .ko and makes it the
# target's KO property.
function(agnocast_add_kernel_module)
  cmake_parse_arguments(PARSE_ARGV 0 arg "COVERAGE;UNTRACED" "TARGET;SOURCE_DIR;MODULE_NAME;KDIR" "")
  if(NOT arg_KDIR)
    set(arg_KDIR "${KDIR}")
  endif()
  file(GLOB_RECURSE sources CONFIGURE_DEPENDS
       "${arg_SOURCE_DIR}/*.c" "${arg_SOURCE_DIR}/*.h" "${arg_SOURCE_DIR}/Kbuild")
  list(FILTER sources EXCLUDE REGEX "/tests/")
  set(build_dir "${CMAKE_CURRENT_BINARY_DIR}/${arg_TARGET}-kbuild")
  set(ko "${build_dir}/${arg_MODULE_NAME}.ko")
  add_custom_command(
    OUTPUT "${ko}"
    COMMAND ${CMAKE_COMMAND} -E rm -rf "${build_dir}"
    COMMAND ${CMAKE_COMMAND} -E copy_directory "${arg_SOURCE_DIR}" "${build_dir}"
    COMMAND ${CMAKE_COMMAND} -E rm -rf "${build_dir}/tests"
    COMMAND make -C "${arg_KDIR}" "M=${build_dir}" W=1
            "AGNOCAST_WERROR=$<BOOL:${AGNOCAST_WERROR}>"
            "AGNOCAST_COVERAGE=$<BOOL:${arg_COVERAGE}>"
            "AGNOCAST_UNTRACED=$<BOOL:${arg_UNTRACED}>" modules
    DEPENDS ${sources}
    COMMENT "Building ${arg_MODULE_NAME}.ko against ${arg_KDIR}"
    VERBATIM)
  # A module without its trace events is built only when asked for.
  set(all ALL)
  if(arg_UNTRACED)
    set(all "")
  endif()
  add_custom_target(${arg_TARGET} ${all} DEPENDS "${ko}")
  set_target_properties(${arg_TARGET} PROPERTIES KO "${ko}")
  set(${arg_TARGET}_KO "${ko}" PARENT_SCOPE)
endfunction()
