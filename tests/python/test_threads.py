# SPDX-License-Identifier: Apache-2.0
# The GIL is released while the C++ works: another Python thread keeps running during a long call.
import threading
import time

import numpy as np


def longest_stall_during(call):
    """Runs `call` in a thread; returns (its duration, the longest the main thread went without running meanwhile)."""
    done = threading.Event()
    span = []

    def worker():
        start = time.perf_counter()
        call()
        span.append(time.perf_counter() - start)
        done.set()

    thread = threading.Thread(target=worker)
    last = time.perf_counter()  # before start(), which itself waits for the GIL once the thread runs
    thread.start()
    stall = 0.0
    while not done.is_set():
        now = time.perf_counter()
        stall = max(stall, now - last)
        last = now
        time.sleep(0.001)
    stall = max(stall, time.perf_counter() - last)  # also when the call ended before the loop first ran
    thread.join()
    return span[0], stall


def test_the_measure_sees_a_call_that_holds_the_gil():
    values = np.random.default_rng(1).uniform(size=2_000_000).tolist()
    duration, stall = longest_stall_during(lambda: sorted(values))  # one C call that never lets the GIL go
    assert stall > 0.5 * duration, (stall, duration)


def test_other_threads_run_while_the_module_works(chromatrace, tmp_path):
    rng = np.random.default_rng(2)
    image = rng.uniform(0.01, 1.0, size=(1500, 2000, 3)).astype(np.float32)
    duration, stall = longest_stall_during(lambda: chromatrace.analyze(image, segment=True))
    # Held, the GIL would stop this thread for the whole call; released, only for the array's reading and the
    # results' conversion, a small part of it.
    assert duration > 0.5, duration
    assert stall < 0.25 * duration, (stall, duration)
    cube = rng.uniform(0, 1, size=(600, 800, 31)).astype(np.float32)
    path = tmp_path / "cube.exr"
    chromatrace.write_spectral_exr(path, cube, list(range(400, 710, 10)))
    duration, stall = longest_stall_during(lambda: chromatrace.sensor(path, preset="canon_eos_5d_mkiii", exposure_s="auto"))
    assert stall < 0.25 * duration, (stall, duration)
