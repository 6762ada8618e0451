//! A second parameter of a regime map: the case's quantity that varies along the map's `p` axis
//! (free amplitude, drive frequency, sample modulus, tip radius, a mode's quality factor or
//! stiffness), its name on the command line, its unit, its physical range, and how a value is
//! put into a [`Case`] (MODEL.md sections 1, 3 and 6 define each quantity).

use std::fmt;
use std::str::FromStr;

use continuation::SystemFamily;

use crate::error::AfmError;
use crate::model::case::Case;
use crate::model::TappingModel;
use crate::validation::{check, ranges, Interval};

/// The quantity varied along a map's parameter axis. Each is a field of a [`Case`]; the model
/// built from the case ([`TappingModel::from_case`]) solves `F_1` from `A0` anew at every value
/// (MODEL.md section 3), so the free amplitude stays the case's unless it is the axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ParameterAxis {
    /// The free amplitude `A0` of `u`, nm (`a0`).
    FreeAmplitude,
    /// The drive frequency `f = w / 2 pi`, kHz (`drive-frequency`).
    DriveFrequency,
    /// The sample's Young's modulus `E_s`, GPa (`sample-modulus`), in Hertz's `E*`.
    SampleModulus,
    /// The tip radius `R`, nm (`tip-radius`), in Hertz's `sqrt(R)`.
    TipRadius,
    /// The quality factor `Q_n` of mode `n` (from 1) (`quality-factor-n`).
    QualityFactor(usize),
    /// The modal stiffness `k_n` of mode `n` (from 1), N/m (`stiffness-n`).
    Stiffness(usize),
}

/// The names [`ParameterAxis::from_str`] accepts, `N` standing for a mode number from 1.
pub const PARAMETER_NAMES: [&str; 6] = [
    "a0",
    "drive-frequency",
    "sample-modulus",
    "tip-radius",
    "quality-factor-N",
    "stiffness-N",
];

impl ParameterAxis {
    /// The command-line name: `a0`, `drive-frequency`, `sample-modulus`, `tip-radius`,
    /// `quality-factor-N`, `stiffness-N`.
    pub fn name(self) -> String {
        match self {
            Self::FreeAmplitude => String::from("a0"),
            Self::DriveFrequency => String::from("drive-frequency"),
            Self::SampleModulus => String::from("sample-modulus"),
            Self::TipRadius => String::from("tip-radius"),
            Self::QualityFactor(mode) => format!("quality-factor-{mode}"),
            Self::Stiffness(mode) => format!("stiffness-{mode}"),
        }
    }

