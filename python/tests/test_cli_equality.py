"""Every Python result equals the CLI's JSON for the same inputs: same keys, same numbers
(both sides are exact binary64: Python's json parses the CLI's shortest round-trip digits)."""

import json
import math

import numpy as np
import pytest

import drumroll
from conftest import cli_json, run_cli


def flattened(record):
    """A JSON record with its `harmonics` list as the tables' (and the CLI CSV's) columns
    harmonic_<n>_amplitude_nm and harmonic_<n>_phase_deg."""
    flat = {key: value for key, value in record.items() if key != "harmonics"}
    for harmonic in record.get("harmonics", []):
        n = harmonic["n"]
        flat[f"harmonic_{n}_amplitude_nm"] = harmonic["amplitude_nm"]
        flat[f"harmonic_{n}_phase_deg"] = harmonic["phase_deg"]
    return flat


@pytest.mark.parametrize("z", [12.0, 8.5, 5.0, 2.7])
def test_orbit_at_z_equals_simulate_json(z):
    case = drumroll.Case("biolever-mica")
    orbit = case.orbit(z=z)
    expected = cli_json("simulate", "--case", "biolever-mica", "--z", str(z), "--json")
    assert orbit.to_dict() == expected
    for key in ("amplitude_ratio", "phase_deg", "impacts_per_period", "peak_force_nn", "state"):
        assert getattr(orbit, key) == expected[key]


def test_orbit_harmonics_equal_simulate_harmonics():
    orbit = drumroll.Case("biolever-mica").orbit(z=5.0, harmonics=8)
    expected = cli_json("simulate", "--case", "biolever-mica", "--z", "5", "--harmonics", "8", "--json")
    assert orbit.to_dict() == expected
    assert [h["n"] for h in orbit.harmonics] == list(range(1, 9))
    for key in ("dissipated_ev", "virial_ev", "max_indentation_nm", "mean_indentation_nm",
                "energy_balance_residual", "harmonics"):
        assert getattr(orbit, key) == expected[key], key


def test_orbit_at_amplitude_ratio_and_transient_start_equal_simulate_json():
    case = drumroll.Case("maclever-mica")
    assert case.orbit(amplitude_ratio=0.9).to_dict() == cli_json(
        "simulate", "--case", "maclever-mica", "--amplitude-ratio", "0.9", "--json"
    )
    assert case.orbit(z=19.997, start="transient").to_dict() == cli_json(
        "simulate", "--case", "maclever-mica", "--z", "19.997", "--start", "transient", "--json"
    )


def test_cantilever_sample_a0_and_drive_equal_the_cli_options():
    case = drumroll.Case(cantilever="biolever", sample="soft", a0=12.5, drive_frequency_khz=9.0)
    expected = cli_json(
        "simulate", "--cantilever", "biolever", "--sample", "soft", "--a0", "12.5",
        "--drive-frequency", "9", "--z", "9", "--json",
    )
    assert case.orbit(z=9.0).to_dict() == expected


@pytest.mark.parametrize("name", ["biolever-mica-acoustic", "biolever-mica-bimodal"])
def test_a_drive_dict_gives_the_built_in_drive_case_numbers(name):
    drive = drumroll.cases()["cases"][name]["drive"]
    case = drumroll.Case("biolever-mica", drive=drive)
    assert case.to_dict()["drive"] == drive
    expected = cli_json("simulate", "--case", name, "--z", "8", "--json")
    got = case.orbit(z=8.0).to_dict()
    # Only the case's name and the command differ: every number is the drive case's.
    for record in (got, expected):
        record.pop("case", None)
        for key in ("case", "command", "options"):
            record["inputs"].pop(key, None)
    assert got == expected


def test_a_case_of_dicts_gives_the_named_case_numbers():
    fixtures = drumroll.cases()
    named = drumroll.Case(cantilever="maclever", sample="soft", a0=20.0)
    from_dicts = drumroll.Case(
        cantilever=fixtures["cantilevers"]["maclever"],
        sample=fixtures["samples"]["soft"],
        a0=20.0,
    )
    assert from_dicts.orbit(z=10.0).to_dict() == named.orbit(z=10.0).to_dict()


