# cmake -DBUILD_DIR=... -DCONSUMER_SOURCE_DIR=... -DWORK_DIR=... [-DGENERATOR=...]
#   [-DCXX_COMPILER=...] [-DBUILD_TYPE=...] [-DSANITIZE=...] -P install_test.cmake
# Installs the odemag build in BUILD_DIR into WORK_DIR/prefix, configures and
# builds the consumer project CONSUMER_SOURCE_DIR against it with
# find_package(odemag) and runs its embed_minimal; fails on the first step
# that fails. SANITIZE: the build's ODEMAG_SANITIZE, whose runtime the
# consumer must link as well.
foreach(var BUILD_DIR CONSUMER_SOURCE_DIR WORK_DIR)
  if(NOT ${var})
    message(FATAL_ERROR "install_test.cmake: -D${var}=... is required")
  endif()
endforeach()
if(NOT BUILD_TYPE)
  set(BUILD_TYPE Release)
endif()

set(prefix ${WORK_DIR}/prefix)
set(consumer_build ${WORK_DIR}/build)
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})

function(step name)
  message(STATUS "install_test: ${name}: ${ARGN}")
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "install_test: ${name} failed (${rc})")
  endif()
endfunction()

step(install ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix} --config ${BUILD_TYPE})
foreach(file include/odemag/engine/magnetic_forces.h include/odemag/magnetics/model.h
        include/odemag/gpu/cuda_backend.h bin/odemag)
  if(NOT EXISTS ${prefix}/${file})
    message(FATAL_ERROR "install_test: ${file} was not installed")
  endif()
endforeach()

set(configure_args -S ${CONSUMER_SOURCE_DIR} -B ${consumer_build}
    -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=${BUILD_TYPE})
if(GENERATOR)
  list(APPEND configure_args -G ${GENERATOR})
endif()
if(CXX_COMPILER)
  list(APPEND configure_args -DCMAKE_CXX_COMPILER=${CXX_COMPILER})
endif()
if(SANITIZE)
  list(APPEND configure_args "-DCMAKE_CXX_FLAGS=-fsanitize=${SANITIZE} -fno-omit-frame-pointer"
       "-DCMAKE_EXE_LINKER_FLAGS=-fsanitize=${SANITIZE}")
endif()
step(configure ${CMAKE_COMMAND} ${configure_args})
step(build ${CMAKE_COMMAND} --build ${consumer_build} --config ${BUILD_TYPE})

# The program checks itself: 0 when the ball ended up touching the magnet.
find_program(program embed_minimal PATHS ${consumer_build} ${consumer_build}/${BUILD_TYPE} NO_DEFAULT_PATH)
if(NOT program)
  message(FATAL_ERROR "install_test: no embed_minimal in ${consumer_build}")
endif()
step(run ${program})
