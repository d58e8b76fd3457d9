#!/usr/bin/env bash
# Runs every test of the build ./setup.sh made (build/): CTest (unit, end-to-end, Blender, Slurm and browser
# tests). CI (.ci/run) runs ./setup.sh and then this. Arguments go to CTest (./test.sh -R core runs a subset).
#
#   ./test.sh --sanitize [CTEST ARGS]   also runs .ci/sanitize afterwards: the core, sensor and analyzer unit
#                                       tests built with AddressSanitizer and UndefinedBehaviorSanitizer into
#                                       build-asan/, and each fuzz harness for FUZZ_SECONDS (30 by default).
#                                       It needs a second, sanitised build (about 20 minutes more on 2 cores),
#                                       which is why CI does not run it.
# Exit status 1 when anything failed.
set -uo pipefail
cd "$(dirname "$0")"
sanitize=0
if [ "${1:-}" = "--sanitize" ]; then
  sanitize=1
  shift
fi
status=0
ctest --test-dir build --output-on-failure -j2 "$@" || status=1
if [ $sanitize -eq 1 ]; then .ci/sanitize || status=1; fi
exit $status
