//! A measured approach curve (MODEL.md section 13.1): the rows of a CSV or TSV file with a
//! header (piezo position `Z`, amplitude, phase), converted to nm and degrees, split by the
//! direction of `Z` into an approach and a retract, with the free amplitude `A0` taken from the
//! rows far from the sample. Bad rows (unparsable, NaN, negative amplitude, duplicate or
//! out-of-order `Z`) are kept in [`Measurement::bad_rows`] with their line numbers.

use serde::Serialize;

use crate::error::AfmError;
use crate::fixtures::read_text;

/// Fewest valid rows a measurement must have.
pub const MIN_ROWS: usize = 50;

/// Most rows (data lines after the header) a measurement may have: the transition test and
/// the fit take about 0.5 ms a row on one core (`drumroll detect` on 60 000 rows: 26 s), so a
/// longer curve is refused with this limit rather than left to run for minutes; thin it first
/// (every other row, or the approach alone).
pub const MAX_ROWS: usize = 50_000;

/// Fewest rows the free part (far from the sample) must have for `A0` to be read from it.
pub const MIN_FREE_ROWS: usize = 10;

/// The unit of a length column: `nm`, `um`, `m`, or `V` (an amplitude in photodiode volts,
/// converted with the inverse optical lever sensitivity InvOLS, nm/V).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LengthUnit {
    /// Nanometres.
    Nanometre,
    /// Micrometres.
    Micrometre,
    /// Metres.
    Metre,
    /// Photodiode volts with InvOLS in nm/V (amplitude only).
    Volt(f64),
}

impl LengthUnit {
    /// Parse `nm`, `um`, `m` or `V`; `V` needs `invols_nm_per_v` (> 0, finite), which is an
    /// error with any other unit. `option` names the command-line option in errors.
    ///
    /// # Errors
    /// [`AfmError::InvalidField`] naming `option` and the allowed units.
    pub fn parse(text: &str, invols_nm_per_v: Option<f64>, option: &str) -> Result<Self, AfmError> {
        let invalid = |value: String, allowed: &str| AfmError::InvalidField {
            file: String::from("command line"),
            field: option.to_string(),
            value,
            allowed: allowed.to_string(),
        };
        let unit = match text {
            "nm" => Self::Nanometre,
            "um" | "µm" => Self::Micrometre,
            "m" => Self::Metre,
            "V" | "v" => match invols_nm_per_v {
                Some(invols) if invols.is_finite() && invols > 0.0 && invols <= 1e6 => {
                    Self::Volt(invols)
                }
                Some(invols) => {
                    return Err(invalid(
                        format!("V with --invols {invols}"),
                        "--invols in (0, 1e6] nm/V",
                    ))
                }
                None => {
                    return Err(invalid(
                        String::from("V"),
                        "V only with --invols NM_PER_V (the inverse optical lever sensitivity)",
                    ))
                }
            },
            _ => {
                return Err(invalid(
                    format!("{text:?}"),
                    "one of nm, um, m, V (with --invols)",
                ))
            }
        };
        if invols_nm_per_v.is_some() && !matches!(unit, Self::Volt(_)) {
            return Err(invalid(
                format!("{text} with --invols"),
                "--invols only with the unit V",
            ));
        }
        Ok(unit)
    }

    /// Nanometres per unit.
    pub fn nm_per_unit(self) -> f64 {
        match self {
            Self::Nanometre => 1.0,
            Self::Micrometre => 1e3,
            Self::Metre => 1e9,
            Self::Volt(invols) => invols,
        }
    }
}

/// How a measurement file is read: the column names, the units, and `A0` if given.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasurementOptions {
    /// Header name of the piezo position column (default `z_nm`).
    pub z_column: String,
    /// Header name of the amplitude column (default `amplitude_nm`).
    pub amplitude_column: String,
    /// Header name of the phase column (default `phase_deg`).
    pub phase_column: String,
    /// Unit of `Z` (not `V`).
    pub z_unit: LengthUnit,
    /// Unit of the amplitude.
    pub amplitude_unit: LengthUnit,
    /// Whether the phase column is in radians (default degrees).
    pub phase_in_radians: bool,
    /// The free amplitude in the amplitude column's unit converted to nm, if given (else read
    /// from the free rows).
    pub a0_nm: Option<f64>,
}

