# The layers depend one way (docs/architecture.md "Layers"): every
# #include "FOLDER/..." of a source file must name its own folder or one below
# it. Run with cmake -DROOT=<source dir> -P check_layers.cmake; fails naming
# each file, line and include that points upwards.
#
# Folder -> the folders its files may include. The public headers
# (include/odemag/, the installed API) include only each other, and every
# folder may include them.
set(allowed_include_odemag                odemag)
set(allowed_magnetics_kernels             odemag magnetics/kernels)
set(allowed_magnetics_cells               odemag magnetics/kernels magnetics/cells)
set(allowed_magnetics_materials           odemag magnetics/kernels magnetics/cells magnetics/materials)
set(allowed_magnetics_sources             odemag magnetics/kernels magnetics/sources)
set(allowed_magnetics_static              odemag magnetics/kernels magnetics/cells magnetics/materials magnetics/static)
set(allowed_magnetics_model               odemag magnetics/kernels magnetics/cells magnetics/materials magnetics/sources
                                          magnetics/model)
set(allowed_magnetics_near_field          odemag magnetics/kernels magnetics/cells magnetics/materials magnetics/sources
                                          magnetics/model magnetics/near_field)
set(allowed_magnetics_relax               odemag magnetics)
set(allowed_gpu                           odemag magnetics gpu)
set(allowed_engine_embedding              odemag magnetics engine/embedding)
set(allowed_engine_scene                  odemag magnetics engine/scene)
set(allowed_engine_simulation             odemag magnetics gpu engine/embedding engine/scene engine/simulation)
set(allowed_render                        odemag magnetics engine render)
set(allowed_cli                           odemag magnetics gpu engine render cli)
set(allowed_demos                         odemag magnetics gpu engine render cli demos)
set(allowed_benchmarks                    odemag magnetics gpu engine benchmarks tests/support)
set(allowed_python                        odemag magnetics gpu engine python)
set(layers include/odemag magnetics/kernels magnetics/cells magnetics/materials magnetics/sources magnetics/static
    magnetics/model magnetics/near_field magnetics/relax gpu engine/embedding engine/scene engine/simulation render
    cli demos benchmarks python)

set(violations "")
set(checked 0)
foreach(layer IN LISTS layers)
  string(REPLACE "/" "_" key "${layer}")
  set(allowed ${allowed_${key}})
  file(GLOB_RECURSE files RELATIVE ${ROOT}
    ${ROOT}/${layer}/*.h ${ROOT}/${layer}/*.cpp ${ROOT}/${layer}/*.cu ${ROOT}/${layer}/*.cuh)
  foreach(f IN LISTS files)
    math(EXPR checked "${checked} + 1")
    file(STRINGS ${ROOT}/${f} lines REGEX "^[ \t]*#[ \t]*include[ \t]+\"")
    foreach(line IN LISTS lines)
      string(REGEX REPLACE "^[ \t]*#[ \t]*include[ \t]+\"([^\"]+)\".*" "\\1" path "${line}")
      if(NOT path MATCHES "/")
        continue()  # a header beside the file
      endif()
      set(ok FALSE)
      foreach(a IN LISTS allowed)
        string(LENGTH "${a}/" n)
        string(SUBSTRING "${path}" 0 ${n} head)
        if(head STREQUAL "${a}/")
          set(ok TRUE)
        endif()
      endforeach()
      if(NOT ok)
        string(APPEND violations "\n  ${f}: #include \"${path}\" (${layer} may include: ${allowed})")
      endif()
    endforeach()
  endforeach()
endforeach()
# Every source file of engine/ lies in one of its layers.
file(GLOB loose RELATIVE ${ROOT} ${ROOT}/engine/*.h ${ROOT}/engine/*.cpp)
foreach(f IN LISTS loose)
  string(APPEND violations "\n  ${f}: outside engine/embedding, engine/scene, engine/simulation")
endforeach()
# The example programs of docs/embedding.md use the public API alone.
foreach(f demos/embed_minimal.cpp demos/scene_minimal.cpp)
  file(STRINGS ${ROOT}/${f} lines REGEX "^[ \t]*#[ \t]*include[ \t]+[\"<]odemag/")
  file(STRINGS ${ROOT}/${f} all REGEX "^[ \t]*#[ \t]*include[ \t]+\"")
  foreach(line IN LISTS all)
    if(NOT line MATCHES "[\"<]odemag/")
      string(APPEND violations "\n  ${f}: ${line} (the example programs include the public API only)")
    endif()
  endforeach()
endforeach()
if(checked LESS 50)
  message(FATAL_ERROR "only ${checked} files found under ${ROOT}: wrong ROOT?")
endif()
if(violations)
  message(FATAL_ERROR "includes from a lower layer to a higher one:${violations}")
endif()
message(STATUS "${checked} files, every include points to its own layer or one below")
