#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The Python module against the command (docs/python.md), side by side in one run.

1. Per image: a loop over the test photographs (tests/data/photos/masks.json), analysed as Python calls
   (chromatrace.analyze(path), the results as Python objects) and as one process per image
   (`chromatrace analyze FILE -o DIR --no-plots --no-report`, analysis.json read back), alternating, best of N.
2. Memory: a 24-megapixel image (6000 x 4000, 8-bit: coffee.png tiled 10 x 10), analysed by the command from an
   uncompressed TIFF and by the module from the same pixels as a NumPy array, each in a process of its own: the peak
   resident memory of each, and the module's peak less what the process held before the call (Python, NumPy, the
   array), which is what the analysis itself took.

3. With --blender EXE: what the Blender add-on's command calls cost, the question before it calls the module in
   process. The batch renders the paper box (64 x 64, 16 samples: a preview) with CHROMATRACE_EXE pointing at a
   wrapper that times each call; printed per subcommand beside the batch's wall time and a bare start of the full
   program (`scene-bands --help`). Then the read-back of each cached Cycles render, at 64 and 128 pixels, both ways
   side by side: in the process with OpenImageIO's Python module, and as a `chromatrace info` process.

Usage: CHROMATRACE_EXE=build/cli/chromatrace PYTHONPATH=build/python python3 bench/bench_python.py [--repeats N]
       [--blender blender]
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

SOURCE = Path(__file__).resolve().parents[1]
EXE = os.environ.get("CHROMATRACE_EXE", str(SOURCE / "build/cli/chromatrace"))


def photographs():
    photos = json.loads((SOURCE / "tests/data/photos/masks.json").read_text())["photos"]
    return [Path(p["file"]) if Path(p["file"]).is_absolute() else SOURCE / "tests/data/photos" / p["file"] for p in photos]


def per_image(repeats, work):
    import chromatrace
    print(f"{'photograph':<22} {'pixels':>10} {'python (s)':>11} {'process (s)':>12} {'ratio':>7}")
    totals = [0.0, 0.0]
    for photo in photographs():
        best = [float("inf"), float("inf")]
        for _ in range(repeats):
            start = time.perf_counter()
            a = chromatrace.analyze(photo)
            regions = len(a.regions)
            best[0] = min(best[0], time.perf_counter() - start)
            start = time.perf_counter()
            out = work / "out"
            subprocess.run([EXE, "analyze", str(photo), "-o", str(out), "--no-plots", "--no-report", "--quiet"], check=True)
            regions_command = len(json.loads((out / "analysis.json").read_text())["regions"])
            best[1] = min(best[1], time.perf_counter() - start)
            assert regions == regions_command
        totals = [t + b for t, b in zip(totals, best)]
        print(f"{photo.name:<22} {a.data['image']['width'] * a.data['image']['height']:>10} {best[0]:>11.3f} {best[1]:>12.3f} "
              f"{best[1] / best[0]:>6.2f}x")
    n = len(photographs())
    print(f"{'mean per image':<22} {'':>10} {totals[0] / n:>11.3f} {totals[1] / n:>12.3f} {totals[1] / totals[0]:>6.2f}x")


MODULE_CHILD = """
import resource, sys, numpy as np, OpenImageIO as oiio, chromatrace
image = oiio.ImageInput.open(sys.argv[1]); pixels = image.read_image(0, 0, 0, 3, "uint8"); image.close()
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
a = chromatrace.analyze(pixels)
print(before, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss, len(a.regions))
"""


def child_peak_kib(args, stdout=None):
    """Runs `args` in a child process (its stdout into the file `stdout`, if given); its peak resident memory (KiB)."""
    fd = os.open(stdout, os.O_WRONLY | os.O_CREAT | os.O_TRUNC) if stdout else None
    pid = os.fork()
    if pid == 0:
        if fd is not None:
            os.dup2(fd, 1)
        os.execvp(args[0], args)
    if fd is not None:
        os.close(fd)
    # The child's own rusage, not the sum over every child so far.
    _, status, usage = os.wait4(pid, 0)
    assert os.waitstatus_to_exitcode(status) == 0, args
    return usage.ru_maxrss


def memory(work):
    import numpy as np
    import OpenImageIO as oiio
    tile = oiio.ImageInput.open("/usr/lib/python3/dist-packages/skimage/data/coffee.png")
    pixels = tile.read_image(0, 0, 0, 3, "uint8")
    tile.close()
    big = np.ascontiguousarray(np.tile(pixels, (10, 10, 1)))
    path = work / "24mp.tif"
    out = oiio.ImageOutput.create(str(path))
    spec = oiio.ImageSpec(big.shape[1], big.shape[0], 3, "uint8")
    spec.attribute("compression", "none")
    out.open(str(path), spec)
    out.write_image(big)
    out.close()
    del big
    command = child_peak_kib([EXE, "analyze", str(path), "-o", str(work / "big"), "--no-plots", "--no-report", "--quiet"])
    result = work / "module.txt"
    module = child_peak_kib([sys.executable, "-c", MODULE_CHILD, str(path)], stdout=result)
    before, _, _ = map(int, result.read_text().split())
    mib = lambda k: k / 1024
    print(f"24-megapixel 8-bit image ({6000 * 4000 * 3 / 2**20:.0f} MiB as uint8, {6000 * 4000 * 12 / 2**20:.0f} MiB as float):")
    print(f"  command, from a TIFF:          peak {mib(command):8.0f} MiB")
    print(f"  module, from a NumPy array:    peak {mib(module):8.0f} MiB; before the call {mib(before):.0f} MiB "
          f"(Python, NumPy, OpenImageIO, the array); the analysis took {mib(module - before):.0f} MiB")
    print(f"  the analysis's memory, module / command: {(module - before) / command:.2f}")