impl Default for MeasurementOptions {
    fn default() -> Self {
        Self {
            z_column: String::from("z_nm"),
            amplitude_column: String::from("amplitude_nm"),
            phase_column: String::from("phase_deg"),
            z_unit: LengthUnit::Nanometre,
            amplitude_unit: LengthUnit::Nanometre,
            phase_in_radians: false,
            a0_nm: None,
        }
    }
}

impl MeasurementOptions {
    /// Set the column names from `z=NAME,amplitude=NAME,phase=NAME` (any subset).
    ///
    /// # Errors
    /// [`AfmError::InvalidField`] naming `--columns` for an unknown key or a missing `=`.
    pub fn set_columns(&mut self, spec: &str) -> Result<(), AfmError> {
        for item in spec.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let bad = || AfmError::InvalidField {
                file: String::from("command line"),
                field: String::from("--columns"),
                value: format!("{item:?}"),
                allowed: String::from("z=NAME,amplitude=NAME,phase=NAME (any of the three)"),
            };
            let (key, name) = item.split_once('=').ok_or_else(bad)?;
            let name = name.trim().to_string();
            if name.is_empty() {
                return Err(bad());
            }
            match key.trim() {
                "z" => self.z_column = name,
                "amplitude" => self.amplitude_column = name,
                "phase" => self.phase_column = name,
                _ => return Err(bad()),
            }
        }
        Ok(())
    }
}

/// One valid row of a measurement, in nm and degrees.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MeasuredPoint {
    /// The row's line number in the file (from 1).
    pub line: usize,
    /// Piezo position in data coordinates, nm (drumroll's `Z` is `z_nm - z_offset`).
    pub z_nm: f64,
    /// Measured amplitude, nm.
    pub amplitude_nm: f64,
    /// Measured phase, degrees (with the instrument's offset).
    pub phase_deg: f64,
}

/// A row left out of the curve, with why.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BadRow {
    /// Line number in the file (from 1).
    pub line: usize,
    /// The column at fault, if one.
    pub column: Option<String>,
    /// Why, in words.
    pub reason: String,
}

/// How `A0` was obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum FreeAmplitudeSource {
    /// The mean amplitude of the free rows.
    FreeRows,
    /// Given by the user (`--a0`).
    Given,
}

/// A measured curve: approach and (if the file has one) retract, `A0`, and the rows left out.
#[derive(Debug, Clone, Serialize)]
pub struct Measurement {
    /// The file it was read from.
    pub source: String,
    /// The approach (`Z` decreasing), sorted by decreasing `Z`.
    pub approach: Vec<MeasuredPoint>,
    /// The retract (`Z` increasing), sorted by increasing `Z`; empty if the file has none.
    pub retract: Vec<MeasuredPoint>,
    /// The free amplitude, nm.
    pub a0_nm: f64,
    /// Its standard error, nm (0 when given).
    pub a0_stderr_nm: f64,
    /// Where `A0` came from.
    pub a0_source: FreeAmplitudeSource,
    /// Approach rows counted as free (amplitude within noise of `A0`, at the top of `Z`).
    pub free_rows: usize,
    /// Rows left out, with their line numbers and reasons.
    pub bad_rows: Vec<BadRow>,
    /// Whether the file's rows were in no sweep order (then sorted as one approach).
    pub unordered: bool,
}

impl Measurement {
    /// Read `path` (CSV, TSV or `;`-separated, with a header; lines starting with `#` are
    /// comments).
    ///
    /// # Errors
    /// [`AfmError::Io`] if unreadable, else as [`Measurement::parse`].
    pub fn from_file(path: &str, options: &MeasurementOptions) -> Result<Self, AfmError> {
        let text = read_text(std::path::Path::new(path))?;
        Self::parse(&text, path, options)
    }

