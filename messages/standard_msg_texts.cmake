# Writes OUTPUT, a C++ source defining agnocast::standard_msg_text() over the
# .msg files under SOURCE_DIR/<package>/msg/ (run with cmake -P).
file(GLOB files RELATIVE ${SOURCE_DIR} ${SOURCE_DIR}/*/msg/*.msg)
list(SORT files)
set(body "// Generated from messages/*/msg/*.msg by messages/standard_msg_texts.cmake.\n")
string(APPEND body "#include \"standard_msg_texts.hpp\"\n\n#include <string>\n\n")
string(APPEND body "namespace agnocast {\nnamespace {\n\nusing namespace std::string_view_literals;\n\n")
string(APPEND body "struct Entry {\n  std::string_view name;\n  std::string_view text;\n};\n\n")
string(APPEND body "const Entry entries[] = {\n")
foreach(file IN LISTS files)
  string(REGEX REPLACE "^([^/]+)/msg/([^/]+)\\.msg$" "\\1/\\2" name "${file}")
  file(READ ${SOURCE_DIR}/${file} text)
  string(APPEND body "    {\"${name}\"sv, R\"agnocast_msg(${text})agnocast_msg\"sv},\n")
endforeach()
string(APPEND body "};\n\n}  // namespace\n\n")
string(APPEND body [=[
const std::string_view* standard_msg_text(std::string_view type_name) {
  std::string name(type_name);
  if (const auto at = name.find("/msg/"); at != std::string::npos) name.erase(at, 4);
  for (const Entry& entry : entries) {
    if (entry.name == name) return &entry.text;
  }
  return nullptr;
}

}  // namespace agnocast
]=])
file(WRITE ${OUTPUT}.tmp "${body}")
file(COPY_FILE ${OUTPUT}.tmp ${OUTPUT} ONLY_IF_DIFFERENT)
