//! `drumroll cantilever`: the Euler-Bernoulli modal table of a cantilever with a point tip mass
//! (`beam::modal_table`), and a cantilever file built from measured values (`k_1`, natural
//! frequencies, quality factors, tip radius) completed by the table's ratios.
//!
//! What is measured and what is computed: `k_1`, `f_1` and every `Q_n` must be given (there is
//! no theory for the quality factors in liquid here, so a missing `Q_n` is refused);
//! `f_n` (n >= 2) are used when given, otherwise `f_1` times the vacuum frequency ratio
//! (liquid loading lowers the higher frequencies less than proportionally, so measured values
//! are better: the paper's `f_2/f_1` in water, 72/9.3 = 7.74 for the Biolever and 28/3.5 = 8.0
//! for the MAClever, differ from the vacuum ratios 6.27 at `m_tip/m_c = 0` and 6.78 at 0.16);
//! `k_n = k_1 (k_n/k_1)`, `chi_n` and `F_n/F_1` always come from the beam model.

use afm::validation::ranges;
use afm::{Cantilever, Eigenmode};
use anyhow::{bail, Context, Result};
use beam::ModalProperties;
use clap::{Args, ValueEnum};
use serde_json::json;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::model_args::output_path;
use crate::option_ranges::{self, check_option};
use crate::output::print_stdout;

/// Modes whose frequency and quality factor have their own option (`--f1 .. --f4`,
/// `--q1 .. --q4`); more modes take the `--frequencies` and `--quality-factors` lists.
const NUMBERED_MODES: usize = 4;

/// How the cantilever is driven: which forcing ratios `F_n / F_1` go into the file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum DriveKind {
    /// A uniformly distributed force on the beam (magnetic excitation, the paper's case).
    Distributed,
    /// A force at the tip.
    Tip,
}

impl DriveKind {
    /// The option's value, as written in the outputs.
    fn name(self) -> &'static str {
        match self {
            Self::Distributed => "distributed",
            Self::Tip => "tip",
        }
    }

    fn force_ratio(self, mode: &ModalProperties) -> f64 {
        match self {
            Self::Distributed => mode.force_ratio_distributed,
            Self::Tip => mode.force_ratio_tip,
        }
    }
}

/// Options of `drumroll cantilever`.
#[derive(Debug, Clone, Args)]
pub struct CantileverArgs {
    /// Tip mass over cantilever mass, m_tip / m_c (dimensionless), in [0, 1000] for the table
    /// and [0, 100] for a cantilever file (the paper: 0 for the Biolever, 0.16 for the MAClever).
    #[arg(long, allow_negative_numbers = true)]
    pub tip_mass_ratio: f64,
    /// Number of eigenmodes N, in [1, 50].
    #[arg(long, default_value_t = 2, allow_negative_numbers = true)]
    pub modes: i64,
    /// Measured stiffness of the first mode k_1, N/m (e.g. by Sader's method), in
    /// [1e-6, 1000000] N/m (typical 0.001 to 1000 N/m).
    #[arg(long, allow_negative_numbers = true)]
    pub k1: Option<f64>,
    /// Measured natural frequency of mode 1 (in liquid), kHz. Every frequency is in
    /// [0.01, 1000000] kHz (typical 0.1 to 100000 kHz).
    #[arg(long, allow_negative_numbers = true)]
    pub f1: Option<f64>,
    /// Measured natural frequency of mode 2, kHz (default: f_1 times the vacuum ratio).
    #[arg(long, allow_negative_numbers = true)]
    pub f2: Option<f64>,
    /// Measured natural frequency of mode 3, kHz (default: f_1 times the vacuum ratio).
    #[arg(long, allow_negative_numbers = true)]
    pub f3: Option<f64>,
    /// Measured natural frequency of mode 4, kHz (default: f_1 times the vacuum ratio).
    #[arg(long, allow_negative_numbers = true)]
    pub f4: Option<f64>,
    /// Measured natural frequencies of modes 1, 2, ... (kHz, comma separated; instead of
    /// --f1 .. --f4; modes beyond the list use f_1 times the vacuum ratio).
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true, conflicts_with_all = ["f1", "f2", "f3", "f4"])]
    pub frequencies: Vec<f64>,
    /// Measured quality factor of mode 1 (in liquid). Every quality factor is in
    /// [0.001, 1000000] (typical 0.1 to 100000).
    #[arg(long, allow_negative_numbers = true)]
    pub q1: Option<f64>,
    /// Measured quality factor of mode 2.
    #[arg(long, allow_negative_numbers = true)]
    pub q2: Option<f64>,
    /// Measured quality factor of mode 3.
    #[arg(long, allow_negative_numbers = true)]
    pub q3: Option<f64>,
    /// Measured quality factor of mode 4.
    #[arg(long, allow_negative_numbers = true)]
    pub q4: Option<f64>,
    /// Measured quality factors of modes 1..N (comma separated; instead of --q1 .. --q4).
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true, conflicts_with_all = ["q1", "q2", "q3", "q4"])]
    pub quality_factors: Vec<f64>,
    /// Tip radius R, nm, in [0.1, 100000] nm (typical 1 to 10000 nm).
    #[arg(long, allow_negative_numbers = true)]
    pub radius: Option<f64>,
    /// Which forcing ratios F_n / F_1 the file gets: a uniformly distributed drive
    /// (magnetic excitation) or a tip force.
    #[arg(long, value_enum, default_value_t = DriveKind::Distributed)]
    pub drive: DriveKind,
    /// The cantilever's name in the file (default: the --out file's stem).
    #[arg(long)]
    pub name: Option<String>,
    /// Write the cantilever file (JSON, accepted by --cantilever and case files) here.
    #[arg(long, value_name = "FILE.json")]
    pub out: Option<PathBuf>,
    /// Print one JSON object {"modes": [...]} (with "cantilever" when one is built) instead of
    /// the table.
    #[arg(long)]
    pub json: bool,
    /// The geometry, material and fluid (`--geometry rectangular ...`).
    #[command(flatten)]
    pub geometry: crate::cantilever_geometry::GeometryArgs,
}

