//! `drumroll theory`: the paper's approximate theory (its Eqs. 3 and 4, the numbers
//! `lambda_1..3` and the ring-down criterion `Q_2 <= w_2 / w_1`) beside the same quantities
//! measured on the simulated steady orbit at one `Z` or `A/A0`, with relative errors.

use afm::{
    compare_theory, find_amplitude_ratio, steady_orbit, AmplitudeRatioSearch, AssumptionFailure,
    OrbitStart, SteadyOrbit, SteadyOrbitSettings, TappingModel, TheoryComparison,
};
use anyhow::{bail, Context, Result};
use clap::Args;
use serde_json::json;
use std::fmt::Write as _;

use crate::inputs::orbit_inputs_json;
use crate::model_args::ModelArgs;
use crate::output::print_stdout;

/// The amplitude ratio used when neither `--z` nor `--amplitude-ratio` is given: the paper's
/// single-impact example (its Fig. 1(a)).
pub const DEFAULT_AMPLITUDE_RATIO: f64 = 0.95;

/// Options of `drumroll theory`.
#[derive(Debug, Clone, Args)]
pub struct TheoryArgs {
    /// The cantilever, sample and drive.
    #[command(flatten)]
    pub model: ModelArgs,
    /// Compare at this separation Z between the cantilever base and the sample, nm, in
    /// [-A0, 100000] nm (at Z <= 0 the theory gives no prediction: the tip rests in the sample).
    #[arg(long, allow_hyphen_values = true, conflicts_with = "amplitude_ratio")]
    pub z: Option<f64>,
    /// Compare at the Z where the approach from first contact reaches this A/A0, in (0, 1);
    /// default 0.95 (the paper's single-impact example, Fig. 1(a)) when --z is not given.
    #[arg(long, allow_negative_numbers = true)]
    pub amplitude_ratio: Option<f64>,
    /// Print one JSON object instead of the readable table.
    #[arg(long)]
    pub json: bool,
}

/// Run `drumroll theory`.
pub fn run(args: &TheoryArgs) -> Result<()> {
    crate::simulate::check_orbit_options(args.z, args.amplitude_ratio)?;
    let (case, model) = args.model.model()?;
    let settings = SteadyOrbitSettings::default();
    let orbit = orbit(args, &model, &settings)?;
    if !orbit.converged {
        bail!(
            "the steady orbit at Z = {} nm did not converge (residual {:.1e}): no comparison",
            orbit.z_nm,
            orbit.residual
        );
    }
    let comparison = compare_theory(&model, &orbit, &settings.integration).with_context(|| {
        format!(
            "cannot compare the theory with the orbit at Z = {} nm",
            orbit.z_nm
        )
    })?;
    for warning in warnings(&model, &comparison) {
        crate::output::print_stderr(&format!("drumroll: warning: {warning}"));
    }
    if args.json {
        let mut object = comparison_json(&case.name, &model, &comparison);
        let options = json!({ "z_nm": args.z, "amplitude_ratio": args.amplitude_ratio });
        object["inputs"] = orbit_inputs_json("theory", options, &case, &model, &settings);
        print_stdout(&format!("{}\n", serde_json::to_string_pretty(&object)?))?;
    } else {
        print_stdout(&summary(&case.name, &model, &comparison))?;
    }
    Ok(())
}

fn orbit(
    args: &TheoryArgs,
    model: &TappingModel,
    settings: &SteadyOrbitSettings,
) -> Result<SteadyOrbit> {
    match (args.z, args.amplitude_ratio) {
        (Some(z), None) => {
            crate::option_ranges::separation_for(model.free_amplitude_nm()).check(z)?;
            steady_orbit(model, z, OrbitStart::Approach, settings)
                .with_context(|| format!("no steady orbit at Z = {z} nm"))
        }
        (None, ratio) => {
            let ratio = ratio.unwrap_or(DEFAULT_AMPLITUDE_RATIO);
            let search = AmplitudeRatioSearch::new(ratio).context("invalid --amplitude-ratio")?;
            find_amplitude_ratio(model, &search, settings)
                .with_context(|| format!("cannot reach A/A0 = {ratio} on the approach"))
        }
        (Some(_), Some(_)) => bail!("give at most one of --z and --amplitude-ratio"),
    }
}

