//! `drumroll map --grid-file FILE`: a brute-force grid (`drumroll grid`'s JSON Lines: a header
//! line with the parameter axis, then one line per row, docs/output-schema.md) read as coloured
//! cells to draw under the continued curves, one cell per `(parameter, Z)` of the approach,
//! coloured by its impacts per period, grey where approach and retract disagree (bistable).

use anyhow::{bail, Context, Result};
use serde_json::Value;
use std::path::Path;

use crate::plot::Cell;

/// One cell of the grid: where it lies and what the approach found there.
#[derive(Debug, Clone, PartialEq)]
pub struct GridCell {
    /// The row's parameter value.
    pub parameter: f64,
    /// The separation, nm.
    pub z_nm: f64,
    /// `A / A0` the approach settled on.
    pub amplitude_ratio: f64,
    /// Impacts per period of that orbit.
    pub impacts_per_period: f64,
    /// Whether approach and retract settled on different orbits (`false` without a retract).
    pub bistable: bool,
}

/// A grid read from its file: the parameter's name and every row's cells.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    /// `parameter.name` of the header.
    pub parameter: String,
    /// The rows, each its cells in approach order (decreasing `Z`).
    pub rows: Vec<Vec<GridCell>>,
}

/// The number at `key` of `value`, or an error naming the file, the line and the key.
fn number_at(value: &Value, key: &str, file: &Path, line: usize) -> Result<f64> {
    let mut v = value;
    for part in key.split('.') {
        v = &v[part];
    }
    v.as_f64().with_context(|| {
        format!(
            "--grid-file {} line {line}: `{key}` is missing or not a number",
            file.display()
        )
    })
}

/// Read a grid file whose parameter must be `parameter` (the map's `--vary`).
///
/// # Errors
/// A file that cannot be read, a line that is not JSON, a missing key, no header, or a grid
/// over another parameter: each naming `--grid-file`, the file and the line.
pub fn read_grid(path: &Path, parameter: &str) -> Result<Grid> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("--grid-file {}: cannot read it", path.display()))?;
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let Some((_, header)) = lines.next() else {
        bail!("--grid-file {}: the file is empty", path.display());
    };
    let header: Value = serde_json::from_str(header)
        .with_context(|| format!("--grid-file {} line 1: not JSON", path.display()))?;
    let Some(name) = header["parameter"]["name"].as_str() else {
        bail!(
            "--grid-file {} line 1: no header (`parameter.name` missing): not a `drumroll grid` file",
            path.display()
        );
    };
    if name != parameter {
        bail!(
            "--grid-file {}: the grid varies `{name}`, the map `--vary {parameter}`",
            path.display()
        );
    }
    let mut rows = Vec::new();
    for (index, line) in lines {
        let n = index + 1;
        let row: Value = serde_json::from_str(line)
            .with_context(|| format!("--grid-file {} line {n}: not JSON", path.display()))?;
        let p = number_at(&row, "parameter_value", path, n)?;
        let Some(cells) = row["cells"].as_array() else {
            bail!("--grid-file {} line {n}: `cells` missing", path.display());
        };
        let mut read = Vec::with_capacity(cells.len());
        for cell in cells {
            read.push(GridCell {
                parameter: p,
                z_nm: number_at(cell, "z_nm", path, n)?,
                amplitude_ratio: number_at(cell, "approach.amplitude_ratio", path, n)?,
                impacts_per_period: number_at(cell, "approach.impacts_per_period", path, n)?,
                bistable: cell["bistable"].as_bool().unwrap_or(false),
            });
        }
        rows.push(read);
    }
    rows.sort_by(|a, b| {
        let pa = a.first().map_or(f64::NAN, |c| c.parameter);
        let pb = b.first().map_or(f64::NAN, |c| c.parameter);
        pa.total_cmp(&pb)
    });
    Ok(Grid {
        parameter: name.to_string(),
        rows,
    })
}

/// Midpoints between consecutive values of `values`, extended by half a spacing at both
/// ends: the edges of the cells centred on them (one value: a width of `fallback`).
fn edges(values: &[f64], fallback: f64) -> Vec<(f64, f64)> {
    let n = values.len();
    (0..n)
        .map(|i| {
            let before = if i > 0 {
                0.5 * (values[i - 1] + values[i])
            } else if n > 1 {
                values[0] - 0.5 * (values[1] - values[0])
            } else {
                values[0] - 0.5 * fallback
            };
            let after = if i + 1 < n {
                0.5 * (values[i] + values[i + 1])
            } else if n > 1 {
                values[n - 1] + 0.5 * (values[n - 1] - values[n - 2])
            } else {
                values[0] + 0.5 * fallback
            };
            (before.min(after), before.max(after))
        })
        .collect()
}

/// The grid's cells in the plane whose vertical coordinate is `y` (`Z` or `A/A0`): each cell
/// spans half the way to its neighbours in the row (vertically) and to the neighbouring rows
/// (horizontally); its colour is the impact count's, or grey (`None`) where bistable.
pub fn grid_cells(grid: &Grid, y: fn(&GridCell) -> f64) -> Vec<Cell> {
    let parameters: Vec<f64> = grid
        .rows
        .iter()
        .filter_map(|r| r.first().map(|c| c.parameter))
        .collect();
    let columns = edges(&parameters, 1.0);
    let mut cells = Vec::new();
    for (row, x) in grid.rows.iter().zip(columns) {
        let values: Vec<f64> = row.iter().map(y).collect();
        for (cell, span) in row.iter().zip(edges(&values, 1e-3)) {
            cells.push(Cell {
                x,
                y: span,
                colour: (!cell.bistable).then(|| cell.impacts_per_period.round().max(0.0) as usize),
            });
        }
    }
    cells
}
