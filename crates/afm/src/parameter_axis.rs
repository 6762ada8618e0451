//! The second parameter of a regime map: which input of a [`Case`] varies along the map's
//! horizontal axis, its unit and physical range, and the model rebuilt at each of its values
//! (MODEL.md sections 1 and 3: the drive is re-solved for the free amplitude every time).

use continuation::SystemFamily;

use crate::eigenmode::{
    MAX_FREQUENCY, MAX_QUALITY, MAX_STIFFNESS, MIN_FREQUENCY, MIN_QUALITY, MIN_STIFFNESS,
};
use crate::{AfmError, Case, TappingModel};

/// Largest free amplitude and tip radius accepted, nm (the case and cantilever file limits).
const MAX_LENGTH_NM: f64 = 1e5;
/// Largest sample modulus accepted, GPa (the sample file limit).
const MAX_MODULUS_GPA: f64 = 1e4;

/// The names `--vary` accepts (`N` a mode number from 1).
pub const PARAMETER_NAMES: &str =
    "a0, drive-frequency, sample-modulus, tip-radius, quality-factor-N, stiffness-N (N = mode number from 1)";

/// An input of a case that a regime map varies.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ParameterAxis {
    /// The free amplitude `A0`, nm.
    FreeAmplitude,
    /// The drive frequency `f`, kHz.
    DriveFrequency,
    /// The sample's Young's modulus `E_s`, GPa.
    SampleModulus,
    /// The tip radius `R`, nm.
    TipRadius,
    /// The quality factor `Q_i` of mode `i` (index from 0).
    QualityFactor(usize),
    /// The stiffness `k_i` of mode `i` (index from 0), N/m.
    Stiffness(usize),
}

impl ParameterAxis {
    /// Parse a name of [`PARAMETER_NAMES`] for a case whose cantilever has `modes` modes.
    ///
    /// # Errors
    /// [`AfmError::InvalidField`] naming the option `--vary` and the allowed names.
    pub fn parse(name: &str, modes: usize) -> Result<Self, AfmError> {
        let unknown = || AfmError::InvalidField {
            file: "command line".into(),
            field: "--vary".into(),
            value: name.to_string(),
            allowed: format!("{PARAMETER_NAMES}; this cantilever has {modes} mode(s)"),
        };
        let mode = |rest: &str| -> Result<usize, AfmError> {
            match rest.parse::<usize>() {
                Ok(n) if n >= 1 && n <= modes => Ok(n - 1),
                _ => Err(unknown()),
            }
        };
        match name {
            "a0" => Ok(Self::FreeAmplitude),
            "drive-frequency" => Ok(Self::DriveFrequency),
            "sample-modulus" => Ok(Self::SampleModulus),
            "tip-radius" => Ok(Self::TipRadius),
            _ => {
                if let Some(rest) = name.strip_prefix("quality-factor-") {
                    Ok(Self::QualityFactor(mode(rest)?))
                } else if let Some(rest) = name.strip_prefix("stiffness-") {
                    Ok(Self::Stiffness(mode(rest)?))
                } else {
                    Err(unknown())
                }
            }
        }
    }

    /// The name `--vary` takes (`a0`, `drive-frequency`, `quality-factor-2`, ...).
    pub fn name(&self) -> String {
        match self {
            Self::FreeAmplitude => "a0".into(),
            Self::DriveFrequency => "drive-frequency".into(),
            Self::SampleModulus => "sample-modulus".into(),
            Self::TipRadius => "tip-radius".into(),
            Self::QualityFactor(i) => format!("quality-factor-{}", i + 1),
            Self::Stiffness(i) => format!("stiffness-{}", i + 1),
        }
    }

