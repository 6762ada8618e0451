//! The scans of MODEL.md section 12 against independent references: the direct amplitude-ratio
//! solve (`find_amplitude_ratio`, its own approach branch and Illinois refinement) at the
//! setpoint on each material, and the exact geometry of heights.

use afm::scan::ideal::ideal_scan;
use afm::scan::line::ScanLine;
use afm::scan::pi::{pi_scan, PiSettings};
use afm::scan::pixel::ScanDirection;
use afm::scan::settings::{ScanDirections, ScanSettings};
use afm::{
    builtin_case, find_amplitude_ratio, AmplitudeRatioSearch, Case, SteadyOrbitSettings,
    TappingModel,
};

/// The paper's experiment: MAClever in water at 3.3 kHz, A0 = 20 nm.
const CASE: &str = "maclever-membrane-experiment";
const SETPOINT: f64 = 0.8;

fn line(text: &str) -> ScanLine {
    ScanLine::parse("test line", text, None).expect("a valid line")
}

/// `Z` at the setpoint on `sample` by the direct solve.
fn setpoint_z(sample: &str) -> f64 {
    let mut case = builtin_case(CASE).unwrap();
    case.sample = afm::builtin_sample(sample).unwrap();
    let model = TappingModel::from_case(&case).unwrap();
    let search = AmplitudeRatioSearch::new(SETPOINT).unwrap();
    find_amplitude_ratio(&model, &search, &SteadyOrbitSettings::default())
        .unwrap()
        .z_nm
}

#[test]
fn uniform_sample_with_a_step_reads_the_orbit_at_the_setpoint_and_the_step() {
    // One material, a 4 nm step at x = 50 nm (sharp): Z is that of the setpoint orbit on every
    // pixel (the direct solve, to its 1e-9 nm tolerance), and the measured height is h.
    let line = line(
        r#"{"segments": [
            {"from_nm": 0, "to_nm": 50, "height_nm": 0, "sample": "mica"},
            {"from_nm": 50, "to_nm": 100, "height_nm": 4, "sample": "mica"}]}"#,
    );
    let case = builtin_case(CASE).unwrap();
    let settings = ScanSettings {
        directions: ScanDirections::Both,
        ..ScanSettings::new(SETPOINT, 8)
    };
    let pixels = ideal_scan(&case, &line, &settings).unwrap();
    assert_eq!(pixels.len(), 16);
    let z = setpoint_z("mica");
    for pixel in &pixels {
        assert!((pixel.z_nm - z).abs() < 2e-9, "Z {} vs {z}", pixel.z_nm);
        assert!((pixel.amplitude_ratio - SETPOINT).abs() < 1e-6);
        let h = if pixel.x_nm < 50.0 { 0.0 } else { 4.0 };
        assert_eq!(pixel.height_true_nm, h);
        assert!((pixel.height_nm - h).abs() < 1e-9, "{pixel:?}");
        assert!(pixel.jump.is_none());
        assert_eq!(pixel.stable, Some(true));
    }
    assert!(pixels[..8]
        .iter()
        .all(|p| p.direction == ScanDirection::Trace));
    assert!(pixels[8..]
        .iter()
        .all(|p| p.direction == ScanDirection::Retrace));
}

#[test]
fn two_materials_at_equal_height_read_the_difference_of_their_setpoint_separations() {
    let line = line(
        r#"{"segments": [
            {"from_nm": 0, "to_nm": 50, "height_nm": 0, "sample": "mica"},
            {"from_nm": 50, "to_nm": 100, "height_nm": 0, "sample": "purple-membrane-film"}]}"#,
    );
    let case = builtin_case(CASE).unwrap();
    let pixels = ideal_scan(&case, &line, &ScanSettings::new(SETPOINT, 4)).unwrap();
    let (z_mica, z_film) = (setpoint_z("mica"), setpoint_z("purple-membrane-film"));
    // Both refined to 1e-9 nm in Z: the difference to 2e-9 nm plus rounding.
    for pixel in &pixels[2..] {
        assert!(
            (pixel.height_nm - (z_film - z_mica)).abs() < 3e-9,
            "{} vs {}",
            pixel.height_nm,
            z_film - z_mica
        );
        assert_eq!(pixel.sample, "purple-membrane-film");
    }
    assert!(pixels[0].height_nm.abs() < 1e-12);
}

