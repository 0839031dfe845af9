# Builds and runs one C++ example as a user of an installed pneumid would:
# install the build tree into a scratch prefix, configure the example's own
# CMakeLists.txt against it (find_package(pneumid)), build, run.
# Invoked by ctest (example.cpp_*):
#   cmake -DSOURCE_DIR=<repo> -DBINARY_DIR=<build> -DGENERATOR=<gen>
#         -DEXAMPLE=step_to_fopdt -DARGS=<args;...> [-DWORK_DIR=<dir>] -P run_example.cmake
# WORK_DIR (default <build>/examples/<example>) receives the prefix and the
# example's build tree; it is emptied first.
if(WORK_DIR)
  set(work ${WORK_DIR})
else()
  set(work ${BINARY_DIR}/examples/${EXAMPLE})
endif()
set(prefix ${work}/prefix)
set(ebuild ${work}/build)
file(REMOVE_RECURSE ${work})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BINARY_DIR} --prefix ${prefix}
                OUTPUT_QUIET RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "install into ${prefix} failed: ${rc}")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -S ${SOURCE_DIR}/examples/cpp/${EXAMPLE} -B ${ebuild}
                        -G ${GENERATOR} -DCMAKE_PREFIX_PATH=${prefix}
                OUTPUT_QUIET RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "configure of examples/cpp/${EXAMPLE} failed: ${rc}")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${ebuild} RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "build of examples/cpp/${EXAMPLE} failed: ${rc}")
endif()
execute_process(COMMAND ${ebuild}/${EXAMPLE} ${ARGS} RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "examples/cpp/${EXAMPLE} exited with ${rc}")
endif()
