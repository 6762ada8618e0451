//! `drumroll grid`: the brute-force regime map. For each value `p` of a parameter (a row), a
//! quasi-static approach in `Z` (and with `--retract`, the retract back) by time-domain
//! transients, each cell started from its neighbour's orbit ([`afm::quasi_static_row`]):
//! impacts per period, the orbit's period, `A / A0`, phase and, with `--retract`, whether
//! approach and retract settle on different orbits (bistable). Rows run in parallel (rayon);
//! `--shard I/N` computes every `N`-th row into a resumable part file, and `drumroll grid
//! merge` assembles the parts into the file one run would have written
//! ([`crate::grid_file`]).

use afm::{
    quasi_static_row, Case, ParameterAxis, QuasiStaticCell, SteadyOrbitSettings, TappingModel,
};
use anyhow::{bail, Context, Result};
use clap::{Args, Subcommand};
use rayon::prelude::*;
use serde::Serialize;
use serde_json::json;
use std::path::{Path, PathBuf};

use crate::grid_file::{assemble, assemble_locked, PartWriter};
use crate::grid_row::seal;
use crate::inputs::orbit_inputs_json;
use crate::model_args::{output_path, ModelArgs};
use crate::output::print_stdout;
use crate::progress::note;

/// The most rows, and the most separations per row, a grid may have.
pub const MAX_STEPS: usize = 100_000;
/// The most cells (rows times separations) a grid may have: at about 200 bytes a cell (300
/// with `--retract`), a map file of 2 to 3 GB.
pub const MAX_CELLS: usize = 10_000_000;
/// The largest separation of a grid, nm (the sweep's bound, `afm::sweep::MAX_SEPARATION_NM`).
const MAX_SEPARATION_NM: f64 = afm::sweep::MAX_SEPARATION_NM;

/// Options of `drumroll grid` (or its `merge` subcommand).
#[derive(Debug, Clone, Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct GridArgs {
    /// `merge PARTS... --output FILE`: assemble shards' part files into the map file.
    #[command(subcommand)]
    pub merge: Option<GridSubcommand>,
    /// The grid to compute.
    #[command(flatten)]
    pub run: GridRunArgs,
}

/// The subcommand of `drumroll grid`.
#[derive(Debug, Clone, Subcommand)]
pub enum GridSubcommand {
    /// Assemble the part files of `--shard` runs into the file a single run would have
    /// written, byte for byte; refuses parts of different grids and names missing rows.
    Merge(MergeArgs),
}

/// Options of `drumroll grid merge`.
#[derive(Debug, Clone, Args)]
pub struct MergeArgs {
    /// The part files (`--output` of each `--shard` run), in any order.
    #[arg(required = true, value_name = "PARTS")]
    pub parts: Vec<PathBuf>,
    /// The map file to write (JSON Lines, `.jsonl`).
    #[arg(long, value_name = "FILE.jsonl")]
    pub output: PathBuf,
}