    /// The unit of the values: `nm`, `kHz`, `GPa`, `N/m`, or empty (a quality factor).
    pub fn unit(self) -> &'static str {
        match self {
            Self::FreeAmplitude | Self::TipRadius => "nm",
            Self::DriveFrequency => "kHz",
            Self::SampleModulus => "GPa",
            Self::QualityFactor(_) => "",
            Self::Stiffness(_) => "N/m",
        }
    }

    /// The physical range of the values: the range the case, cantilever and sample files
    /// accept for the field ([`crate::validation::ranges`]; a drive frequency must besides lie
    /// within `[f_1 / 100, 100 f_N]`, which depends on the cantilever: see
    /// [`ParameterAxis::physical_range`]).
    fn range(self) -> Interval {
        match self {
            Self::FreeAmplitude => ranges::FREE_AMPLITUDE_NM,
            Self::DriveFrequency => ranges::FREQUENCY_KHZ,
            Self::SampleModulus => ranges::YOUNGS_MODULUS_GPA,
            Self::TipRadius => ranges::TIP_RADIUS_NM,
            Self::QualityFactor(_) => ranges::QUALITY_FACTOR,
            Self::Stiffness(_) => ranges::STIFFNESS_N_PER_M,
        }
    }

    /// Parse a name of [`PARAMETER_NAMES`] given as the option `--vary` for a case whose
    /// cantilever has `modes` modes.
    ///
    /// # Errors
    /// [`AfmError::InvalidField`] naming `--vary` and the allowed names (with the modes the
    /// cantilever has).
    pub fn parse(name: &str, modes: usize) -> Result<Self, AfmError> {
        let unknown = || AfmError::InvalidField {
            file: String::from("command line"),
            field: String::from("--vary"),
            value: name.to_string(),
            allowed: format!(
                "one of {} (N: a mode number from 1 to {modes}, the cantilever's modes)",
                PARAMETER_NAMES.join(", ")
            ),
        };
        let axis: Self = name.parse().map_err(|_| unknown())?;
        match axis {
            Self::QualityFactor(mode) | Self::Stiffness(mode) if mode > modes => Err(unknown()),
            _ => Ok(axis),
        }
    }

    /// The physical range of the values for `case`: the file range of the field, and for the
    /// drive frequency its intersection with the model's `[f_1 / 100, 100 f_N]`
    /// ([`crate::model::cantilever::Cantilever::drive_frequency_range_khz`]).
    pub fn physical_range(self, case: &Case) -> Interval {
        let range = self.range();
        match self {
            Self::DriveFrequency => {
                let (low, high) = case.cantilever.drive_frequency_range_khz();
                Interval::closed(low.max(range.min), high.min(range.max), range.unit)
            }
            _ => range,
        }
    }

    /// Whether `value` lies in [`ParameterAxis::physical_range`] for `case`.
    pub fn allows(self, case: &Case, value: f64) -> bool {
        self.physical_range(case).contains(value)
    }

    /// [`ParameterAxis::physical_range`] in words, e.g. `[0.001, 100000] nm`.
    pub fn describe_range(self, case: &Case) -> String {
        self.physical_range(case).describe()
    }

    /// Check that `value` lies in the axis's physical range; the error names `source` (e.g. the
    /// command-line option `--from`), the axis and the allowed range.
    pub fn check(self, source: &str, value: f64) -> Result<(), AfmError> {
        check(source, &self.name(), value, self.range())
    }

    /// The case's own value of the quantity (the drive frequency of a case without one is
    /// `f_1`).
    ///
    /// # Errors
    /// [`AfmError::InvalidField`] for a mode the cantilever does not have.
    pub fn value(self, case: &Case) -> Result<f64, AfmError> {
        Ok(match self {
            Self::FreeAmplitude => case.free_amplitude_nm,
            Self::DriveFrequency => case.drive_frequency_or_fundamental_khz(),
            Self::SampleModulus => case.sample.youngs_modulus_gpa,
            Self::TipRadius => case.cantilever.tip_radius_nm,
            Self::QualityFactor(_) => case.cantilever.modes[self.mode_index(case)?].quality_factor,
            Self::Stiffness(_) => case.cantilever.modes[self.mode_index(case)?].stiffness_n_per_m,
        })
    }

    /// `case` with the quantity set to `value`, checked in full ([`Case::validate`]); `source`
    /// names the value's origin in errors.
    ///
    /// # Errors
    /// [`AfmError::InvalidField`] for a value outside the physical range, a mode the cantilever
    /// does not have, or a case that the new value makes invalid.
    pub fn apply(self, case: &Case, value: f64, source: &str) -> Result<Case, AfmError> {
        self.check(source, value)?;
        let mut case = case.clone();
        match self {
            Self::FreeAmplitude => case.free_amplitude_nm = value,
            Self::DriveFrequency => case.drive_frequency_khz = Some(value),
            Self::SampleModulus => case.sample.youngs_modulus_gpa = value,
            Self::TipRadius => case.cantilever.tip_radius_nm = value,
            Self::QualityFactor(_) => {
                let index = self.mode_index(&case)?;
                case.cantilever.modes[index].quality_factor = value;
            }
            Self::Stiffness(_) => {
                let index = self.mode_index(&case)?;
                case.cantilever.modes[index].stiffness_n_per_m = value;
            }
        }
        case.validate(source)?;
        Ok(case)
    }

    /// The tapping model of `case` with the quantity set to `value` (see
    /// [`ParameterAxis::apply`]), at first contact `Z = Z_G1`.
    ///
    /// # Errors
    /// As [`ParameterAxis::apply`], and [`TappingModel::from_case`]'s (a drive frequency
    /// outside `[f_1 / 100, 100 f_N]`, a drive that cannot reach `A0`).
    pub fn model(self, case: &Case, value: f64, source: &str) -> Result<TappingModel, AfmError> {
        TappingModel::from_case(&self.apply(case, value, source)?)
    }

    /// The 0-based index of the axis's mode in `case`'s cantilever.
    fn mode_index(self, case: &Case) -> Result<usize, AfmError> {
        let mode = match self {
            Self::QualityFactor(mode) | Self::Stiffness(mode) => mode,
            _ => return Ok(0),
        };
        let count = case.cantilever.mode_count();
        if (1..=count).contains(&mode) {
            Ok(mode - 1)
        } else {
            Err(AfmError::InvalidField {
                file: format!("cantilever `{}`", case.cantilever.name),
                field: String::from("modes"),
                value: format!("mode {mode} ({})", self.name()),
                allowed: format!("a mode from 1 to {count} (the cantilever's modes)"),
            })
        }
    }
}