def test_diagram_equals_continue_json():
    case = drumroll.Case("biolever-mica")
    diagram = case.diagram()
    expected = cli_json("continue", "--case", "biolever-mica", "--json")
    assert diagram.to_dict() == expected
    assert diagram.special_points == expected["special_points"]
    assert [p["label"] for p in diagram.special_points] == ["G1", "G2", "G3"]
    points = diagram.points
    assert list(points.columns)[:3] == ["z_nm", "amplitude_ratio", "phase_deg"]
    rows = [flattened(p) for p in expected["points"]]
    assert set(points.columns) == set(rows[0])
    assert "harmonic_4_phase_deg" in points.columns and "dissipated_ev" in points.columns
    assert len(points) == len(expected["points"])
    for column in points.columns:
        values = [p[column] for p in rows]
        if column == "min_gap_nm":
            values = [math.nan if v is None else v for v in values]
            np.testing.assert_array_equal(points[column].to_numpy(), np.array(values))
        else:
            assert list(points[column]) == values, column


def test_diagram_options_and_retract_equal_continue_json():
    case = drumroll.Case("maclever-mica")
    diagram = case.diagram(floor=15.0, min_amplitude_ratio=0.0, max_step=0.1, retract=True)
    expected = cli_json(
        "continue", "--case", "maclever-mica", "--floor", "15", "--min-amplitude-ratio", "0",
        "--max-step", "0.1", "--retract", "--json",
    )
    assert diagram.to_dict() == expected
    assert diagram.retract_special_points == expected["retract"]["special_points"]
    assert diagram.bistable_ranges_nm == expected["bistable_ranges_nm"]
    assert len(diagram.retract_points) == len(expected["retract"]["points"])


def test_approach_rows_equal_the_jsonl_records():
    case = drumroll.Case("biolever-mica")
    table = case.approach(from_nm=8.8, to_nm=8.7, rate_nm_per_s=1.0, every=50, retract=True)
    lines = run_cli(
        "approach", "--case", "biolever-mica", "--from", "8.8", "--to", "8.7", "--rate", "1",
        "--every", "50", "--retract", "--jsonl",
    ).stdout.splitlines()
    inputs = json.loads(lines[0])["inputs"]
    records = [json.loads(line) for line in lines[1:]]
    assert table.to_dict(orient="records") == [flattened(r) for r in records]
    assert list(table.columns) == [
        "cycle", "z_nm", "amplitude_ratio", "phase_deg", "impacts_per_period",
        "peak_force_nn", "dissipated_ev", "direction",
    ] + [f"harmonic_{n}_{q}" for n in range(1, 5) for q in ("amplitude_nm", "phase_deg")]
    assert table.attrs["inputs"] == inputs
    assert set(table["direction"]) == {"approach", "retract"}


def test_cases_lists_the_built_in_fixtures():
    fixtures = drumroll.cases()
    assert "biolever-mica" in fixtures["cases"]
    assert set(fixtures["cantilevers"]) >= {"biolever", "maclever"}
    assert set(fixtures["samples"]) >= {"mica", "soft", "purple-membrane"}
    for name, case_dict in fixtures["cases"].items():
        assert drumroll.Case(name).to_dict() == case_dict
    inputs = cli_json("simulate", "--case", "maclever-soft", "--z", "15", "--json")["inputs"]
    case_dict = fixtures["cases"]["maclever-soft"]
    assert case_dict["cantilever"] == inputs["cantilever"]
    assert case_dict["sample"] == inputs["sample"]