    /// The unit of the values (`nm`, `kHz`, `GPa`, `N/m`, or empty for a quality factor).
    pub fn unit(&self) -> &'static str {
        match self {
            Self::FreeAmplitude | Self::TipRadius => "nm",
            Self::DriveFrequency => "kHz",
            Self::SampleModulus => "GPa",
            Self::QualityFactor(_) => "",
            Self::Stiffness(_) => "N/m",
        }
    }

    /// The physical range `(low, high)` of the values for `case`, as the input files accept
    /// them (open at 0 for positive quantities: `low` itself is excluded then); for the drive
    /// frequency, the model's own range `[f_1 / 100, 100 f_N]`.
    pub fn physical_range(&self, case: &Case) -> (f64, f64) {
        match self {
            Self::FreeAmplitude | Self::TipRadius => (0.0, MAX_LENGTH_NM),
            Self::SampleModulus => (0.0, MAX_MODULUS_GPA),
            Self::DriveFrequency => {
                let f1 = case.cantilever.fundamental_frequency_khz();
                let top = case
                    .cantilever
                    .modes
                    .iter()
                    .map(|m| m.frequency_khz)
                    .fold(0.0, f64::max);
                (
                    (0.01 * f1).max(MIN_FREQUENCY),
                    (100.0 * top).min(MAX_FREQUENCY),
                )
            }
            Self::QualityFactor(_) => (MIN_QUALITY, MAX_QUALITY),
            Self::Stiffness(_) => (MIN_STIFFNESS, MAX_STIFFNESS),
        }
    }

    /// Whether `value` lies in the physical range (the lower end excluded for quantities that
    /// must be positive).
    pub fn allows(&self, case: &Case, value: f64) -> bool {
        let (low, high) = self.physical_range(case);
        let low_ok = if low == 0.0 {
            value > 0.0
        } else {
            value >= low
        };
        value.is_finite() && low_ok && value <= high
    }

    /// The physical range in words, e.g. `(0, 100000] nm` or `[0.001, 1000000]`.
    pub fn describe_range(&self, case: &Case) -> String {
        let (low, high) = self.physical_range(case);
        let open = if low == 0.0 { '(' } else { '[' };
        format!("{open}{low}, {high}] {}", self.unit())
            .trim_end()
            .to_string()
    }

    /// The case's own value of the parameter.
    pub fn value(&self, case: &Case) -> f64 {
        match self {
            Self::FreeAmplitude => case.free_amplitude_nm,
            Self::DriveFrequency => case.drive_frequency_or_fundamental_khz(),
            Self::SampleModulus => case.sample.youngs_modulus_gpa,
            Self::TipRadius => case.cantilever.tip_radius_nm,
            Self::QualityFactor(i) => case.cantilever.modes[*i].quality_factor,
            Self::Stiffness(i) => case.cantilever.modes[*i].stiffness_n_per_m,
        }
    }

    /// `case` with the parameter set to `value`.
    ///
    /// # Errors
    /// [`AfmError::InvalidField`] if `value` is outside the physical range.
    pub fn apply(&self, case: &Case, value: f64) -> Result<Case, AfmError> {
        if !self.allows(case, value) {
            let (low, high) = self.physical_range(case);
            return Err(AfmError::InvalidField {
                file: "regime map".into(),
                field: self.name(),
                value: value.to_string(),
                allowed: format!("{low} .. {high} {}", self.unit())
                    .trim_end()
                    .to_string(),
            });
        }
        let mut case = case.clone();
        match self {
            Self::FreeAmplitude => case.free_amplitude_nm = value,
            Self::DriveFrequency => case.drive_frequency_khz = Some(value),
            Self::SampleModulus => case.sample.youngs_modulus_gpa = value,
            Self::TipRadius => case.cantilever.tip_radius_nm = value,
            Self::QualityFactor(i) => case.cantilever.modes[*i].quality_factor = value,
            Self::Stiffness(i) => case.cantilever.modes[*i].stiffness_n_per_m = value,
        }
        Ok(case)
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
    /// As [`ParameterAxis::apply`] and [`TappingModel::from_case`].
    pub fn model_at(&self, value: f64) -> Result<TappingModel, AfmError> {
        TappingModel::from_case(&self.axis.apply(&self.case, value)?)
    }
}

impl SystemFamily for CaseFamily {
    type System = TappingModel;
    fn system_at(&self, q: f64) -> Result<TappingModel, String> {
        self.model_at(q).map_err(|e| e.to_string())
    }
}
