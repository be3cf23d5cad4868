# `cmake --install` rules and the find_package(odemag) package
# (docs/embedding.md). Included from the top-level CMakeLists.txt after the
# targets are defined.
#
# Installed: the libraries odemag::magnetics, odemag::gpu (the CUDA backend or
# its stub), odemag::scene and odemag::engine, the umbrella odemag::odemag,
# the headers under include/odemag/{magnetics,engine,gpu} (so that
# #include "engine/magnetic_forces.h" works as in the source tree) and the
# odemag program. odemag_warnings and odemag_tuning (-march=native) are
# build-only: the libraries link them as $<BUILD_INTERFACE:...>, so consumers
# compile with their own flags.
include(CMakePackageConfigHelpers)

set(ODEMAG_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/odemag)

# odemag::odemag: everything an ODE program needs to embed odemag.
add_library(odemag_all INTERFACE)
target_link_libraries(odemag_all INTERFACE odemag_engine)
set_target_properties(odemag_all PROPERTIES EXPORT_NAME odemag)
add_library(odemag::odemag ALIAS odemag_all)

install(TARGETS odemag_magnetics odemag_gpu odemag_scene odemag_engine odemag_all
  EXPORT odemagTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
# The include directory, include/odemag, comes with odemag::magnetics
# (INSTALL_INTERFACE in magnetics/CMakeLists.txt), which all of them link.
install(TARGETS odemag RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})

file(GLOB ODEMAG_MAGNETICS_HEADERS ${PROJECT_SOURCE_DIR}/magnetics/*.h)
file(GLOB ODEMAG_ENGINE_HEADERS ${PROJECT_SOURCE_DIR}/engine/*.h)
install(FILES ${ODEMAG_MAGNETICS_HEADERS} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/odemag/magnetics)
install(FILES ${ODEMAG_ENGINE_HEADERS} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/odemag/engine)
install(FILES ${PROJECT_SOURCE_DIR}/gpu/cuda_backend.h DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/odemag/gpu)

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
