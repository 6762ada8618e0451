//! The command-line options that read a measured curve (`drumroll detect`, `drumroll fit`):
//! the file, its column names and units (MODEL.md section 13.1).

use afm::fit::measurement::{LengthUnit, Measurement, MeasurementOptions};
use anyhow::Result;
use clap::Args;

/// Where the measured curve is and how to read it.
#[derive(Debug, Clone, Args)]
pub struct MeasurementArgs {
    /// The measured curve: CSV or TSV with a header; columns `z_nm`, `amplitude_nm`,
    /// `phase_deg` unless `--columns` names others; rows in any order (an approach has Z
    /// decreasing; a file with approach and retract is split by direction); lines starting
    /// with `#` are comments.
    #[arg(long, value_name = "FILE")]
    pub data: String,
    /// Other column names, e.g. `z=ZSnsr,amplitude=Amp,phase=Phase` (any of the three).
    #[arg(long, value_name = "z=NAME,amplitude=NAME,phase=NAME")]
    pub columns: Option<String>,
    /// Unit of the Z column: nm, um or m.
    #[arg(long, default_value = "nm")]
    pub z_unit: String,
    /// Unit of the amplitude column: nm, um, m, or V (photodiode volts, with `--invols`).
    #[arg(long, default_value = "nm")]
    pub amplitude_unit: String,
    /// Inverse optical lever sensitivity, nm/V, in (0, 1e6]: converts an amplitude in V.
    #[arg(long, value_name = "NM_PER_V")]
    pub invols: Option<f64>,
    /// The phase column is in radians (default degrees).
    #[arg(long)]
    pub phase_radians: bool,
}

impl MeasurementArgs {
    /// The reading options, with `a0_nm` the free amplitude if given (nm).
    ///
    /// # Errors
    /// A bad unit, `--invols` without `V`, a bad `--columns`.
    pub fn options(&self, a0_nm: Option<f64>) -> Result<MeasurementOptions> {
        let mut options = MeasurementOptions {
            z_unit: LengthUnit::parse(&self.z_unit, None, "--z-unit")?,
            amplitude_unit: LengthUnit::parse(
                &self.amplitude_unit,
                self.invols,
                "--amplitude-unit",
            )?,
            phase_in_radians: self.phase_radians,
            a0_nm,
            ..MeasurementOptions::default()
        };
        if let Some(columns) = &self.columns {
            options.set_columns(columns)?;
        }
        Ok(options)
    }

    /// Read the measurement; bad rows are reported on stderr with their line numbers (at most
    /// 20, then a count).
    ///
    /// # Errors
    /// As [`MeasurementArgs::options`] and [`Measurement::from_file`].
    pub fn read(&self, a0_nm: Option<f64>) -> Result<Measurement> {
        let measurement = Measurement::from_file(&self.data, &self.options(a0_nm)?)?;
        for bad in measurement.bad_rows.iter().take(20) {
            crate::output::print_stderr(&format!(
                "drumroll: warning: {} line {}{}: {}; row left out",
                self.data,
                bad.line,
                bad.column
                    .as_ref()
                    .map_or_else(String::new, |c| format!(" column `{c}`")),
                bad.reason
            ));
        }
        if measurement.bad_rows.len() > 20 {
            crate::output::print_stderr(&format!(
                "drumroll: warning: {}: {} more bad rows (all listed in the JSON's bad_rows)",
                self.data,
                measurement.bad_rows.len() - 20
            ));
        }
        Ok(measurement)
    }
}
