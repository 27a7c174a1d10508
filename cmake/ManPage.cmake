# The manual page eol(1), made from the program's own help text: help2man (Debian package
# help2man) on `eol --help`, with every subcommand's `eol SUB --help` as its COMMANDS section
# (cmake/eol_man_include.sh). Built with the program and installed with the package as
# share/man/man1/eol.1.gz.
find_program(EOL_HELP2MAN help2man)
if(NOT EOL_HELP2MAN)
  message(WARNING "help2man not found: no manual page (bash deploy/install-deps.sh installs it)")
  return()
endif()
set(EOL_MAN_INCLUDE ${PROJECT_BINARY_DIR}/eol-commands.h2m)
set(EOL_MAN_PAGE ${PROJECT_BINARY_DIR}/eol.1)
add_custom_command(
  OUTPUT ${EOL_MAN_PAGE} ${EOL_MAN_PAGE}.gz
  COMMAND bash ${PROJECT_SOURCE_DIR}/cmake/eol_man_include.sh $<TARGET_FILE:eol> ${EOL_MAN_INCLUDE}
  COMMAND ${EOL_HELP2MAN} --no-info --section 1 --source "eol-station ${PROJECT_VERSION}"
          --name "end-of-line test station for permanent-magnet motors"
          --include ${EOL_MAN_INCLUDE} --output ${EOL_MAN_PAGE} $<TARGET_FILE:eol>
  COMMAND gzip -9nf -k ${EOL_MAN_PAGE}
  DEPENDS eol ${PROJECT_SOURCE_DIR}/cmake/eol_man_include.sh
  COMMENT "Manual page eol(1) from eol --help"
  VERBATIM)
add_custom_target(eol_man ALL DEPENDS ${EOL_MAN_PAGE})
install(FILES ${EOL_MAN_PAGE}.gz DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)
