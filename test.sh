#!/usr/bin/env bash
# Runs every test of the build ./setup.sh made (build/): CTest (unit, end-to-end, Blender and browser tests),
# then the sanitised check, .ci/sanitize (the core, sensor and analyzer unit tests built with AddressSanitizer
# and UndefinedBehaviorSanitizer into build-asan/, and each fuzz harness for FUZZ_SECONDS, 30 by default).
# CI (.ci/run) runs ./setup.sh and then this. Arguments go to CTest (./test.sh -R core runs a subset of it).
# Exit status 1 when anything failed.
set -uo pipefail
cd "$(dirname "$0")"
status=0
ctest --test-dir build --output-on-failure -j2 "$@" || status=1
.ci/sanitize || status=1
exit $status
