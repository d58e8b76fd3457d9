# SPDX-License-Identifier: Apache-2.0
# Turns data files into a C++ source that holds their bytes, so the tools need no data path at run time.
# embed_files(OUTPUT <cpp> [NAMESPACE <ns>] FILES <name>=<path> ...) defines, in namespace <ns>
# (default ct::embedded; each library that embeds files needs its own),
#   std::string_view file(std::string_view name);  // empty view if unknown
function(embed_files)
  cmake_parse_arguments(EMB "" "OUTPUT;NAMESPACE" "FILES" ${ARGN})
  if(NOT EMB_NAMESPACE)
    set(EMB_NAMESPACE ct::embedded)
  endif()
  set(body "")
  set(deps "")
  foreach(entry IN LISTS EMB_FILES)
    string(REPLACE "=" ";" pair "${entry}")
    list(GET pair 0 name)
    list(GET pair 1 path)
    list(APPEND deps "${path}")
  endforeach()
  # A CMake list cannot pass through the shell intact, so entries travel joined by '|'.
  string(REPLACE ";" "|" joined "${EMB_FILES}")
  add_custom_command(
    OUTPUT "${EMB_OUTPUT}"
    COMMAND ${CMAKE_COMMAND} "-DOUTPUT=${EMB_OUTPUT}" "-DNAMESPACE=${EMB_NAMESPACE}" "-DFILES=${joined}"
            -P "${CMAKE_SOURCE_DIR}/cmake/EmbedFilesScript.cmake"
    DEPENDS ${deps} "${CMAKE_SOURCE_DIR}/cmake/EmbedFilesScript.cmake"
    COMMENT "Embedding data files into ${EMB_OUTPUT}"
    VERBATIM)
endfunction()