#[test]
fn edge_width_ramps_the_true_height_linearly() {
    let line = line(
        r#"{"edge_width_nm": 10, "segments": [
            {"from_nm": 0, "to_nm": 50, "height_nm": 0, "sample": "mica"},
            {"from_nm": 50, "to_nm": 100, "height_nm": 6, "sample": "soft"}]}"#,
    );
    // Exact: a line from (45, 0) to (55, 6).
    for (x, h) in [
        (40.0, 0.0),
        (45.0, 0.0),
        (47.5, 1.5),
        (50.0, 3.0),
        (54.0, 5.4),
        (55.0, 6.0),
        (90.0, 6.0),
    ] {
        assert!(
            (line.height_at(x) - h).abs() < 1e-12,
            "h({x}) = {}",
            line.height_at(x)
        );
    }
    assert_eq!(line.materials[line.material_at(49.9)].name, "mica");
    assert_eq!(line.materials[line.material_at(50.0)].name, "soft");
}

/// The height's step between two points: the sum over the boundaries crossed of the height
/// after less the height before, signed by the direction of travel; zero where the edges are
/// ramps. The ideal feedback holds the base across a material boundary, so the tip arrives
/// over the new material at the old Z less that step (MODEL.md section 12): across a 2 nm step
/// up onto a soft sample both passes still read the setpoint on every pixel.
#[test]
fn a_sharp_step_at_a_material_boundary_moves_the_arrival_by_the_step() {
    let sharp = line(
        r#"{"segments": [
            {"from_nm": 0, "to_nm": 50, "height_nm": 0, "sample": "mica"},
            {"from_nm": 50, "to_nm": 100, "height_nm": 2, "sample": "soft"},
            {"from_nm": 100, "to_nm": 150, "height_nm": -1, "sample": "mica"}]}"#,
    );
    assert_eq!(sharp.height_step_between(25.0, 75.0), 2.0);
    assert_eq!(sharp.height_step_between(75.0, 25.0), -2.0);
    assert_eq!(sharp.height_step_between(25.0, 125.0), -1.0);
    assert_eq!(sharp.height_step_between(60.0, 90.0), 0.0);
    let ramped = line(
        r#"{"edge_width_nm": 10, "segments": [
            {"from_nm": 0, "to_nm": 50, "height_nm": 0, "sample": "mica"},
            {"from_nm": 50, "to_nm": 100, "height_nm": 2, "sample": "soft"}]}"#,
    );
    assert_eq!(ramped.height_step_between(25.0, 75.0), 0.0);
    let case = builtin_case(CASE).unwrap();
    let settings = ScanSettings {
        directions: ScanDirections::Both,
        ..ScanSettings::new(SETPOINT, 6)
    };
    for pixel in ideal_scan(&case, &sharp, &settings).unwrap() {
        assert!((pixel.amplitude_ratio - SETPOINT).abs() < 1e-6, "{pixel:?}");
    }
}

