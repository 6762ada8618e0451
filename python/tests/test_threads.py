"""The GIL is released: two threads computing diagrams finish in clearly less than twice the
time of one, and Ctrl-C interrupts a long computation."""

import os
import signal
import subprocess
import sys
import threading
import time

import pytest

import drumroll
from conftest import REPO


def diagram_work(case):
    # About half a second of work: the Fig. 2 diagram with steps of 0.01 nm (1000 orbits),
    # three times.
    for _ in range(3):
        case.diagram(min_amplitude_ratio=0.0, max_step=0.01)


def best_of(runs, call):
    best = float("inf")
    for _ in range(runs):
        start = time.perf_counter()
        call()
        best = min(best, time.perf_counter() - start)
    return best


def test_two_threads_run_diagrams_in_parallel():
    case = drumroll.Case("biolever-mica")
    one = best_of(2, lambda: diagram_work(case))

    def two_threads():
        threads = [threading.Thread(target=diagram_work, args=(case,)) for _ in range(2)]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()

    two = best_of(2, two_threads)
    ratio = two / one
    load = os.getloadavg()[0]
    print(
        f"one thread {one:.3f} s, two threads {two:.3f} s: ratio {ratio:.2f} "
        f"(2 if the GIL were held; load average {load:.1f} on {os.cpu_count()} cores)"
    )
    if load > os.cpu_count() - 1 and ratio >= 1.6:
        pytest.skip(f"the machine is busy (load {load:.1f}): ratio {ratio:.2f} says nothing")
    # On 2 free cores the ratio is about 1; the bound leaves room for other work.
    assert ratio < 1.6


def test_python_runs_while_a_diagram_computes():
    # While one thread computes a diagram the main thread keeps running Python: the longest
    # pause between its loop iterations is a scheduling slice, not the diagram's duration
    # (which it would be with the GIL held).
    case = drumroll.Case("biolever-mica")
    worker = threading.Thread(target=diagram_work, args=(case,))
    stamps = []
    start = time.perf_counter()
    worker.start()
    while worker.is_alive():
        stamps.append(time.perf_counter())
    duration = time.perf_counter() - start
    longest_pause = max(b - a for a, b in zip([start] + stamps, stamps))
    print(f"diagram {duration:.3f} s, longest pause of the main thread {longest_pause * 1e3:.1f} ms")
    assert duration > 0.3
    assert longest_pause < 0.3 * duration


def _ctrl_c_after_a_second(code, timeout):
    """Run `code` in a fresh Python, which prints `started` before its long computation; send
    it SIGINT a second later. Returns its stdout, its stderr and the seconds from the signal
    to its end."""
    process = subprocess.Popen(
        [sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    assert process.stdout.readline().strip() == "started"
    time.sleep(1.0)
    sent = time.perf_counter()
    process.send_signal(signal.SIGINT)
    out, err = process.communicate(timeout=timeout)
    return out, err, time.perf_counter() - sent


def _interrupted_within_two_seconds(setup, call, timeout=60):
    """Run `setup` (lines of Python making `case` and the call's arguments), then `call` (one
    expression, the long computation), in a fresh Python; Ctrl-C a second after it starts must
    raise KeyboardInterrupt within 2 s of the signal."""
    code = (
        "import drumroll\n"
        f"{setup}"
        "print('started', flush=True)\n"
        "try:\n"
        f"    {call}\n"
        "    print('finished')\n"
        "except KeyboardInterrupt:\n"
        "    print('interrupted')\n"
    )
    out, err, answered = _ctrl_c_after_a_second(code, timeout)
    assert out.strip() == "interrupted", (out, err)
    assert answered < 2.0, answered


def test_ctrl_c_interrupts_an_approach():
    code = (
        "import drumroll, time\n"
        "case = drumroll.Case('biolever-mica')\n"
        "print('started', flush=True)\n"
        "start = time.perf_counter()\n"
        "try:\n"
        "    case.approach(from_nm=10.2, to_nm=0.0, rate_nm_per_s=0.2)\n"
        "    print('finished')\n"
        "except KeyboardInterrupt:\n"
        "    print(f'interrupted after {time.perf_counter() - start:.2f} s')\n"
    )
    out, err, answered = _ctrl_c_after_a_second(code, timeout=30)
    assert out.startswith("interrupted after"), (out, err)
    # The sweep (about 475,000 cycles: 7 s on two cores, 12 s on one) stops within the check
    # interval (50 ms) and a cycle, also while its cycles ahead run on rayon's threads.
    assert answered < 2.0, answered


def test_ctrl_c_interrupts_an_approach_between_its_records():
    # One record kept of about 475,000 cycles (every millionth): Ctrl-C is looked for between
    # cycles, on every thread the sweep runs on, not only when a record comes.
    _interrupted_within_two_seconds(
        "case = drumroll.Case('biolever-mica')\n",
        "case.approach(from_nm=10.2, to_nm=0.0, rate_nm_per_s=0.2, every=1000000)",
    )


def test_ctrl_c_interrupts_a_diagram():
    _interrupted_within_two_seconds(
        "case = drumroll.Case('maclever-soft')\n",
        "[case.diagram(min_amplitude_ratio=0.0, max_step=0.01) for _ in range(100)]",
        timeout=30,
    )


def test_ctrl_c_interrupts_a_raster_scan_on_several_threads():
    # The rows run on rayon's threads, which do not see signals: the calling thread looks for
    # the Ctrl-C while they run, and they stop (the scan takes about 10 s on two cores).
    raster = str(REPO / "fixtures" / "rasters" / "membrane-disc.json")
    _interrupted_within_two_seconds(
        "case = drumroll.Case('maclever-membrane-experiment')\n",
        f"case.scan(raster={raster!r}, pixels=64, feedback='pi', scan_rate_nm_per_s=10.0)",
    )


def test_ctrl_c_interrupts_a_fit():
    # Seven parameters on the MAClever's curve: about 8 s on two cores, each Levenberg-Marquardt
    # evaluation a followed branch (its Jacobian's columns on rayon's threads). Ctrl-C is looked
    # for between the branches' points, on every thread, not only when the fit returns.
    data = str(REPO / "fixtures" / "measurements" / "maclever-mica-synthetic.csv")
    fit = [
        "z-offset", "amplitude-calibration", "phase-offset", "sample-modulus", "tip-radius",
        "quality-factor-1", "stiffness-1",
    ]
    _interrupted_within_two_seconds(
        f"measurement = drumroll.Measurement.from_csv({data!r})\n"
        "case = drumroll.Case('maclever-mica')\n",
        f"case.fit(measurement, fit={fit!r})",
    )


def test_ctrl_c_interrupts_a_map():
    # Three grazing curves of 1500 points each over A0 on the hydration case: about 6 s on two
    # cores, the curves on rayon's threads. Ctrl-C is looked for before every curve step.
    _interrupted_within_two_seconds(
        "case = drumroll.Case('biolever-mica-hydration')\n",
        "case.map('a0', 5.0, 20.0, points=1500)",
    )