WRAPPER = """#!/bin/sh
start=$(date +%s.%N)
"{exe}" "$@"
status=$?
echo "$1 $start $(date +%s.%N)" >> "{log}"
exit $status
"""


def blender_calls(blender, work):
    log = work / "calls.log"
    wrapper = work / "chromatrace"
    wrapper.write_text(WRAPPER.format(exe=os.path.abspath(EXE), log=log))
    wrapper.chmod(0o755)
    start = time.perf_counter()
    subprocess.run([blender, "--background", "--factory-startup", "--python", str(SOURCE / "blender_addon/batch.py"), "--",
                    "--scene", str(SOURCE / "scenes/paper/box.json"), "--out", str(work / "box.exr"), "--resolution", "64x64",
                    "--samples", "16", "--quiet"], check=True, env={**os.environ, "CHROMATRACE_EXE": str(wrapper)},
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall = time.perf_counter() - start
    calls: dict[str, list[float]] = {}
    for line in log.read_text().splitlines():
        name, t0, t1 = line.split()
        calls.setdefault(name, []).append(float(t1) - float(t0))
    bare = min(_timed([EXE, "scene-bands", "--help"]) for _ in range(5))
    print(f"Blender add-on batch ({blender}), paper box 64 x 64, 16 samples: {wall:.2f} s wall")
    print(f"{'subcommand':<14} {'calls':>5} {'seconds':>8} {'each':>7}")
    for name, times in sorted(calls.items(), key=lambda kv: -sum(kv[1])):
        print(f"{name:<14} {len(times):>5} {sum(times):>8.2f} {sum(times) / len(times):>7.3f}")
    total = sum(sum(t) for t in calls.values())
    count = sum(len(t) for t in calls.values())
    print(f"{'all':<14} {count:>5} {total:>8.2f} {total / count:>7.3f}   ({100 * total / wall:.0f} % of the batch's wall time)")
    print(f"a bare start of the full program (scene-bands --help): {bare:.3f} s; {count} starts: {count * bare:.2f} s")


def readback_side_by_side(blender, work, sizes=(64, 128), repeats=3):
    """The add-on's read-back of each Cycles render, both ways side by side on the same files, at two sizes: in the
    process with OpenImageIO's Python module (blender_addon/chromatrace/readback.py, as Blender's own Python runs
    it) against a `chromatrace info --json` process, best of N each."""
    sys.path.insert(0, str(SOURCE / "blender_addon"))
    from chromatrace import readback  # the add-on's module; it needs no Blender where OpenImageIO imports
    print(f"{'size':>9} {'renders':>7} {'in process (s)':>15} {'info process (s)':>17} {'ratio':>7}")
    for size in sizes:
        cache = work / f"cache-{size}"
        subprocess.run([blender, "--background", "--factory-startup", "--python", str(SOURCE / "blender_addon/batch.py"), "--",
                        "--scene", str(SOURCE / "scenes/paper/box.json"), "--out", str(work / f"box-{size}.exr"),
                        "--resolution", f"{size}x{size}", "--samples", "16", "--cache-dir", str(cache), "--keep-cache",
                        "--quiet"], check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        files = sorted(str(p) for p in cache.rglob("*.exr"))
        inside = outside = 0.0
        for f in files:
            best = [float("inf"), float("inf")]
            for _ in range(repeats):
                start = time.perf_counter()
                info = readback.read_back(f)
                best[0] = min(best[0], time.perf_counter() - start)
                assert isinstance(info, dict), info
                best[1] = min(best[1], _timed([EXE, "info", f, "--json"]))
            inside += best[0]
            outside += best[1]
        print(f"{size:>4} x{size:<4} {len(files):>7} {inside / len(files):>15.4f} {outside / len(files):>17.4f} "
              f"{outside / inside:>6.0f}x")


def _timed(args):
    start = time.perf_counter()
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - start


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--blender", help="also time the Blender add-on's command calls in a batch run with this Blender")
    parser.add_argument("--only-blender", action="store_true", help="only that")
    args = parser.parse_args()
    print(f"load average {' '.join(f'{v:.2f}' for v in os.getloadavg())}, {os.cpu_count()} cores")
    with tempfile.TemporaryDirectory(prefix="chromatrace-bench-") as scratch:
        if not args.only_blender:
            per_image(args.repeats, Path(scratch))
            memory(Path(scratch))
        if args.blender:
            blender_calls(args.blender, Path(scratch))
            readback_side_by_side(args.blender, Path(scratch))


if __name__ == "__main__":
    main()
