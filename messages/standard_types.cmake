# Writes OUTPUT, a C++ source defining agnocast::standard_message_type() over
# every type under SOURCE_DIR/<package>/msg/ (run with cmake -P): the type
# name, hash and schema a subscriber built with the generated headers registers.
file(GLOB files RELATIVE ${SOURCE_DIR} ${SOURCE_DIR}/*/msg/*.msg)
list(SORT files)

# agnocast-msggen's header name: PointCloud2 -> point_cloud2, TFMessage -> tf_message.
function(snake_case name out)
  string(LENGTH "${name}" length)
  set(result "")
  math(EXPR last "${length} - 1")
  foreach(i RANGE 0 ${last})
    string(SUBSTRING "${name}" ${i} 1 c)
    if(i GREATER 0 AND c MATCHES "[A-Z]")
      math(EXPR previous "${i} - 1")
      string(SUBSTRING "${name}" ${previous} 1 before)
      set(next "")
      math(EXPR following "${i} + 1")
      if(following LESS length)
        string(SUBSTRING "${name}" ${following} 1 next)
      endif()
      if(before MATCHES "[a-z0-9]" OR (before MATCHES "[A-Z]" AND next MATCHES "[a-z]"))
        string(APPEND result "_")
      endif()
    endif()
    string(TOLOWER "${c}" lower)
    string(APPEND result "${lower}")
  endforeach()
  set(${out} "${result}" PARENT_SCOPE)
endfunction()

set(includes "")
set(entries "")
foreach(file IN LISTS files)
  string(REGEX REPLACE "^([^/]+)/msg/([^/]+)\\.msg$" "\\1" package "${file}")
  string(REGEX REPLACE "^([^/]+)/msg/([^/]+)\\.msg$" "\\2" name "${file}")
  snake_case("${name}" header)
  string(APPEND includes "#include <${package}/msg/${header}.hpp>\n")
  string(APPEND entries "      detail::message_type_of<${package}::msg::${name}>(),\n")
endforeach()

file(WRITE ${OUTPUT}.tmp "// Generated from messages/*/msg/*.msg by messages/standard_types.cmake.
#include \"standard_types.hpp\"

#include <vector>

${includes}
namespace agnocast {

const detail::MessageType* standard_message_type(std::string_view type_name) {
  static const std::vector<detail::MessageType> types{
${entries}  };
  for (const detail::MessageType& type : types) {
    if (type.name == type_name) return &type;
  }
  return nullptr;
}

}  // namespace agnocast
")
file(COPY_FILE ${OUTPUT}.tmp ${OUTPUT} ONLY_IF_DIFFERENT)