/// Where a mode's natural frequency comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum FrequencySource {
    Measured,
    VacuumRatio,
}

impl FrequencySource {
    fn name(self) -> &'static str {
        match self {
            Self::Measured => "measured",
            Self::VacuumRatio => "f1 x vacuum ratio",
        }
    }
}

impl CantileverArgs {
    /// Whether any option beyond the table's (`--tip-mass-ratio`, `--modes`, `--drive`,
    /// `--json`) asks for a cantilever to be built.
    fn builds(&self) -> bool {
        self.k1.is_some()
            || self.numbered_frequencies().iter().any(Option::is_some)
            || !self.frequencies.is_empty()
            || self.numbered_qualities().iter().any(Option::is_some)
            || !self.quality_factors.is_empty()
            || self.radius.is_some()
            || self.name.is_some()
            || self.out.is_some()
    }

    fn numbered_frequencies(&self) -> [Option<f64>; NUMBERED_MODES] {
        [self.f1, self.f2, self.f3, self.f4]
    }

    fn numbered_qualities(&self) -> [Option<f64>; NUMBERED_MODES] {
        [self.q1, self.q2, self.q3, self.q4]
    }

    /// The measured frequency of each of the N modes, or `None`.
    fn frequency_inputs(&self) -> Result<Vec<Option<f64>>> {
        per_mode(
            self.modes.max(0) as usize,
            &self.numbered_frequencies(),
            &self.frequencies,
            "--f",
            "--frequencies",
        )
    }

    /// The quality factor of each of the N modes, or `None`.
    fn quality_inputs(&self) -> Result<Vec<Option<f64>>> {
        per_mode(
            self.modes.max(0) as usize,
            &self.numbered_qualities(),
            &self.quality_factors,
            "--q",
            "--quality-factors",
        )
    }
}

/// Merge numbered options and a list into one value per mode; refuse values for modes beyond N.
fn per_mode(
    modes: usize,
    numbered: &[Option<f64>; NUMBERED_MODES],
    list: &[f64],
    prefix: &str,
    list_option: &str,
) -> Result<Vec<Option<f64>>> {
    if !list.is_empty() {
        if list.len() > modes {
            bail!(
                "{list_option} has {} values but --modes is {modes}",
                list.len()
            );
        }
        let mut values: Vec<Option<f64>> = list.iter().copied().map(Some).collect();
        values.resize(modes, None);
        return Ok(values);
    }
    if let Some(index) = (modes..NUMBERED_MODES).find(|&i| numbered[i].is_some()) {
        bail!(
            "{prefix}{} is given but --modes is {modes}: raise --modes or drop it",
            index + 1
        );
    }
    let mut values: Vec<Option<f64>> = numbered.iter().take(modes).copied().collect();
    values.resize(modes, None);
    Ok(values)
}

