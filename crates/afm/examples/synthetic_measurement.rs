//! Print a synthetic measured approach curve made by drumroll itself (MODEL.md section 13.5):
//! the followed approach branch of a built-in case through the test instrument
//! (offset 12.5 nm, calibration 1.08, phase offset 90 deg, noise 0.3% of A0 and 0.15 deg,
//! 1000 rows), as the CSV of `fixtures/measurements/`.
//!
//! `cargo run --release -p afm --example synthetic_measurement -- CASE SEED > FILE.csv`
use afm::fit::synthetic::{model_branch, synthetic_approach, to_csv, SyntheticInstrument};
use afm::{builtin_case, TappingModel};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let (Some(case_name), Some(seed)) = (args.get(1), args.get(2)) else {
        return Err("usage: synthetic_measurement CASE SEED".into());
    };
    let seed: u64 = seed.parse()?;
    let case = builtin_case(case_name)?;
    let model = TappingModel::from_case(&case)?;
    let branch = model_branch(&model)?;
    let instrument = SyntheticInstrument {
        seed,
        ..SyntheticInstrument::default()
    };
    let points = synthetic_approach(&branch, model.free_amplitude_nm(), &instrument);
    let comments = vec![
        format!("SYNTHETIC, not measured: drumroll's approach branch of case {case_name} plus instrument errors and noise."),
        format!("made by: cargo run --release -p afm --example synthetic_measurement -- {case_name} {seed}"),
        format!(
            "truth: z_offset_nm = {}, amplitude_calibration = {}, phase_offset_deg = {}, sample_modulus_gpa = {}; noise {} A0 and {} deg",
            instrument.z_offset_nm,
            instrument.amplitude_calibration,
            instrument.phase_offset_deg,
            case.sample.youngs_modulus_gpa,
            instrument.amplitude_noise_fraction,
            instrument.phase_noise_deg
        ),
    ];
    print!("{}", to_csv(&points, &comments));
    Ok(())
}
