# agnocast_add_man_page(SOURCE file.N.in COMPONENT name): a man page written
# in roff, built into file.N.gz (the project's version filled in) and
# installed into man/manN with the install component. Section N is the
# source's last suffix before .in.
function(agnocast_add_man_page)
  cmake_parse_arguments(PARSE_ARGV 0 arg "" "SOURCE;COMPONENT" "")
  get_filename_component(source ${arg_SOURCE} ABSOLUTE)
  get_filename_component(page ${source} NAME)
  string(REGEX REPLACE "\\.in$" "" page ${page})
  string(REGEX REPLACE "^.*\\.([0-9])$" "\\1" section ${page})
  set(configured ${CMAKE_CURRENT_BINARY_DIR}/man/${page})
  configure_file(${source} ${configured} @ONLY)
  add_custom_command(OUTPUT ${configured}.gz
                     COMMAND gzip -n -9 -c ${configured} > ${configured}.gz
                     DEPENDS ${configured}
                     COMMENT "Compressing man page ${page}")
  add_custom_target(man-${page} ALL DEPENDS ${configured}.gz)
  install(FILES ${configured}.gz DESTINATION ${CMAKE_INSTALL_MANDIR}/man${section}
          COMPONENT ${arg_COMPONENT})
endfunction()
