//! Continue the periodic orbits of the hard impact oscillator
//! `x'' + c x' + k x = A cos(w t)`, impacts at `x = d` with restitution `e`, in the drive
//! amplitude `A`, and print the labelled special points; the last line is the grazing
//! amplitude `A_g = <value>` (first contact, G1), which has the closed form
//! `A_g = d sqrt((k - w^2)^2 + (c w)^2)`.
//!
//! `cargo run --release --example impact_oscillator -- --k 1 --c 0.1 --w 1 --d 1 --e 0.8`

mod oscillator;

use std::process::ExitCode;
use std::time::Instant;

use clap::Parser;
use oscillator::{continue_in_amplitude, first_grazing, ImpactOscillator};

/// Command-line parameters of the impact oscillator.
#[derive(Parser, Debug)]
#[command(
    about = "Continuation of the periodic orbits of a hard impact oscillator in the drive amplitude"
)]
struct Arguments {
    /// Stiffness k (> 0).
    #[arg(long, default_value_t = 1.0)]
    k: f64,
    /// Damping c (> 0).
    #[arg(long, default_value_t = 0.1)]
    c: f64,
    /// Drive frequency w (> 0).
    #[arg(long, default_value_t = 1.0)]
    w: f64,
    /// Position of the stop d (> 0).
    #[arg(long, default_value_t = 1.0)]
    d: f64,
    /// Coefficient of restitution e (0 ..= 1).
    #[arg(long, default_value_t = 0.8)]
    e: f64,
    /// Largest drive amplitude; default 2 d (k + w^2 + c w), above twice the grazing amplitude.
    #[arg(long)]
    a_max: Option<f64>,
    /// Largest number of branch points.
    #[arg(long, default_value_t = 400)]
    max_points: usize,
}

fn main() -> ExitCode {
    let args = Arguments::parse();
    let valid = args.k > 0.0
        && args.c > 0.0
        && args.w > 0.0
        && args.d > 0.0
        && (0.0..=1.0).contains(&args.e)
        && [args.k, args.c, args.w, args.d]
            .iter()
            .all(|v| v.is_finite());
    if !valid {
        eprintln!("error: need k, c, w, d > 0 (finite) and 0 <= e <= 1");
        return ExitCode::FAILURE;
    }
    let oscillator = ImpactOscillator {
        k: args.k,
        c: args.c,
        w: args.w,
        d: args.d,
        e: args.e,
        amplitude: 0.0,
    };
    let a_max = args
        .a_max
        .unwrap_or(2.0 * args.d * (args.k + args.w * args.w + args.c * args.w));
    let started = Instant::now();
    let branch = match continue_in_amplitude(&oscillator, a_max, args.max_points) {
        Ok(branch) => branch,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::FAILURE;
        }
    };
    let elapsed = started.elapsed();
    let last = branch.points.last();
    println!(
        "branch: {} points, A from {:.6} to {:.6}, stopped: {:?}{} ({:.1} ms)",
        branch.points.len(),
        branch.points.first().map_or(0.0, |p| p.parameter),
        last.map_or(0.0, |p| p.parameter),
        branch.stop,
        branch
            .error
            .as_ref()
            .map_or(String::new(), |e| format!(" ({e})")),
        elapsed.as_secs_f64() * 1e3
    );
    for point in &branch.special_points {
        println!(
            "{:<16} A = {:.12}  bracket [{:.12}, {:.12}]  precision {:.1e}  converged {}  impacts {} -> {}",
            point.label,
            point.parameter,
            point.bracket.0,
            point.bracket.1,
            point.precision,
            point.converged,
            point.impacts_before,
            point.impacts_after
        );
    }
    println!(
        "closed form d sqrt((k - w^2)^2 + (c w)^2) = {:.12}",
        oscillator.grazing_amplitude_closed_form()
    );
    match first_grazing(&branch) {
        Some(a_g) => {
            println!("A_g = {a_g:.12}");
            ExitCode::SUCCESS
        }
        None => {
            eprintln!("error: no grazing (G1) found below A = {a_max}");
            ExitCode::FAILURE
        }
    }
}
