# The standard set's tests, one source per package made from
# standard_package_test.cpp.in: every type of the package, found from its .msg
# files, and a check of each constant and default those files declare, read
# here independently of agnocast-msggen.

# The C++ type agnocast-msggen gives a primitive .msg type.
function(_standard_cpp_type msg_type out)
  set(map bool=bool byte=std::uint8_t char=std::uint8_t int8=std::int8_t uint8=std::uint8_t
          int16=std::int16_t uint16=std::uint16_t int32=std::int32_t uint32=std::uint32_t
          int64=std::int64_t uint64=std::uint64_t float32=float float64=double)
  string(REGEX REPLACE "<=[0-9]+$" "" msg_type "${msg_type}")
  if(msg_type STREQUAL "string")
    set(${out} "std::string_view" PARENT_SCOPE)
    return()
  endif()
  foreach(entry IN LISTS map)
    if(entry MATCHES "^${msg_type}=(.*)$")
      set(${out} "${CMAKE_MATCH_1}" PARENT_SCOPE)
      return()
    endif()
  endforeach()
  set(${out} "" PARENT_SCOPE)  # a message type
endfunction()

# A .msg value as a C++ expression of type cpp: strings quoted '...' or "..."
# (without escapes) or bare; numbers and bools as written.
function(_standard_cpp_value cpp value out)
  string(STRIP "${value}" value)
  if(cpp STREQUAL "std::string_view")
    if(value MATCHES "^'(.*)'$" OR value MATCHES "^\"(.*)\"$")
      set(value "${CMAKE_MATCH_1}")
    endif()
    set(${out} "std::string_view{R\"__(${value})__\"}" PARENT_SCOPE)
  elseif(value MATCHES "^\\[(.*)\\]$")
    set(${out} "{${CMAKE_MATCH_1}}" PARENT_SCOPE)
  else()
    set(${out} "${cpp}{${value}}" PARENT_SCOPE)
  endif()
endfunction()

function(agnocast_add_standard_package_test package target)
  file(GLOB files CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/${package}/msg/*.msg)
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${files})
  set(includes "")
  set(types "")
  set(checks "")
  foreach(file IN LISTS files)
    get_filename_component(name ${file} NAME_WE)
    _agnocast_snake_case(${name} snake)
    string(APPEND includes "#include <${package}/msg/${snake}.hpp>\n")
    list(APPEND types "${package}::msg::${name}")
    set(message "${package}::msg::${name}")
    file(STRINGS ${file} lines)
    foreach(line IN LISTS lines)
      if(line MATCHES "^[ \t]*([a-z][a-z0-9<=]*)[ \t]+([A-Z][A-Z0-9_]*)[ \t]*=(.*)$")
        # A constant: a string's value runs to the end of the line.
        set(constant ${CMAKE_MATCH_2})
        set(value "${CMAKE_MATCH_3}")
        _standard_cpp_type(${CMAKE_MATCH_1} cpp)
        if(NOT cpp STREQUAL "std::string_view")
          string(REGEX REPLACE "#.*" "" value "${value}")
        endif()
        _standard_cpp_value(${cpp} "${value}" expected)
        string(APPEND checks
               "  static_assert(std::is_same_v<decltype(${message}::${constant}), const ${cpp}>);\n"
               "  EXPECT_EQ(${message}::${constant}, ${expected});\n")
      elseif(line MATCHES "^[ \t]*([a-z][a-z0-9<=]*)(\\[[^]]*\\])?[ \t]+([a-z][a-z0-9_]*)[ \t]+([^# \t][^#]*)")
        # A field with a default value.
        set(field ${CMAKE_MATCH_3})
        set(value "${CMAKE_MATCH_4}")
        _standard_cpp_type(${CMAKE_MATCH_1} cpp)
        _standard_cpp_value(${cpp} "${value}" expected)
        if(CMAKE_MATCH_2)
          set(expected "decltype(${message}::${field})(${expected})")
        endif()
        string(APPEND checks "  EXPECT_EQ(${message}{}.${field}, ${expected});\n")
      endif()
    endforeach()
  endforeach()
  list(JOIN types ",\n                               " types)
  set(constant_tests "")
  if(checks)
    set(constant_tests
        "TEST_F(Standard_${package}, ConstantsAndDefaultsAreThoseOfTheMsgFiles) {\n${checks}}\n")
  endif()
  set(source ${CMAKE_CURRENT_BINARY_DIR}/standard_${package}_test.cpp)
  configure_file(${CMAKE_CURRENT_SOURCE_DIR}/tests/standard_package_test.cpp.in ${source} @ONLY)
  target_sources(${target} PRIVATE ${source})
  target_link_libraries(${target} PRIVATE ${package})
endfunction()