/// Run `drumroll cantilever`.
pub fn run(args: &CantileverArgs) -> Result<()> {
    if args.geometry.geometry.is_some() {
        let common = crate::cantilever_geometry::CommonOptions {
            tip_mass_ratio: args.tip_mass_ratio,
            modes: args.modes,
            tip_drive: args.drive == DriveKind::Tip,
            drive_name: args.drive.name(),
            radius: args.radius,
            name: args.name.as_deref(),
            out: args.out.as_deref(),
            json: args.json,
        };
        return crate::cantilever_geometry::run(&args.geometry, &common);
    }
    if args.geometry.any_option() {
        bail!(
            "--length-um, --width-um, --thickness-um, --youngs-modulus-gpa, --density-kg-m3 and \
             --fluid describe a cantilever by its geometry: add --geometry rectangular"
        );
    }
    option_ranges::TIP_MASS_RATIO.check(args.tip_mass_ratio)?;
    let modes = option_ranges::MODES.count(args.modes)?;
    let table = beam::modal_table(args.tip_mass_ratio, modes)
        .context("invalid --tip-mass-ratio or --modes")?;
    let out = args
        .out
        .as_ref()
        .map(|p| output_path(p, "json", "--out"))
        .transpose()?;
    let built = if args.builds() {
        Some(build(args, &table, out.as_deref())?)
    } else {
        None
    };
    if let (Some(path), Some((cantilever, _))) = (&out, &built) {
        crate::cantilever_file::write_cantilever_file(path, cantilever)?;
    }
    if args.json {
        let json = table_json(args, &table, built.as_ref(), out.as_deref());
        print_stdout(&format!("{}\n", serde_json::to_string_pretty(&json)?))?;
    } else {
        print_stdout(&summary(args, &table, built.as_ref(), out.as_deref()))?;
    }
    Ok(())
}

/// The cantilever from the measured values and the table, with where each frequency came from.
fn build(
    args: &CantileverArgs,
    table: &[ModalProperties],
    out: Option<&Path>,
) -> Result<(Cantilever, Vec<FrequencySource>)> {
    let frequencies = args.frequency_inputs()?;
    let qualities = args.quality_inputs()?;
    // Every value given is checked first, so that a bad value is named even when others are
    // missing.
    check_given(args, &frequencies, &qualities)?;
    let missing = missing_options(args, &frequencies, &qualities);
    let (Some(k1), Some(Some(f1)), Some(radius), true) = (
        args.k1,
        frequencies.first(),
        args.radius,
        missing.is_empty(),
    ) else {
        bail!(
            "to build a cantilever, missing: {} (a measured Q for every mode, e.g. from thermal \
             spectra in liquid: there is no theory for Q in liquid here; with only \
             --tip-mass-ratio and --modes the modal table is printed alone)",
            missing.join(", ")
        );
    };
    let mut modes = Vec::with_capacity(table.len());
    let mut sources = Vec::with_capacity(table.len());
    for ((mode, frequency), quality) in table.iter().zip(&frequencies).zip(&qualities) {
        let index = mode.index;
        let quality = quality.unwrap_or(f64::NAN);
        let (frequency, source) = match frequency {
            Some(value) => (*value, FrequencySource::Measured),
            None => (*f1 * mode.frequency_ratio, FrequencySource::VacuumRatio),
        };
        let first = index == 1;
        modes.push(Eigenmode {
            stiffness_n_per_m: k1 * mode.stiffness_ratio,
            frequency_khz: frequency,
            quality_factor: quality,
            optical_sensitivity: if first { 1.0 } else { mode.chi },
            force_ratio: if first {
                1.0
            } else {
                args.drive.force_ratio(mode)
            },
        });
        sources.push(source);
    }
    for (index, pair) in modes.windows(2).enumerate() {
        if pair[1].frequency_khz <= pair[0].frequency_khz {
            bail!(
                "f{} = {} kHz is not above f{} = {} kHz: the natural frequencies must increase \
                 with the mode number",
                index + 2,
                pair[1].frequency_khz,
                index + 1,
                pair[0].frequency_khz
            );
        }
    }
    let name = match (&args.name, out) {
        (Some(name), _) => name.clone(),
        (None, Some(path)) => path
            .file_stem()
            .and_then(|stem| stem.to_str())
            .unwrap_or("cantilever")
            .to_string(),
        (None, None) => String::from("cantilever"),
    };
    let measured_frequencies: Vec<String> = sources
        .iter()
        .enumerate()
        .filter(|(_, s)| **s == FrequencySource::Measured)
        .map(|(index, _)| format!("f{}", index + 1))
        .collect();
    let cantilever = Cantilever {
        name,
        description: format!(
            "built by `drumroll cantilever`: measured k1, {}, Q1..Q{}, R; k_n/k_1, chi_n, \
             F_n/F_1 ({} drive){} from Euler-Bernoulli modes with m_tip/m_c = {}",
            measured_frequencies.join(", "),
            table.len(),
            args.drive.name(),
            if measured_frequencies.len() < table.len() {
                ", the other frequencies f_1 x vacuum ratio"
            } else {
                ""
            },
            args.tip_mass_ratio
        ),
        tip_radius_nm: radius,
        tip_mass_ratio: args.tip_mass_ratio,
        tip_youngs_modulus_gpa: afm::model::cantilever::DEFAULT_TIP_YOUNGS_MODULUS_GPA,
        tip_poisson_ratio: afm::model::cantilever::DEFAULT_POISSON_RATIO,
        modes,
    };
    cantilever
        .validate("the built cantilever")
        .context("the built cantilever is not valid")?;
    Ok((cantilever, sources))
}

