# Fails when a file of a target includes a header its layer may not see (README "Design").
# Run by the build (cmake/EolTargets.cmake), so a wrong include fails the build that adds it.
#   cmake -DTARGET=eol_analysis -DFILES_LIST=<file with one path a line>
#         -DFORBID="drivers/;db/" -DSTAMP=<file> -P CheckLayering.cmake
file(STRINGS "${FILES_LIST}" files)
set(errors "")
foreach(f IN LISTS files)
  file(STRINGS "${f}" includes REGEX "^[ \t]*#[ \t]*include[ \t]*\"[^\"]+\"")
  foreach(line IN LISTS includes)
    string(REGEX REPLACE "^[ \t]*#[ \t]*include[ \t]*\"([^\"]+)\".*$" "\\1" header "${line}")
    foreach(prefix IN LISTS FORBID)
      string(FIND "${header}" "${prefix}" at)
      if(at EQUAL 0)
        string(APPEND errors "  ${f}: includes \"${header}\"; ${TARGET} may not include ${prefix}*\n")
      endif()
    endforeach()
  endforeach()
endforeach()
if(errors)
  message(FATAL_ERROR "layering: an include points against the dependency direction "
                      "(README \"Design\"):\n${errors}")
endif()
file(WRITE "${STAMP}" "ok\n")
