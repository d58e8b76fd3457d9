# SPDX-License-Identifier: Apache-2.0
"""The EMVA 1288 reference implementation (PyPI's emva1288, pinned in setup.sh) on a descriptor file: prints its
results as JSON, for tests/calibrate/test_calibrate.cpp to compare with chromatrace calibrate.

Usage: python emva1288_reference.py DESCRIPTOR
"""
import json
import logging
import sys

from emva1288.process import Data1288, LoadImageData, ParseEmvaDescriptorFile, Results1288


def reference_results(descriptor):
    """The reference implementation's results on a descriptor file, as a dict (NaN as None)."""
    parser = ParseEmvaDescriptorFile(descriptor, loglevel=logging.ERROR)
    images = LoadImageData(parser.images, loglevel=logging.ERROR)
    data = Data1288(images.data, loglevel=logging.ERROR)
    r = Results1288(data.data, loglevel=logging.ERROR)
    out = {
        "K": r.K,
        "QE": r.QE / 100.0,
        "sigma_y_dark": r.sigma_y_dark,
        "sigma_d": r.sigma_d,
        "u_e_sat": r.u_e_sat,
        "dark_current_mean": r.u_I_mean,
        "dark_current_var": r.u_I_var,
        "DSNU": r.DSNU1288,
        "DSNU_row": r.DSNU1288_row,
        "DSNU_col": r.DSNU1288_col,
        "DSNU_pixel": r.DSNU1288_pixel,
        "PRNU": r.PRNU1288 / 100.0,
        "PRNU_row": r.PRNU1288_row / 100.0,
        "PRNU_col": r.PRNU1288_col / 100.0,
        "PRNU_pixel": r.PRNU1288_pixel / 100.0,
        "LE_min": r.LE_min / 100.0,
        "LE_max": r.LE_max / 100.0,
        "R": r.R,
        "inverse_K": r.inverse_K(),
        "u_p_min": r.u_p_min,
        "u_e_min": r.u_e_min,
        "u_p_sat": r.u_p_sat,
        "SNR_max": r.SNR_max,
        "DR": r.DR,
        "DSNU_DN": r.DSNU1288_DN(),
    }
    # NaN (a part the reference cannot split off) as null.
    return {k: (None if v != v else float(v)) for k, v in out.items()}


def main(descriptor):
    print(json.dumps(reference_results(descriptor)))


if __name__ == "__main__":
    main(sys.argv[1])