/// Check every measured value given (`--k1`, `--radius`, `--fN`, `--qN`) against its range in
/// [`option_ranges`] and the range table; the error names the option.
fn check_given(
    args: &CantileverArgs,
    frequencies: &[Option<f64>],
    qualities: &[Option<f64>],
) -> Result<()> {
    if let Some(k1) = args.k1 {
        option_ranges::K1.check(k1)?;
    }
    if let Some(radius) = args.radius {
        option_ranges::RADIUS.check(radius)?;
    }
    for (index, frequency) in frequencies.iter().enumerate() {
        if let Some(frequency) = frequency {
            check_option(
                &format!("--f{}", index + 1),
                ranges::FREQUENCY_KHZ,
                *frequency,
            )?;
        }
    }
    for (index, quality) in qualities.iter().enumerate() {
        if let Some(quality) = quality {
            check_option(
                &format!("--q{}", index + 1),
                ranges::QUALITY_FACTOR,
                *quality,
            )?;
        }
    }
    Ok(())
}

/// The options a build needs that are not given: `--k1`, `--f1`, `--radius` and a quality
/// factor for every mode.
fn missing_options(
    args: &CantileverArgs,
    frequencies: &[Option<f64>],
    qualities: &[Option<f64>],
) -> Vec<String> {
    let mut missing: Vec<String> = Vec::new();
    if args.k1.is_none() {
        missing.push(String::from("--k1 (N/m)"));
    }
    if frequencies.first().copied().flatten().is_none() {
        missing.push(String::from("--f1 (kHz)"));
    }
    if args.radius.is_none() {
        missing.push(String::from("--radius (nm)"));
    }
    missing.extend(
        qualities
            .iter()
            .enumerate()
            .filter(|(_, q)| q.is_none())
            .map(|(index, _)| format!("--q{}", index + 1)),
    );
    missing
}

