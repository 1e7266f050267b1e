# agnocast_generate_messages(<target> PACKAGE <package> FILES <file.msg or file.srv>...
#                            [DEPENDENCIES <package or target>...] [PYTHON])
#
# Generates <package>/msg/<snake_case>.hpp for each .msg file and
# <package>/srv/<snake_case>.hpp for each .srv file, and makes <target>, an
# INTERFACE library to link: it carries the include folder, agnocast::agnocast
# and the targets of the dependencies. The .msg FILES of one package live in one
# folder (its msg/), the .srv FILES in one folder (its srv/).
# A dependency is a target made by this function, or a package of the standard
# set (std_msgs, geometry_msgs, sensor_msgs, nav_msgs, ...: agnocast::<name>).
# PYTHON also makes <target>_python, which writes the Python message module
# <dir>/agnocast/msg/<package>.py and, for .srv files, the service module
# <dir>/agnocast/srv/<package>.py (see AgnocastPythonMessages.cmake); <dir> is
# the target's property AGNOCAST_PYTHON_DIR, for PYTHONPATH or installation.

include(${CMAKE_CURRENT_LIST_DIR}/AgnocastPythonMessages.cmake)

# "PointCloud2" -> "point_cloud2", the rule of agnocast-msggen's snake_case().
function(_agnocast_snake_case name out)
  string(REGEX REPLACE "([A-Z])([A-Z][a-z])" "\\1_\\2" name "${name}")
  string(REGEX REPLACE "([a-z0-9])([A-Z])" "\\1_\\2" name "${name}")
  string(TOLOWER "${name}" name)
  set(${out} "${name}" PARENT_SCOPE)
endfunction()

function(agnocast_generate_messages target)
  cmake_parse_arguments(PARSE_ARGV 1 arg "PYTHON" "PACKAGE" "FILES;DEPENDENCIES")
  if(NOT arg_PACKAGE OR NOT arg_FILES)
    message(FATAL_ERROR "agnocast_generate_messages(${target}): PACKAGE and FILES are required")
  endif()
  if(TARGET agnocast-msggen)
    set(generator agnocast-msggen)  # building agnocast itself
  else()
    set(generator agnocast::agnocast-msggen)
  endif()

  set(output_dir ${CMAKE_CURRENT_BINARY_DIR}/agnocast_messages/${target})
  set(inputs "")
  set(msg_files "")
  set(srv_files "")
  set(headers "")
  foreach(file IN LISTS arg_FILES)
    get_filename_component(file "${file}" ABSOLUTE)
    get_filename_component(name "${file}" NAME_WE)
    get_filename_component(extension "${file}" LAST_EXT)
    _agnocast_snake_case(${name} snake)
    if(extension STREQUAL ".msg")
      list(APPEND msg_files ${file})
      list(APPEND headers ${output_dir}/${arg_PACKAGE}/msg/${snake}.hpp)
    elseif(extension STREQUAL ".srv")
      list(APPEND srv_files ${file})
      list(APPEND headers ${output_dir}/${arg_PACKAGE}/srv/${snake}.hpp)
    else()
      message(FATAL_ERROR "agnocast_generate_messages(${target}): '${file}' is neither a .msg "
                          "nor a .srv file")
    endif()
    list(APPEND inputs ${file})
  endforeach()

  # Every package reachable through the dependencies, as PKG=DIR for --include;
  # the package's own folder of .msg files first, if it has any.
  set(includes "")
  if(msg_files)
    list(GET msg_files 0 first_msg)
    get_filename_component(msg_dir "${first_msg}" DIRECTORY)
    set(includes "${arg_PACKAGE}=${msg_dir}")
  endif()
  set(dependency_targets "")
  set(dependency_files "")
  foreach(dependency IN LISTS arg_DEPENDENCIES)
    if(TARGET ${dependency})
      set(dependency_target ${dependency})
    elseif(TARGET agnocast::${dependency})
      set(dependency_target agnocast::${dependency})
    else()
      message(FATAL_ERROR "agnocast_generate_messages(${target}): no message package "
                          "'${dependency}' (a target of agnocast_generate_messages or agnocast::<name>)")
    endif()
    get_target_property(dependency_includes ${dependency_target} AGNOCAST_MSG_INCLUDES)
    list(APPEND includes ${dependency_includes})
    list(APPEND dependency_targets ${dependency_target})
    foreach(include IN LISTS dependency_includes)
      string(REGEX REPLACE "^[^=]*=" "" folder "${include}")
      file(GLOB folder_files "${folder}/*.msg")
      list(APPEND dependency_files ${folder_files})
    endforeach()
  endforeach()
  list(REMOVE_DUPLICATES includes)
  set(include_options "")
  foreach(include IN LISTS includes)
    list(APPEND include_options --include ${include})
  endforeach()

  # The names of the package's constants, for its Python module.
  set(constant_list ${output_dir}/agnocast_constants.inc)
  add_custom_command(
    OUTPUT ${headers} ${constant_list}
    COMMAND $<TARGET_FILE:${generator}> --package ${arg_PACKAGE} --output-dir ${output_dir} ${include_options}
            --constant-list ${constant_list} ${inputs}
    DEPENDS ${inputs} ${dependency_files} ${generator}
    COMMENT "Generating agnocast messages of ${arg_PACKAGE}"
    VERBATIM)
  add_library(${target} INTERFACE ${headers} ${constant_list})
  target_include_directories(${target} INTERFACE $<BUILD_INTERFACE:${output_dir}>)
  target_link_libraries(${target} INTERFACE agnocast::agnocast ${dependency_targets})
  set_target_properties(${target} PROPERTIES
    AGNOCAST_MSG_INCLUDES "${includes}"
    AGNOCAST_PACKAGE ${arg_PACKAGE}
    AGNOCAST_MSG_FILES "${msg_files}"
    AGNOCAST_SRV_FILES "${srv_files}"
    AGNOCAST_CONSTANT_LIST ${constant_list}
    AGNOCAST_HEADER_DIR ${output_dir})
  if(arg_PYTHON)
    agnocast_python_messages(${target}_python OUTPUT_DIR ${output_dir}/python PACKAGES ${target})
    set_target_properties(${target} PROPERTIES AGNOCAST_PYTHON_DIR ${output_dir}/python)
  endif()
endfunction()
