# `cmake --install` rules and the find_package(odemag) package
# (docs/embedding.md). Included from the top-level CMakeLists.txt after the
# targets are defined.
#
# Installed: the libraries odemag::magnetics, odemag::ode (the embedding
# library: MagneticForces and the step loop; magnetics + ODE only),
# odemag::gpu (the CUDA backend or its stub, and MagneticForces' constructor
# by backend kind), odemag::scene (scene files), odemag::engine (the
# simulation) and the umbrella odemag::odemag; the public API, the headers
# of include/odemag/ (#include <odemag/odemag.h>); and the odemag program.
# Everything else is private. odemag_warnings and odemag_tuning
# (-march=native) are build-only: the libraries link them as
# $<BUILD_INTERFACE:...>, so consumers compile with their own flags.
include(CMakePackageConfigHelpers)

set(ODEMAG_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/odemag)

# odemag::odemag: everything an ODE program needs to load and run scenes.
add_library(odemag_all INTERFACE)
target_link_libraries(odemag_all INTERFACE odemag_engine)
set_target_properties(odemag_all PROPERTIES EXPORT_NAME odemag)
add_library(odemag::odemag ALIAS odemag_all)

install(TARGETS odemag_magnetics odemag_gpu odemag_ode odemag_scene odemag_engine odemag_all
  EXPORT odemagTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
# The include directory comes with odemag::magnetics (INSTALL_INTERFACE in
# magnetics/CMakeLists.txt), which all of them link.
install(TARGETS odemag RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})

# The public API: include/odemag/, closed under #include
# (tests/install/install_test.cmake checks that).
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/odemag DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        FILES_MATCHING PATTERN "*.h")

install(EXPORT odemagTargets
  NAMESPACE odemag::
  DESTINATION ${ODEMAG_INSTALL_CMAKEDIR})

set(ODEMAG_CUDA_TOOLKIT_ROOT "")
if(ODEMAG_WITH_CUDA)
  get_filename_component(ODEMAG_CUDA_TOOLKIT_ROOT "${CUDAToolkit_BIN_DIR}" DIRECTORY)
endif()
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/odemagConfig.cmake.in
  ${PROJECT_BINARY_DIR}/odemagConfig.cmake
  INSTALL_DESTINATION ${ODEMAG_INSTALL_CMAKEDIR})
# 0.x: a minor version may change the API.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/odemagConfigVersion.cmake
  VERSION ${PROJECT_VERSION}
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/odemagConfig.cmake ${PROJECT_BINARY_DIR}/odemagConfigVersion.cmake
  DESTINATION ${ODEMAG_INSTALL_CMAKEDIR})