/// The JSON of `drumroll cantilever --json` (docs/output-schema.md): `{"modes": [...]}` with
/// every table ratio (the optical sensitivity `chi_n` under the cantilever file's name,
/// `optical_sensitivity`), plus the built values per mode and the whole cantilever when one is
/// built, and the `inputs` it was computed from.
fn table_json(
    args: &CantileverArgs,
    table: &[ModalProperties],
    built: Option<&(Cantilever, Vec<FrequencySource>)>,
    out: Option<&Path>,
) -> serde_json::Value {
    let modes: Vec<serde_json::Value> = table
        .iter()
        .enumerate()
        .map(|(index, mode)| {
            let mut entry = json!({
                "index": mode.index,
                "eigenvalue": mode.eigenvalue,
                "frequency_ratio": mode.frequency_ratio,
                "stiffness_ratio": mode.stiffness_ratio,
                "optical_sensitivity": mode.chi,
                "force_ratio_distributed": mode.force_ratio_distributed,
                "force_ratio_tip": mode.force_ratio_tip,
            });
            if let (Some((cantilever, sources)), Some(map)) = (built, entry.as_object_mut()) {
                let eigenmode = &cantilever.modes[index];
                map.insert(
                    "stiffness_n_per_m".into(),
                    eigenmode.stiffness_n_per_m.into(),
                );
                map.insert("frequency_khz".into(), eigenmode.frequency_khz.into());
                map.insert("frequency_source".into(), sources[index].name().into());
                map.insert("quality_factor".into(), eigenmode.quality_factor.into());
                map.insert("force_ratio".into(), eigenmode.force_ratio.into());
            }
            entry
        })
        .collect();
    let mut value = json!({
        "inputs": {
            "drumroll_version": env!("CARGO_PKG_VERSION"),
            "command": "cantilever",
            "options": {
                "tip_mass_ratio": args.tip_mass_ratio,
                "modes": args.modes,
                "drive": args.drive.name(),
                "k1_n_per_m": args.k1,
                "frequencies_khz": args.frequency_inputs().ok(),
                "quality_factors": args.quality_inputs().ok(),
                "radius_nm": args.radius,
                "name": args.name,
                "out": out.map(|path| path.display().to_string()),
            },
        },
        "tip_mass_ratio": args.tip_mass_ratio,
        "drive": args.drive.name(),
        "frequency_ratios": "in vacuum (liquid loading changes them)",
        "modes": modes,
    });
    if let (Some((cantilever, _)), Some(map)) = (built, value.as_object_mut()) {
        map.insert("cantilever".into(), json!(cantilever));
        if let Some(path) = out {
            map.insert("out".into(), path.display().to_string().into());
        }
    }
    value
}

/// The readable output: the modal table, then the built cantilever's modes.
fn summary(
    args: &CantileverArgs,
    table: &[ModalProperties],
    built: Option<&(Cantilever, Vec<FrequencySource>)>,
    out: Option<&Path>,
) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "Euler-Bernoulli cantilever, tip mass ratio m_tip/m_c = {}, modes normalised to unit tip \
         deflection",
        args.tip_mass_ratio
    );
    let _ = writeln!(
        s,
        "{:>4}{:>12}{:>12}{:>12}{:>10}{:>16}{:>14}",
        "n", "b_n", "w_n/w_1", "k_n/k_1", "chi_n", "F_n/F_1 distr.", "F_n/F_1 tip"
    );
    for mode in table {
        let _ = writeln!(
            s,
            "{:>4}{:>12.6}{:>12.6}{:>12.4}{:>10.4}{:>16.4}{:>14.4}",
            mode.index,
            mode.eigenvalue,
            mode.frequency_ratio,
            mode.stiffness_ratio,
            mode.chi,
            mode.force_ratio_distributed,
            mode.force_ratio_tip
        );
    }
    let _ = writeln!(
        s,
        "(w_n/w_1 in vacuum: liquid loading changes the frequency ratios; measured frequencies \
         are better)"
    );
    if let Some((cantilever, sources)) = built {
        let _ = writeln!(
            s,
            "cantilever `{}`: R = {} nm, {} drive",
            cantilever.name,
            cantilever.tip_radius_nm,
            args.drive.name()
        );
        let _ = writeln!(
            s,
            "{:>4}{:>14}{:>14}{:>20}{:>10}{:>10}{:>10}",
            "n", "k_n [N/m]", "f_n [kHz]", "f_n from", "Q_n", "chi_n", "F_n/F_1"
        );
        for (index, (mode, source)) in cantilever.modes.iter().zip(sources).enumerate() {
            let _ = writeln!(
                s,
                "{:>4}{:>14.6}{:>14.6}{:>20}{:>10}{:>10.4}{:>10.4}",
                index + 1,
                mode.stiffness_n_per_m,
                mode.frequency_khz,
                source.name(),
                mode.quality_factor,
                mode.optical_sensitivity,
                mode.force_ratio
            );
        }
        if let Some(path) = out {
            let _ = writeln!(s, "written: {}", path.display());
        }
    }
    s
}
