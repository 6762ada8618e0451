//! `drumroll simulate`: the steady periodic orbit at one separation `Z`, or at the `Z` where the
//! approach curve reaches an amplitude ratio, with its impacts, gap minima and forces.

use afm::{
    find_amplitude_ratio, steady_orbit, AmplitudeRatioSearch, Case, OrbitStart, SteadyOrbit,
    SteadyOrbitSettings, TappingModel,
};
use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use serde_json::json;
use std::path::PathBuf;

use crate::digits;
use crate::inputs::InputsJson;
use crate::json_value::plain_value;
use crate::model_args::ModelArgs;
use crate::option_ranges;
use crate::orbit_json::OrbitJson;
use crate::output::print_stdout;
use crate::plot::{render_svg, FigureFile};
use crate::trajectory_plot::{harmonic_spectrum_panel, trajectory_panels};

/// Options of `drumroll simulate`.
#[derive(Debug, Clone, Args)]
pub struct SimulateArgs {
    /// The cantilever, sample and drive.
    #[command(flatten)]
    pub model: ModelArgs,
    /// Separation Z between the cantilever base and the sample, nm (Z > 0 above the sample), in
    /// [-A0, 100000] nm.
    #[arg(
        long,
        allow_hyphen_values = true,
        conflicts_with = "amplitude_ratio",
        required_unless_present = "amplitude_ratio"
    )]
    pub z: Option<f64>,
    /// Instead of --z: approach from above first contact (Z decreasing, each orbit started from
    /// the previous one) and stop at the Z where A/A0 equals this ratio, in (0, 1).
    #[arg(long, allow_negative_numbers = true)]
    pub amplitude_ratio: Option<f64>,
    /// Which orbit --z reports where several coexist: `approach`, the orbit of the quasi-static
    /// approach (the one `continue` and the paper report: the free orbit above first contact,
    /// else the approach branch followed down from it), or `transient`, the attractor that
    /// transients from the free orbit's state at Z settle on. The other one is reported too
    /// when it differs.
    #[arg(long, value_enum, default_value_t = Start::Approach)]
    pub start: Start,
    /// The harmonics n = 1..N of u reported (amplitude and phase of each, MODEL.md section 10),
    /// N in [1, 1000].
    #[arg(long, default_value_t = crate::approach::DEFAULT_HARMONICS, allow_negative_numbers = true)]
    pub harmonics: i64,
    /// Print one JSON object instead of the readable summary.
    #[arg(long)]
    pub json: bool,
    /// Draw two periods of u(t) and F_ts(t) (the layout of the paper's Fig. 1) and the
    /// harmonic spectrum of u into this file (.svg, .png or .pdf by the extension).
    #[arg(long, value_name = "FILE.svg|png|pdf")]
    pub plot: Option<PathBuf>,
}

/// The orbit `simulate --z` reports where several coexist (see [`SimulateArgs::start`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Start {
    /// The orbit of the quasi-static approach.
    Approach,
    /// The attractor of transients from the free orbit's state.
    Transient,
}

impl Start {
    /// The steady-orbit search's start for this choice.
    pub fn orbit_start(self) -> OrbitStart<'static> {
        match self {
            Self::Approach => OrbitStart::Approach,
            Self::Transient => OrbitStart::Transient,
        }
    }

    /// The other choice.
    pub fn other(self) -> Self {
        match self {
            Self::Approach => Self::Transient,
            Self::Transient => Self::Approach,
        }
    }

    /// The name in outputs.
    pub fn name(self) -> &'static str {
        self.orbit_start().name()
    }
}

/// The orbit the other start reaches at the same `Z`, if it is a different converged orbit
/// (`afm`'s coexistence check: from a stable approach orbit, the transient start stops as soon
/// as its transient enters the orbit's basin).
pub fn coexisting_orbit(
    model: &TappingModel,
    orbit: &SteadyOrbit,
    start: Start,
    settings: &SteadyOrbitSettings,
) -> Option<SteadyOrbit> {
    afm::orbit::steady_orbit::coexisting_orbit(model, orbit, start.other().orbit_start(), settings)
}

