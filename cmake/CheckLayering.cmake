# Fails when a file of a target includes a header from a folder its layer may not see
# (cmake/Layering.cmake lists, per target, the folders it may include from).
# Run by the build (cmake/EolTargets.cmake), so a wrong include fails the build that adds it.
#   cmake -DTARGET=eol_analysis -DFILES_LIST=<file with one path a line>
#         -DALLOW="analysis/;analysis/fit/" -DSTAMP=<file> -P CheckLayering.cmake
cmake_minimum_required(VERSION 3.25)  # if(IN_LIST) in script mode
file(STRINGS "${FILES_LIST}" files)
list(JOIN ALLOW " " allowed)
set(errors "")
foreach(f IN LISTS files)
  file(STRINGS "${f}" includes REGEX "^[ \t]*#[ \t]*include[ \t]*\"[^\"]+\"")
  foreach(line IN LISTS includes)
    string(REGEX REPLACE "^[ \t]*#[ \t]*include[ \t]*\"([^\"]+)\".*$" "\\1" header "${line}")
    string(REGEX MATCH "^.*/" folder "${header}")
    if(NOT folder IN_LIST ALLOW AND NOT header IN_LIST ALLOW)
      string(APPEND errors "  ${f}: includes \"${header}\", but ${TARGET} may include only "
                           "from ${allowed}\n")
    endif()
  endforeach()
endforeach()
if(errors)
  message(FATAL_ERROR "layering: an include from a folder the target may not see (the "
                      "table is cmake/Layering.cmake):\n${errors}")
endif()
file(WRITE "${STAMP}" "ok\n")
