//! The paper's Fig. 1 layout: the photodiode signal `u(t)` above the tip-sample force
//! `F_ts(t)` over a few periods of a steady orbit; and the orbit's harmonic spectrum.

use afm::{sample_trajectory, SteadyOrbit, TappingModel};
use anyhow::Result;

use crate::plot::{Panel, Series, Stroke};

/// Samples per drive period in the figure: enough to resolve an impact of 1 % of a period.
const SAMPLES_PER_PERIOD: usize = 2000;

/// Two panels, `u` (nm) and `F_ts` (nN) against time in drive periods, over `periods` periods of
/// `orbit` (started from its state at `t = 0`).
pub fn trajectory_panels(
    model: &TappingModel,
    orbit: &SteadyOrbit,
    periods: usize,
) -> Result<Vec<Panel>> {
    let mut model = model.clone();
    model.set_separation(afm::Separation::Constant(orbit.z_nm))?;
    let samples = sample_trajectory(
        &model,
        &orbit.state,
        periods,
        SAMPLES_PER_PERIOD,
        &hybrid::Settings::default(),
    )?;
    let period = model.period_us();
    let (ratio, _) = orbit.lockin(model.free_amplitude_nm());
    let title = format!(
        "Z = {:.4} nm, A/A0 = {ratio:.3}, {} impact(s) per period",
        orbit.z_nm,
        crate::digits::impacts_per_period(orbit.impacts_per_orbit(), orbit.multiplicity)
    );
    let series = |label: &str, value: fn(&afm::TrajectorySample) -> f64| Series {
        label: label.to_string(),
        points: samples
            .iter()
            .map(|s| (s.t_us / period, value(s)))
            .collect(),
        stroke: Stroke::Solid,
        colour: 0,
    };
    Ok(vec![
        Panel {
            title,
            x_label: String::from("time t / T (drive periods)"),
            y_label: String::from("photodiode signal u (nm)"),
            series: vec![series("", |s| s.u_nm)],
            markers: Vec::new(),
            y_period: None,
            y_integer_ticks: false,
            regions: Vec::new(),
            shaded: Vec::new(),
            cells: Vec::new(),
        },
        Panel {
            title: String::from("tip-sample force (Hertz)"),
            x_label: String::from("time t / T (drive periods)"),
            y_label: String::from("tip-sample force F_ts (nN)"),
            series: vec![series("", |s| s.force_nn)],
            markers: Vec::new(),
            y_period: None,
            y_integer_ticks: false,
            regions: Vec::new(),
            shaded: Vec::new(),
            cells: Vec::new(),
        },
    ])
}

/// The harmonic spectrum of `orbit`'s `u`: `log10 |U_n|` (amplitude in nm, MODEL.md section
/// 10) against the order `n = 1..N`, one dot per harmonic (harmonics that vanish to rounding,
/// below 1e-15 nm, are left out).
pub fn harmonic_spectrum_panel(orbit: &SteadyOrbit) -> Panel {
    let points = orbit
        .observables()
        .harmonics
        .iter()
        .filter(|h| h.amplitude_nm > 1e-15)
        .map(|h| (h.n as f64, h.amplitude_nm.log10()))
        .collect();
    Panel {
        title: String::from("harmonic spectrum of u"),
        x_label: String::from("harmonic n (multiple of the drive frequency)"),
        y_label: String::from("log10 |U_n| (amplitude in nm)"),
        series: vec![Series {
            label: String::new(),
            points,
            stroke: Stroke::Dots,
            colour: 0,
        }],
        y_integer_ticks: false,
        ..Panel::default()
    }
}
