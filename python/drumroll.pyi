"""drumroll: non-smooth dynamics of AFM cantilevers tapping a sample (Melcher, Xu, Raman,
Appl. Phys. Lett. 93, 093111 (2008)).

Units everywhere: lengths nm, forces nN, time us (or drive periods, `_periods`), frequencies
kHz, phases degrees (a lag). Every result's keys and numbers are those of the `drumroll`
command's JSON (docs/output-schema.md); `to_dict()` gives that JSON object.
"""

from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

__version__: str

# A pandas DataFrame when pandas is installed, else a dict of numpy arrays (one per column).
Table = Any

class Case:
    """A cantilever tapping a sample at free amplitude `a0` (nm) and a drive frequency (kHz),
    resolved into the model of MODEL.md (Eq. 1 with Hertz contact).

    `Case("biolever-mica")`: a built-in case or a case file path.
    `Case(cantilever="biolever", sample="soft", a0=10.0)`: a cantilever and a sample (built-in
    names, file paths, or dicts in the files' format). `a0` and `drive_frequency_khz` override
    a named case's values; `Case()` is `biolever-mica`. `contact` and `electrostatic` (dicts in
    the sample files' format, MODEL.md section 9, e.g. `contact={"law": "dmt",
    "hamaker_constant_j": 5e-22, "intermolecular_distance_nm": 0.165}`) set the sample's
    contact law and double layer (default: the sample's own, Hertz); `drive` (a dict in the
    case files' format, MODEL.md section 14, e.g. `drive={"kind": "acoustic"}`) sets the
    excitation (default: the case's own, direct). Bad input raises ValueError (unknown
    name, out-of-range value: the message names the field and its allowed range) or
    TypeError; a file that cannot be read raises OSError. Pickles (travels to Dask workers).
    """

    def __init__(
        self,
        name_or_path: Optional[str] = None,
        *,
        cantilever: Union[str, Dict[str, Any], None] = None,
        sample: Union[str, Dict[str, Any], None] = None,
        a0: Optional[float] = None,
        drive_frequency_khz: Optional[float] = None,
        contact: Optional[Dict[str, Any]] = None,
        electrostatic: Optional[Dict[str, Any]] = None,
        drive: Optional[Dict[str, Any]] = None,
    ) -> None: ...
    @property
    def name(self) -> str:
        """The case's name, e.g. `biolever-mica`."""
    @property
    def a0(self) -> float:
        """The free amplitude A0 of the photodiode signal u, nm."""
    @property
    def drive_frequency_khz(self) -> float:
        """The drive frequency, kHz (the case's, else the fundamental f_1)."""
    @property
    def period_us(self) -> float:
        """The drive period T = 1/f, us."""
    @property
    def first_contact_z_nm(self) -> float:
        """First contact Z_G1: where the free orbit's lowest gap is zero, nm."""
    @property
    def free_phase_deg(self) -> float:
        """The free orbit's phase, degrees."""
    def orbit(
        self,
        z: Optional[float] = None,
        *,
        amplitude_ratio: Optional[float] = None,
        start: Union[str, "Orbit", Sequence[float], None] = None,
        harmonics: int = 4,
    ) -> "Orbit":
        """The steady orbit at separation `z` (nm), or where the approach reaches
        `amplitude_ratio` (A/A0), as `drumroll simulate`. `start`: "approach" (default),
        "transient", or a state near the orbit (a previous Orbit at a nearby Z: the fast warm
        start; or [q_1 nm, q_1' nm/us, q_2, q_2', ...]). `harmonics`: the harmonics
        n = 1..N of u in `Orbit.harmonics` (N in [1, 1000]). Releases the GIL."""
    def diagram(
        self,
        *,
        floor: Optional[float] = None,
        min_amplitude_ratio: float = 0.3,
        max_step: Optional[float] = None,
        max_points: int = 20000,
        retract: bool = False,
        harmonics: int = 4,
    ) -> "Diagram":
        """The bifurcation diagram in Z (the paper's Fig. 2), as `drumroll continue`: from
        above first contact down to `floor` (nm, default 0.05 A0) or A/A0 <
        `min_amplitude_ratio`; arclength steps up to `max_step` nm (default A0/250); with
        `retract=True` back up too; at most `max_points` points per branch (`completed` is
        False on a branch cut short); `harmonics` N: the columns harmonic_<n>_amplitude_nm and
        harmonic_<n>_phase_deg, n = 1..N, of every point. Releases the GIL; Ctrl-C
        interrupts it."""
    def approach(
        self,
        *,
        from_nm: Optional[float] = None,
        to_nm: float = 0.0,
        rate_nm_per_s: float = 1.0,
        retract: bool = False,
        lockin_cycles: int = 1,
        every: int = 1,
        settle_cycles: int = 20,
        tolerance: float = 1e-8,
        harmonics: int = 4,
    ) -> Table:
        """A time-domain approach sweep, as `drumroll approach`: Z from `from_nm` (default
        Z_G1 + 0.2 nm) to `to_nm` (nm) at `rate_nm_per_s` (nm/s), read by a lock-in over
        `lockin_cycles` drive cycles, every `every`-th reading kept. One row per reading:
        cycle, z_nm, amplitude_ratio, phase_deg, impacts_per_period, peak_force_nn (nN),
        dissipated_ev (eV per cycle), direction, then harmonic_<n>_amplitude_nm (nm) and
        harmonic_<n>_phase_deg (deg) for n = 1..`harmonics`; a DataFrame's attrs["inputs"]
        holds the inputs. Releases the GIL; Ctrl-C
        stops it."""
    def fit(
        self,
        measurement: "Measurement",
        *,
        fit: Sequence[str] = ("z-offset", "phase-offset", "sample-modulus"),
        max_evaluations: int = 40,
    ) -> "FitResult":
        """Fit this case's approach branch to `measurement` over the parameters in `fit`
        ("z-offset", "amplitude-calibration", "phase-offset", "sample-modulus", "tip-radius",
        ...), as `drumroll fit` (MODEL.md section 13.3): Levenberg-Marquardt on the followed
        branch, about `max_evaluations` residual evaluations (rounded up to a multiple of the
        varied quantities plus one, as `drumroll fit --max-evaluations`). Releases the GIL;
        Ctrl-C stops it."""
    def scan(
        self,
        line: Union[str, Dict[str, Any], None] = None,
        *,
        raster: Union[str, Dict[str, Any], None] = None,
        setpoint: float = 0.8,
        pixels: int = 64,
        feedback: str = "ideal",
        direction: str = "trace",
        gain_p: float = 0.2,
        gain_i_per_ms: float = 0.5,
        scan_rate_nm_per_s: float = 100.0,
        lockin_time_constant_ms: float = 0.0,
        harmonics: int = 4,
    ) -> Table:
        """An image line with amplitude feedback, as `drumroll scan` (MODEL.md section 12):
        this case's cantilever, drive and A0 over `line` (a built-in line name, default
        "membrane-patch", a line file path, or a dict in the line files' format), `pixels`
        pixels at the setpoint A/A0 `setpoint`, `feedback` "ideal" (steady orbits followed
        along their branches, jumps marked) or "pi" (the time-domain loop: `gain_p` nm/nm,
        `gain_i_per_ms` 1/ms, `scan_rate_nm_per_s` nm/s, `lockin_time_constant_ms` ms),
        `direction` "trace", "retrace" or "both". One row per pixel in scan order with the
        columns of `drumroll scan`'s CSV (height_nm, z_nm, phase_deg, impacts_per_period,
        ...); a DataFrame's attrs["inputs"] and attrs["line"] as in `--json`. `raster` (a
        raster file path or a dict in the raster files' format) instead of `line` scans every
        row as a line, as `drumroll scan --raster` (rows in parallel): the columns row and
        y_nm (nm) follow direction, and attrs["raster"] replaces attrs["line"]. Releases the
        GIL; Ctrl-C stops it."""
    def map(
        self,
        vary: str,
        start: float,
        stop: float,
        *,
        at: Optional[Sequence[float]] = None,
        labels: Optional[Sequence[str]] = None,
        points: int = 100,
        floor: Optional[float] = None,
        min_amplitude_ratio: float = 0.3,
        max_step: Optional[float] = None,
        harmonics: int = 4,
    ) -> "RegimeMap":
        """The impact-regime map, as `drumroll map`: each special point of the approach
        diagram (G_n, fold, period-doubling; or those in `labels`) continued over `vary`
        ("a0" nm, "drive-frequency" kHz, "sample-modulus" GPa, "tip-radius" nm,
        "quality-factor-N", "stiffness-N" N/m) from the case's value over [start, stop],
        exactly at each value of `at`, at least `points` points per curve; every point
        carries the contrast observables and harmonics n = 1..`harmonics` of u. Releases the
        GIL; Ctrl-C stops it."""
    def to_dict(self) -> Dict[str, Any]:
        """The case in the case files' format, cantilever and sample inline."""
    @classmethod
    def from_dict(cls, data: Dict[str, Any]) -> "Case":
        """The case of a dict as `to_dict` returns it."""

