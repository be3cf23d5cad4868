# Comments cite files that exist: scans the sources of magnetics/,
# gpu/, engine/, demos/, tests/ and benchmarks/ (*.h *.cpp *.cu *.cuh) and
# fails, naming file and line, on
#  (a) a citation of the specification files that live outside the repository
#      (MODEL, INTERFACE, STYLE; the patterns below are written so that this
#      script does not match itself, and it is excluded anyway);
#  (b) a mention of docs/NAME.md where ROOT/docs/NAME.md does not exist.
# Run: cmake -DROOT=<source dir> -P tests/docs/check_citations.cmake
if(NOT ROOT OR NOT IS_DIRECTORY "${ROOT}")
  message(FATAL_ERROR "check_citations: pass -DROOT=<odemag source dir>")
endif()

set(outside_regex "(MODEL|INTERFACE|STYLE)[.]md")
set(docs_regex "docs/[A-Za-z0-9_./-]*[.]md")
set(self "${CMAKE_CURRENT_LIST_FILE}")

set(files "")
foreach(dir magnetics gpu engine demos tests benchmarks)
  foreach(ext h cpp cu cuh)
    file(GLOB_RECURSE found "${ROOT}/${dir}/*.${ext}")
    list(APPEND files ${found})
  endforeach()
endforeach()
list(REMOVE_DUPLICATES files)
list(SORT files)

set(errors "")
set(error_count 0)
set(citation_count 0)
list(LENGTH files file_count)
foreach(path IN LISTS files)
  if(path STREQUAL self)
    continue()
  endif()
  file(READ "${path}" content)
  if(NOT content MATCHES "${outside_regex}" AND NOT content MATCHES "${docs_regex}")
    continue()
  endif()
  file(RELATIVE_PATH rel "${ROOT}" "${path}")
  # One list element per line: characters that CMake lists treat specially
  # (; [ ] \) are replaced first, so the line numbers stay right.
  string(REPLACE "\\" "/" content "${content}")
  string(REPLACE ";" "," content "${content}")
  string(REPLACE "[" "(" content "${content}")
  string(REPLACE "]" ")" content "${content}")
  string(REPLACE "\n" ";" lines "${content}")
  set(line_number 0)
  foreach(line IN LISTS lines)
    math(EXPR line_number "${line_number} + 1")
    string(REGEX MATCHALL "${outside_regex}" outside "${line}")
    foreach(name IN LISTS outside)
      string(APPEND errors "${rel}:${line_number}: cites ${name}, which is not part of the "
                           "repository; cite docs/ instead\n")
      math(EXPR error_count "${error_count} + 1")
    endforeach()
    string(REGEX MATCHALL "${docs_regex}" cited "${line}")
    foreach(doc IN LISTS cited)
      math(EXPR citation_count "${citation_count} + 1")
      if(NOT EXISTS "${ROOT}/${doc}")
        string(APPEND errors "${rel}:${line_number}: cites ${doc}, which does not exist\n")
        math(EXPR error_count "${error_count} + 1")
      endif()
    endforeach()
  endforeach()
endforeach()

if(error_count GREATER 0)
  message(FATAL_ERROR "${error_count} bad citation(s) in comments:\n${errors}")
endif()
message(STATUS "check_citations: ${file_count} files, ${citation_count} docs/ citations, all exist")