impl fmt::Display for ParameterAxis {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.name())
    }
}

impl FromStr for ParameterAxis {
    type Err = AfmError;

    /// Parse a command-line name (see [`PARAMETER_NAMES`]); the error lists the allowed names.
    fn from_str(name: &str) -> Result<Self, AfmError> {
        let moded = |prefix: &str| {
            name.strip_prefix(prefix)
                .and_then(|digits| digits.parse::<usize>().ok())
                .filter(|&mode| mode >= 1)
        };
        match name {
            "a0" => Ok(Self::FreeAmplitude),
            "drive-frequency" => Ok(Self::DriveFrequency),
            "sample-modulus" => Ok(Self::SampleModulus),
            "tip-radius" => Ok(Self::TipRadius),
            _ => {
                if let Some(mode) = moded("quality-factor-") {
                    Ok(Self::QualityFactor(mode))
                } else if let Some(mode) = moded("stiffness-") {
                    Ok(Self::Stiffness(mode))
                } else {
                    Err(AfmError::InvalidField {
                        file: String::from("parameter axis"),
                        field: String::from("parameter"),
                        value: format!("{name:?}"),
                        allowed: format!(
                            "one of {} (N: a mode number from 1)",
                            PARAMETER_NAMES.join(", ")
                        ),
                    })
                }
            }
        }
    }
}

/// The models of a case along a [`ParameterAxis`]: the [`SystemFamily`] a regime map's curves
/// are continued over (the first parameter of each member is the separation `Z`, nm).
#[derive(Debug, Clone)]
pub struct CaseFamily {
    /// The case at its own parameter value.
    pub case: Case,
    /// The varied input.
    pub axis: ParameterAxis,
}

impl CaseFamily {
    /// The model at parameter value `value` (separation at first contact).
    ///
    /// # Errors
    /// As [`ParameterAxis::model`].
    pub fn model_at(&self, value: f64) -> Result<TappingModel, AfmError> {
        self.axis.model(&self.case, value, "regime map")
    }
}

impl SystemFamily for CaseFamily {
    type System = TappingModel;
    fn system_at(&self, q: f64) -> Result<TappingModel, String> {
        self.model_at(q).map_err(|e| e.to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::builtin_case;

    #[test]
    fn names_round_trip_and_unknown_names_list_the_allowed_ones() {
        for axis in [
            ParameterAxis::FreeAmplitude,
            ParameterAxis::DriveFrequency,
            ParameterAxis::SampleModulus,
            ParameterAxis::TipRadius,
            ParameterAxis::QualityFactor(2),
            ParameterAxis::Stiffness(1),
        ] {
            assert_eq!(axis.name().parse::<ParameterAxis>().unwrap(), axis);
        }
        for bad in ["amplitude", "quality-factor-0", "stiffness-", "stiffness-x"] {
            let message = bad.parse::<ParameterAxis>().unwrap_err().to_string();
            assert!(message.contains("sample-modulus, tip-radius"), "{message}");
        }
    }

    #[test]
    fn apply_sets_the_field_and_checks_range_and_mode() {
        let case = builtin_case("biolever-mica").unwrap();
        let axis = ParameterAxis::QualityFactor(2);
        let changed = axis.apply(&case, 3.5, "--from").unwrap();
        assert_eq!(changed.cantilever.modes[1].quality_factor, 3.5);
        assert_eq!(axis.value(&changed).unwrap(), 3.5);
        let message = ParameterAxis::Stiffness(3)
            .apply(&case, 1.0, "--from")
            .unwrap_err()
            .to_string();
        assert!(message.contains("a mode from 1 to 2"), "{message}");
        let message = ParameterAxis::SampleModulus
            .apply(&case, -1.0, "--to")
            .unwrap_err()
            .to_string();
        assert!(
            message.contains("--to") && message.contains(&ranges::YOUNGS_MODULUS_GPA.describe()),
            "{message}"
        );
        let message = ParameterAxis::DriveFrequency
            .model(&case, 1e5, "--to")
            .unwrap_err()
            .to_string();
        assert!(message.contains("drive_frequency_khz"), "{message}");
    }
}
