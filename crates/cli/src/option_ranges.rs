//! The one place where numeric command-line options are checked: a table of every option's
//! allowed range (the ranges of the input files' fields, `afm::validation::ranges`, for the
//! same quantity), checked after parsing, before any computation. A value outside its range is
//! an error naming the option, the allowed range and, when a unit prefix explains it, the
//! likely unit mistake; an allowed value outside the range typical of AFM is a warning on
//! stderr. Ranges that depend on the model (`--z`, `--floor`, `--max-step`,
//! `--drive-frequency` for a cantilever) are built from it with [`OptionRange::new`] and
//! checked the same way.

use afm::validation::{format_number, ranges, Interval};
use anyhow::{bail, Result};

/// One option and its allowed range.
#[derive(Debug, Clone, Copy)]
pub struct OptionRange {
    /// The option, e.g. `--a0`.
    pub option: &'static str,
    /// Its allowed (and typical) values.
    pub interval: Interval,
}

/// Largest count of cycles or readings (`afm::sweep::MAX_CYCLE_COUNT`).
const MAX_COUNT: f64 = afm::sweep::MAX_CYCLE_COUNT as f64;

/// `--a0`: the free amplitude, as a case file's `free_amplitude_nm`.
pub const A0: OptionRange = OptionRange::new("--a0", ranges::FREE_AMPLITUDE_NM);
/// `--drive-frequency`: as a case file's `drive_frequency_khz` (the same in every command;
/// further limited per cantilever, [`drive_frequency_for`]).
pub const DRIVE_FREQUENCY: OptionRange =
    OptionRange::new("--drive-frequency", ranges::FREQUENCY_KHZ);
/// `--z` of `simulate` and `theory`, before the model's `-A0` bound ([`separation_for`]).
pub const Z: OptionRange = OptionRange::new(
    "--z",
    Interval::closed(
        -afm::sweep::MAX_SEPARATION_NM,
        afm::sweep::MAX_SEPARATION_NM,
        "nm",
    ),
);
/// `--amplitude-ratio`: `A / A0` strictly between 0 and 1.
pub const AMPLITUDE_RATIO: OptionRange = OptionRange::new(
    "--amplitude-ratio",
    Interval {
        min_inclusive: false,
        ..Interval::right_open(0.0, 1.0, "")
    },
);
/// `--min-amplitude-ratio` of `continue` (0 disables the stop).
pub const MIN_AMPLITUDE_RATIO: OptionRange =
    OptionRange::new("--min-amplitude-ratio", Interval::right_open(0.0, 1.0, ""));
/// `--harmonics` of `simulate` and `continue`: the harmonics `1..=N` of `u` reported.
pub const HARMONICS: OptionRange =
    OptionRange::new("--harmonics", Interval::closed(1.0, 1000.0, ""));
/// `--harmonics` of `approach`: the lock-in's harmonics per reading, at most
/// [`afm::orbit::lockin::MAX_LOCKIN_HARMONICS`].
pub const LOCKIN_HARMONICS: OptionRange = OptionRange::new(
    "--harmonics",
    Interval::closed(1.0, afm::orbit::lockin::MAX_LOCKIN_HARMONICS as f64, ""),
);
/// `--max-points` of `continue`.
pub const MAX_POINTS: OptionRange =
    OptionRange::new("--max-points", Interval::closed(2.0, 1e7, ""));
/// `--rate` of `approach`, nm/s (the paper's simulations: 1 nm/s).
pub const RATE: OptionRange = OptionRange::new(
    "--rate",
    Interval::positive(afm::sweep::MAX_RATE_NM_PER_S, "nm/s").with_typical(1e-3, 1e5),
);
/// `--to` of `approach`, nm.
pub const TO: OptionRange = OptionRange::new(
    "--to",
    Interval::closed(0.0, afm::sweep::MAX_SEPARATION_NM, "nm"),
);
/// `--tolerance` of `approach`.
pub const TOLERANCE: OptionRange =
    OptionRange::new("--tolerance", Interval::closed(1e-14, 1e-4, ""));
/// `--lockin-cycles` of `approach`.
pub const LOCKIN_CYCLES: OptionRange =
    OptionRange::new("--lockin-cycles", Interval::closed(1.0, MAX_COUNT, ""));
/// `--every` of `approach`.
pub const EVERY: OptionRange = OptionRange::new("--every", Interval::closed(1.0, MAX_COUNT, ""));
/// `--settle-cycles` of `approach`.
pub const SETTLE_CYCLES: OptionRange =
    OptionRange::new("--settle-cycles", Interval::closed(0.0, MAX_COUNT, ""));