/// Run `drumroll simulate`.
pub fn run(args: &SimulateArgs) -> Result<()> {
    check_orbit_options(args.z, args.amplitude_ratio)?;
    let harmonics = option_ranges::HARMONICS.count(args.harmonics)?;
    let plot_path = args
        .plot
        .as_ref()
        .map(|p| FigureFile::new(p, "--plot"))
        .transpose()?;
    let (case, model) = args.model.model()?;
    let settings = SteadyOrbitSettings {
        harmonics,
        ..SteadyOrbitSettings::default()
    };
    let (orbit, start) = orbit_at(&model, args.z, args.amplitude_ratio, args.start, &settings)?;
    let coexisting = match args.z {
        Some(_) => coexisting_orbit(&model, &orbit, start, &settings),
        None => None,
    };
    let min_gap = orbit.observables().min_gap_nm();
    let orbits = [(orbit.z_nm, min_gap.is_finite().then_some(min_gap))];
    if let Some(warning) = afm::film_range_warning(&model, orbits) {
        crate::output::print_stderr(&format!("warning: {warning}"));
    }
    if args.json {
        let coexisting = coexisting
            .as_ref()
            .map(|other| (other, start.other().name()));
        let options = json!({
            "z_nm": args.z,
            "amplitude_ratio": args.amplitude_ratio,
            "start": start.name(),
            "harmonics": harmonics,
        });
        let object = simulate_object(
            &case,
            &model,
            &settings,
            &orbit,
            start.name(),
            coexisting,
            options,
        );
        print_stdout(&format!("{}\n", serde_json::to_string_pretty(&object)?))?;
    } else {
        print_stdout(&summary(&case.name, &model, &orbit))?;
        if let Some(other) = &coexisting {
            print_stdout(&coexisting_note(&model, start, other))?;
        }
    }
    if let Some(path) = plot_path {
        path.write(&orbit_figure(&case.name, &model, &orbit)?)?;
        if !args.json {
            print_stdout(&format!("figure: {}\n", path.path.display()))?;
        }
    }
    Ok(())
}

/// The steady orbit `simulate` reports: at separation `z` from `start`, or (with
/// `amplitude_ratio` instead) where the approach reaches that `A/A0`; exactly one of the two is
/// given, each checked against [`crate::option_ranges`]. Returns the orbit and the start that
/// found it (`Approach` for an amplitude ratio).
pub fn orbit_at(
    model: &TappingModel,
    z: Option<f64>,
    amplitude_ratio: Option<f64>,
    start: Start,
    settings: &SteadyOrbitSettings,
) -> Result<(SteadyOrbit, Start)> {
    check_orbit_options(z, amplitude_ratio)?;
    match (z, amplitude_ratio) {
        (Some(z), None) => {
            option_ranges::separation_for(model.free_amplitude_nm()).check(z)?;
            let orbit = steady_orbit(model, z, start.orbit_start(), settings)
                .with_context(|| format!("no steady orbit at Z = {z} nm"))?;
            Ok((orbit, start))
        }
        (None, Some(ratio)) => {
            let search = AmplitudeRatioSearch::new(ratio).context("invalid --amplitude-ratio")?;
            let orbit = find_amplitude_ratio(model, &search, settings)
                .with_context(|| format!("cannot reach A/A0 = {ratio} on the approach"))?;
            Ok((orbit, Start::Approach))
        }
        _ => bail!("give exactly one of --z and --amplitude-ratio"),
    }
}

/// The whole `simulate --json` object: [`OrbitJson`] of `orbit` found from the start named
/// `start` (`approach`, `transient`, `near`, ...), with `coexisting_orbit` (the other start's
/// orbit and that start's name, or `null`) and `inputs` (the command's `options` and
/// `settings`).
pub fn simulate_object<'a>(
    case: &'a Case,
    model: &TappingModel,
    settings: &SteadyOrbitSettings,
    orbit: &'a SteadyOrbit,
    start: &'a str,
    coexisting: Option<(&'a SteadyOrbit, &'a str)>,
    options: serde_json::Value,
) -> OrbitJson<'a> {
    let coexisting = coexisting.map(|(other, other_start)| {
        OrbitJson::new(&case.name, model, other).with_start(other_start)
    });
    OrbitJson::new(&case.name, model, orbit)
        .with_start(start)
        .with_coexisting_and_inputs(
            coexisting,
            InputsJson::orbit("simulate", options, case, model, settings),
        )
}

/// [`simulate_object`] as a `serde_json::Value`.
pub fn simulate_json(
    case: &Case,
    model: &TappingModel,
    settings: &SteadyOrbitSettings,
    orbit: &SteadyOrbit,
    start: &str,
    coexisting: Option<(&SteadyOrbit, &str)>,
    options: serde_json::Value,
) -> serde_json::Value {
    plain_value(&simulate_object(
        case, model, settings, orbit, start, coexisting, options,
    ))
}

/// The figure `simulate --plot` draws (SVG): two periods of `u(t)` above `F_ts(t)` of `orbit`
/// (the layout of the paper's Fig. 1), titled with the case's name `case`.
pub fn orbit_figure(case: &str, model: &TappingModel, orbit: &SteadyOrbit) -> Result<String> {
    let mut panels = trajectory_panels(model, orbit, 2)?;
    if let Some(first) = panels.first_mut() {
        first.title = format!("{case}: {}", first.title);
    }
    panels.push(harmonic_spectrum_panel(orbit));
    render_svg(&panels, 3, 1, (800, 320))
}

