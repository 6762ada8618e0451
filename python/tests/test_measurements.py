"""drumroll.Measurement, .detect() and Case.fit(): the CLI's JSON for the same inputs
(`drumroll detect`, `drumroll fit`; MODEL.md section 13). The fixtures are synthetic curves
made by drumroll (their first lines give the command and the truth)."""

import json

import pytest

import drumroll
from conftest import REPO, run_cli

FIXTURE = REPO / "fixtures" / "measurements" / "maclever-mica-synthetic.csv"


def test_detect_equals_the_cli():
    measurement = drumroll.Measurement.from_csv(str(FIXTURE))
    ours = measurement.detect()
    theirs = json.loads(run_cli("detect", "--data", str(FIXTURE), "--json").stdout)
    assert ours == theirs
    # The model's G2 (7.9588 nm, `drumroll continue --case maclever-mica-experiment`) plus
    # the instrument's offset of 12.5 nm, within 3 of the reported sigmas.
    g2 = [t for t in ours["transitions"] if abs(t["z_nm"] - 20.4588) <= 3 * t["z_uncertainty_nm"]]
    assert len(g2) == 1 and g2[0]["kind"] == "kink"


def test_bad_files_raise_value_errors_naming_the_column(tmp_path):
    path = tmp_path / "bad.csv"
    path.write_text("z_nm,amp,phase_deg\n" + "".join(f"{i},1,1\n" for i in range(60)))
    with pytest.raises(ValueError, match="amplitude_nm"):
        drumroll.Measurement.from_csv(str(path))
    with pytest.raises(OSError):
        drumroll.Measurement.from_csv(str(tmp_path / "absent.csv"))


def test_fit_equals_the_cli_and_recovers_the_offset():
    measurement = drumroll.Measurement.from_csv(str(FIXTURE))
    case = drumroll.Case("maclever-mica-experiment")
    result = case.fit(measurement, fit=["z-offset", "amplitude-calibration", "phase-offset"])
    theirs = json.loads(
        run_cli(
            "fit", "--data", str(FIXTURE), "--case", "maclever-mica-experiment",
            "--fit", "z-offset,amplitude-calibration,phase-offset", "--json",
        ).stdout
    )
    assert result.to_dict() == theirs
    offset = result.parameters["z_offset_nm"]
    # The truth (the fixture's header): 12.5 nm; within 4 standard errors.
    assert abs(offset["value"] - 12.5) <= 4 * offset["stderr"]
    assert len(result.points["z_nm"]) == len(measurement.approach["z_nm"])
