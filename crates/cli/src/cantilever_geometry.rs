//! `drumroll cantilever --geometry rectangular ...`: the modes of a rectangular cantilever in a
//! fluid from its geometry and material (`beam::RectangularCantilever::modes_in_fluid`, Sader's
//! hydrodynamic function; MODEL.md section 11), and a cantilever file built from them.

use std::path::Path;

use afm::{Cantilever, Eigenmode};
use anyhow::{bail, Context, Result};
use beam::{BeamError, Fluid, FluidMode, RectangularCantilever};
use clap::{Args, ValueEnum};
use serde_json::json;
use std::fmt::Write as _;

use crate::model_args::output_path;
use crate::option_ranges;
use crate::output::print_stdout;

/// The cantilever geometries `--geometry` accepts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Geometry {
    /// A uniform rectangular beam (length, width, thickness).
    Rectangular,
}

/// The options of `drumroll cantilever` that describe the cantilever by its geometry
/// (flattened into `CantileverArgs`).
#[derive(Debug, Clone, Args)]
pub struct GeometryArgs {
    /// Build the modes in a fluid from the cantilever's geometry and material (Sader's
    /// hydrodynamic function) instead of measured values; needs --length-um, --width-um,
    /// --thickness-um, --youngs-modulus-gpa, --density-kg-m3 and --fluid (a cantilever file
    /// is built with --radius).
    #[arg(long, value_enum, conflicts_with_all = ["k1", "f1", "f2", "f3", "f4", "frequencies", "q1", "q2", "q3", "q4", "quality_factors"])]
    pub geometry: Option<Geometry>,
    /// Length L of the beam, um, in [1, 10000].
    #[arg(long, allow_negative_numbers = true)]
    pub length_um: Option<f64>,
    /// Width b of the beam, um, in [0.1, 1000] (and at most L/2).
    #[arg(long, allow_negative_numbers = true)]
    pub width_um: Option<f64>,
    /// Thickness h of the beam, um, in [0.01, 100] (and at most b).
    #[arg(long, allow_negative_numbers = true)]
    pub thickness_um: Option<f64>,
    /// Young's modulus E of the beam's material, GPa, in [0.1, 1500] (silicon 169, silicon
    /// nitride about 250).
    #[arg(long, allow_negative_numbers = true)]
    pub youngs_modulus_gpa: Option<f64>,
    /// Density of the beam's material, kg/m^3, in [500, 25000] (silicon 2330, silicon
    /// nitride about 3100).
    #[arg(long, allow_negative_numbers = true)]
    pub density_kg_m3: Option<f64>,
    /// The fluid: `water` (20 C: 998.2 kg/m^3, 1.002e-3 Pa s), `air` (1.18 kg/m^3,
    /// 1.86e-5 Pa s) or a JSON file {"name", "density_kg_m3", "viscosity_pa_s"}.
    #[arg(long, value_name = "water|air|FILE")]
    pub fluid: Option<String>,
}

/// The options `drumroll cantilever` shares between its two ways of building a cantilever.
#[derive(Debug, Clone, Copy)]
pub struct CommonOptions<'a> {
    /// `--tip-mass-ratio`, `m_tip / m_c`.
    pub tip_mass_ratio: f64,
    /// `--modes` as typed (checked here).
    pub modes: i64,
    /// `--drive tip`: every `F_n / F_1 = 1`; otherwise a distributed load.
    pub tip_drive: bool,
    /// `--drive`'s value as written in the outputs.
    pub drive_name: &'static str,
    /// `--radius`, nm.
    pub radius: Option<f64>,
    /// `--name`.
    pub name: Option<&'a str>,
    /// `--out`.
    pub out: Option<&'a Path>,
    /// `--json`.
    pub json: bool,
}

/// The geometry and material options, once all are given.
struct GeometryInputs {
    cantilever: RectangularCantilever,
    fluid: Fluid,
    /// Where the fluid came from: `water`, `air` or the file's path.
    fluid_source: String,
}

