"""Pickling, time series, warm starts, and the tables without pandas."""

import json
import pickle
import subprocess
import sys

import numpy as np

import drumroll


def test_case_orbit_and_diagram_pickle_to_equal_objects():
    case = drumroll.Case("maclever-soft", a0=18.0)
    back = pickle.loads(pickle.dumps(case))
    assert back.to_dict() == case.to_dict()
    orbit = case.orbit(z=12.0)
    orbit_back = pickle.loads(pickle.dumps(orbit))
    assert orbit_back.to_dict() == orbit.to_dict()
    assert back.orbit(z=12.0).to_dict() == orbit.to_dict()
    t0, u0, f0 = orbit.time_series(samples=200)
    t1, u1, f1 = orbit_back.time_series(samples=200)
    np.testing.assert_array_equal(u0, u1)
    diagram = drumroll.Case("biolever-mica").diagram(min_amplitude_ratio=0.8)
    assert pickle.loads(pickle.dumps(diagram)).to_dict() == diagram.to_dict()
    regime = drumroll.Case("biolever-mica").map(vary="a0", start=9.5, stop=10.5, points=4)
    assert pickle.loads(pickle.dumps(regime)).to_dict() == regime.to_dict()


def test_time_series_samples_the_orbit():
    case = drumroll.Case("biolever-mica")
    orbit = case.orbit(z=5.0)
    t, u, force = orbit.time_series(samples=20000)
    assert t.shape == u.shape == force.shape == (20001,)
    assert t[0] == 0.0 and abs(t[-1] - case.period_us) < 1e-9 * case.period_us
    # u(0) is the photodiode signal of the orbit's state: sum_i chi_i q_i (MODEL.md section 1).
    chi = [mode["optical_sensitivity"] for mode in case.to_dict()["cantilever"]["modes"]]
    q = orbit.state[0::2]
    assert abs(u[0] - sum(c * x for c, x in zip(chi, q))) < 1e-12
    # The sampled force never exceeds the located peak, and a grid of T/20000 (impacts last
    # about T/150) comes within 1 % of it.
    assert force.max() <= orbit.peak_force_nn * (1 + 1e-9)
    assert force.max() >= 0.99 * orbit.peak_force_nn
    # Force only where the gap is negative: contact time from the samples (+- a sample per
    # impact edge) matches the located contact time.
    contact = np.count_nonzero(force > 0) / 20000
    assert abs(contact - orbit.contact_time_periods) < 2 * len(orbit.impacts) / 20000 + 1e-12


def test_warm_start_from_a_neighbouring_orbit_is_the_same_orbit():
    case = drumroll.Case("biolever-mica")
    neighbour = case.orbit(z=5.01)
    warm = case.orbit(z=5.0, start=neighbour)
    cold = case.orbit(z=5.0)
    assert warm.start == "near" and warm.converged
    assert np.max(np.abs(np.array(warm.state) - np.array(cold.state))) < 1e-9
    assert abs(warm.phase_deg - cold.phase_deg) < 1e-7
    from_list = case.orbit(z=5.0, start=list(neighbour.state))
    assert from_list.state == warm.state
    assert warm.to_dict()["coexisting_orbit"] is None


def test_tables_are_dicts_of_numpy_arrays_without_pandas():
    code = (
        "import sys, json; sys.modules['pandas'] = None\n"
        "import drumroll, numpy\n"
        "d = drumroll.Case('biolever-mica').diagram(min_amplitude_ratio=0.9)\n"
        "p = d.points\n"
        "a = drumroll.Case('biolever-mica').approach(from_nm=8.8, to_nm=8.79)\n"
        "print(json.dumps({'type': type(p).__name__, 'z': str(p['z_nm'].dtype),"
        " 'stable': str(p['stable'].dtype), 'impacts': str(p['impacts_per_orbit'].dtype),"
        " 'state': str(p['state'].dtype), 'n': len(p['z_nm']),"
        " 'direction': list(a['direction'][:1]), 'points': len(d.to_dict()['points'])}))\n"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    seen = json.loads(result.stdout)
    assert seen["type"] == "dict"
    assert (seen["z"], seen["stable"], seen["impacts"], seen["state"]) == (
        "float64", "bool", "int64", "object",
    )
    assert seen["n"] == seen["points"]
    assert seen["direction"] == ["approach"]
