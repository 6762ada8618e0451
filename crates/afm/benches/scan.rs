//! Benchmark of the scans of MODEL.md section 12 against the issue's targets: an ideal-feedback
//! line of 512 pixels over three materials (mica, the purple-membrane film, the soft sample) in
//! under 1 s, and a PI line of 512 pixels at 20 drive cycles per pixel in under 10 s. The
//! MAClever at 3.3 kHz, A0 = 20 nm, setpoint 0.8; wall time of each, best of three runs.
//!
//! Run with `cargo bench -p afm --bench scan`.

use afm::builtin_case;
use afm::scan::ideal::ideal_scan;
use afm::scan::line::ScanLine;
use afm::scan::pi::{pi_scan, PiSettings};
use afm::scan::settings::ScanSettings;
use std::time::Instant;

const LINE: &str = r#"{"name": "three-materials", "edge_width_nm": 10, "segments": [
    {"from_nm": 0, "to_nm": 100, "height_nm": 0, "sample": "mica"},
    {"from_nm": 100, "to_nm": 200, "height_nm": 6, "sample": "purple-membrane-film"},
    {"from_nm": 200, "to_nm": 300, "height_nm": 3, "sample": "soft"},
    {"from_nm": 300, "to_nm": 400, "height_nm": 0, "sample": "mica"}]}"#;

/// The best wall time of three runs of `run`, seconds.
fn best_of_three(mut run: impl FnMut()) -> f64 {
    (0..3)
        .map(|_| {
            let start = Instant::now();
            run();
            start.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let case = builtin_case("maclever-membrane-experiment").expect("built-in case");
    let line = ScanLine::parse("bench line", LINE, None).expect("line");
    let settings = ScanSettings::new(0.8, 512);
    let ideal = best_of_three(|| {
        let pixels = ideal_scan(&case, &line, &settings).expect("ideal scan");
        assert_eq!(pixels.len(), 512);
    });
    println!("ideal feedback, 512 pixels, 3 materials: {ideal:.3} s (target < 1 s)");

    let period_us = 1e3 / 3.3;
    let mut pi = PiSettings::for_case(&case).expect("PI settings");
    // 20 drive cycles per pixel: 400 nm in 512 * 20 cycles.
    pi.scan_rate_nm_per_s = 400.0 / (512.0 * 20.0 * period_us * 1e-6);
    let timed = best_of_three(|| {
        let pixels = pi_scan(&case, &line, &settings, &pi).expect("PI scan");
        assert_eq!(pixels.len(), 512);
    });
    println!(
        "PI loop, 512 pixels x 20 cycles ({:.1} nm/s): {timed:.3} s, {:.1} us per cycle (target < 10 s)",
        pi.scan_rate_nm_per_s,
        timed / (512.0 * 20.0) * 1e6
    );
}
