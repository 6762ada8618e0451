"""The cost of `case.orbit(z, start=previous)` from Python against the same Rust call.

The Rust side is `cargo bench -p afm --bench steady_orbit`, column "no workspace": a steady
orbit of the Biolever on mica at the paper's Fig. 1 points (A/A0 = 0.95, 0.90, 0.50) from the
state of the orbit 0.01 nm above (`afm::steady_orbit` with `OrbitStart::Near`). This script
times the same call through the Python module, the same way (median of 201 calls of wall
time; best of 5 batches of 400 calls on the thread's CPU clock), so the two tables compare
row by row:

    python python/benchmarks/warm_orbit.py
    cargo bench -p afm --bench steady_orbit
"""

import statistics
import time

import drumroll


def median_us(repetitions, call):
    times = []
    for _ in range(repetitions):
        start = time.perf_counter()
        call()
        times.append((time.perf_counter() - start) * 1e6)
    return statistics.median(times)


def cpu_us(calls, call):
    best = float("inf")
    for _ in range(5):
        start = time.thread_time()
        for _ in range(calls):
            call()
        best = min(best, (time.thread_time() - start) * 1e6 / calls)
    return best


def main():
    case = drumroll.Case("biolever-mica")
    print("warm steady orbit from Python, Biolever on mica, A0 = 10 nm")
    print(f"{'A/A0':>6} {'Z (nm)':>10} {'impacts':>8} {'median us':>10} {'(CPU us)':>9}")
    for ratio in (0.95, 0.90, 0.50):
        target = case.orbit(amplitude_ratio=ratio)
        z = target.z_nm
        second = case.orbit(z=z + 0.02, start=target)
        neighbour = case.orbit(z=z + 0.01, start=second)
        warm = case.orbit(z=z, start=neighbour)
        assert warm.converged
        call = lambda: case.orbit(z=z, start=neighbour)  # noqa: E731
        print(
            f"{ratio:>6.2f} {z:>10.6f} {len(target.impacts):>8} "
            f"{median_us(201, call):>10.1f} {cpu_us(400, call):>9.1f}"
        )


if __name__ == "__main__":
    main()