def test_regime_map_equals_map_json(tmp_path):
    case = drumroll.Case("biolever-mica")
    regime = case.map(vary="a0", start=9.0, stop=11.0, at=[10.5], points=10)
    expected = cli_json(
        "map", "--case", "biolever-mica", "--vary", "a0", "--from", "9", "--to", "11",
        "--at", "10.5", "--points", "10", "--json",
    )
    assert regime.to_dict() == expected
    assert set(regime.curves) == {c["label"] for c in expected["curves"]}
    csv_path = tmp_path / "map.csv"
    run_cli(
        "map", "--case", "biolever-mica", "--vary", "a0", "--from", "9", "--to", "11",
        "--at", "10.5", "--points", "10", "--csv", str(csv_path),
    )
    csv_lines = csv_path.read_text().splitlines()
    csv_columns = csv_lines[0].split(",")[1:]
    for curve in expected["curves"]:
        table = regime.curves[curve["label"]]
        rows = [flattened(p) for p in curve["points"]]
        # The table's first columns are the CSV's (after its `label`), with the same values.
        assert list(table.columns)[: len(csv_columns)] == csv_columns
        for column in csv_columns:
            assert list(table[column]) == [p[column] for p in rows], column
        assert regime.ends[curve["label"]] == curve["ends"]
    assert "dissipated_ev" in csv_columns and "harmonic_4_phase_deg" in csv_columns
    assert regime.codim2_points == expected["codim2_points"]
    assert regime.parameter_info["case_value"] == 10.0


def test_regime_map_of_chosen_labels_and_its_errors():
    case = drumroll.Case("biolever-mica")
    regime = case.map(vary="sample-modulus", start=50.0, stop=70.0, labels=["G2"], points=5)
    assert regime.to_dict() == cli_json(
        "map", "--case", "biolever-mica", "--vary", "sample-modulus", "--from", "50", "--to",
        "70", "--labels", "G2", "--points", "5", "--json",
    )
    with pytest.raises(ValueError, match="--labels G9"):
        case.map(vary="a0", start=9.0, stop=11.0, labels=["G9"])
    with pytest.raises(ValueError, match="--labels bump"):
        case.map(vary="a0", start=9.0, stop=11.0, labels=["bump"])
    with pytest.raises(ValueError):
        case.map(vary="colour", start=9.0, stop=11.0)


DMT = {"law": "dmt", "hamaker_constant_j": 5e-22, "intermolecular_distance_nm": 0.165}


def test_contact_law_given_in_python_equals_a_sample_file_with_it(tmp_path):
    soft = drumroll.cases()["samples"]["soft"]
    path = tmp_path / "soft.json"
    path.write_text(json.dumps(dict(soft, contact=DMT)))
    expected = cli_json(
        "simulate", "--cantilever", "biolever", "--sample", str(path), "--a0", "10", "--z", "8",
        "--json",
    )
    by_keyword = drumroll.Case(cantilever="biolever", sample="soft", a0=10.0, contact=DMT)
    by_dict = drumroll.Case(cantilever="biolever", sample=dict(soft, contact=DMT), a0=10.0)
    by_file = drumroll.Case(cantilever="biolever", sample=str(path), a0=10.0)
    for case in (by_keyword, by_dict, by_file):
        assert case.orbit(z=8.0).to_dict() == expected
    assert expected["inputs"]["sample"]["contact"]["law"] == "dmt"
    hertz = drumroll.Case(cantilever="biolever", sample="soft", a0=10.0).orbit(z=8.0)
    assert hertz.phase_deg != expected["phase_deg"]
    with pytest.raises(ValueError, match="contact"):
        drumroll.Case(cantilever="biolever", sample="soft", a0=10.0, contact={"law": "glue"})


def test_film_case_equals_the_cli_and_warns_as_it_does():
    case = drumroll.Case("maclever-membrane-film")
    with pytest.warns(UserWarning, match="film correction is used beyond"):
        orbit = case.orbit(z=10.0)
    assert orbit.to_dict() == cli_json(
        "simulate", "--case", "maclever-membrane-film", "--z", "10", "--json"
    )
    with pytest.warns(UserWarning, match="film correction is used beyond"):
        diagram = case.diagram()
    assert diagram.to_dict() == cli_json("continue", "--case", "maclever-membrane-film", "--json")