/// Check `--z` and `--amplitude-ratio` of `simulate` and `theory` against the table of
/// [`crate::option_ranges`] (`--z` again against the model's `-A0` once it is built).
pub fn check_orbit_options(z: Option<f64>, amplitude_ratio: Option<f64>) -> Result<()> {
    if let Some(z) = z {
        option_ranges::Z.check(z)?;
    }
    if let Some(ratio) = amplitude_ratio {
        option_ranges::AMPLITUDE_RATIO.check(ratio)?;
    }
    Ok(())
}

/// The JSON object of one steady orbit ([`OrbitJson::new`]; units in the key names,
/// docs/output-schema.md) as a `serde_json::Value`.
pub fn orbit_json(case: &str, model: &TappingModel, orbit: &SteadyOrbit) -> serde_json::Value {
    plain_value(&OrbitJson::new(case, model, orbit))
}

/// Distance from +1 within which a real Floquet multiplier of an orbit Newton did not converge
/// to marks a fold: next to a saddle-node, transients linger at the ghost of the orbit that
/// vanished there for longer than the periods a search integrates, and Newton has no fixed
/// point to find; the best attempts there have a multiplier within a few 1e-6 of +1.
const FOLD_MULTIPLIER_DISTANCE: f64 = 1e-2;

/// The real Floquet multiplier within [`FOLD_MULTIPLIER_DISTANCE`] of +1 of an orbit that did
/// not converge, if any.
fn fold_multiplier(orbit: &SteadyOrbit) -> Option<f64> {
    if orbit.converged {
        return None;
    }
    orbit
        .multipliers
        .iter()
        .filter(|m| m.im == 0.0 && (m.re - 1.0).abs() < FOLD_MULTIPLIER_DISTANCE)
        .map(|m| m.re)
        .min_by(|a, b| (a - 1.0).abs().total_cmp(&(b - 1.0).abs()))
}

/// The table's note on a coexisting orbit that the other start reaches.
fn coexisting_note(model: &TappingModel, start: Start, other: &SteadyOrbit) -> String {
    let (ratio, phase) = other.lockin(model.free_amplitude_nm());
    format!(
        "another orbit coexists at this Z: the {} start reaches a period-{} orbit with A/A0 = {ratio:.6}, phase {phase:.4} deg, {} impacts per period (drumroll simulate --start {} reports it); the orbit above is the {} start's\n",
        start.other().name(),
        other.multiplicity,
        digits::impacts_per_period(other.impacts_per_orbit(), other.multiplicity),
        start.other().name(),
        start.name(),
    )
}

