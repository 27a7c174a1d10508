# Self-test of cmake/CheckLayering.cmake: a file that includes only from allowed folders passes;
# one header from a forbidden layer, from a subfolder of an allowed folder and from a folder
# that is in no list each fail the check, named.
#   cmake -DSOURCE_DIR=<repo> -DWORK=<scratch dir> -P layering_self_test.cmake
set(check ${SOURCE_DIR}/cmake/CheckLayering.cmake)
file(MAKE_DIRECTORY ${WORK})
function(run_check name body expect_fail)
  file(WRITE ${WORK}/${name}.cc "${body}")
  file(WRITE ${WORK}/${name}.txt "${WORK}/${name}.cc\n")
  execute_process(COMMAND ${CMAKE_COMMAND} -DTARGET=eol_demo -DFILES_LIST=${WORK}/${name}.txt
                          "-DALLOW=analysis/;analysis/fit/" -DSTAMP=${WORK}/${name}.stamp
                          -P ${check}
                  RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(expect_fail)
    foreach(header IN LISTS ARGN)
      if(rc EQUAL 0 OR NOT err MATCHES "includes \"${header}\", but eol_demo")
        message(FATAL_ERROR "${name}: expected a refusal naming ${header}; got rc=${rc}:\n${err}")
      endif()
    endforeach()
  elseif(NOT rc EQUAL 0)
    message(FATAL_ERROR "${name}: expected to pass; got rc=${rc}:\n${err}")
  endif()
endfunction()

run_check(good "#include \"analysis/frf.h\"\n#include \"analysis/fit/rational_fit.h\"\n#include <vector>\n" FALSE)
set(deep "analysis/fit")
string(APPEND deep "/deep")  # a subfolder of an allowed folder
run_check(bad "#include \"analysis/frf.h\"\n#include \"station/daemon/judge.h\"\n#include \"${deep}/x.h\"\n  #  include \"newfolder/y.h\"\n" TRUE
          station/daemon/judge.h ${deep}/x.h newfolder/y.h)
message(STATUS "layering self-test: the allowed file passed, the three bad includes were named")