    /// Parse the text of a measurement file; `source` names it in errors.
    ///
    /// # Errors
    /// [`AfmError::InvalidField`] naming the file, line and column: no header, a missing
    /// column, fewer than [`MIN_ROWS`] valid rows, more than [`MAX_ROWS`] rows, amplitudes that the unit makes implausible
    /// (`A0` outside `[0.01, 10000]` nm), no free part.
    pub fn parse(text: &str, source: &str, options: &MeasurementOptions) -> Result<Self, AfmError> {
        let error =
            |line: usize, field: &str, value: String, allowed: String| AfmError::InvalidField {
                file: if line > 0 {
                    format!("{source} line {line}")
                } else {
                    source.to_string()
                },
                field: field.to_string(),
                value,
                allowed,
            };
        if matches!(options.z_unit, LengthUnit::Volt(_)) {
            return Err(error(
                0,
                "--z-unit",
                String::from("V"),
                String::from(
                    "nm, um or m (convert a piezo voltage with the scanner's sensitivity first)",
                ),
            ));
        }
        // A UTF-8 byte-order mark (written by some Windows programs) is not part of the
        // header's first name.
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(i, l)| (i + 1, l.trim_end_matches('\r')))
            .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
        let (header_line, header) = lines.next().ok_or_else(|| {
            error(
                0,
                "header",
                String::from("none"),
                String::from("a header line naming the columns, then one row per point"),
            )
        })?;
        let separator = if header.contains('\t') {
            '\t'
        } else if header.contains(';') {
            ';'
        } else {
            ','
        };
        let names: Vec<String> = header
            .split(separator)
            .map(|s| s.trim().trim_matches('"').to_string())
            .collect();
        let index_of = |name: &str| {
            names.iter().position(|n| n == name).ok_or_else(|| {
                error(
                    header_line,
                    name,
                    String::from("missing"),
                    format!(
                        "a column named `{name}` in the header (columns: {}); name others with --columns z=NAME,amplitude=NAME,phase=NAME",
                        names.join(", ")
                    ),
                )
            })
        };
        let columns = [
            index_of(&options.z_column)?,
            index_of(&options.amplitude_column)?,
            index_of(&options.phase_column)?,
        ];
        let column_names = [
            &options.z_column,
            &options.amplitude_column,
            &options.phase_column,
        ];
        let scale = [
            options.z_unit.nm_per_unit(),
            options.amplitude_unit.nm_per_unit(),
            if options.phase_in_radians {
                180.0 / std::f64::consts::PI
            } else {
                1.0
            },
        ];
        let data_lines = lines.clone().count();
        if data_lines > MAX_ROWS {
            return Err(error(
                0,
                "rows",
                data_lines.to_string(),
                format!(
                    "at most {MAX_ROWS} rows (detect and fit take about 0.5 ms a row): thin the \
                     curve, e.g. keep every other row or the approach only"
                ),
            ));
        }
        let mut rows: Vec<MeasuredPoint> = Vec::new();
        let mut bad_rows: Vec<BadRow> = Vec::new();
        for (line, text) in lines {
            let fields: Vec<&str> = text
                .split(separator)
                .map(|s| s.trim().trim_matches('"'))
                .collect();
            let mut values = [0.0; 3];
            let mut fault: Option<BadRow> = None;
            for k in 0..3 {
                let Some(field) = fields.get(columns[k]) else {
                    fault = Some(BadRow {
                        line,
                        column: Some(column_names[k].clone()),
                        reason: format!(
                            "the row has {} fields, the header {}",
                            fields.len(),
                            names.len()
                        ),
                    });
                    break;
                };
                match field.parse::<f64>() {
                    Ok(v) if v.is_finite() => values[k] = v * scale[k],
                    _ => {
                        fault = Some(BadRow {
                            line,
                            column: Some(column_names[k].clone()),
                            reason: format!("{field:?} is not a finite number"),
                        });
                        break;
                    }
                }
            }
            if fault.is_none() && values[1] < 0.0 {
                fault = Some(BadRow {
                    line,
                    column: Some(column_names[1].clone()),
                    reason: String::from("negative amplitude"),
                });
            }
            match fault {
                Some(bad) => bad_rows.push(bad),
                None => rows.push(MeasuredPoint {
                    line,
                    z_nm: values[0],
                    amplitude_nm: values[1],
                    phase_deg: values[2],
                }),
            }
        }
        let (approach, retract, unordered) =
            split_sweeps(rows, &mut bad_rows, &column_names[0].clone());
        if approach.len() < MIN_ROWS {
            return Err(error(
                0,
                "rows",
                format!(
                    "{} valid approach rows ({} bad rows)",
                    approach.len(),
                    bad_rows.len()
                ),
                format!("at least {MIN_ROWS} valid rows on the approach"),
            ));
        }
        let (a0_nm, a0_stderr_nm, a0_source, free_rows) = match options.a0_nm {
            Some(a0) => {
                if !(a0.is_finite() && a0 > 0.0) {
                    return Err(error(0, "--a0", a0.to_string(), String::from("> 0, nm")));
                }
                (
                    a0,
                    0.0,
                    FreeAmplitudeSource::Given,
                    count_free_rows(&approach, a0),
                )
            }
            None => {
                let (a0, stderr, count) = free_amplitude(&approach).ok_or_else(|| {
                    error(
                        0,
                        &options.amplitude_column,
                        String::from("no free part"),
                        format!(
                            "at least {MIN_FREE_ROWS} rows at the largest Z with a constant amplitude (the free oscillation, far from the sample), or --a0"
                        ),
                    )
                })?;
                (a0, stderr, FreeAmplitudeSource::FreeRows, count)
            }
        };
        if !(0.01..=1e4).contains(&a0_nm) {
            return Err(error(
                0,
                &options.amplitude_column,
                format!("A0 = {a0_nm:e} nm"),
                String::from(
                    "A0 in [0.01, 10000] nm: check --amplitude-unit (nm, um, m, V with --invols)",
                ),
            ));
        }
        Ok(Self {
            source: source.to_string(),
            approach,
            retract,
            a0_nm,
            a0_stderr_nm,
            a0_source,
            free_rows,
            bad_rows,
            unordered,
        })
    }
}

