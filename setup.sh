#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Installs chromatrace's dependencies from Debian 12 packages and builds it into build/.
# Usage: ./setup.sh            (as root, or with sudo available)
set -euo pipefail
cd "$(dirname "$0")"

packages=(
  build-essential cmake ninja-build pkg-config
  libopenexr-dev libopenimageio-dev openimageio-tools libopencv-dev
  libtiff-dev libraw-dev  # DNG output (libtiff) and camera raw input (LibRaw)
  dcraw libraw-bin rawtherapee libimage-exiftool-perl  # independent raw readers the DNG test checks against (tests/cli/test_camera_raw.cpp)
  libembree-dev libtbb-dev libeigen3-dev
  nlohmann-json3-dev libcli11-dev libfmt-dev libgtest-dev
  chromium  # the browser test of analyze's report.html (tests/browser)
  blender  # the Blender add-on (blender_addon/) and its headless tests (tests/blender)
  xvfb xauth  # a display for the add-on's test in a real Blender window (tests/blender/test_gui.py)
  clang libclang-rt-14-dev  # libFuzzer and the sanitisers (.ci/sanitize, tests/fuzz)
  python-matplotlib-data python3-skimage rawtran-doc  # real photographs the analyzer is tested on (tests/data/photos/masks.json)
  slurm-wlm munge  # chromatrace farm's test on a single-node Slurm on localhost (tests/farm), and bench/bench_farm.sh
  python3-venv  # the virtual environments of the Blender modules below
  python3-dev pybind11-dev python3-numpy  # the Python module (python/)
  python3-pytest python3-openimageio python3-nbclient python3-nbformat python3-ipykernel python3-nbconvert \
    python3-matplotlib python3-pil  # its tests and the worked notebook (tests/python, docs/notebooks)
)
# The report viewer is bundled from npm packages (package.json): node and npm from Debian unless a node
# with its own npm (e.g. NodeSource's) is already there.
command -v npm >/dev/null || packages+=(nodejs npm)

sudo=""
[ "$(id -u)" -eq 0 ] || sudo="sudo"
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

npm ci --no-audit --no-fund

# Blender 4.5 LTS, 5.2 LTS and 5.3 as Python modules (PyPI's bpy, pinned), each in its own virtual environment in
# build/, for the add-on's tests against the Blenders artists run (tests/blender; Debian's blender above is 3.4).
# bpy 4.5 is built for CPython 3.11, Debian 12's python3; bpy 5.x for CPython 3.13, which Debian 12 lacks: it is
# taken from the PATH (python3.13, if it runs: pyenv's shim does not unless 3.13 is selected) or from pyenv's
# versions.
bpy_versions=(4.5.15 5.2.3 5.3.0)
python313() {
  local p
  for p in "$(command -v python3.13 || true)" "$(pyenv root 2>/dev/null || echo "$HOME/.pyenv")"/versions/3.13*/bin/python3.13; do
    [ -n "$p" ] && "$p" -c 'import sys; sys.exit(sys.version_info[:2] != (3, 13))' 2>/dev/null && { echo "$p"; return 0; }
  done
  return 1
}
# The first (4.5) is installed before the build, which packages the extension with it; the others, and the
# emva1288 oracle below, download and install while the build compiles (nothing in the build needs them).
mkdir -p build
background=()  # "PID LOG" of each install running beside the build
trap 'for job in "${background[@]}"; do kill "${job%% *}" 2>/dev/null || true; done' EXIT  # a failed build stops them
for v in "${bpy_versions[@]}"; do
  venv="build/bpy-$v"
  if ! "$venv/bin/python" -c "import importlib.metadata as m, sys; sys.exit(m.version('bpy') != '$v')" 2>/dev/null; then
    python=/usr/bin/python3
    if [ "${v%%.*}" -ge 5 ]; then
      python=$(python313) || { echo "setup.sh: error: bpy $v (Blender ${v%.*}) needs CPython 3.13: no python3.13 on the PATH or under pyenv (pyenv install 3.13)" >&2; exit 2; }
    fi
    rm -rf "$venv"
    "$python" -m venv "$venv"
    if [ "$v" = "${bpy_versions[0]}" ]; then
      "$venv/bin/pip" install --quiet --disable-pip-version-check "bpy==$v"
    else
      "$venv/bin/pip" install --quiet --disable-pip-version-check "bpy==$v" >"$venv.log" 2>&1 &
      background+=("$! $venv.log")
    fi
  fi
done
rm -rf build/bpy-5.0.1  # Blender 5.0, out of support, tested no more

# The EMVA 1288 reference implementation (PyPI's emva1288 and what it needs, pinned), a test-only oracle for
# chromatrace calibrate (tests/calibrate).
emva="build/emva1288-venv"
if ! cmp -s tests/calibrate/emva1288-requirements.txt "$emva/requirements.txt" 2>/dev/null; then
  rm -rf "$emva"
  /usr/bin/python3 -m venv "$emva"
  { "$emva/bin/pip" install --quiet --disable-pip-version-check -r tests/calibrate/emva1288-requirements.txt &&
      cp tests/calibrate/emva1288-requirements.txt "$emva/requirements.txt"; } >"$emva.log" 2>&1 &
  background+=("$! $emva.log")
fi

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release "-DCHROMATRACE_BPY_VERSIONS=$(IFS=';'; echo "${bpy_versions[*]}")"
cmake --build build

status=0
for job in "${background[@]}"; do
  if ! wait "${job%% *}"; then
    echo "setup.sh: error: a Python package install failed (${job#* }):" >&2
    cat "${job#* }" >&2
    status=1
  fi
done
exit $status