/// Options of a grid computation.
#[derive(Debug, Clone, Args)]
pub struct GridRunArgs {
    /// The cantilever, sample and drive (the parameter's other values).
    #[command(flatten)]
    pub model: ModelArgs,
    /// The parameter along the rows: a0 (nm), drive-frequency (kHz), sample-modulus (GPa),
    /// tip-radius (nm), quality-factor-N, stiffness-N (N/m) of mode N.
    #[arg(long, required = true, value_name = "PARAM")]
    pub vary: Option<String>,
    /// The parameter's value in the first row, in its unit.
    #[arg(long, required = true, allow_negative_numbers = true)]
    pub from: Option<f64>,
    /// The parameter's value in the last row, in its unit.
    #[arg(long, required = true, allow_negative_numbers = true)]
    pub to: Option<f64>,
    /// The number of rows (parameter values, evenly spaced from --from to --to), 1..=100000;
    /// one row needs --from = --to.
    #[arg(long, required = true)]
    pub steps: Option<usize>,
    /// The highest separation, where each row's approach starts from the free orbit, nm
    /// (above every row's first contact Z_G1 for an approach from free oscillation).
    #[arg(long, required = true, allow_negative_numbers = true)]
    pub z_from: Option<f64>,
    /// The lowest separation, where the approach ends, nm (at least -A0 of every row).
    #[arg(long, required = true, allow_negative_numbers = true)]
    pub z_to: Option<f64>,
    /// The number of separations per row (evenly spaced from --z-from down to --z-to),
    /// 2..=100000.
    #[arg(long, required = true)]
    pub z_steps: Option<usize>,
    /// After each row's approach, retract back up over the same separations and mark the
    /// cells where the two settle on different orbits (bistable).
    #[arg(long)]
    pub retract: bool,
    /// The map file (JSON Lines, `.jsonl`); with --shard, this shard's part file.
    #[arg(long, required = true, value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Worker threads (default: one per core). The output does not depend on it.
    #[arg(long)]
    pub threads: Option<usize>,
    /// `I/N`: compute rows I, I+N, I+2N, ... (I from 0) into the --output part file, resuming
    /// from the rows it already holds; `drumroll grid merge` assembles the parts.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<String>,
}

/// One shard of the rows: every `count`-th row from `index`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// The shard's index `I`, from 0.
    pub index: usize,
    /// The number of shards `N`.
    pub count: usize,
}

impl std::str::FromStr for Shard {
    type Err = anyhow::Error;

    /// Parse `I/N` with `0 <= I < N`.
    fn from_str(text: &str) -> Result<Self> {
        let parsed = text
            .split_once('/')
            .and_then(|(i, n)| Some((i.trim().parse().ok()?, n.trim().parse().ok()?)));
        match parsed {
            Some((index, count)) if index < count => Ok(Self { index, count }),
            Some(_) => bail!(
                "--shard {text}: the shard index I must be below the shard count N (I from 0 \
                 to N - 1)"
            ),
            None => bail!("--shard {text}: expected I/N, two integers with 0 <= I < N"),
        }
    }
}

/// A grid's resolved inputs.
struct Grid {
    case: Case,
    axis: ParameterAxis,
    parameters: Vec<f64>,
    separations: Vec<f64>,
    retract: bool,
    settings: SteadyOrbitSettings,
}

/// One row's line in the files.
#[derive(Serialize)]
struct RowRecord<'a> {
    row: usize,
    parameter_value: f64,
    first_contact_z_nm: f64,
    cells: Vec<CellRecord<'a>>,
}

/// One cell of a row's line.
#[derive(Serialize)]
struct CellRecord<'a> {
    z_nm: f64,
    approach: &'a QuasiStaticCell,
    #[serde(skip_serializing_if = "Option::is_none")]
    retract: Option<&'a QuasiStaticCell>,
    #[serde(skip_serializing_if = "Option::is_none")]
    bistable: Option<bool>,
}

/// Run `drumroll grid` or `drumroll grid merge`.
pub fn run(args: &GridArgs) -> Result<()> {
    match &args.merge {
        Some(GridSubcommand::Merge(merge)) => {
            let output = output_path(&merge.output, "jsonl", "--output")?;
            assemble(&merge.parts, &output)?;
            print_stdout(&format!(
                "merged {} part files into {}\n",
                merge.parts.len(),
                output.display()
            ))?;
            Ok(())
        }
        None => compute(&args.run),
    }
}

/// `n` evenly spaced values from `from` to `to`, both ends exact.
fn evenly_spaced(from: f64, to: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| match i {
            0 => from,
            _ if i == n - 1 => to,
            _ => from + (to - from) * (i as f64 / (n - 1) as f64),
        })
        .collect()
}