/// Split valid rows into approach and retract by the direction of `Z` in file order. A file
/// whose consecutive rows reverse direction more than at one turning point and at scattered
/// glitches (over 10% of steps) is unordered: sorted as one approach. Otherwise the file is
/// split at the extreme `Z` (a decreasing run is the approach, an increasing one the retract);
/// inside a run, a row whose `Z` does not continue the run's direction (a repeated `Z` or a
/// step back) is a bad row. A single increasing run is taken as the approach read bottom-up.
fn split_sweeps(
    rows: Vec<MeasuredPoint>,
    bad_rows: &mut Vec<BadRow>,
    z_column: &str,
) -> (Vec<MeasuredPoint>, Vec<MeasuredPoint>, bool) {
    if rows.len() < 3 {
        return (rows, Vec::new(), false);
    }
    let steps: Vec<f64> = rows.windows(2).map(|w| w[1].z_nm - w[0].z_nm).collect();
    let signs: Vec<i8> = steps
        .iter()
        .map(|s| {
            if *s > 0.0 {
                1
            } else if *s < 0.0 {
                -1
            } else {
                0
            }
        })
        .collect();
    let changes = signs
        .windows(2)
        .filter(|w| w[0] != w[1] && w[0] != 0 && w[1] != 0)
        .count();
    if changes as f64 > 0.1 * steps.len() as f64 {
        let mut sorted = rows;
        sorted.sort_by(|a, b| b.z_nm.total_cmp(&a.z_nm));
        let approach = keep_strict(sorted, -1.0, bad_rows, z_column);
        return (approach, Vec::new(), true);
    }
    let (min_index, _) = rows
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.z_nm.total_cmp(&b.1.z_nm))
        .expect("non-empty");
    let (max_index, _) = rows
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.z_nm.total_cmp(&b.1.z_nm))
        .expect("non-empty");
    let n = rows.len();
    let interior = |i: usize| i >= MIN_FREE_ROWS && i + MIN_FREE_ROWS < n;
    let mut rows = rows;
    if interior(min_index) {
        // Down then up: approach, then retract.
        let retract = rows.split_off(min_index + 1);
        let approach = keep_strict(rows, -1.0, bad_rows, z_column);
        let retract = keep_strict(retract, 1.0, bad_rows, z_column);
        (approach, retract, false)
    } else if interior(max_index) {
        // Up then down: retract, then approach.
        let approach = rows.split_off(max_index + 1);
        let retract = keep_strict(rows, 1.0, bad_rows, z_column);
        let approach = keep_strict(approach, -1.0, bad_rows, z_column);
        (approach, retract, false)
    } else {
        let direction = if rows[n - 1].z_nm < rows[0].z_nm {
            -1.0
        } else {
            1.0
        };
        let mut approach = keep_strict(rows, direction, bad_rows, z_column);
        if direction > 0.0 {
            approach.reverse();
        }
        (approach, Vec::new(), false)
    }
}

