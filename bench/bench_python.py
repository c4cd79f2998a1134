"""The Python batch call against the same batch in C++ (issue 5: within 1.3x).

10^5 capsule pairs (the shapes of bench_proximity.cpp's batch rows) at poses given by a formula
that bench_proximity.cpp's Batch_CapsuleCapsule_PythonPoses row reproduces exactly, so both
languages time identical work. Prints the median and the best of 15 calls, per thread count, with
fresh outputs and with caller-owned outputs (out=).

    PYTHONPATH=build/python /usr/bin/python3 bench/bench_python.py
"""

import statistics
import time

import numpy as np

import diffpills

N = 100_000


def formula_poses(n):
    i = np.arange(n, dtype=np.float64)
    r_a = 1.5 * np.stack([np.sin(0.37 * i), np.cos(0.11 * i), np.sin(0.05 * i)], axis=1)
    r_b = 1.5 * np.stack([np.cos(0.23 * i), np.sin(0.17 * i), np.cos(0.07 * i)], axis=1)
    q_a = np.stack([np.cos(0.13 * i), np.sin(0.29 * i), np.cos(0.41 * i), np.sin(0.07 * i)], axis=1) + 0.1
    q_b = np.stack([np.sin(0.19 * i), np.cos(0.31 * i), np.sin(0.43 * i), np.cos(0.03 * i)], axis=1) + 0.1
    return r_a, q_a, r_b, q_b


def timings(call, repeats=15):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return statistics.median(times) * 1e3, min(times) * 1e3


def main():
    a, b = diffpills.Capsule(1.2, 0.2), diffpills.Capsule(0.8, 0.15)
    r_a, q_a, r_b, q_b = formula_poses(N)
    phi, gradient = np.empty(N), np.empty((N, 14))
    for threads in (1, 2):
        fresh = timings(lambda: diffpills.proximity_batch(a, r_a, q_a, b, r_b, q_b, threads=threads))
        owned = timings(
            lambda: diffpills.proximity_batch(a, r_a, q_a, b, r_b, q_b, threads=threads, out=(phi, gradient))
        )
        print(f"threads={threads}: fresh outputs median {fresh[0]:.2f} ms (best {fresh[1]:.2f}); "
              f"out= median {owned[0]:.2f} ms (best {owned[1]:.2f})")


if __name__ == "__main__":
    main()