/// The warnings of a comparison: every assumption of the theory that the orbit violates
/// ([`afm::AssumptionFailure`], in words), and a force that acts outside contact (DMT, a
/// double layer, a hydration force; JKR's neck and the meniscus, attached beyond `d = 0` up to
/// their release gap: Eqs. 3-4 assume force-free flight between impacts; MODEL.md section 9);
/// printed on stderr, in the table and in the JSON's `warnings`.
pub fn warnings(model: &TappingModel, comparison: &TheoryComparison) -> Vec<String> {
    let mut warnings: Vec<String> = comparison
        .assumption_failures
        .iter()
        .map(ToString::to_string)
        .collect();
    let force = model.contact_force();
    if force.acts_outside_contact() {
        warnings.push(
            "the sample's force acts outside contact (van der Waals, double layer or hydration): \
             Eqs. 3-4 assume short impacts and force-free flight between them and do not apply \
             (MODEL.md section 9); computed anyway"
                .to_string(),
        );
    }
    if let Some(release) = force.release_gap_nm() {
        warnings.push(format!(
            "the sample's contact stays attached after the tip leaves d = 0, pulling until the \
             release gap {} nm (JKR's pull-off or the meniscus's rupture): Eqs. 3-4 assume \
             force-free flight between impacts and hold only as far as that pull is small \
             (MODEL.md section 9); computed anyway",
            afm::validation::format_number(release)
        ));
    }
    warnings
}

/// The JSON object of `drumroll theory --json` (docs/output-schema.md; units in the key
/// names): a prediction the theory withholds, a relative error without both sides, and a
/// quantity that is undefined on the orbit are `null`, and `warnings` says why.
pub fn comparison_json(
    case: &str,
    model: &TappingModel,
    comparison: &TheoryComparison,
) -> serde_json::Value {
    let theory = &comparison.theory;
    let prediction = &comparison.prediction;
    let measurement = &comparison.measurement;
    let ringing = measurement.ringing;
    json!({
        "case": case,
        "z_nm": measurement.z_nm,
        "amplitude_ratio": measurement.amplitude_ratio,
        "free_amplitude_nm": model.free_amplitude_nm(),
        "free_q1_amplitude_nm": theory.free_q1_amplitude_nm,
        "drive_frequency_khz": model.drive_frequency_khz(),
        "drive_at_fundamental": theory.drive_at_fundamental,
        "assumption_failures": comparison
            .assumption_failures
            .iter()
            .map(AssumptionFailure::kind)
            .collect::<Vec<_>>(),
        "warnings": warnings(model, comparison),
        "lambda_1": theory.lambda_1,
        "lambda_2": theory.lambda_2,
        "lambda_3": theory.lambda_3,
        "ring_down_criterion": {
            "q2": theory.quality_factor_2,
            "w2_over_w1": theory.angular_frequency_2 / theory.angular_frequency_1,
            "holds": theory.ring_down_criterion_holds,
        },
        "phase_used": "q1_first_harmonic",
        "q1_phase_deg": measurement.q1_phase_deg,
        "u_phase_deg": measurement.u_phase_deg,
        "impulse_eq3_nn_us": prediction.map(|p| p.impulse_nn_us),
        "q2_initial_amplitude_nm": prediction.map(|p| p.q2_initial_amplitude_nm),
        "q2_decay_time_us": prediction.map(|p| p.q2_decay_time_us),
        "q2_decay_over_period": prediction.map(|p| p.q2_decay_over_period),
        "impulse_eq3_from_u_phase_nn_us": comparison.prediction_from_u_phase.map(|p| p.impulse_nn_us),
        "q2_initial_amplitude_from_simulated_impulse_nm": comparison
            .q2_initial_amplitude_from_simulated_impulse_nm,
        "simulated": {
            "impacts_per_period": measurement.impacts.len() as f64,
            "impulse_nn_us": measurement.impulse_nn_us,
            "q1_amplitude_nm": measurement.q1_amplitude_nm,
            "cos_expansion_residual_nn_us": measurement.cos_expansion_residual_nn_us,
            "harmonic_balance_impulse_nn_us": measurement.harmonic_balance_impulse_nn_us,
            "contact_time_periods": measurement.contact_time_periods,
            "impacts": measurement.impacts,
            "main_impact": measurement.main_impact,
            "ringing": ringing,
        },
        "relative_error": {
            "impulse": comparison.impulse_relative_error,
            "q2_initial_amplitude": comparison.q2_initial_amplitude_relative_error,
            "q2_decay_over_period": comparison.q2_decay_over_period_relative_error,
        },
    })
}