class Orbit:
    """One steady periodic orbit at a separation Z (MODEL.md section 4); every key of
    `drumroll simulate --json` is an attribute. `to_dict()` is the whole object (for an orbit
    found by `z=` the other start's coexisting orbit is looked for then, as the CLI does)."""

    z_nm: float
    """Separation Z between the cantilever base and the sample, nm."""
    amplitude_ratio: float
    """A/A0 of the photodiode signal's first harmonic."""
    phase_deg: float
    """Phase of u's first harmonic, degrees (a lag)."""
    free_phase_deg: float
    """The free orbit's phase, degrees."""
    first_contact_z_nm: float
    """First contact Z_G1, nm."""
    free_amplitude_nm: float
    """A0, nm."""
    drive_frequency_khz: float
    """Drive frequency, kHz."""
    period_us: float
    """Drive period, us."""
    multiplicity: int
    """The orbit's period in drive periods."""
    impacts_per_period: float
    """Impacts over the orbit divided by its multiplicity."""
    impacts_per_orbit: int
    """Impacts over the whole orbit."""
    peak_force_nn: float
    """Largest tip-sample force, nN."""
    mean_force_nn: float
    """Mean tip-sample force per drive period, nN."""
    impulse_nn_us: float
    """Tip-sample impulse per drive period, nN us."""
    contact_time_periods: float
    """Time in contact per drive period, in drive periods."""
    min_gap_nm: Optional[float]
    """Lowest gap d over the orbit, nm."""
    dissipated_ev: float
    """Energy dissipated in the sample per drive period, -int F_ts w' dt, eV (MODEL.md
    section 10; 0 for a conservative law)."""
    virial_ev: float
    """The virial (1/T) int F_ts w dt, eV."""
    max_indentation_nm: float
    """Largest indentation over the orbit, nm: the depth below the contact surface (a standard
    linear solid's below its unrecovered surface; MODEL.md section 10)."""
    mean_indentation_nm: float
    """Mean indentation over the time in contact, nm."""
    energy_balance_residual: float
    """The largest mode's energy-balance residual over the total damping loss."""
    harmonics: List[Dict[str, Any]]
    """Harmonics n = 1..N of u: dicts n, amplitude_nm (nm), phase_deg (deg)."""
    gap_minima: List[Dict[str, Any]]
    """Every local minimum of the gap: t_periods, gap_nm, kind."""
    impacts: List[Dict[str, Any]]
    """Every impact: start_periods, end_periods, velocity_nm_per_us, peak_force_nn."""
    periods: List[Dict[str, Any]]
    """Per drive period of the orbit: amplitude_ratio, phase_deg, impacts, ..."""
    converged: bool
    newton_iterations: int
    residual: float
    stable: bool
    floquet_multipliers: List[List[float]]
    """[re, im] pairs by decreasing modulus."""
    spectral_radius: float
    state: List[float]
    """[q_1 nm, q_1' nm/us, q_2, q_2', ...] at t = 0."""
    start: str
    """"approach", "transient" or "near"."""
    case: str
    coexisting_orbit: Optional[Dict[str, Any]]
    """The other start's orbit at this Z when it is a different one (as the CLI's JSON)."""
    inputs: Dict[str, Any]
    """What the orbit was computed from (docs/output-schema.md)."""

    def time_series(
        self, samples: int = 1000, periods: Optional[int] = None
    ) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(t us, u nm, F_ts nN) at `samples` points per drive period over `periods` drive
        periods (default: one whole orbit), both ends included."""
    def to_dict(self) -> Dict[str, Any]:
        """The `drumroll simulate --json` object."""

class Diagram:
    """A bifurcation diagram in Z, as `drumroll continue --json`. Pickles."""

    @property
    def points(self) -> Table:
        """The approach's branch points: columns z_nm (nm), amplitude_ratio, phase_deg (deg),
        multiplicity, impacts_per_period, impacts_per_orbit, min_gap_nm (nm), peak_force_nn
        (nN), mean_force_nn (nN), impulse_nn_us (nN us), contact_time_periods,
        spectral_radius, stable, iterations, residual, floquet_multipliers, gap_minima,
        state."""
    @property
    def special_points(self) -> List[Dict[str, Any]]:
        """label, z_nm, amplitude_ratio, phase_deg, impacts_before, impacts_after,
        bracket_nm, precision_nm, converged, state."""
    @property
    def stop(self) -> str:
        """Why the approach stopped."""
    @property
    def completed(self) -> bool:
        """Whether the approach reached its requested end (the CLI exits with status 3 when
        not)."""
    @property
    def error(self) -> Optional[str]:
        """The error that ended the branch early, if any."""
    @property
    def retract_points(self) -> Optional[Table]:
        """The retract's branch points (with retract=True)."""
    @property
    def retract_special_points(self) -> Optional[List[Dict[str, Any]]]:
        """The retract's special points (with retract=True)."""
    @property
    def bistable_ranges_nm(self) -> Optional[List[List[float]]]:
        """[Z_low, Z_high] ranges (nm) with two stable orbits (with retract=True)."""
    def to_dict(self) -> Dict[str, Any]:
        """The `drumroll continue --json` object."""
    @classmethod
    def from_dict(cls, data: Dict[str, Any]) -> "Diagram":
        """A diagram from its dict (or a saved `continue --json` file's content)."""