#[test]
fn bad_line_files_name_the_field_and_the_range() {
    let cases = [
        (r#"{"segments": []}"#, "segments"),
        (
            r#"{"segments": [{"from_nm": 0, "to_nm": -1, "height_nm": 0, "sample": "mica"}]}"#,
            "segments[0].to_nm",
        ),
        (
            r#"{"segments": [{"from_nm": 0, "to_nm": 10, "height_nm": 0, "sample": "mica"},
                              {"from_nm": 12, "to_nm": 20, "height_nm": 0, "sample": "mica"}]}"#,
            "segments[1].from_nm",
        ),
        (
            r#"{"segments": [{"from_nm": 0, "to_nm": 10, "height_nm": 0, "sample": "glass"}]}"#,
            "segments[0].sample",
        ),
        (
            r#"{"edge_width_nm": 20, "segments": [{"from_nm": 0, "to_nm": 10, "height_nm": 0, "sample": "mica"}]}"#,
            "edge_width_nm",
        ),
        (
            r#"{"segments": [{"from_nm": 0, "to_nm": 10, "height_nm": 1e9, "sample": "mica"}]}"#,
            "segments[0].height_nm",
        ),
        (
            r#"{"segments": [{"from_nm": 0, "to_nm": 10, "height": 0, "sample": "mica"}]}"#,
            "segments[0]",
        ),
        (
            r#"{"segments": [{"from_nm": 0, "to_nm": 10, "height_nm": 0,
                "sample": {"name": "x", "youngs_modulus_gpa": -3}}]}"#,
            "youngs_modulus_gpa",
        ),
        (
            r#"{"segments": [{"from_nm": 0, "to_nm": 10, "height_nm": 0, "sample": "missing.json"}]}"#,
            "cannot read",
        ),
    ];
    for (text, field) in cases {
        let error = ScanLine::parse("bad.json", text, None)
            .unwrap_err()
            .to_string();
        assert!(error.contains("bad.json"), "{error}");
        assert!(error.contains(field), "{field}: {error}");
    }
}

#[test]
fn the_builtin_line_is_the_paper_setting() {
    let line = ScanLine::builtin("membrane-patch").unwrap();
    assert_eq!(line.materials.len(), 2);
    assert_eq!(line.height_at(200.0), 6.0);
    assert_eq!(
        line.materials[line.material_at(200.0)].name,
        "purple-membrane-film"
    );
    assert!(ScanLine::find("no-such-line")
        .unwrap_err()
        .to_string()
        .contains("membrane-patch"));
}

#[test]
fn a_slow_pi_scan_converges_to_the_ideal_feedback() {
    // The paper's line: mica, a 6 nm film patch, mica; 16 pixels of 25 nm, ~40 drive cycles
    // each. Away from the edges (the pixels holding a ramp or a change of material and the
    // one after it) the loop has settled: Z within 0.05 nm of the ideal feedback's.
    let line = ScanLine::builtin("membrane-patch").unwrap();
    let case = builtin_case(CASE).unwrap();
    let settings = ScanSettings::new(SETPOINT, 16);
    let mut pi = PiSettings::for_case(&case).unwrap();
    pi.scan_rate_nm_per_s = 2000.0;
    let ideal = ideal_scan(&case, &line, &settings).unwrap();
    let timed = pi_scan(&case, &line, &settings, &pi).unwrap();
    assert_eq!(timed.len(), 16);
    for (a, b) in ideal.iter().zip(&timed) {
        assert_eq!(a.index, b.index);
        let near_edge = [100.0, 300.0]
            .iter()
            .any(|edge| (a.x_nm - edge).abs() < 2.0 * 25.0);
        if !near_edge {
            assert!(
                (a.z_nm - b.z_nm).abs() < 0.05,
                "x = {}: {} vs {}",
                a.x_nm,
                a.z_nm,
                b.z_nm
            );
            assert!((b.amplitude_ratio - SETPOINT).abs() < 0.01);
        }
    }
}

/// Every pixel of every pass is read once, whatever the scan rate: at 1000 and 1700 nm/s over
/// the paper's 400 nm line in 64 pixels some cycle's middle lies exactly on a pixel boundary
/// (checked below from `K = round(L / (v T))`), where a count and a pass that placed it by
/// different floating-point arithmetic lost pixels (61 of the retrace's 64 at 1000 nm/s).
#[test]
fn a_pi_scan_reads_every_pixel_once_in_both_passes() {
    let line = ScanLine::builtin("membrane-patch").unwrap();
    let case = builtin_case(CASE).unwrap();
    let period_us = TappingModel::from_case(&case).unwrap().period_us();
    let pixels = 64;
    let settings = ScanSettings {
        directions: ScanDirections::Both,
        ..ScanSettings::new(SETPOINT, pixels)
    };
    for rate in [1000.0, 1700.0] {
        // Some cycle's middle `(j + 1/2) L / K` lies exactly on a pixel boundary `m L / N`.
        let cycles = (400.0 / (rate * 1e-6 * period_us)).round() as usize;
        assert!(
            (0..cycles).any(|j| ((2 * j + 1) * pixels) % (2 * cycles) == 0),
            "{rate} nm/s: {cycles} cycles"
        );
        let mut pi = PiSettings::for_case(&case).unwrap();
        pi.scan_rate_nm_per_s = rate;
        let scanned = pi_scan(&case, &line, &settings, &pi).unwrap();
        for direction in [ScanDirection::Trace, ScanDirection::Retrace] {
            let mut indices: Vec<usize> = scanned
                .iter()
                .filter(|p| p.direction == direction)
                .map(|p| p.index)
                .collect();
            indices.sort_unstable();
            assert_eq!(
                indices,
                (0..pixels).collect::<Vec<_>>(),
                "{rate} nm/s, {direction:?}"
            );
        }
    }
}

