"""Steady orbits over a grid of separations Z, computed in parallel with Dask.

`drumroll.Case` objects (and the `Orbit` results) pickle, so `client.map(case.orbit, z_grid)`
ships the case to the workers and the orbits back. Here on a `LocalCluster` of two worker
processes; the same code runs on a cluster across machines by changing only the cluster line,
e.g. on Slurm with dask-jobqueue (drumroll installed in an environment the nodes share):

    from dask_jobqueue import SLURMCluster
    cluster = SLURMCluster(cores=1, processes=1, memory="2GB", walltime="01:00:00")
    cluster.scale(jobs=16)

Run: python python/examples/dask_orbits.py  (prints the table and checks it against the
serial loop, number for number).
"""

import drumroll
from dask.distributed import Client, LocalCluster

KEYS = ("z_nm", "amplitude_ratio", "phase_deg", "impacts_per_period", "peak_force_nn")


def main():
    case = drumroll.Case("biolever-mica")
    # From above first contact (Z_G1 = 10.01 nm) to A/A0 of about 0.3: every impact regime.
    z_grid = [10.5 - 0.5 * i for i in range(20)]

    serial = [case.orbit(z=z) for z in z_grid]

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True) as cluster, Client(
        cluster
    ) as client:
        futures = client.map(case.orbit, z_grid)
        parallel = client.gather(futures)

    print(f"{'Z (nm)':>8} {'A/A0':>10} {'phase (deg)':>12} {'impacts':>8} {'peak F (nN)':>12}")
    for orbit in parallel:
        print(
            f"{orbit.z_nm:>8.2f} {orbit.amplitude_ratio:>10.6f} {orbit.phase_deg:>12.4f} "
            f"{orbit.impacts_per_period:>8} {orbit.peak_force_nn:>12.6f}"
        )
    same = all(
        a.to_dict() == b.to_dict() and all(getattr(a, k) == getattr(b, k) for k in KEYS)
        for a, b in zip(serial, parallel)
    )
    if not same:
        raise SystemExit("the Dask results differ from the serial loop")
    print(f"{len(parallel)} orbits on 2 worker processes: identical to the serial loop")


if __name__ == "__main__":
    main()