/// Resolve and check the options (every row's model is built once here, so that a value out
/// of range stops the run before it computes anything).
fn resolve(args: &GridRunArgs) -> Result<Grid> {
    // clap enforces the required options; these only unwrap them.
    let (Some(vary), Some(from), Some(to), Some(steps), Some(z_from), Some(z_to), Some(z_steps)) = (
        &args.vary,
        args.from,
        args.to,
        args.steps,
        args.z_from,
        args.z_to,
        args.z_steps,
    ) else {
        bail!("give --vary, --from, --to, --steps, --z-from, --z-to and --z-steps");
    };
    let axis: ParameterAxis = vary.parse().with_context(|| format!("--vary {vary}"))?;
    let case = args.model.case()?;
    axis.check("--from", from)?;
    axis.check("--to", to)?;
    if !(1..=MAX_STEPS).contains(&steps) {
        bail!("--steps {steps}: allowed 1..={MAX_STEPS}");
    }
    if steps == 1 && from != to {
        bail!("--steps 1: one row needs --from = --to (here {from} and {to})");
    }
    if !(2..=MAX_STEPS).contains(&z_steps) {
        bail!("--z-steps {z_steps}: allowed 2..={MAX_STEPS}");
    }
    if steps.saturating_mul(z_steps) > MAX_CELLS {
        bail!(
            "--steps {steps} x --z-steps {z_steps} = {} cells: allowed at most {MAX_CELLS} cells \
             per grid (split it into several grids over parts of the --from/--to range)",
            steps.saturating_mul(z_steps)
        );
    }
    if !(z_from.is_finite() && z_from <= MAX_SEPARATION_NM) {
        bail!("--z-from {z_from}: allowed up to {MAX_SEPARATION_NM} nm");
    }
    if !(z_to.is_finite() && z_to < z_from) {
        bail!("--z-to {z_to}: must lie below --z-from {z_from} (the approach goes down)");
    }
    if args.threads == Some(0) {
        bail!("--threads 0: allowed 1 or more");
    }
    axis.value(&case)
        .with_context(|| format!("--vary {vary}"))?;
    let parameters = evenly_spaced(from, to, steps);
    for (row, &p) in parameters.iter().enumerate() {
        let option = match row {
            0 => "--from",
            _ if row == steps - 1 => "--to",
            _ => "--from/--to",
        };
        let model = axis.model(&case, p, option).with_context(|| {
            format!(
                "{option}: no valid model at {axis} = {p} {} (row {row})",
                axis.unit()
            )
        })?;
        let lowest = -model.free_amplitude_nm();
        if z_to < lowest {
            bail!(
                "--z-to {z_to}: below -A0 = {lowest} nm of row {row} ({axis} = {p}), the lowest \
                 separation a steady orbit is computed at"
            );
        }
    }
    Ok(Grid {
        case,
        axis,
        parameters,
        separations: evenly_spaced(z_from, z_to, z_steps),
        retract: args.retract,
        settings: SteadyOrbitSettings::default(),
    })
}

/// The header line (newline included): the inputs and the grid's axes.
fn header_line(args: &GridRunArgs, grid: &Grid) -> Result<String> {
    let model = TappingModel::from_case(&grid.case)
        .with_context(|| format!("cannot build the model of case `{}`", grid.case.name))?;
    let options = json!({
        "vary": grid.axis.name(),
        "from": args.from,
        "to": args.to,
        "steps": grid.parameters.len(),
        "z_from_nm": args.z_from,
        "z_to_nm": args.z_to,
        "z_steps": grid.separations.len(),
        "retract": grid.retract,
    });
    let header = json!({
        "inputs": orbit_inputs_json("grid", options, &grid.case, &model, &grid.settings),
        "case": grid.case.name,
        "parameter": {
            "name": grid.axis.name(),
            "unit": grid.axis.unit(),
            "from": args.from,
            "to": args.to,
            "values": grid.parameters,
        },
        "z_nm": grid.separations,
    });
    Ok(serde_json::to_string(&header)? + "\n")
}

