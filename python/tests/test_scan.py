"""`Case.scan` equals `drumroll scan --json` pixel for pixel (MODEL.md section 12)."""

import pytest

import drumroll
from conftest import REPO, cli_json


def _rows(table):
    columns = list(table.keys())
    count = len(table[columns[0]])
    return [{c: table[c][i] for c in columns} for i in range(count)]


@pytest.mark.parametrize("feedback", ["ideal", "pi"])
def test_scan_equals_the_cli_json(feedback):
    case = drumroll.Case("maclever-membrane-experiment")
    table = case.scan(
        "membrane-patch", pixels=6, feedback=feedback, scan_rate_nm_per_s=4000.0, direction="both"
    )
    expected = cli_json(
        "scan", "--pixels", "6", "--feedback", feedback, "--scan-rate", "4000",
        "--direction", "both", "--json",
    )
    rows = _rows(table)
    assert len(rows) == len(expected["pixels"]) == 12
    for row, pixel in zip(rows, expected["pixels"]):
        for key in ("direction", "index", "sample", "height_nm", "z_nm", "amplitude_ratio",
                    "phase_deg", "impacts_per_period", "peak_force_nn", "jumped"):
            assert row[key] == pixel[key], key


def test_a_line_dict_and_bad_options_give_clear_errors():
    case = drumroll.Case("maclever-membrane-experiment")
    line = {"segments": [
        {"from_nm": 0, "to_nm": 10, "height_nm": 0, "sample": "mica"},
        {"from_nm": 10, "to_nm": 20, "height_nm": 3, "sample": "mica"},
    ]}
    rows = _rows(case.scan(line, pixels=2))
    assert abs(rows[1]["height_nm"] - 3.0) < 1e-9
    with pytest.raises(ValueError, match="setpoint"):
        case.scan(setpoint=1.5)
    with pytest.raises(ValueError, match=r"segments\[0\].to_nm"):
        case.scan({"segments": [{"from_nm": 0, "to_nm": -1, "height_nm": 0, "sample": "mica"}]})
    with pytest.raises(ValueError, match="feedback"):
        case.scan(feedback="magic")


def test_a_raster_scan_equals_the_cli_json_row_by_row():
    # The round membrane patch of fixtures/rasters (rows in parallel, as the CLI scans them),
    # from its file and from the same raster as a dict of built-in and inline rows.
    case = drumroll.Case("maclever-membrane-experiment")
    path = str(REPO / "fixtures" / "rasters" / "membrane-disc.json")
    table = case.scan(raster=path, pixels=4)
    expected = cli_json("scan", "--raster", path, "--pixels", "4", "--json")
    rows = _rows(table)
    assert len(rows) == len(expected["pixels"]) == 9 * 4
    for row, pixel in zip(rows, expected["pixels"]):
        for key in ("direction", "row", "y_nm", "index", "sample", "height_nm", "z_nm",
                    "amplitude_ratio", "phase_deg", "impacts_per_period", "jumped"):
            assert row[key] == pixel[key], key
    if hasattr(table, "attrs"):
        assert table.attrs["raster"] == expected["raster"]
    flat = {"segments": [{"from_nm": 0, "to_nm": 40, "height_nm": 0, "sample": "mica"}]}
    dict_table = case.scan(raster={"row_spacing_nm": 5, "rows": [flat, flat]}, pixels=2)
    dict_rows = _rows(dict_table)
    assert [r["row"] for r in dict_rows] == [0, 0, 1, 1]
    assert [r["y_nm"] for r in dict_rows] == [0.0, 0.0, 5.0, 5.0]
    assert dict_rows[0]["z_nm"] == dict_rows[2]["z_nm"]
    with pytest.raises(ValueError, match="not both"):
        case.scan("membrane-patch", raster=path)
    with pytest.raises(ValueError, match="row_spacing_nm"):
        case.scan(raster={"row_spacing_nm": -1, "rows": [flat]})