/// The PI loop of MODEL.md section 12 written out again with a brute-force integration: Eq. 1
/// by classical Runge-Kutta at `steps` fixed steps per drive cycle (the contact force taken
/// from the state's own mode at every stage, so no event location), the first harmonic of `u`
/// by composite Simpson over the same nodes, the same controller. Returns each cycle's
/// `(mid-cycle Z, a / A0, b / A0)`, `a` and `b` the first-harmonic Fourier coefficients of `u`.
#[allow(clippy::too_many_arguments)]
fn brute_force_pi(
    model: &TappingModel,
    line: &ScanLine,
    cycles: usize,
    setpoint: f64,
    gain_p: f64,
    gain_i_per_ms: f64,
    steps: usize,
) -> Vec<(f64, f64, f64)> {
    use afm::Separation;
    use hybrid::HybridSystem;
    let a0 = model.free_amplitude_nm();
    let period = model.period_us();
    let w = model.drive_angular_frequency();
    let search = AmplitudeRatioSearch::new(setpoint).unwrap();
    let engaged = find_amplitude_ratio(model, &search, &SteadyOrbitSettings::default()).unwrap();
    let (start, end) = (line.start_nm(), line.end_nm());
    let travel = (end - start) / cycles as f64;
    let hold = line.height_at(start) + engaged.z_nm;
    let (mut base_start, mut base_end) = (hold, hold);
    let (mut integral, mut state) = (0.0, engaged.state.clone());
    let mut model = model.clone();
    let n = state.len();
    let field = |model: &TappingModel, t: f64, x: &[f64], out: &mut [f64]| {
        model.vector_field(model.mode_of(t, x), t, x, out)
    };
    let mut readings = Vec::new();
    for k in 0..cycles {
        let (x0, x1) = (start + k as f64 * travel, start + (k + 1) as f64 * travel);
        let (z0, z1) = (
            base_start - line.height_at(x0),
            base_end - line.height_at(x1),
        );
        model
            .set_separation(Separation::Ramp {
                z0_nm: z0,
                rate_nm_per_us: (z0 - z1) / period,
            })
            .unwrap();
        let h = period / steps as f64;
        let (mut a, mut b) = (0.0, 0.0);
        let mut k1 = vec![0.0; n];
        let (mut k2, mut k3, mut k4, mut stage) = (k1.clone(), k1.clone(), k1.clone(), k1.clone());
        for step in 0..=steps {
            let t = step as f64 * h;
            let weight = if step == 0 || step == steps {
                1.0
            } else if step % 2 == 1 {
                4.0
            } else {
                2.0
            };
            let u = model.photodiode(&state);
            a += weight * u * (w * t).cos();
            b += weight * u * (w * t).sin();
            if step == steps {
                break;
            }
            field(&model, t, &state, &mut k1);
            for i in 0..n {
                stage[i] = state[i] + 0.5 * h * k1[i];
            }
            field(&model, t + 0.5 * h, &stage, &mut k2);
            for i in 0..n {
                stage[i] = state[i] + 0.5 * h * k2[i];
            }
            field(&model, t + 0.5 * h, &stage, &mut k3);
            for i in 0..n {
                stage[i] = state[i] + h * k3[i];
            }
            field(&model, t + h, &stage, &mut k4);
            for i in 0..n {
                state[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
        }
        let scale = 2.0 / period * h / 3.0;
        let amplitude = (scale * a).hypot(scale * b);
        readings.push((0.5 * (z0 + z1), scale * a / a0, scale * b / a0));
        let error = amplitude - setpoint * a0;
        integral += error * period * 1e-3;
        base_start = base_end;
        base_end = hold - gain_p * error - gain_i_per_ms * integral;
    }
    readings
}

#[test]
fn a_fast_pi_scan_off_a_step_tracks_as_a_brute_force_loop_does() {
    // Mica with a 6 nm step down at x = 20 nm, 8 pixels of 8 drive cycles: after the step the
    // tip parachutes (free, A -> A0) for several cycles while the integral brings the base
    // down. Every pixel's Z and A/A0 against the brute-force loop (Runge-Kutta with 20000
    // steps per cycle, Simpson demodulation): the two integrations (tolerance 1e-8 against
    // fixed steps) differ by at most 1.5e-6 nm in Z and 4e-8 in A/A0 as measured; the
    // tolerances are 2e-5 nm and 1e-6, and the tracking error itself is over 1 nm.
    let line = line(
        r#"{"segments": [
            {"from_nm": 0, "to_nm": 20, "height_nm": 6, "sample": "mica"},
            {"from_nm": 20, "to_nm": 40, "height_nm": 0, "sample": "mica"}]}"#,
    );
    let case = builtin_case(CASE).unwrap();
    let model = TappingModel::from_case(&Case {
        sample: afm::builtin_sample("mica").unwrap(),
        ..case.clone()
    })
    .unwrap();
    let (pixels, cycles_per_pixel) = (8, 8);
    let cycles = pixels * cycles_per_pixel;
    let mut pi = PiSettings::for_case(&case).unwrap();
    pi.scan_rate_nm_per_s = 40.0 / (cycles as f64 * model.period_us() * 1e-6);
    let scanned = pi_scan(&case, &line, &ScanSettings::new(SETPOINT, pixels), &pi).unwrap();
    let reference = brute_force_pi(
        &model,
        &line,
        cycles,
        SETPOINT,
        pi.gain_p,
        pi.gain_i_per_ms,
        20_000,
    );
    for (pixel, cycles) in scanned.iter().zip(reference.chunks(cycles_per_pixel)) {
        // A pixel reads the mean Z and the amplitude of the mean Fourier coefficients.
        let mean = |f: fn(&(f64, f64, f64)) -> f64| {
            cycles.iter().map(f).sum::<f64>() / cycles_per_pixel as f64
        };
        let z = mean(|c| c.0);
        let ratio = mean(|c| c.1).hypot(mean(|c| c.2));
        assert!(
            (pixel.z_nm - z).abs() < 2e-5,
            "x = {}: Z {} vs {z}",
            pixel.x_nm,
            pixel.z_nm
        );
        assert!(
            (pixel.amplitude_ratio - ratio).abs() < 1e-6,
            "x = {}: A/A0 {} vs {ratio}",
            pixel.x_nm,
            pixel.amplitude_ratio
        );
    }
    let after_step = scanned.iter().find(|p| p.x_nm > 20.0).unwrap();
    assert!(after_step.height_error_nm > 1.0, "{after_step:?}");
}