/// One row's line (newline included).
fn row_line(grid: &Grid, row: usize) -> Result<String> {
    let p = grid.parameters[row];
    let source = format!("--vary {} = {p} (row {row})", grid.axis);
    let model = grid.axis.model(&grid.case, p, &source)?;
    let computed = quasi_static_row(&model, &grid.separations, grid.retract, &grid.settings)
        .with_context(|| format!("row {row} ({} = {p}) failed", grid.axis))?;
    let cells = (0..computed.z_nm.len())
        .map(|j| CellRecord {
            z_nm: computed.z_nm[j],
            approach: &computed.approach[j],
            retract: computed.retract.as_ref().map(|cells| &cells[j]),
            bistable: computed.bistable(j),
        })
        .collect();
    let record = RowRecord {
        row,
        parameter_value: p,
        first_contact_z_nm: model.grazing_separation_nm(),
        cells,
    };
    Ok(seal(&serde_json::to_string(&record)?))
}

/// Compute the rows of `shard` that `part` does not hold yet into it, on `threads` threads;
/// a resumed part says how many rows it already held. Returns the part's writer, still
/// holding the part's lock.
fn fill_part(
    grid: &Grid,
    header: &str,
    part: &Path,
    shard: Shard,
    threads: Option<usize>,
) -> Result<PartWriter> {
    let (writer, done) = PartWriter::open(part, header, "--output")?;
    let all: Vec<usize> = (shard.index..grid.parameters.len())
        .step_by(shard.count)
        .collect();
    let rows: Vec<usize> = all
        .iter()
        .copied()
        .filter(|row| !done.contains(row))
        .collect();
    if !done.is_empty() {
        note(&format!(
            "resuming: {} of {} rows already in {}, {} left to compute",
            all.len() - rows.len(),
            all.len(),
            part.display(),
            rows.len()
        ));
    }
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(threads) = threads {
        pool = pool.num_threads(threads);
    }
    let pool = pool.build().context("cannot start the worker threads")?;
    pool.install(|| {
        rows.par_iter()
            .try_for_each(|&row| writer.append(&row_line(grid, row)?))
    })?;
    Ok(writer)
}

/// `drumroll grid` without `merge`.
fn compute(args: &GridRunArgs) -> Result<()> {
    let shard = args.shard.as_deref().map(str::parse::<Shard>).transpose()?;
    let grid = resolve(args)?;
    let header = header_line(args, &grid)?;
    let Some(output) = &args.output else {
        bail!("give --output FILE");
    };
    match shard {
        Some(shard) => {
            drop(fill_part(&grid, &header, output, shard, args.threads)?);
            print_stdout(&format!(
                "shard {}/{}: rows {}, {}, ... of {} in {}\n",
                shard.index,
                shard.count,
                shard.index,
                shard.index + shard.count,
                grid.parameters.len(),
                output.display()
            ))?;
        }
        None => {
            let output = output_path(output, "jsonl", "--output")?;
            let mut part_name = output.as_os_str().to_os_string();
            part_name.push(".part");
            let part = PathBuf::from(part_name);
            let whole = Shard { index: 0, count: 1 };
            let writer = fill_part(&grid, &header, &part, whole, args.threads)?;
            assemble_locked(std::slice::from_ref(&part), &output)?;
            std::fs::remove_file(&part)
                .with_context(|| format!("cannot remove {}", part.display()))?;
            drop(writer);
            print_stdout(&format!(
                "{} rows x {} separations written to {}\n",
                grid.parameters.len(),
                grid.separations.len(),
                output.display()
            ))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_parse_and_out_of_range_indices_are_refused() {
        assert_eq!(
            "1/4".parse::<Shard>().unwrap(),
            Shard { index: 1, count: 4 }
        );
        let message = "3/2".parse::<Shard>().unwrap_err().to_string();
        assert!(message.contains("--shard 3/2") && message.contains("below the shard count"));
        assert!("x".parse::<Shard>().is_err() && "0/0".parse::<Shard>().is_err());
    }

    #[test]
    fn evenly_spaced_values_hit_both_ends_exactly() {
        let values = evenly_spaced(0.1, 0.7, 7);
        assert_eq!(values[0], 0.1);
        assert_eq!(values[6], 0.7);
        assert!((values[3] - 0.4).abs() < 1e-15);
    }
}
