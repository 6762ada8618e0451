//! `drumroll`: non-smooth dynamics of AFM cantilevers tapping a sample (Melcher, Xu, Raman,
//! APL 93, 093111 (2008)). Thin: parses arguments and hands each subcommand to its module.

use clap::{CommandFactory, Parser, Subcommand};
use std::process::ExitCode;

/// Non-smooth dynamics of AFM cantilevers tapping a sample: steady orbits, impacts, grazing
/// bifurcations (Melcher, Xu, Raman, Appl. Phys. Lett. 93, 093111 (2008)).
#[derive(Debug, Parser)]
#[command(name = "drumroll", version, about)]
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
    /// A time-domain approach (and retract) sweep at a constant rate, read by a lock-in once
    /// per drive cycle (or block of cycles); the records stream out as CSV or JSON Lines.
    Approach(drumroll::approach::ApproachArgs),
    /// The paper's approximate theory (Eqs. 3-4, lambda_1..3, the ring-down criterion) beside
    /// the same quantities measured on the simulated steady orbit at one Z or A/A0.
    Theory(drumroll::theory::TheoryArgs),
    /// The Euler-Bernoulli modal table of a cantilever with a point tip mass, and a cantilever
    /// file built from measured k_1, frequencies and quality factors.
    Cantilever(drumroll::cantilever::CantileverArgs),
    /// The built-in cases, cantilevers and samples with their key parameters; `cases show NAME`
    /// prints one file to copy and edit.
    Cases(drumroll::cases::CasesArgs),
    /// Print a shell completion script (bash, zsh, fish, elvish, powershell).
    Completions(drumroll::shell::CompletionsArgs),
    /// Print the manual page (roff), or write one per subcommand with --out-dir.
    Man(drumroll::shell::ManArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    drumroll::progress::set_quiet(cli.quiet);
    let result = match &cli.command {
        Command::Simulate(args) => drumroll::simulate::run(args),
        Command::Continue(args) => drumroll::continue_diagram::run(args),
        Command::Approach(args) => drumroll::approach::run(args),
        Command::Theory(args) => drumroll::theory::run(args),
        Command::Cantilever(args) => drumroll::cantilever::run(args),
        Command::Cases(args) => drumroll::cases::run(args),
        Command::Completions(args) => drumroll::shell::completions(args, Cli::command()),
        Command::Man(args) => drumroll::shell::man(args, Cli::command()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("drumroll: error: {error}");
            for cause in error.chain().skip(1) {
                eprintln!("  caused by: {cause}");
            }
            ExitCode::FAILURE
        }
    }
}
