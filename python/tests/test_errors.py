"""Bad input: wrong types raise TypeError, unknown names and out-of-range values ValueError,
with the CLI's messages; nothing crashes the interpreter."""

import pytest

import drumroll
from conftest import cli_error


@pytest.mark.parametrize(
    "kwargs, cli_args",
    [
        ({"z": float("nan")}, ["--z", "NaN"]),
        ({"z": 1e9}, ["--z", "1e9"]),
        ({"amplitude_ratio": 1.5}, ["--amplitude-ratio", "1.5"]),
        ({"z": 5.0, "harmonics": 0}, ["--z", "5", "--harmonics", "0"]),
    ],
)
def test_orbit_out_of_range_raises_the_cli_message(kwargs, cli_args):
    case = drumroll.Case("biolever-mica")
    with pytest.raises(ValueError) as raised:
        case.orbit(**kwargs)
    assert str(raised.value) == cli_error("simulate", "--case", "biolever-mica", *cli_args)


@pytest.mark.parametrize(
    "kwargs, cli_args",
    [
        ({"floor": 50.0}, ["--floor", "50"]),
        ({"min_amplitude_ratio": 1.0}, ["--min-amplitude-ratio", "1"]),
        ({"max_step": -1.0}, ["--max-step=-1"]),
        ({"harmonics": 1001}, ["--harmonics", "1001"]),
    ],
)
def test_diagram_out_of_range_raises_the_cli_message(kwargs, cli_args):
    case = drumroll.Case("biolever-mica")
    with pytest.raises(ValueError) as raised:
        case.diagram(**kwargs)
    assert str(raised.value) == cli_error("continue", "--case", "biolever-mica", *cli_args)


@pytest.mark.parametrize(
    "kwargs, cli_args",
    [
        ({"rate_nm_per_s": 0.0}, ["--rate", "0"]),
        ({"from_nm": 1.0, "to_nm": 2.0}, ["--from", "1", "--to", "2"]),
        ({"lockin_cycles": 0}, ["--lockin-cycles", "0"]),
        ({"tolerance": 1.0}, ["--tolerance", "1"]),
    ],
)
def test_approach_out_of_range_raises_the_cli_message(kwargs, cli_args):
    case = drumroll.Case("biolever-mica")
    with pytest.raises(ValueError) as raised:
        case.approach(**kwargs)
    assert str(raised.value) == cli_error("approach", "--case", "biolever-mica", *cli_args)


def test_unknown_names_and_bad_values_raise_value_errors_with_the_cli_message():
    with pytest.raises(ValueError) as raised:
        drumroll.Case("no-such-case")
    assert str(raised.value) == cli_error("simulate", "--case", "no-such-case", "--z", "1")
    assert "built-in cases: biolever-mica" in str(raised.value)
    with pytest.raises(ValueError) as raised:
        drumroll.Case(cantilever="biolever", sample="granite", a0=10.0)
    assert str(raised.value) == cli_error(
        "simulate", "--cantilever", "biolever", "--sample", "granite", "--a0", "10", "--z", "1"
    )
    with pytest.raises(ValueError) as raised:
        drumroll.Case("biolever-mica", a0=-3.0)
    assert str(raised.value) == cli_error("simulate", "--case", "biolever-mica", "--a0=-3", "--z", "1")
    assert "--a0 -3: allowed" in str(raised.value)
    cantilever = drumroll.cases()["cantilevers"]["biolever"]
    with pytest.raises(ValueError) as from_dict:
        drumroll.Case(cantilever=cantilever, sample="mica", a0=-3.0)
    assert str(from_dict.value) == str(raised.value)
    with pytest.raises(ValueError) as raised:
        drumroll.Case("biolever-mica", drive_frequency_khz=1e9)
    assert str(raised.value) == cli_error(
        "simulate", "--case", "biolever-mica", "--drive-frequency", "1e9", "--z", "1"
    )
    with pytest.raises(ValueError) as raised:
        drumroll.Case(cantilever="biolever", sample="mica")
    assert str(raised.value) == cli_error(
        "simulate", "--cantilever", "biolever", "--sample", "mica", "--z", "1"
    ) or "--a0" in str(raised.value)


def test_a_bad_dict_names_its_field_and_range():
    cantilever = dict(drumroll.cases()["cantilevers"]["biolever"])
    cantilever["modes"] = [dict(cantilever["modes"][0], quality_factor=-2.0)] + cantilever["modes"][1:]
    with pytest.raises(ValueError, match="quality_factor"):
        drumroll.Case(cantilever=cantilever, sample="mica", a0=10.0)
    with pytest.raises(ValueError, match="unknown field"):
        drumroll.Case(cantilever=dict(cantilever, colour="red"), sample="mica", a0=10.0)


def test_wrong_types_raise_type_errors():
    case = drumroll.Case("biolever-mica")
    with pytest.raises(TypeError):
        case.orbit(z="five")
    with pytest.raises(TypeError):
        case.orbit(z=5.0, start=3.5)
    with pytest.raises(TypeError):
        case.diagram(retract="yes please")
    with pytest.raises(TypeError):
        drumroll.Case(42)
    with pytest.raises(TypeError):
        drumroll.Case(cantilever=object(), sample="mica", a0=10.0)
    with pytest.raises(ValueError, match="start"):
        case.orbit(z=5.0, start="sideways")
    with pytest.raises(ValueError, match="2 x 2 numbers"):
        case.orbit(z=5.0, start=[1.0, 2.0, 3.0])
    with pytest.raises(OSError):
        drumroll.Case("/no/such/dir/case.json")
    with pytest.raises(AttributeError, match="simulate --json"):
        case.orbit(z=12.0).no_such_key


def test_a_bad_drive_names_the_field():
    with pytest.raises(ValueError, match="drive"):
        drumroll.Case("biolever-mica", drive={"kind": "magnetic"})
    with pytest.raises(ValueError, match="second_free_amplitude_nm|drive"):
        drumroll.Case("biolever-mica", drive={"kind": "bimodal", "second_free_amplitude_nm": -1.0})
