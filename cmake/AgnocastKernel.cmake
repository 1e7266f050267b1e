# Chooses the kernel the module is built for and the test VM boots:
# KDIR (cache or environment) wins; otherwise the newest Debian kernel image
# in /boot whose headers are installed.
set(KDIR "$ENV{KDIR}" CACHE PATH "Kernel build directory the module is built against")

file(GLOB _agnocast_vmlinuz_candidates /boot/vmlinuz-*)
list(SORT _agnocast_vmlinuz_candidates COMPARE NATURAL ORDER DESCENDING)
set(AGNOCAST_KERNEL_RELEASE "")
foreach(_image IN LISTS _agnocast_vmlinuz_candidates)
  string(REGEX REPLACE "^/boot/vmlinuz-" "" _release "${_image}")
  if(EXISTS "/usr/src/linux-headers-${_release}/Makefile")
    set(AGNOCAST_KERNEL_RELEASE "${_release}")
    break()
  endif()
endforeach()

if(NOT KDIR AND AGNOCAST_KERNEL_RELEASE)
  set(KDIR "/usr/src/linux-headers-${AGNOCAST_KERNEL_RELEASE}" CACHE PATH
      "Kernel build directory the module is built against" FORCE)
endif()
if(AGNOCAST_KERNEL_RELEASE)
  set(AGNOCAST_VM_KERNEL_IMAGE "/boot/vmlinuz-${AGNOCAST_KERNEL_RELEASE}")
  set(AGNOCAST_VM_KERNEL_MODULES "/lib/modules/${AGNOCAST_KERNEL_RELEASE}")
endif()

if(NOT KDIR)
  message(WARNING "No kernel headers found: install linux-image-amd64 and "
                  "linux-headers-amd64 (scripts/test does) or pass -DKDIR=. "
                  "The module and the VM suite are skipped.")
endif()

# agnocast_add_kernel_module(TARGET name SOURCE_DIR dir)
# Builds the Kbuild module in SOURCE_DIR (its Kbuild file, *.c, *.h and
# include/) out of tree against KDIR.  Sets <name>_KO in the caller's scope to
# the resulting .ko and makes it the target's KO property.
function(agnocast_add_kernel_module)
  cmake_parse_arguments(PARSE_ARGV 0 arg "" "TARGET;SOURCE_DIR;MODULE_NAME" "")
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
    COMMAND make -C "${KDIR}" "M=${build_dir}" W=1 modules
    DEPENDS ${sources}
    COMMENT "Building ${arg_MODULE_NAME}.ko against ${KDIR}"
    VERBATIM)
  add_custom_target(${arg_TARGET} ALL DEPENDS "${ko}")
  set_target_properties(${arg_TARGET} PROPERTIES KO "${ko}")
  set(${arg_TARGET}_KO "${ko}" PARENT_SCOPE)
endfunction()