#[test]
fn engaging_past_the_fold_near_first_contact_is_marked_as_a_jump() {
    // The MAClever on mica is bistable just below first contact: its approach branch folds
    // back at Z = 19.99584 nm (A/A0 = 0.999834) and forward again at 19.99820 nm (0.998662).
    // A setpoint of 0.998 lies only on the lower stable part: engaging from above, the
    // feedback walks down the upper part to its fold and jumps, released from the fold's orbit
    // as the diagram's special-point search located it (not from the part's last branch point,
    // up to one branch step short of it, where the cantilever would settle back on the part it
    // left).
    // Back from the film, the cantilever lands on the lower part directly: no jump. A
    // setpoint inside the gap between the folds' A/A0 (0.9992) has no stable orbit: the scan
    // stops with an error that says so.
    let case = builtin_case("maclever-mica").unwrap();
    let model = TappingModel::from_case(&case).unwrap();
    let diagram = afm::approach_diagram(&model, &afm::DiagramSettings::approach(&model)).unwrap();
    let fold = diagram
        .special_points
        .iter()
        .find(|p| p.label == "fold")
        .expect("the first fold")
        .z_nm;
    let line = line(
        r#"{"segments": [
            {"from_nm": 0, "to_nm": 20, "height_nm": 0, "sample": "mica"},
            {"from_nm": 20, "to_nm": 40, "height_nm": 0, "sample": "purple-membrane-film"},
            {"from_nm": 40, "to_nm": 60, "height_nm": 0, "sample": "mica"}]}"#,
    );
    let pixels = ideal_scan(&case, &line, &ScanSettings::new(0.998, 3)).unwrap();
    let jump = pixels[0].jump.expect("the engagement jumps at the fold");
    assert_eq!(jump.from_z_nm, fold, "{jump:?} vs {fold}");
    assert!(jump.from_amplitude_ratio > 0.998);
    assert!((pixels[0].amplitude_ratio - 0.998).abs() < 1e-6);
    assert!(pixels[1].jump.is_none() && pixels[2].jump.is_none());
    assert!((pixels[2].z_nm - pixels[0].z_nm).abs() < 2e-9);

    let error = ideal_scan(&case, &line, &ScanSettings::new(0.9992, 3))
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("jumped") && error.contains("mica"),
        "{error}"
    );
}

