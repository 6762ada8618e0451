"""A plain scipy transient integration of the steady-orbit benchmark's orbit, for the speed
ratio the steady-orbit issue asks for (drumroll's Newton from the neighbouring orbit against
"a plain Python/scipy transient integration of the same orbit to the same accuracy").

Eq. 1 of Melcher, Xu, Raman (2008) for N modes (MODEL.md section 1), written here from the
modal parameters alone:

    q_i'' = w_i^2 [ (F_i/k_i) cos(w t) + F_ts(d)/k_i - q_i ] - (w_i/Q_i) q_i',
    d = Z + sum_i q_i,   F_ts = c (-d)^{3/2} for d < 0, else 0

(nm, us, nN; k_i in N/m = nN/nm), integrated period by period with `solve_ivp` from the
neighbouring orbit's state until the state at the period's end is within 1e-10 nm (max norm)
of drumroll's converged orbit. That stopping rule knows the answer, which a plain transient
run does not: it favours scipy. The contact kink is stepped through by the error control
(no events), as a plain integration would.

Usage (after `pip install -r crates/afm/benches/requirements.txt`):

    cargo run --release -p afm --example transient_reference -- 0.5 > orbit.json
    python3 crates/afm/benches/scipy_transient.py orbit.json [METHOD [TOLERANCE]]

METHOD is a solve_ivp method (DOP853 by default), TOLERANCE its rtol = atol (1e-13 by
default: at 1e-12 and 1e-11, DOP853's error at the contact kink keeps the state 1e-9 to 1e-8 nm
away from the orbit for tens of periods).
"""
import json
import math
import sys
import time

import numpy as np
from scipy.integrate import solve_ivp


def main():
    problem = json.load(open(sys.argv[1]))
    method = sys.argv[2] if len(sys.argv) > 2 else "DOP853"
    tolerance = float(sys.argv[3]) if len(sys.argv) > 3 else 1e-13
    z = problem["z_nm"]
    w = problem["omega_rad_per_us"]
    period = problem["period_us"]
    c = problem["hertz_nn_per_nm_1_5"]
    modes = problem["modes"]
    omega = np.array([m["omega_rad_per_us"] for m in modes])
    quality = np.array([m["quality_factor"] for m in modes])
    stiffness = np.array([m["stiffness_n_per_m"] for m in modes])
    force = np.array([m["force_nn"] for m in modes])
    orbit = np.array(problem["orbit_state"])

    def field(t, x):
        q, v = x[0::2], x[1::2]
        d = z + q.sum()
        contact = c * (-d) ** 1.5 if d < 0.0 else 0.0
        out = np.empty_like(x)
        out[0::2] = v
        out[1::2] = omega**2 * ((force * math.cos(w * t) + contact) / stiffness - q) - (
            omega / quality
        ) * v
        return out

    x = np.array(problem["neighbour_state"])
    errors, evaluations = [], 0
    start = time.perf_counter()
    while True:
        k = len(errors)
        run = solve_ivp(
            field, (k * period, (k + 1) * period), x, method=method, rtol=tolerance, atol=tolerance
        )
        evaluations += run.nfev
        x = run.y[:, -1]
        errors.append(float(np.abs(x - orbit).max()))
        if errors[-1] < 1e-10 or len(errors) >= 40:
            break
    seconds = time.perf_counter() - start
    print(
        f"A/A0 = {problem['amplitude_ratio']}, Z = {z:.6f} nm, {method} at {tolerance:g}: "
        f"{len(errors)} periods, {evaluations} RHS evaluations, {seconds:.3f} s"
        + ("" if errors[-1] < 1e-10 else " (NOT within 1e-10 nm)")
    )
    print("distance to the orbit after each period (nm):", " ".join(f"{e:.1e}" for e in errors))


if __name__ == "__main__":
    main()
