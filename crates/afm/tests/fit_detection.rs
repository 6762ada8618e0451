//! Detection of regime boundaries in synthetic measured curves (MODEL.md section 13.2).
use afm::fit::measurement::MeasuredPoint;
use afm::fit::synthetic::{model_branch, synthetic_approach, SyntheticInstrument};
use afm::fit::transitions::{detect_transitions, DetectionSettings};
use afm::{builtin_case, TappingModel};

#[test]
fn explore() {
    for case in ["maclever-mica-experiment", "biolever-soft"] {
        let model = TappingModel::from_case(&builtin_case(case).unwrap()).unwrap();
        let branch = model_branch(&model).unwrap();
        let a0 = model.free_amplitude_nm();
        for sp in &branch.diagram.special_points {
            println!("{case} {} z={:.4} (data {:.4}) r={:.3}", sp.label, sp.z_nm, sp.z_nm + 12.5, sp.amplitude_ratio);
        }
        for seed in 0..5 {
            let instrument = SyntheticInstrument { seed, ..SyntheticInstrument::default() };
            let points: Vec<MeasuredPoint> = synthetic_approach(&branch, a0, &instrument);
            let measured_a0 = a0 * instrument.amplitude_calibration;
            let d = detect_transitions(&points, measured_a0, &DetectionSettings::default()).unwrap();
            println!("seed {seed}: noise {:?} w {} thr {:.1}", d.noise, d.half_window, d.threshold);
            for t in &d.transitions {
                println!("   {:?} z={:.4} +- {:.4} r={:.3} T={:.1}", t.kind, t.z_nm, t.z_uncertainty_nm, t.amplitude_ratio, t.statistic);
            }
        }
    }
}
