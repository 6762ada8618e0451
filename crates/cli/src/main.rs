//! `drumroll`: non-smooth dynamics of AFM cantilevers tapping a sample (Melcher, Xu, Raman,
//! APL 93, 093111 (2008)). Thin: parses arguments and hands each subcommand to its module.

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};
use std::process::ExitCode;

/// Non-smooth dynamics of AFM cantilevers tapping a sample: steady orbits, impacts, grazing
/// bifurcations (Melcher, Xu, Raman, Appl. Phys. Lett. 93, 093111 (2008)).
#[derive(Debug, Parser)]
#[command(
    name = "drumroll",
    version,
    about,
    after_help = "Exit status: 0 success; 1 error (bad input or a failed computation); 2 the \
                  command line does not parse; 3 the run stopped before its requested end (the \
                  output computed so far is written, and stderr says why)."
)]
struct Cli {
    /// No progress bars and no notes on standard error (bars are drawn only on a terminal,
    /// and only for runs longer than about 2 s).
    #[arg(long, short, global = true)]
    quiet: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// The steady periodic orbit at one separation Z (or one amplitude ratio A/A0).
    Simulate(drumroll::simulate::SimulateArgs),
    /// The bifurcation diagram in Z: periodic orbits continued from above first contact down
    /// to a floor, grazing points G1, G2, G3, ..., folds and period doubling located.
    Continue(drumroll::continue_diagram::ContinueArgs),
    /// The impact-regime map over a second parameter (a0, drive-frequency, sample-modulus,
    /// tip-radius, quality-factor-N, stiffness-N): the G_n, fold and period-doubling points of
    /// the approach continued over a range, in the (PARAM, Z) and (PARAM, A/A0) planes.
    Map(drumroll::map::MapArgs),
    /// A time-domain approach (and retract) sweep at a constant rate, read by a lock-in once
    /// per drive cycle (or block of cycles); the records stream out as CSV or JSON Lines.
    Approach(drumroll::approach::ApproachArgs),
    /// A tapping-mode scan line with amplitude feedback over a heterogeneous sample (a line
    /// file of segments): ideal feedback along the orbit branches, or a time-domain PI loop;
    /// per pixel the measured height, phase, impacts, forces and dissipation.
    Scan(drumroll::scan::ScanArgs),
    /// The paper's approximate theory (Eqs. 3-4, lambda_1..3, the ring-down criterion) beside
    /// the same quantities measured on the simulated steady orbit at one Z or A/A0.
    Theory(drumroll::theory::TheoryArgs),
    /// The brute-force regime map: for each value of a parameter (a row), a quasi-static
    /// approach (and retract) in Z by transients, each cell's impacts per period, period, A/A0
    /// and phase; shardable (`--shard I/N`, then `grid merge`) and resumable.
    Grid(drumroll::grid::GridArgs),
    /// The Euler-Bernoulli modal table of a cantilever with a point tip mass, and a cantilever
    /// file built from measured k_1, frequencies and quality factors.
    Cantilever(drumroll::cantilever::CantileverArgs),
    /// The transitions of a measured approach curve: kinks (a grazing G_n) and jumps, each
    /// with its Z, 1-sigma uncertainty, A/A0, phase and significance (MODEL.md section 13).
    Detect(drumroll::detect::DetectArgs),
    /// Fit the model's approach branch to a measured curve: piezo offset, amplitude
    /// calibration, phase offset, sample modulus, ... with standard errors (MODEL.md section 13).
    Fit(drumroll::fit::FitArgs),
    /// The built-in cases, cantilevers and samples with their key parameters; `cases show NAME`
    /// prints one file to copy and edit.
    Cases(drumroll::cases::CasesArgs),
    /// Print a shell completion script (bash, zsh, fish, elvish, powershell).
    Completions(drumroll::shell::CompletionsArgs),
    /// Print the manual page (roff), or write one per subcommand with --out-dir.
    Man(drumroll::shell::ManArgs),
}

/// The command line parsed as `Cli::parse` does (a bad option prints clap's error and exits
/// with status 2), except that clap's command tree, every subcommand's options with their help,
/// is not freed: the process ends soon after, and freeing it cost about 0.12 M instructions
/// (a tenth of `drumroll --version`, which, like `--help` and a bad option, now exits inside
/// clap without freeing it either).
fn parse_command_line() -> Cli {
    let mut command = Cli::command();
    let mut matches = command.get_matches_mut();
    let cli = Cli::from_arg_matches_mut(&mut matches)
        .unwrap_or_else(|error| error.format(&mut command).exit());
    std::mem::forget(command);
    cli
}

fn main() -> ExitCode {
    let cli = parse_command_line();
    drumroll::progress::set_quiet(cli.quiet);
    let result = match &cli.command {
        Command::Simulate(args) => drumroll::simulate::run(args),
        Command::Continue(args) => drumroll::continue_diagram::run(args),
        Command::Map(args) => drumroll::map::run(args),
        Command::Approach(args) => drumroll::approach::run(args),
        Command::Scan(args) => drumroll::scan::run(args),
        Command::Theory(args) => drumroll::theory::run(args),
        Command::Grid(args) => drumroll::grid::run(args),
        Command::Cantilever(args) => drumroll::cantilever::run(args),
        Command::Cases(args) => drumroll::cases::run(args),
        Command::Detect(args) => drumroll::detect::run(args),
        Command::Fit(args) => drumroll::fit::run(args),
        Command::Completions(args) => drumroll::shell::completions(args, Cli::command()),
        Command::Man(args) => drumroll::shell::man(args, Cli::command()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            if let Some(incomplete) = error.downcast_ref::<drumroll::exit_status::Incomplete>() {
                drumroll::output::print_stderr(&format!("drumroll: {incomplete}"));
                return ExitCode::from(drumroll::exit_status::INCOMPLETE);
            }
            drumroll::output::print_stderr(&format!("drumroll: error: {error}"));
            for cause in distinct_causes(&error) {
                drumroll::output::print_stderr(&format!("  caused by: {cause}"));
            }
            ExitCode::FAILURE
        }
    }
}

/// The causes of `error` below its top message, each once: a cause whose text the message
/// above it already contains (an error that prints its source, e.g. `solver failure: ...`)
/// is skipped.
fn distinct_causes(error: &anyhow::Error) -> Vec<String> {
    let mut above = error.to_string();
    let mut causes = Vec::new();
    for cause in error.chain().skip(1) {
        let text = cause.to_string();
        if !above.contains(&text) {
            causes.push(text.clone());
        }
        above = text;
    }
    causes
}