class RegimeMap:
    """An impact-regime map, as `drumroll map --json`. Pickles."""

    @property
    def curves(self) -> Dict[str, Table]:
        """Each curve's points by label: parameter (its unit), z_nm (nm), amplitude_ratio,
        phase_deg (deg), impacts_before, impacts_after, stable, spectral_radius, residual,
        at_fixed_parameter, floquet_multipliers, state."""
    @property
    def ends(self) -> Dict[str, List[Dict[str, Any]]]:
        """Each curve's ends by label: reason, parameter, z_nm (nm), error."""
    @property
    def codim2_points(self) -> List[Dict[str, Any]]:
        """The codimension-two points met on the curves, each with the observables of its
        orbit (`phase_deg`, `dissipated_ev`, `virial_ev`, indentations, `harmonics`, `state`),
        as `map --json` prints them."""
    @property
    def parameter_info(self) -> Dict[str, Any]:
        """name, unit, from, to, case_value of the varied parameter."""
    def to_dict(self) -> Dict[str, Any]:
        """The `drumroll map --json` object."""
    @classmethod
    def from_dict(cls, data: Dict[str, Any]) -> "RegimeMap":
        """A map from its dict (or a saved `map --json` file's content)."""

class Measurement:
    """A measured approach curve read from a CSV or TSV file with a header, as `drumroll
    detect --data` reads it (MODEL.md section 13.1)."""

    @staticmethod
    def from_csv(
        path: str,
        *,
        columns: Optional[str] = None,
        z_unit: str = "nm",
        amplitude_unit: str = "nm",
        invols: Optional[float] = None,
        phase_radians: bool = False,
        a0: Optional[float] = None,
    ) -> "Measurement":
        """Read `path`: the columns z_nm, amplitude_nm, phase_deg unless `columns`
        ("z=NAME,amplitude=NAME,phase=NAME", any of the three) names others; `z_unit` "nm",
        "um" or "m"; `amplitude_unit` "nm", "um", "m" or "V" (with `invols`, nm/V);
        `phase_radians`; `a0` the free amplitude (nm; default the mean of the free rows).
        ValueError names the file, line and column of a bad file."""
    @property
    def a0(self) -> float:
        """The free amplitude, nm."""
    @property
    def approach(self) -> Table:
        """The approach rows (Z decreasing): line, z_nm, amplitude_nm, phase_deg."""
    @property
    def bad_rows(self) -> List[Dict[str, Any]]:
        """The rows left out: dicts line, column, reason."""
    def detect(self, *, significance: float = 0.01, window: int = 0) -> Dict[str, Any]:
        """The transitions (kinks and jumps) with their Z, 1-sigma uncertainty, A/A0, phase
        and significance: the dict of `drumroll detect --json` (MODEL.md section 13.2)."""

class FitResult:
    """The result of `Case.fit`."""

    @property
    def parameters(self) -> Dict[str, Dict[str, Any]]:
        """The fitted parameters: name -> {"value", "stderr" (None: undetermined),
        "initial"}."""
    @property
    def points(self) -> Table:
        """The measured points with the fitted model, one row each (docs/output-schema.md)."""
    def to_dict(self) -> Dict[str, Any]:
        """The whole `drumroll fit --json` object."""

def cases() -> Dict[str, Dict[str, Dict[str, Any]]]:
    """The built-in fixtures: {"cases": {...}, "cantilevers": {...}, "samples": {...}}, each
    entry in its file's format."""
