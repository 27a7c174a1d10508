# eol_add_library(NAME ALIAS SOURCES ... [HEADER_DIRS dir...] FORBID prefix... [PUBLIC ...] [PRIVATE ...])
#
# One static library per concern, with an eol:: alias. FORBID lists the include prefixes the
# target's sources and headers may not use ("station/", "analysis/sim/", ...): the build runs
# cmake/CheckLayering.cmake over them before compiling the target, so an include against the
# dependency direction fails the build with the file and header named.
function(eol_add_library name alias)
  cmake_parse_arguments(A "" "" "SOURCES;HEADER_DIRS;FORBID;PUBLIC;PRIVATE" ${ARGN})
  add_library(${name} STATIC ${A_SOURCES})
  add_library(eol::${alias} ALIAS ${name})
  target_compile_features(${name} PUBLIC cxx_std_20)
  target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(${name} PUBLIC ${A_PUBLIC} PRIVATE ${A_PRIVATE} eol_warnings)
  set(checked ${A_SOURCES})
  foreach(dir IN LISTS A_HEADER_DIRS)
    file(GLOB headers CONFIGURE_DEPENDS ${dir}/*.h)
    list(APPEND checked ${headers})
  endforeach()
  eol_check_layering(${name} "${checked}" "${A_FORBID}")
endfunction()

function(eol_check_layering name files forbid)
  if(NOT forbid)
    return()
  endif()
  set(list_file ${CMAKE_CURRENT_BINARY_DIR}/${name}.layering.txt)
  string(REPLACE ";" "\n" lines "${files}")
  file(WRITE ${list_file}.in "${lines}\n")
  configure_file(${list_file}.in ${list_file} COPYONLY)
  set(stamp ${CMAKE_CURRENT_BINARY_DIR}/${name}.layering.stamp)
  add_custom_command(OUTPUT ${stamp}
    COMMAND ${CMAKE_COMMAND} -DTARGET=${name} -DFILES_LIST=${list_file} "-DFORBID=${forbid}"
            -DSTAMP=${stamp} -P ${PROJECT_SOURCE_DIR}/cmake/CheckLayering.cmake
    DEPENDS ${files} ${list_file} ${PROJECT_SOURCE_DIR}/cmake/CheckLayering.cmake
    COMMENT "Checking the includes of ${name} against the layering" VERBATIM)
  add_custom_target(${name}_layering DEPENDS ${stamp})
  add_dependencies(${name} ${name}_layering)
endfunction()
