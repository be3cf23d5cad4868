# cmake -DBUILD_DIR=... -DCONSUMER_SOURCE_DIR=... -DWORK_DIR=... [-DGENERATOR=...]
#   [-DCXX_COMPILER=...] [-DBUILD_TYPE=...] [-DSANITIZE=...]
#   [-DPYTHON=... -DPYTHON_PACKAGE_DIR=... -DSCENE=...] -P install_test.cmake
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
# The Python package (docs/python.md), when the build has it: the installed
# copy imports and solves SCENE.
if(PYTHON)
  step(python ${CMAKE_COMMAND} -E env PYTHONPATH=${prefix}/${PYTHON_PACKAGE_DIR} ${PYTHON} -c
       "import sys, odemag; assert odemag.__file__.startswith(sys.argv[1]), odemag.__file__; assert odemag.load(sys.argv[2]).solve().forces.shape == (2, 3)"
       ${prefix}/${PYTHON_PACKAGE_DIR} ${SCENE})
endif()
# The public API: the headers of include/odemag/ (at most 12, the umbrella
# odemag.h among them), closed under #include, nothing else under include/.
file(GLOB_RECURSE installed RELATIVE ${prefix}/include ${prefix}/include/*)
list(LENGTH installed count)
if(count GREATER 12)
  message(FATAL_ERROR "install_test: ${count} headers installed (at most 12): ${installed}")
endif()
foreach(file include/odemag/odemag.h include/odemag/magnetic_forces.h include/odemag/simulation.h bin/odemag)
  if(NOT EXISTS ${prefix}/${file})
    message(FATAL_ERROR "install_test: ${file} was not installed")
  endif()
endforeach()
foreach(header IN LISTS installed)
  if(NOT header MATCHES "^odemag/[a-z0-9_]+[.]h$")
    message(FATAL_ERROR "install_test: ${header} installed outside include/odemag/")
  endif()
  file(STRINGS ${prefix}/include/${header} includes REGEX "^[ \t]*#[ \t]*include[ \t]+\"")
  foreach(line IN LISTS includes)
    string(REGEX REPLACE "^[ \t]*#[ \t]*include[ \t]+\"([^\"]+)\".*" "\\1" path "${line}")
    if(NOT EXISTS ${prefix}/include/${path})
      message(FATAL_ERROR "install_test: installed ${header} includes ${path}, which is not installed")
    endif()
  endforeach()
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

# The embedding example links the embedding library alone: its link line has
# no scene library (nlohmann-json), no GPU library or CUDA runtime, no OSMesa.
set(link_line "")
if(EXISTS ${consumer_build}/CMakeFiles/embed_minimal.dir/link.txt)
  file(READ ${consumer_build}/CMakeFiles/embed_minimal.dir/link.txt link_line)
elseif(EXISTS ${consumer_build}/build.ninja)
  file(STRINGS ${consumer_build}/build.ninja link_line REGEX "LINK_LIBRARIES")
endif()
if(link_line STREQUAL "")
  message(FATAL_ERROR "install_test: found no link line of embed_minimal in ${consumer_build}")
endif()
if(NOT link_line MATCHES "odemag_ode")
  message(FATAL_ERROR "install_test: embed_minimal does not link odemag_ode: ${link_line}")
endif()
foreach(forbidden odemag_scene odemag_engine odemag_gpu cudart OSMesa nlohmann)
  string(TOLOWER "${link_line}" lower)
  string(TOLOWER "${forbidden}" f)
  if(lower MATCHES "${f}")
    message(FATAL_ERROR "install_test: embed_minimal links ${forbidden}: ${link_line}")
  endif()
endforeach()
message(STATUS "install_test: embed_minimal link line: ${link_line}")

# The program checks itself: 0 when the ball ended up touching the magnet.
find_program(program embed_minimal PATHS ${consumer_build} ${consumer_build}/${BUILD_TYPE} NO_DEFAULT_PATH)
if(NOT program)
  message(FATAL_ERROR "install_test: no embed_minimal in ${consumer_build}")
endif()
step(run ${program})
# The public API from a scene file: solve_scene and Simulation.
find_program(scene_program scene_minimal PATHS ${consumer_build} ${consumer_build}/${BUILD_TYPE} NO_DEFAULT_PATH)
if(NOT scene_program)
  message(FATAL_ERROR "install_test: no scene_minimal in ${consumer_build}")
endif()
if(SCENE)
  step(scene ${scene_program} ${SCENE})
endif()