/// A relative error as a signed percentage, `-` when there is none.
fn relative(value: Option<f64>) -> String {
    value
        .filter(|v| v.is_finite())
        .map_or_else(|| String::from("-"), |v| format!("{:+.2}%", 100.0 * v))
}

/// A value with `format`, `-` when there is none.
fn optional(value: Option<f64>, format: &dyn Fn(f64) -> String) -> String {
    value.map_or_else(|| String::from("-"), format)
}

/// The four rows theory / simulated / relative error of the table (`-` where a value is
/// withheld or undefined).
fn comparison_rows(s: &mut String, comparison: &TheoryComparison) {
    let (p, m) = (comparison.prediction, &comparison.measurement);
    let ringing = m.ringing;
    let six = |v: f64| format!("{v:.6}");
    let four_e = |v: f64| format!("{v:.4e}");
    let _ = writeln!(
        s,
        "{:<34}{:>16}{:>16.6}{:>12}",
        "impulse per period (Eq. 3), nN us",
        optional(p.map(|p| p.impulse_nn_us), &six),
        m.impulse_nn_us,
        relative(comparison.impulse_relative_error)
    );
    let _ = writeln!(
        s,
        "{:<34}{:>16}{:>16}{:>12}",
        "q_2 initial amplitude (Eq. 4), nm",
        optional(p.map(|p| p.q2_initial_amplitude_nm), &six),
        optional(ringing.map(|r| r.initial_amplitude_nm), &six),
        relative(comparison.q2_initial_amplitude_relative_error)
    );
    let decay_time = ringing.and_then(|r| r.effective_decay_time_us);
    let _ = writeln!(
        s,
        "{:<34}{:>16}{:>16}{:>12}",
        "q_2 decay time tau (Eq. 4), us",
        optional(p.map(|p| p.q2_decay_time_us), &six),
        optional(decay_time, &six),
        relative(
            p.zip(decay_time)
                .map(|(p, measured)| p.q2_decay_time_us / measured - 1.0)
        )
    );
    let _ = writeln!(
        s,
        "{:<34}{:>16}{:>16}{:>12}",
        "q_2 decay over one period (Eq. 4)",
        optional(p.map(|p| p.q2_decay_over_period), &four_e),
        optional(ringing.map(|r| r.decay_over_period), &four_e),
        relative(comparison.q2_decay_over_period_relative_error)
    );
    if p.is_none() {
        let _ = writeln!(
            s,
            "(-: no prediction, the theory's assumptions fail on this orbit; see the warnings)"
        );
    }
}