/// The readable summary of one steady orbit.
pub fn summary(case: &str, model: &TappingModel, orbit: &SteadyOrbit) -> String {
    use std::fmt::Write;
    let observables = orbit.observables();
    let (ratio, phase) = orbit.lockin(model.free_amplitude_nm());
    let mut s = String::new();
    let _ = writeln!(
        s,
        "case {case}: A0 = {} nm, drive {:.4} kHz, first contact at Z_G1 = {:.9} nm",
        model.free_amplitude_nm(),
        model.drive_frequency_khz(),
        model.grazing_separation_nm()
    );
    if let Some(base) = model.base_motion() {
        let _ = writeln!(
            s,
            "acoustic drive: the base moves by Y cos(w t), Y = {:.6} nm (MODEL.md section 14)",
            base.amplitude_nm
        );
    }
    if let Some(second) = model.second_drive() {
        let _ = writeln!(
            s,
            "bimodal drive: + {:.4} kHz with A0_b = {} nm (ratio {}/{}; the orbit's period is              the common period {:.6} us)",
            second.frequency_khz,
            second.free_amplitude_nm,
            second.ratio.numerator,
            second.ratio.denominator,
            model.period_us()
        );
    }
    let status = if orbit.converged {
        format!(
            "converged in {} Newton iterations, residual {:.1e}",
            orbit.iterations, orbit.residual
        )
    } else {
        format!("NOT CONVERGED after {} Newton iterations, residual {:.1e}: the values below are the best attempt", orbit.iterations, orbit.residual)
    };
    let _ = writeln!(s, "steady orbit at Z = {:.9} nm: {status}", orbit.z_nm);
    if let Some(multiplier) = fold_multiplier(orbit) {
        let _ = writeln!(
            s,
            "  a Floquet multiplier is {multiplier:.6}, at +1: Z is next to a fold, where the transients linger at the ghost of the orbit that vanished there and Newton has no orbit near to find; `drumroll continue` locates the fold, and `drumroll simulate` finds the orbit beyond it farther from the fold"
        );
    }
    if orbit.multiplicity > 1 {
        let _ = writeln!(
            s,
            "the orbit is NOT period-1: its period is {} drive periods",
            orbit.multiplicity
        );
    }
    let radius = continuation::spectral_radius(&orbit.multipliers);
    let _ = writeln!(
        s,
        "stability: {} (largest |Floquet multiplier| = {radius:.3e})",
        if orbit.stable { "stable" } else { "unstable" }
    );
    let _ = writeln!(
        s,
        "A/A0 = {ratio:.6}   phase = {phase:.4} deg (free: {:.4} deg)",
        model.free_phase_deg()
    );
    if let Some(response) = observables.second_drive {
        let free_phase = model
            .free_response()
            .second_photodiode_harmonic()
            .map_or(f64::NAN, |[a, b]| b.atan2(a).to_degrees());
        let _ = writeln!(
            s,
            "at the second frequency: A_b = {:.6} nm   phase = {:.4} deg (free: {:.4} deg)",
            response.amplitude_nm, response.phase_deg, free_phase
        );
    }
    let k = orbit.multiplicity;
    let per_period = digits::impacts_per_period(orbit.impacts_per_orbit(), k);
    if k > 1 {
        let _ = writeln!(
            s,
            "impacts per period: {per_period} ({} over the orbit's {k} drive periods)",
            orbit.impacts_per_orbit()
        );
    } else {
        let _ = writeln!(s, "impacts per period: {per_period}");
    }
    let time_origin = if k > 1 { "the orbit's start" } else { "t = 0" };
    for (i, impact) in observables.impacts.iter().enumerate() {
        let _ = writeln!(s, "  impact {}: t = {:.6} .. {:.6} periods, onset velocity {:.6} nm/us, peak force {:.6} nN",
            i + 1, impact.start_periods, impact.end_periods, impact.velocity_nm_per_us, impact.peak_force_nn);
    }
    let _ = writeln!(
        s,
        "gap minima (t in drive periods from {time_origin}, gap d in nm; a near impact has 0 <= d <= {} A0 = {} nm):",
        afm::NEAR_IMPACT_FRACTION,
        afm::NEAR_IMPACT_FRACTION * model.free_amplitude_nm()
    );
    for minimum in &observables.gap_minima {
        let _ = writeln!(
            s,
            "  t = {:.6}  d = {:+.6e}  ({})",
            minimum.t_periods,
            minimum.gap_nm,
            minimum.kind.name()
        );
    }
    // (+ 0.0 prints a negative zero as 0.)
    let _ = writeln!(s, "peak force {:.6} nN, mean force {:.6e} nN, contact time {:.6} periods per period, impulse {:.6} nN us per period",
        observables.peak_force_nn, observables.mean_force_nn + 0.0, observables.contact_time_periods + 0.0, observables.impulse_nn_us + 0.0);
    let _ = writeln!(
        s,
        "dissipated {:.6e} eV per period, virial {:.6e} eV, indentation max {:.6} nm, mean {:.6} nm (in contact); energy balance residual {:.1e}",
        observables.dissipated_ev + 0.0,
        observables.virial_ev + 0.0,
        observables.max_indentation_nm,
        observables.mean_indentation_nm,
        observables.energy_balance_residual
    );
    let _ = writeln!(s, "harmonics of u:  n  amplitude (nm)  phase (deg)");
    for harmonic in &observables.harmonics {
        let _ = writeln!(
            s,
            "  {:>16} {:>14.6e} {:>12.4}",
            harmonic.n, harmonic.amplitude_nm, harmonic.phase_deg
        );
    }
    if k > 1 {
        let _ = writeln!(
            s,
            "per period:  {:>9} {:>10} {:>8} {:>12} {:>12} {:>12}",
            "A/A0", "phase", "impacts", "peak F (nN)", "impulse", "min gap (nm)"
        );
        for period in orbit.period_breakdown(model.free_amplitude_nm()) {
            let _ = writeln!(
                s,
                "  period {:<3} {:>9.6} {:>10.4} {:>8} {:>12.6} {:>12.6} {:>12}",
                period.period + 1,
                period.amplitude_ratio,
                period.phase_deg,
                period.impacts,
                period.peak_force_nn,
                period.impulse_nn_us + 0.0,
                period
                    .min_gap_nm
                    .map_or_else(|| String::from("none"), |gap| format!("{gap:+.4e}"))
            );
        }
    }
    s
}