/// `--tip-mass-ratio` of `cantilever` (the beam model's range; a cantilever file takes up to
/// 100).
pub const TIP_MASS_RATIO: OptionRange = OptionRange::new(
    "--tip-mass-ratio",
    Interval::closed(0.0, beam::MAX_TIP_MASS_RATIO, ""),
);
/// `--modes` of `cantilever`.
pub const MODES: OptionRange =
    OptionRange::new("--modes", Interval::closed(1.0, beam::MAX_MODES as f64, ""));
/// `--k1` of `cantilever`: as a cantilever file's `stiffness_n_per_m`.
pub const K1: OptionRange = OptionRange::new("--k1", ranges::STIFFNESS_N_PER_M);
/// `--radius` of `cantilever`: as a cantilever file's `tip_radius_nm`.
pub const RADIUS: OptionRange = OptionRange::new("--radius", ranges::TIP_RADIUS_NM);

/// Every fixed range of the table, for `--help` and its test.
pub const TABLE: &[OptionRange] = &[
    A0,
    DRIVE_FREQUENCY,
    Z,
    AMPLITUDE_RATIO,
    MIN_AMPLITUDE_RATIO,
    MAX_POINTS,
    HARMONICS,
    LOCKIN_HARMONICS,
    RATE,
    TO,
    TOLERANCE,
    LOCKIN_CYCLES,
    EVERY,
    SETTLE_CYCLES,
    TIP_MASS_RATIO,
    MODES,
    K1,
    RADIUS,
];

impl OptionRange {
    /// `option` with `interval`.
    pub const fn new(option: &'static str, interval: Interval) -> Self {
        Self { option, interval }
    }

    /// Check `value`: an error outside the allowed range (naming the option, the range and
    /// the likely unit mistake), a warning on stderr outside the typical range.
    pub fn check(&self, value: f64) -> Result<()> {
        if let Some(warning) = self.warning(value)? {
            crate::output::print_stderr(&format!("drumroll: warning: {warning}"));
        }
        Ok(())
    }

    /// [`Self::check`] without printing: the warning for an allowed but implausible value.
    pub fn warning(&self, value: f64) -> Result<Option<String>> {
        option_warning(self.option, self.interval, value)
    }

    /// [`Self::check`] of a count; returns it as `usize`.
    pub fn count(&self, value: i64) -> Result<usize> {
        self.check(value as f64)?;
        usize::try_from(value).map_err(|_| anyhow::anyhow!("{} {value}: not a count", self.option))
    }
}

/// Check `value` of `option` (a name built at run time, e.g. `--f3`) against `interval`, as
/// [`OptionRange::check`] does.
pub fn check_option(option: &str, interval: Interval, value: f64) -> Result<()> {
    if let Some(warning) = option_warning(option, interval, value)? {
        crate::output::print_stderr(&format!("drumroll: warning: {warning}"));
    }
    Ok(())
}

/// The error for `value` of `option` outside `interval` (with the likely unit mistake), or
/// the warning for an allowed value outside the typical range.
fn option_warning(option: &str, interval: Interval, value: f64) -> Result<Option<String>> {
    let hint = interval
        .unit_hint(value)
        .map_or_else(String::new, |hint| format!("; {hint}"));
    if !interval.contains(value) {
        bail!(
            "{option} {}: allowed {}{hint}",
            format_number(value),
            interval.describe()
        );
    }
    Ok(interval.implausible(value).then(|| {
        format!(
            "{option} {} is unusual for AFM (allowed {}){hint}",
            format_number(value),
            interval.describe()
        )
    }))
}

/// `--z` for a model with free amplitude `a0_nm`: `[-A0, 1e5]` nm (below `-A0` the tip is
/// pressed into the sample by more than its free amplitude; `continue --floor` has the same
/// lower bound).
pub fn separation_for(a0_nm: f64) -> OptionRange {
    OptionRange::new(
        "--z",
        Interval::closed(-a0_nm, afm::sweep::MAX_SEPARATION_NM, "nm"),
    )
}

/// `--drive-frequency` for `cantilever`: its [`afm::Cantilever::drive_frequency_range_khz`].
pub fn drive_frequency_for(cantilever: &afm::Cantilever) -> OptionRange {
    let (lowest, highest) = cantilever.drive_frequency_range_khz();
    OptionRange::new(
        "--drive-frequency",
        Interval::closed(lowest, highest, "kHz").with_typical(
            ranges::FREQUENCY_KHZ
                .typical
                .map_or(lowest, |(low, _)| low.max(lowest)),
            ranges::FREQUENCY_KHZ
                .typical
                .map_or(highest, |(_, high)| high.min(highest)),
        ),
    )
}
