# eol_add_library(NAME ALIAS SOURCES ... [HEADER_DIRS dir...] [PUBLIC ...] [PRIVATE ...])
#
# One static library per concern, with an eol:: alias. cmake/Layering.cmake lists, for every
# library NAME, the folders whose headers it may include (EOL_ALLOW_<NAME>): the build runs
# cmake/CheckLayering.cmake over the sources and headers before compiling the target, so an
# include from any other folder fails the build with the file and header named. A library
# missing from that table is refused at configure time.
include(${CMAKE_CURRENT_LIST_DIR}/Layering.cmake)
function(eol_add_library name alias)
  cmake_parse_arguments(A "" "" "SOURCES;HEADER_DIRS;PUBLIC;PRIVATE" ${ARGN})
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
  if(NOT DEFINED EOL_ALLOW_${name})
    message(FATAL_ERROR "${name}: no entry EOL_ALLOW_${name} in cmake/Layering.cmake (the folders "
                        "its headers may come from)")
  endif()
  eol_check_layering(${name} "${checked}" "${EOL_ALLOW_${name}}")
endfunction()

function(eol_check_layering name files allow)
  set(list_file ${CMAKE_CURRENT_BINARY_DIR}/${name}.layering.txt)
  string(REPLACE ";" "\n" lines "${files}")
  file(WRITE ${list_file}.in "${lines}\n")
  configure_file(${list_file}.in ${list_file} COPYONLY)
  set(stamp ${CMAKE_CURRENT_BINARY_DIR}/${name}.layering.stamp)
  add_custom_command(OUTPUT ${stamp}
    COMMAND ${CMAKE_COMMAND} -DTARGET=${name} -DFILES_LIST=${list_file} "-DALLOW=${allow}"
            -DSTAMP=${stamp} -P ${PROJECT_SOURCE_DIR}/cmake/CheckLayering.cmake
    DEPENDS ${files} ${list_file} ${PROJECT_SOURCE_DIR}/cmake/CheckLayering.cmake
            ${PROJECT_SOURCE_DIR}/cmake/Layering.cmake
    COMMENT "Checking the includes of ${name} against the layering" VERBATIM)
  add_custom_target(${name}_layering DEPENDS ${stamp})
  add_dependencies(${name} ${name}_layering)
endfunction()
