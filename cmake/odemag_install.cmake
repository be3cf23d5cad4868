# `cmake --install` rules and the find_package(odemag) package
# (docs/embedding.md). Included from the top-level CMakeLists.txt after the
# targets are defined.
#
# Installed: the libraries odemag::magnetics, odemag::gpu (the CUDA backend or
# its stub), odemag::ode (the embedding library: MagneticForces and the force
# accumulators, magnetics + ODE only), odemag::scene (scene files),
# odemag::engine (the simulation) and the umbrella odemag::odemag; the public
# headers (ODEMAG_PUBLIC_HEADERS below: the embedding, scene-loading and
# simulation headers and the magnetics headers they include) under
# include/odemag/ with their source paths, so that
# #include "engine/embedding/magnetic_forces.h" works as in the source tree; and
# the odemag program. Everything else is private, in particular the SIMD
# kernels (magnetics/kernels/simd.h, pair_sums.h), whose intrinsics are chosen by the
# compiler flags. odemag_warnings and odemag_tuning (-march=native) are
# build-only: the libraries link them as $<BUILD_INTERFACE:...>, so consumers
# compile with their own flags.
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
# The include directory, include/odemag, comes with odemag::magnetics
# (INSTALL_INTERFACE in magnetics/CMakeLists.txt), which all of them link.
install(TARGETS odemag RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})

# The public API: three entry headers and what they include (closed under
# #include; tests/install/install_test.cmake checks that).
set(ODEMAG_PUBLIC_HEADERS
  engine/embedding/magnetic_forces.h engine/embedding/force_accumulator.h       # embedding
  engine/embedding/magnetic_stepper.h engine/embedding/substeps.h engine/embedding/exact_step.h
  engine/scene/scene.h                                              # scene loading
  engine/simulation/simulation.h engine/simulation/rigid_world.h engine/simulation/frame_writer.h
  engine/simulation/magnetic_system.h engine/simulation/outcomes.h engine/simulation/solve.h engine/simulation/winding_solids.h  # simulation
  gpu/cuda_backend.h
  magnetics/model/backend.h magnetics/cells/cells.h include/odemag/constants.h magnetics/cells/demag_tensor.h
  magnetics/materials/bh_curve.h magnetics/model/body_response.h magnetics/sources/coil.h magnetics/kernels/hd.h magnetics/kernels/llg.h include/odemag/material.h magnetics/model/model.h magnetics/relax/relax.h
  magnetics/kernels/rng.h include/odemag/shape.h magnetics/kernels/small_eigen.h magnetics/model/state.h include/odemag/vec3.h)
foreach(header IN LISTS ODEMAG_PUBLIC_HEADERS)
  get_filename_component(dir ${header} DIRECTORY)
  install(FILES ${PROJECT_SOURCE_DIR}/${header} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/odemag/${dir})
endforeach()

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