/// The rows of a run that continue its direction (`direction * dZ > 0` from the last kept
/// row); the others become bad rows.
fn keep_strict(
    rows: Vec<MeasuredPoint>,
    direction: f64,
    bad_rows: &mut Vec<BadRow>,
    z_column: &str,
) -> Vec<MeasuredPoint> {
    let mut kept: Vec<MeasuredPoint> = Vec::with_capacity(rows.len());
    for row in rows {
        match kept.last() {
            Some(last) if direction * (row.z_nm - last.z_nm) <= 0.0 => bad_rows.push(BadRow {
                line: row.line,
                column: Some(z_column.to_string()),
                reason: if row.z_nm == last.z_nm {
                    format!("duplicate Z = {} nm (line {})", row.z_nm, last.line)
                } else {
                    format!(
                        "Z = {} nm is not monotonic: the sweep goes {} (line {} has {} nm)",
                        row.z_nm,
                        if direction < 0.0 { "down" } else { "up" },
                        last.line,
                        last.z_nm
                    )
                },
            }),
            _ => kept.push(row),
        }
    }
    kept
}

/// The standard deviation of white noise on a smooth sampled signal, from its second
/// differences: `1.4826 MAD(y_{i-1} - 2 y_i + y_{i+1}) / sqrt(6)` (robust to kinks and jumps;
/// MODEL.md section 13.1).
pub fn noise_sigma(values: &[f64]) -> f64 {
    if values.len() < 3 {
        return 0.0;
    }
    let mut second: Vec<f64> = values
        .windows(3)
        .map(|w| w[0] - 2.0 * w[1] + w[2])
        .collect();
    let centre = median(&mut second);
    let mut deviations: Vec<f64> = second.iter().map(|d| (d - centre).abs()).collect();
    1.4826 * median(&mut deviations) / 6f64.sqrt()
}

/// The median of `values` (reordered in place); 0 for none.
pub fn median(values: &mut [f64]) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    values.sort_by(f64::total_cmp);
    let n = values.len();
    if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    }
}

/// `A0` from the free rows of an approach sorted by decreasing `Z`: the reference is the
/// median amplitude of the top `max(10, n/20)` rows, the free rows the leading rows within
/// `max(4 sigma, 0.5% A0)` of it (sigma from [`noise_sigma`]); `A0` is their mean, with standard
/// error `sigma / sqrt(count)`. `None` if fewer than [`MIN_FREE_ROWS`] rows are free.
fn free_amplitude(approach: &[MeasuredPoint]) -> Option<(f64, f64, usize)> {
    let amplitudes: Vec<f64> = approach.iter().map(|p| p.amplitude_nm).collect();
    let sigma = noise_sigma(&amplitudes);
    let top = (approach.len() / 20).max(MIN_FREE_ROWS).min(approach.len());
    let reference = median(&mut amplitudes[..top].to_vec());
    let tolerance = (4.0 * sigma).max(0.005 * reference);
    let count = amplitudes
        .iter()
        .take_while(|a| (*a - reference).abs() <= tolerance)
        .count();
    if count < MIN_FREE_ROWS || reference <= 0.0 {
        return None;
    }
    let mean = amplitudes[..count].iter().sum::<f64>() / count as f64;
    Some((mean, sigma / (count as f64).sqrt(), count))
}

/// The leading approach rows within `max(4 sigma, 0.5% A0)` of a given `A0`.
fn count_free_rows(approach: &[MeasuredPoint], a0: f64) -> usize {
    let amplitudes: Vec<f64> = approach.iter().map(|p| p.amplitude_nm).collect();
    let tolerance = (4.0 * noise_sigma(&amplitudes)).max(0.005 * a0);
    amplitudes
        .iter()
        .take_while(|a| (*a - a0).abs() <= tolerance)
        .count()
}
