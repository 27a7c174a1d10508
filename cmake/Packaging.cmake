# Installation layout and the Debian package (cpack -G DEB, or `cmake --build build --target
# package`). See deploy/OPERATIONS.md "Installing on a station PC".
#   /usr/bin/eol-station                      the daemon (what the unit runs)
#   /usr/bin/eol                              the tool: every command, `eol station` too
#   /usr/share/man/man1/eol.1.gz              its manual page (cmake/ManPage.cmake)
#   /usr/share/eol/recipes/, /usr/share/eol/web/   shipped recipes, the operator and engineer pages
#   /usr/share/eol/bench/                     the SciPy peer of `eol fit-bench`
#   /etc/eol/station.json                     the station config (a conffile)
#   /lib/systemd/system/eol-station.service   the daemon, with systemd's watchdog
#   /var/lib/eol/                             records and the recipes in use (made by postinst)
include(GNUInstallDirs)
include(${CMAKE_CURRENT_LIST_DIR}/ManPage.cmake)  # share/man/man1/eol.1.gz
install(TARGETS eol eol-station RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/recipes/ DESTINATION ${CMAKE_INSTALL_DATADIR}/eol/recipes)
install(FILES ${PROJECT_SOURCE_DIR}/station/web/index.html ${PROJECT_SOURCE_DIR}/station/web/app.js
              ${PROJECT_SOURCE_DIR}/station/web/style.css
              ${PROJECT_SOURCE_DIR}/station/web/engineer.html
              ${PROJECT_SOURCE_DIR}/station/web/engineer.js
              ${PROJECT_SOURCE_DIR}/station/web/engineer.css
        DESTINATION ${CMAKE_INSTALL_DATADIR}/eol/web)
# The operator page's word catalogues, one per language (station/web/README.md).
install(DIRECTORY ${PROJECT_SOURCE_DIR}/station/web/i18n DESTINATION ${CMAKE_INSTALL_DATADIR}/eol/web)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/deploy/bench/ DESTINATION ${CMAKE_INSTALL_DATADIR}/eol/bench)
# The config may hold API tokens: readable by root and the service's group only (postinst
# gives it to group eol).
install(FILES ${PROJECT_SOURCE_DIR}/deploy/debian/station.json DESTINATION /etc/eol
        PERMISSIONS OWNER_READ OWNER_WRITE GROUP_READ)
install(FILES ${PROJECT_SOURCE_DIR}/deploy/eol-station.service DESTINATION /lib/systemd/system)

set(CPACK_GENERATOR "DEB")
set(CPACK_PACKAGE_NAME "eol-station")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_CONTACT "EOL station maintainers <eol-station@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "End-of-line test station for permanent-magnet motors (magnet bond check by impedance)")
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION "science")
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# The operator page in Japanese needs a CJK font in the browser that shows it.
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "fonts-noto-cjk")
# The packaged program carries no debug information (build/eol.debug keeps it).
set(CPACK_STRIP_FILES ON)
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA
    ${PROJECT_SOURCE_DIR}/deploy/debian/conffiles ${PROJECT_SOURCE_DIR}/deploy/debian/postinst)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
include(CPack)
