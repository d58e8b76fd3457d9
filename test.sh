#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Runs every test of the build ./setup.sh made (build/): CTest (unit, end-to-end, Blender, Slurm and browser
# tests), then the sanitised parsers (.ci/sanitize-parsers): the readers of bad input and their unit tests built
# with AddressSanitizer and UndefinedBehaviorSanitizer into build-asan/, and each fuzz harness for 30 s. CI
# (.ci/run) runs ./setup.sh and then this.
#
#   ./test.sh                           CTest, then the sanitised parsers (about 10 minutes more on 2 cores)
#   ./test.sh CTEST ARGS                CTest only, with these arguments (./test.sh -R core runs a subset)
#   ./test.sh --sanitize [CTEST ARGS]   CTest, then the full sanitised check (.ci/sanitize): the core, sensor and
#                                       analyzer unit tests under the sanitisers as well, and every fuzz harness
#                                       for FUZZ_SECONDS (30 by default); about 40 minutes more on 2 cores
# Exit status 1 when anything failed.
set -uo pipefail
cd "$(dirname "$0")"
sanitize=parsers
if [ "${1:-}" = "--sanitize" ]; then
  sanitize=full
  shift
elif [ $# -gt 0 ]; then
  sanitize=none
fi
status=0
ctest --test-dir build --output-on-failure -j2 "$@" || status=1
case $sanitize in
  parsers) .ci/sanitize-parsers || status=1 ;;
  full) .ci/sanitize || status=1 ;;
esac
exit $status
