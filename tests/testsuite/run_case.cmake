# SPDX-License-Identifier: Apache-2.0
# Script mode: one CLI regression case in the OpenImageIO style. Runs CASE/run with sh in the source tree,
# with CHROMATRACE set to the executable, and compares its whole text output (stdout and stderr, merged in the
# order written) with CASE/ref/out.txt. -DUPDATE=ON writes the reference instead.
set(ENV{CHROMATRACE} "${EXE}")
execute_process(COMMAND sh "${CASE}/run" WORKING_DIRECTORY "${SOURCE}" OUTPUT_VARIABLE out ERROR_VARIABLE out)
string(REPLACE "${EXE}" "chromatrace" out "${out}")  # the program name in messages, wherever it was built
if(UPDATE)
  file(WRITE "${CASE}/ref/out.txt" "${out}")
  return()
endif()
file(READ "${CASE}/ref/out.txt" reference)
if(NOT out STREQUAL reference)
  message(FATAL_ERROR "${CASE}: the output differs from ref/out.txt.\n--- expected\n${reference}\n--- got\n${out}")
endif()
