# SPDX-License-Identifier: Apache-2.0
"""A photon-transfer series made by the EMVA 1288 package's own camera simulator (PyPI's emva1288, pinned in
setup.sh; not chromatrace's simulator), and the reference implementation's results on it, for
tests/calibrate/test_calibrate.cpp to run chromatrace calibrate on the same frames and compare.

Usage: python emva1288_simulated_camera.py OUTDIR CAMERA
CAMERA:
  standard     320 x 256, 12 bits, K 0.35 DN/e-, QE 0.55, 5 e- of read noise, 100 e-/s dark current, a 10 000 e-
               full well, DSNU and PRNU with row and column parts;
  compressive  the same, its response compressed by 3 % at the top of its range (y - b)(1 - 0.03 (y - b)/(top - b));
  subtracted   the same, its dark offset subtracted on chip: every frame at exposure t less the darks' mean growth
               since the shortest exposure (the mean flat in time, its shot noise kept);
  quantised    K 0.08 DN/e- and 2 e- of read noise: the dark variance under the 0.24 DN2 quantisation limit.
Prints JSON: {"frames": [{"file", "kind" ("b" flat or "d" dark), "exposure_s", "photons"}], "reference": {...}}.
"""
import json
import os
import sys

import numpy as np
from PIL import Image

from emva1288.camera.dataset_generator import DatasetGenerator
from emva1288.camera.routines import Qe

from emva1288_reference import reference_results

WIDTH, HEIGHT, BITS, BLACK = 320, 256, 12, 30


def generate(outdir, camera):
    rng = np.random.default_rng(1)
    dsnu = rng.normal(0, 2.0, (HEIGHT, WIDTH)) + rng.normal(0, 1.0, (1, WIDTH)) + rng.normal(0, 0.5, (HEIGHT, 1))
    prnu = 1 + rng.normal(0, 0.01, (HEIGHT, WIDTH)) + rng.normal(0, 0.005, (1, WIDTH)) + rng.normal(0, 0.003, (HEIGHT, 1))
    quantised = camera == "quantised"
    qe = Qe(qe=np.full((HEIGHT, WIDTH, 1), 0.55), wavelength=np.array([550.0]), width=WIDTH, height=HEIGHT)
    return DatasetGenerator(steps=30, L=16, image_format="tif", outdir=outdir, width=WIDTH, height=HEIGHT, bit_depth=BITS,
                            K=0.08 if quantised else 0.35, K_min=0.05, qe=qe, blackoffset=BLACK, u_esat=10000.0,
                            dark_current_ref=100, sigma2_dark_0=4.0 if quantised else 25.0, dsnu=dsnu, prnu=prnu, seed=3,
                            exposure_max=100000000)


def frames_of(descriptor):
    frames, kind, exposure, photons = [], None, None, None
    directory = os.path.dirname(descriptor)
    with open(descriptor) as f:
        for line in f:
            parts = line.split()
            if parts[0] in ("b", "d"):
                kind, exposure = parts[0], float(parts[1]) * 1e-9
                photons = float(parts[2]) if kind == "b" else None
            elif parts[0] == "i":
                path = os.path.join(directory, parts[1].replace("\\", "/"))
                frames.append({"file": path, "kind": kind, "exposure_s": exposure, "photons": photons})
    return frames


def post_process(frames, camera):
    """The camera's own processing on chip, applied to the simulator's frames in place."""
    if camera == "compressive":
        top = 2 ** BITS - 1
        for f in frames:
            y = np.asarray(Image.open(f["file"]), dtype=np.float64) - BLACK
            y = BLACK + y * (1 - 0.03 * np.clip(y, 0, None) / (top - BLACK))
            Image.fromarray(np.rint(y).astype(np.int32), "I").save(f["file"])
    elif camera == "subtracted":
        dark_mean = {}
        for f in frames:
            if f["kind"] == "d":
                dark_mean.setdefault(f["exposure_s"], []).append(np.asarray(Image.open(f["file"]), dtype=np.float64).mean())
        base = dark_mean[min(dark_mean)]
        base = sum(base) / len(base)
        for f in frames:
            means = dark_mean[f["exposure_s"]]
            offset = int(round(sum(means) / len(means) - base))
            y = np.asarray(Image.open(f["file"]), dtype=np.int64) - offset
            Image.fromarray(np.clip(y, 0, None).astype(np.int32), "I").save(f["file"])


def main(outdir, camera):
    generator = generate(outdir, camera)
    frames = frames_of(generator.descriptor_path)
    post_process(frames, camera)
    print(json.dumps({"frames": frames, "reference": reference_results(generator.descriptor_path)}))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
