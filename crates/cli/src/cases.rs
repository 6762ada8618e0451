//! `drumroll cases`: the built-in cases, cantilevers and samples with their descriptions and
//! key parameters (MODEL.md sections 1, 3 and 6 define them); `drumroll cases show NAME`
//! prints one fixture file as shipped, to copy and edit.

use afm::fixtures;
use anyhow::{bail, Result};
use clap::{Args, Subcommand};
use std::fmt::Write as _;

use crate::output::print_stdout;

/// Options of `drumroll cases`.
#[derive(Debug, Clone, Args)]
pub struct CasesArgs {
    /// Without a subcommand: list everything built in.
    #[command(subcommand)]
    pub command: Option<CasesCommand>,
}

/// Subcommands of `drumroll cases`.
#[derive(Debug, Clone, Subcommand)]
pub enum CasesCommand {
    /// Print the JSON file of a built-in case, cantilever, sample or scan line: save it, edit
    /// it, and pass its path to --case, --cantilever, --sample or --line.
    Show {
        /// A built-in name (`drumroll cases` lists them).
        name: String,
    },
}

/// Run `drumroll cases`.
pub fn run(args: &CasesArgs) -> Result<()> {
    match &args.command {
        None => print_stdout(&listing()?)?,
        Some(CasesCommand::Show { name }) => print_stdout(&show(name)?)?,
    }
    Ok(())
}

/// The text of the built-in fixture `name`, ending in a newline.
pub fn show(name: &str) -> Result<String> {
    let Some((_, _, text)) = fixtures::builtin_file(name) else {
        bail!(
            "cases show {name}: no built-in case, cantilever, sample or scan line of that name; \
             known: {}",
            known_names()
        );
    };
    let mut text = text.to_string();
    if !text.ends_with('\n') {
        text.push('\n');
    }
    Ok(text)
}

fn known_names() -> String {
    let mut names = fixtures::case_names();
    names.extend(fixtures::cantilever_names());
    names.extend(fixtures::sample_names());
    names.extend(fixtures::line_names());
    names.join(", ")
}

/// The listing: every built-in case (free amplitude, drive, cantilever and sample, and its
/// description), cantilever (k_1, f_1, Q_1, modes, tip radius) and sample (E, nu).
pub fn listing() -> Result<String> {
    let mut s = String::new();
    writeln!(s, "cases (--case NAME):")?;
    for name in fixtures::case_names() {
        let case = fixtures::builtin_case(name)?;
        // The drive's kind when not the default direct one (MODEL.md section 14).
        let drive = match &case.drive {
            afm::model::drive_spec::DriveSpec::Direct => String::new(),
            afm::model::drive_spec::DriveSpec::Acoustic { .. } => String::from(" (acoustic)"),
            afm::model::drive_spec::DriveSpec::Bimodal {
                second_frequency_khz,
                second_free_amplitude_nm,
            } => format!(
                " + {second_frequency_khz:.3} kHz (bimodal, A0_b = {second_free_amplitude_nm} nm)"
            ),
        };
        writeln!(
            s,
            "  {name:<30} A0 = {} nm, drive {:.3} kHz{drive}, {} on {}",
            case.free_amplitude_nm,
            case.drive_frequency_or_fundamental_khz(),
            case.cantilever.name,
            case.sample.name
        )?;
        writeln!(s, "  {:<30} {}", "", case.description)?;
    }
    writeln!(
        s,
        "\ncantilevers (--cantilever NAME, with --sample and --a0):"
    )?;
    for name in fixtures::cantilever_names() {
        let cantilever = fixtures::builtin_cantilever(name)?;
        let Some(first) = cantilever.modes.first() else {
            continue;
        };
        writeln!(
            s,
            "  {name:<30} k1 = {} N/m, f1 = {} kHz, Q1 = {}, {} modes, tip radius {} nm",
            first.stiffness_n_per_m,
            first.frequency_khz,
            first.quality_factor,
            cantilever.modes.len(),
            cantilever.tip_radius_nm
        )?;
        writeln!(s, "  {:<30} {}", "", cantilever.description)?;
    }
    writeln!(s, "\nsamples (--sample NAME):")?;
    for name in fixtures::sample_names() {
        let sample = fixtures::builtin_sample(name)?;
        writeln!(
            s,
            "  {name:<30} E = {} GPa, Poisson ratio {}",
            sample.youngs_modulus_gpa, sample.poisson_ratio
        )?;
        writeln!(s, "  {:<30} {}", "", sample.description)?;
    }
    writeln!(
        s,
        "\nscan lines (drumroll scan --line NAME; MODEL.md section 12):"
    )?;
    for name in fixtures::line_names() {
        let line = afm::scan::line::ScanLine::builtin(name)?;
        let segments: Vec<String> = line
            .segments
            .iter()
            .map(|segment| {
                format!(
                    "{} {} nm at {} nm",
                    line.materials[segment.material].name,
                    segment.to_nm - segment.from_nm,
                    segment.height_nm
                )
            })
            .collect();
        writeln!(s, "  {name:<30} {}", segments.join(", "))?;
        writeln!(s, "  {:<30} {}", "", line.description)?;
    }
    writeln!(
        s,
        "\n`drumroll cases show NAME` prints a file to copy and edit; pass the edited file's path \
         to --case, --cantilever, --sample or --line (fields and ranges: MODEL.md)."
    )?;
    Ok(s)
}