/// The `Z` where the stable parts of `diagram` cross `A/A0 = ratio`, by linear interpolation
/// between consecutive stable points (branch order).
fn stable_crossings(diagram: &afm::BifurcationDiagram, ratio: f64) -> Vec<(f64, f64)> {
    diagram
        .points
        .windows(2)
        .filter(|pair| pair[0].stable && pair[1].stable)
        .filter_map(|pair| {
            let (r0, r1) = (pair[0].amplitude_ratio, pair[1].amplitude_ratio);
            ((r0 - ratio) * (r1 - ratio) <= 0.0 && r0 != r1).then(|| {
                let s = (ratio - r0) / (r1 - r0);
                let z = pair[0].z_nm + s * (pair[1].z_nm - pair[0].z_nm);
                let phase = pair[0].phase_deg + s * (pair[1].phase_deg - pair[0].phase_deg);
                (z, phase)
            })
        })
        .collect()
}

#[test]
fn where_attractive_and_repulsive_orbits_coexist_trace_and_retrace_differ_as_the_branches_say() {
    // The silicon-air cantilever over the strong van der Waals polymer is bistable: its
    // approach branch (the diagram, independent of the scan's walk) crosses A/A0 = 0.8 on two
    // stable parts, the attractive regime (phase above 90 deg) at the larger Z and the
    // repulsive one (below 90 deg) beyond the fold. The built-in blend line engages in the
    // attractive regime (the first crossing, as a slow approach does), is pushed into the
    // repulsive regime over the weak polymer (one orbit at every Z) and stays there over the
    // strong polymer after it, so the retrace reads the strong polymer at the repulsive Z
    // everywhere while the trace read it at the attractive Z first. Tolerances: the Illinois
    // refinement's 1e-9 nm between scan passes; 2e-3 nm against the linear interpolation of
    // branch points A0/250 = 0.04 nm apart; 0.05 deg on the interpolated phase.
    let case = builtin_case("silicon-air-polymer").unwrap();
    let model = TappingModel::from_case(&case).unwrap();
    let diagram = afm::approach_diagram(&model, &afm::DiagramSettings::approach(&model)).unwrap();
    let crossings = stable_crossings(&diagram, 0.8);
    assert_eq!(crossings.len(), 2, "{crossings:?}");
    let (attractive, repulsive) = (crossings[0], crossings[1]);
    assert!(attractive.1 > 90.0 && repulsive.1 < 90.0, "{crossings:?}");
    assert!(attractive.0 - repulsive.0 > 0.5, "{crossings:?}");

    let line = ScanLine::builtin("polymer-blend").unwrap();
    let settings = ScanSettings {
        directions: ScanDirections::Both,
        ..ScanSettings::new(0.8, 6)
    };
    let pixels = ideal_scan(&case, &line, &settings).unwrap();
    let (trace, retrace): (Vec<_>, Vec<_>) = pixels
        .iter()
        .partition(|p| p.direction == ScanDirection::Trace);
    let near = |z: f64, reference: (f64, f64), phase: f64| {
        (z - reference.0).abs() < 2e-3 && (phase - reference.1).abs() < 0.05
    };
    for pixel in &pixels {
        assert!((pixel.amplitude_ratio - 0.8).abs() < 1e-6, "{pixel:?}");
        assert!(pixel.jump.is_none(), "{pixel:?}");
    }
    // Trace: attractive on the first strong segment, repulsive on the last one.
    for pixel in &trace[..2] {
        assert!(near(pixel.z_nm, attractive, pixel.phase_deg), "{pixel:?}");
    }
    for pixel in &trace[4..] {
        assert!(near(pixel.z_nm, repulsive, pixel.phase_deg), "{pixel:?}");
    }
    // Retrace (from the trace's end): repulsive on both strong segments.
    for pixel in retrace.iter().filter(|p| p.sample == "polymer-strong-vdw") {
        assert!(near(pixel.z_nm, repulsive, pixel.phase_deg), "{pixel:?}");
    }
    // The weak polymer reads the same both ways; the first segment differs by the branches.
    let weak: Vec<f64> = pixels
        .iter()
        .filter(|p| p.sample == "polymer-weak-vdw")
        .map(|p| p.z_nm)
        .collect();
    assert!(weak.iter().all(|z| (z - weak[0]).abs() < 1e-9), "{weak:?}");
    let first_trace = trace[0].z_nm;
    let first_retrace = retrace.iter().find(|p| p.index == 0).unwrap().z_nm;
    assert!(
        (first_trace - first_retrace - (attractive.0 - repulsive.0)).abs() < 4e-3,
        "{first_trace} {first_retrace}"
    );
}