/// The options `--geometry` needs, with their values or `None`.
fn geometry_options(args: &GeometryArgs) -> [(&'static str, Option<f64>); 5] {
    [
        ("--length-um", args.length_um),
        ("--width-um", args.width_um),
        ("--thickness-um", args.thickness_um),
        ("--youngs-modulus-gpa", args.youngs_modulus_gpa),
        ("--density-kg-m3", args.density_kg_m3),
    ]
}

impl GeometryArgs {
    /// Whether any geometry option (or `--fluid`) is given, so that a forgotten `--geometry`
    /// is named rather than the options silently ignored.
    #[must_use]
    pub fn any_option(&self) -> bool {
        geometry_options(self).iter().any(|(_, v)| v.is_some()) || self.fluid.is_some()
    }
}

/// Read the options into a validated geometry and fluid; errors name the option or the fluid
/// file and field.
fn inputs(args: &GeometryArgs, tip_mass_ratio: f64) -> Result<GeometryInputs> {
    let options = geometry_options(args);
    let mut missing: Vec<&str> = options
        .iter()
        .filter(|(_, value)| value.is_none())
        .map(|(name, _)| *name)
        .collect();
    if args.fluid.is_none() {
        missing.push("--fluid (water, air or a fluid file)");
    }
    if !missing.is_empty() {
        bail!("--geometry rectangular needs {}", missing.join(", "));
    }
    let value = |index: usize| options[index].1.unwrap_or(f64::NAN);
    let cantilever = RectangularCantilever {
        length_um: value(0),
        width_um: value(1),
        thickness_um: value(2),
        youngs_modulus_gpa: value(3),
        density_kg_m3: value(4),
        tip_mass_ratio,
    };
    cantilever.validate().map_err(|error| match error {
        BeamError::FieldOutOfRange {
            field,
            value,
            min,
            max,
        } => anyhow::anyhow!(
            "invalid --{} = {value}: must be finite and in [{min}, {max}]",
            field.replace('_', "-")
        ),
        other => anyhow::anyhow!("invalid geometry options: {other}"),
    })?;
    let source = args.fluid.clone().unwrap_or_default();
    let fluid = match Fluid::builtin(&source) {
        Some(fluid) => fluid,
        None => read_fluid(Path::new(&source))?,
    };
    Ok(GeometryInputs {
        cantilever,
        fluid,
        fluid_source: source,
    })
}

/// A fluid file: `{"name": ..., "density_kg_m3": ..., "viscosity_pa_s": ...}`.
fn read_fluid(path: &Path) -> Result<Fluid> {
    let text = std::fs::read_to_string(path).with_context(|| {
        format!(
            "--fluid `{}` is neither `water`, `air` nor a readable fluid file (JSON with name, \
             density_kg_m3, viscosity_pa_s)",
            path.display()
        )
    })?;
    let fluid: Fluid = serde_json::from_str(&text)
        .with_context(|| format!("fluid file {}: not a fluid", path.display()))?;
    fluid
        .validate()
        .with_context(|| format!("fluid file {}", path.display()))?;
    Ok(fluid)
}

/// Run `drumroll cantilever --geometry rectangular`.
pub fn run(geometry: &GeometryArgs, args: &CommonOptions) -> Result<()> {
    option_ranges::TIP_MASS_RATIO.check(args.tip_mass_ratio)?;
    let count = option_ranges::MODES.count(args.modes)?;
    let inputs = inputs(geometry, args.tip_mass_ratio)?;
    if let Some(radius) = args.radius {
        option_ranges::RADIUS.check(radius)?;
    }
    let out = args
        .out
        .map(|p| output_path(p, "json", "--out"))
        .transpose()?;
    if out.is_some() && args.radius.is_none() {
        bail!("--out needs --radius (nm): a cantilever file holds the tip radius");
    }
    let modes = inputs
        .cantilever
        .modes_in_fluid(&inputs.fluid, count)
        .with_context(|| format!("the modes in {}", inputs.fluid.name))?;
    let built = args
        .radius
        .map(|radius| build(args, &inputs, &modes, radius, out.as_deref()))
        .transpose()?;
    if let (Some(path), Some(cantilever)) = (&out, &built) {
        crate::cantilever_file::write_cantilever_file(path, cantilever)?;
    }
    if args.json {
        let value = report_json(args, &inputs, &modes, built.as_ref(), out.as_deref());
        print_stdout(&format!("{}\n", serde_json::to_string_pretty(&value)?))
    } else {
        print_stdout(&summary(
            args,
            &inputs,
            &modes,
            built.as_ref(),
            out.as_deref(),
        ))
    }
}

/// The cantilever file: every mode's `k_n`, `f_n`, `Q_n`, `chi_n` in the fluid and the drive's
/// forcing ratios.
fn build(
    args: &CommonOptions,
    inputs: &GeometryInputs,
    modes: &[FluidMode],
    radius: f64,
    out: Option<&Path>,
) -> Result<Cantilever> {
    let geometry = &inputs.cantilever;
    let name = match (args.name, out) {
        (Some(name), _) => name.to_string(),
        (None, Some(path)) => path
            .file_stem()
            .and_then(|stem| stem.to_str())
            .unwrap_or("cantilever")
            .to_string(),
        (None, None) => String::from("cantilever"),
    };
    let cantilever = Cantilever {
        name,
        description: format!(
            "built by `drumroll cantilever --geometry rectangular`: L = {} um, b = {} um, \
             h = {} um, E = {} GPa, rho_c = {} kg/m^3, m_tip/m_c = {}, in {} (rho = {} kg/m^3, \
             eta = {} Pa s); f_n, Q_n, k_n from Sader's hydrodynamic function (J. Appl. Phys. \
             84, 64 (1998)); {} drive",
            geometry.length_um,
            geometry.width_um,
            geometry.thickness_um,
            geometry.youngs_modulus_gpa,
            geometry.density_kg_m3,
            geometry.tip_mass_ratio,
            inputs.fluid.name,
            inputs.fluid.density_kg_m3,
            inputs.fluid.viscosity_pa_s,
            args.drive_name
        ),
        tip_radius_nm: radius,
        tip_mass_ratio: geometry.tip_mass_ratio,
        tip_youngs_modulus_gpa: afm::model::cantilever::DEFAULT_TIP_YOUNGS_MODULUS_GPA,
        tip_poisson_ratio: afm::model::cantilever::DEFAULT_POISSON_RATIO,
        modes: modes
            .iter()
            .map(|mode| Eigenmode {
                stiffness_n_per_m: mode.stiffness_n_per_m,
                frequency_khz: mode.frequency_khz,
                quality_factor: mode.quality_factor,
                optical_sensitivity: if mode.index == 1 {
                    1.0
                } else {
                    mode.optical_sensitivity
                },
                force_ratio: if mode.index == 1 || args.tip_drive {
                    1.0
                } else {
                    mode.force_ratio_distributed
                },
            })
            .collect(),
    };
    cantilever
        .validate("the built cantilever")
        .context("the cantilever built from the geometry is not valid")?;
    Ok(cantilever)
}

/// The JSON of `drumroll cantilever --geometry rectangular --json` (docs/output-schema.md).
fn report_json(
    args: &CommonOptions,
    inputs: &GeometryInputs,
    modes: &[FluidMode],
    built: Option<&Cantilever>,
    out: Option<&Path>,
) -> serde_json::Value {
    let geometry = &inputs.cantilever;
    let modes: Vec<serde_json::Value> = modes
        .iter()
        .map(|mode| {
            json!({
                "index": mode.index,
                "vacuum_frequency_khz": mode.vacuum_frequency_khz,
                "frequency_khz": mode.frequency_khz,
                "quality_factor": mode.quality_factor,
                "stiffness_n_per_m": mode.stiffness_n_per_m,
                "reynolds_number": mode.reynolds_number,
                "hydrodynamic_function": [mode.hydrodynamic_real, mode.hydrodynamic_imaginary],
                "effective_tip_mass_ratio": mode.effective_tip_mass_ratio,
                "optical_sensitivity": mode.optical_sensitivity,
                "force_ratio_distributed": mode.force_ratio_distributed,
                "force_ratio_tip": 1.0,
                "base_participation": mode.base_participation,
            })
        })
        .collect();
    let mut value = json!({
        "inputs": {
            "drumroll_version": env!("CARGO_PKG_VERSION"),
            "command": "cantilever",
            "options": {
                "tip_mass_ratio": args.tip_mass_ratio,
                "modes": args.modes,
                "drive": args.drive_name,
                "geometry": "rectangular",
                "length_um": geometry.length_um,
                "width_um": geometry.width_um,
                "thickness_um": geometry.thickness_um,
                "youngs_modulus_gpa": geometry.youngs_modulus_gpa,
                "density_kg_m3": geometry.density_kg_m3,
                "fluid": inputs.fluid_source,
                "radius_nm": args.radius,
                "name": args.name,
                "out": out.map(|path| path.display().to_string()),
            },
        },
        "tip_mass_ratio": args.tip_mass_ratio,
        "drive": args.drive_name,
        "fluid": {
            "name": inputs.fluid.name,
            "density_kg_m3": inputs.fluid.density_kg_m3,
            "viscosity_pa_s": inputs.fluid.viscosity_pa_s,
        },
        "static_stiffness_n_per_m": geometry.static_stiffness_n_per_m(),
        "modes": modes,
    });
    if let (Some(cantilever), Some(map)) = (built, value.as_object_mut()) {
        map.insert("cantilever".into(), json!(cantilever));
        if let Some(path) = out {
            map.insert("out".into(), path.display().to_string().into());
        }
    }
    value
}

/// The readable output: the modes in the fluid, then the written file.
fn summary(
    args: &CommonOptions,
    inputs: &GeometryInputs,
    modes: &[FluidMode],
    built: Option<&Cantilever>,
    out: Option<&Path>,
) -> String {
    let geometry = &inputs.cantilever;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "rectangular cantilever L = {} um, b = {} um, h = {} um, E = {} GPa, rho_c = {} kg/m^3, \
         m_tip/m_c = {}; 3EI/L^3 = {:.6} N/m",
        geometry.length_um,
        geometry.width_um,
        geometry.thickness_um,
        geometry.youngs_modulus_gpa,
        geometry.density_kg_m3,
        args.tip_mass_ratio,
        geometry.static_stiffness_n_per_m()
    );
    let _ = writeln!(
        s,
        "in {} (rho = {} kg/m^3, eta = {} Pa s), Sader's hydrodynamic function (J. Appl. Phys. \
         84, 64 (1998)), Re_n at each mode's own frequency",
        inputs.fluid.name, inputs.fluid.density_kg_m3, inputs.fluid.viscosity_pa_s
    );
    let _ = writeln!(
        s,
        "{:>4}{:>14}{:>14}{:>10}{:>14}{:>12}{:>18}{:>10}{:>10}{:>10}",
        "n",
        "f_vac [kHz]",
        "f_n [kHz]",
        "Q_n",
        "k_n [N/m]",
        "Re_n",
        "Gamma_n",
        "chi_n",
        "F_n/F_1",
        "gamma_n"
    );
    for mode in modes {
        let _ = writeln!(
            s,
            "{:>4}{:>14.6}{:>14.6}{:>10.4}{:>14.6}{:>12.4}{:>18}{:>10.4}{:>10.4}{:>10.4}",
            mode.index,
            mode.vacuum_frequency_khz,
            mode.frequency_khz,
            mode.quality_factor,
            mode.stiffness_n_per_m,
            mode.reynolds_number,
            format!(
                "{:.3}+{:.3}i",
                mode.hydrodynamic_real, mode.hydrodynamic_imaginary
            ),
            mode.optical_sensitivity,
            mode.force_ratio_distributed,
            mode.base_participation
        );
    }
    let _ = writeln!(
        s,
        "(F_n/F_1: a load distributed on the beam; gamma_n: the base-motion participation factor)"
    );
    if let Some(cantilever) = built {
        let _ = writeln!(
            s,
            "cantilever `{}`: R = {} nm, {} drive",
            cantilever.name, cantilever.tip_radius_nm, args.drive_name
        );
    }
    if let Some(path) = out {
        let _ = writeln!(s, "written: {}", path.display());
    }
    s
}
