#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Makes docs/images/calibrate_report.png, the calibration report of docs/sensor.md: a photon-transfer series (two
# flats and two darks at each of tests/calibrate's 16 exposure times) simulated by `sensor` for a camera with
# K = 0.25 DN/e-, 5 e- dark noise, a 20 000 e- full well, 100 e-/s dark current, DSNU 2 e-, PRNU 1 % and
# QE 0.6, calibrated with --report, and the report's page in headless Chromium.
# Usage: docs/images/make_calibrate_report.sh [build-dir]   (needs oiiotool from openimageio-tools, and chromium)
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$root/build}
exe=$build/cli/chromatrace
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# The flats: a uniform radiance L = 0.0098 W m⁻² sr⁻¹ nm⁻¹ in one 1 nm band at 550 nm, which at f/4 on 5 µm pixels
# brings μp = (π/4)(1/N)²·L·A·λ/(hc)·Δλ = 33 298 photons per pixel and second: at QE 0.6 the full well in 1 s.
oiiotool --create 192x192 1 --chnames "S0.550nm" -d float -o "$tmp/dark.exr"
oiiotool --create 192x192 1 --chnames "S0.550nm" -d float --addc 0.0098 -o "$tmp/flat.exr"
printf 'wavelength_nm,r,g,b\n300,1,1,1\n900,1,1,1\n' > "$tmp/flat_camera.csv"
seed=1
flats=()
darks=()
for share in 0.04 0.11 0.18 0.25 0.32 0.39 0.46 0.53 0.6 0.67 0.94 0.97 1.0 1.03 1.3 1.6; do
  for kind in flat dark; do
    for k in 0 1; do
      cat > "$tmp/camera.json" <<JSON
{"optics": {"f_number": 4, "cos4": false}, "exposure": {"time_s": $share}, "pixel": {"pitch_um": 5},
 "spectral_response": {"camera": "$tmp/flat_camera.csv", "basis": "photon", "peak_qe": 0.6},
 "noise": {"enabled": true, "dark_current_e_per_s": 100, "read_e": 5, "dsnu_e": 2, "prnu": 0.01, "seed": $seed,
           "pattern_seed": 7},
 "full_well": {"enabled": true, "electrons": 20000},
 "adc": {"enabled": true, "gain_dn_per_e": 0.25, "black_level_dn": 100, "bits": 16}, "display": {"enabled": false}}
JSON
      seed=$((seed + 1))
      frame=$tmp/$share-$kind-$k.exr
      "$exe" sensor "$tmp/$kind.exr" -o "$frame" --config "$tmp/camera.json" --quiet
      if [ "$kind" = flat ]; then flats+=("$frame"); else darks+=("$frame"); fi
    done
  done
done
"$exe" calibrate --flat "${flats[@]}" --dark "${darks[@]}" -o "$tmp/settings.json" --report "$tmp/report" \
    --photons-per-s 33298 --wavelength 550 --camera "$tmp/flat_camera.csv" --basis photon --pixel-um 5 --temperature 25 --quiet
chromium --headless --no-sandbox --disable-gpu --hide-scrollbars --window-size=1150,3800 \
    --screenshot="$root/docs/images/calibrate_report.png" "file://$tmp/report/index.html" > /dev/null 2>&1