#[test]
fn the_time_domain_loop_follows_the_same_regimes_over_the_polymer_blend() {
    // The ideal feedback's coexisting regimes (the test above) checked by an independent
    // mechanism: the PI loop integrates the cantilever through the line in the time domain
    // (no branches, no settling rules), at 3000 nm/s (about 5000 drive cycles of the 300 kHz lever per pixel of 50 nm).
    // On the last pixel of each segment of each pass it has settled: Z within 0.01 nm of the
    // ideal feedback's, so it too engages attractive, turns repulsive over the weak polymer
    // and stays repulsive on the way back.
    let case = builtin_case("silicon-air-polymer").unwrap();
    let line = ScanLine::builtin("polymer-blend").unwrap();
    let settings = ScanSettings {
        directions: ScanDirections::Both,
        ..ScanSettings::new(0.8, 6)
    };
    let mut pi = PiSettings::for_case(&case).unwrap();
    pi.scan_rate_nm_per_s = 3000.0;
    let ideal = ideal_scan(&case, &line, &settings).unwrap();
    let timed = pi_scan(&case, &line, &settings, &pi).unwrap();
    assert_eq!(timed.len(), ideal.len());
    for (a, b) in ideal.iter().zip(&timed) {
        assert_eq!((a.index, a.direction), (b.index, b.direction));
        let last_of_segment = match a.direction {
            ScanDirection::Trace => a.index % 2 == 1,
            ScanDirection::Retrace => a.index % 2 == 0,
        };
        if last_of_segment {
            assert!(
                (a.z_nm - b.z_nm).abs() < 0.01 && (a.phase_deg - b.phase_deg).abs() < 0.1,
                "{:?} {}: ideal Z {} phase {}, PI Z {} phase {}",
                a.direction,
                a.index,
                a.z_nm,
                a.phase_deg,
                b.z_nm,
                b.phase_deg
            );
        }
    }
    assert!(timed[1].phase_deg > 90.0 && timed[11].phase_deg < 90.0);
}