/// The readable table of `drumroll theory`.
pub fn summary(case: &str, model: &TappingModel, comparison: &TheoryComparison) -> String {
    let theory = &comparison.theory;
    let m = &comparison.measurement;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "case {case}: A0 = {} nm (of u), a0 = {:.6} nm (free amplitude of q_1), drive {:.4} kHz",
        model.free_amplitude_nm(),
        theory.free_q1_amplitude_nm,
        model.drive_frequency_khz()
    );
    for warning in warnings(model, comparison) {
        let _ = writeln!(s, "WARNING: {warning}");
    }
    let _ = writeln!(s, "nondimensional numbers (the paper, below Eq. 4):");
    let _ = writeln!(
        s,
        "  lambda_1 = w_2^2 k_1 / (w_1 w_2d k_2 Q_1) = {:.6}",
        theory.lambda_1
    );
    let _ = writeln!(s, "  lambda_2 = w_2d / w_1 = {:.6}", theory.lambda_2);
    let _ = writeln!(s, "  lambda_3 = Q_2 w_1 / w_2 = {:.6}", theory.lambda_3);
    let ratio = theory.angular_frequency_2 / theory.angular_frequency_1;
    let _ = writeln!(
        s,
        "criterion Q_2 <= w_2/w_1: {} <= {ratio:.4}: {} (the ringing keeps {:.3e} of its amplitude \
         after one period, exp(-T/tau))",
        theory.quality_factor_2,
        if theory.ring_down_criterion_holds {
            "holds, q_2 rings down before the next impact"
        } else {
            "FAILS, q_2 still rings at the next impact"
        },
        theory.q2_decay_over_period
    );
    let _ = writeln!(
        s,
        "steady orbit at Z = {:.9} nm: A/A0 = {:.6}, {} impact(s) per period, contact {:.5} periods",
        m.z_nm,
        m.amplitude_ratio,
        m.impacts.len(),
        m.contact_time_periods
    );
    if m.impacts.is_empty() {
        let _ = writeln!(
            s,
            "no impact on this orbit (first contact is at Z_G1 = {:.9} nm): nothing to compare",
            model.grazing_separation_nm()
        );
    }
    let _ = writeln!(
        s,
        "phase used: phi = {:.4} deg, the first harmonic of the simulated q_1 (u's phase is \
         Phi = {:.4} deg)",
        m.q1_phase_deg, m.u_phase_deg
    );
    let _ = writeln!(
        s,
        "{:<34}{:>16}{:>16}{:>12}",
        "quantity", "theory", "simulated", "error"
    );
    comparison_rows(&mut s, comparison);
    let ringing = m.ringing;
    if let Some(from_u) = comparison.prediction_from_u_phase {
        let _ = writeln!(
            s,
            "with u's phase Phi instead of phi: impulse {:.6} nN us, q_2 amplitude {:.6} nm",
            from_u.impulse_nn_us, from_u.q2_initial_amplitude_nm
        );
    }
    let _ = writeln!(
        s,
        "what Eq. 3 neglects: int F_ts (1 + cos theta) dt = {:.6} nN us (cos theta = -1 over the \
         contact)",
        m.cos_expansion_residual_nn_us
    );
    for (index, impact) in m.impacts.iter().enumerate() {
        let main = if m.main_impact == Some(index) {
            " (main)"
        } else {
            ""
        };
        let _ = writeln!(
            s,
            "  impact {}{main}: t = {:.6} .. {:.6} periods, impulse {:.6} nN us, {:+.3} deg from \
             q_1's lowest point (up to {:.3} deg)",
            index + 1,
            impact.start_periods,
            impact.end_periods,
            impact.impulse_nn_us,
            impact.centroid_theta_bar_deg,
            impact.largest_theta_bar_deg
        );
    }
    if let (Some(ringing), Some(from_impulse)) = (
        ringing,
        comparison.q2_initial_amplitude_from_simulated_impulse_nm,
    ) {
        let _ = writeln!(
            s,
            "q_2 ringing = q_2 minus its free steady response to the drive, referred to the main \
             impact's force centroid (t = {:.6} periods); phase {:+.3} deg (Eq. 4: 0)",
            ringing.reference_time_periods, ringing.phase_deg
        );
        let _ = writeln!(
            s,
            "Eq. 4 with the simulated main impulse instead of Eq. 3: {:.6} nm ({} from the \
             measured ringing: the impulse-response idealisation alone)",
            from_impulse,
            relative(Some(from_impulse / ringing.initial_amplitude_nm - 1.0))
        );
    }
    s
}
