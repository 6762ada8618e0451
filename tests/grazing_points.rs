//! The grazing points of the four paper cases (MODEL.md sections 5 and 6), located by the
//! continuation (`afm::approach_diagram`), checked three ways:
//!
//! * against the regression fixtures `fixtures/grazing/<case>.json` (label, `Z`, impacts on
//!   each side), so that a silent change of the located points shows;
//! * G1 against the exact first-contact separation of the free (linear) solution;
//! * every `G_n` independently: a plain time-domain run (no Newton, no continuation) at
//!   `Z_G +/- 1e-3 nm`, started on the located orbit and run for 60 periods, shows `n - 1`
//!   impacts per period on one side and `n` on the other, with the grazing gap minimum a near
//!   impact (positive) on the first side and a shallow impact (negative) on the second.

use std::path::PathBuf;
use std::sync::OnceLock;

use acceptance::{state_distance, time_domain_run};
use afm::{
    approach_diagram, builtin_case, diagram, BifurcationDiagram, DiagramPoint, DiagramSettings,
    DiagramSpecialPoint, TappingModel,
};
use serde::Deserialize;

/// The paper's four cases (MODEL.md section 6).
const CASES: [&str; 4] = [
    "biolever-mica",
    "biolever-soft",
    "maclever-mica",
    "maclever-soft",
];

/// Offset of the time-domain runs from a grazing point, nm (the 1e-3 nm).
const OFFSET_NM: f64 = 1e-3;

/// Periods of each time-domain run. The slowest free decay loses `exp(-pi / Q_1)` per period
/// (0.07 for the Biolever, 0.14 for the MAClever), and away from folds the branch has
/// `|mu_max| <= 0.86`, so 60 periods leave a small fraction of a start that is already within
/// ~1e-3 nm of the orbit. Near the MAClever-on-mica folds (3e-3 nm below G1) the decay is
/// slower, so that the run has settled is checked rather than assumed: its drift over the last
/// period must be below 1e-8 (measured: at most 7e-11).
const PERIODS: usize = 60;

/// A regression fixture: the special points of one case's approach diagram.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct GrazingFixture {
    /// How the values were computed and how they are confirmed.
    description: String,
    /// The built-in case name.
    case: String,
    /// Exact first contact of the free orbit, nm.
    first_contact_z_nm: f64,
    /// The special points in branch order.
    special_points: Vec<FixturePoint>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FixturePoint {
    label: String,
    z_nm: f64,
    impacts_before: usize,
    impacts_after: usize,
}

fn fixture(case: &str) -> GrazingFixture {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures/grazing")
        .join(format!("{case}.json"));
    let text = std::fs::read_to_string(&path).expect("fixture file");
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

struct Computed {
    model: TappingModel,
    approach: BifurcationDiagram,
}

/// The four approach diagrams, computed once for all tests of this file.
fn computed() -> &'static [Computed] {
    static DIAGRAMS: OnceLock<Vec<Computed>> = OnceLock::new();
    DIAGRAMS.get_or_init(|| {
        CASES
            .iter()
            .map(|name| {
                let model = TappingModel::from_case(&builtin_case(name).expect("built-in case"))
                    .expect("model");
                let approach = approach_diagram(&model, &DiagramSettings::approach(&model))
                    .expect("approach diagram");
                Computed { model, approach }
            })
            .collect()
    })
}

/// `n` of a label `G<n>`, if it is one.
fn grazing_order(label: &str) -> Option<usize> {
    label.strip_prefix('G')?.parse().ok()
}

#[test]
fn special_points_match_the_regression_fixtures() {
    for (name, computed) in CASES.iter().zip(computed()) {
        let fixture = fixture(name);
        assert_eq!(fixture.case, *name);
        assert!(!fixture.description.is_empty());
        let found = &computed.approach.special_points;
        let labels: Vec<&str> = found.iter().map(|s| s.label.as_str()).collect();
        let expected: Vec<&str> = fixture
            .special_points
            .iter()
            .map(|s| s.label.as_str())
            .collect();
        assert_eq!(labels, expected, "{name}: special points in branch order");
        // The fixture's first contact is the free solution's: the minimum of a trigonometric
        // polynomial, found by root finding to rounding (measured changes between versions of
        // that code: 2e-15 nm); 1e-12 nm is far below anything the diagram resolves.
        let first_contact = computed.model.grazing_separation_nm();
        assert!(
            (fixture.first_contact_z_nm - first_contact).abs() < 1e-12,
            "{name}: first contact {first_contact} nm, fixture {} nm",
            fixture.first_contact_z_nm
        );
        for (s, f) in found.iter().zip(&fixture.special_points) {
            // Each point is located to |dZ| < 1e-9 nm; the orbit under it is integrated at
            // tolerances 1e-12 and Newton-converged to 1e-10, so a recomputation (possibly
            // along other branch points, after changes in the step control) may land within
            // the location precision on either side: 1e-8 nm leaves a factor 10 for that.
            assert!(
                (s.z_nm - f.z_nm).abs() < 1e-8,
                "{name} {}: Z = {} nm, fixture {} nm",
                s.label,
                s.z_nm,
                f.z_nm
            );
            assert_eq!(
                (s.impacts_before, s.impacts_after),
                (f.impacts_before, f.impacts_after),
                "{name} {}",
                s.label
            );
            assert!(s.converged, "{name} {}: location converged", s.label);
            // The target: every special point to 1e-9 nm.
            assert!(
                s.precision_nm < 1e-9,
                "{name} {}: precision {} nm",
                s.label,
                s.precision_nm
            );
        }
    }
}

#[test]
fn g1_and_g2_are_located_on_every_case_and_g3_on_the_biolevers() {
    for (name, computed) in CASES.iter().zip(computed()) {
        let orders: Vec<usize> = computed
            .approach
            .special_points
            .iter()
            .filter_map(|s| grazing_order(&s.label))
            .collect();
        // Impact counts along the branch: G_n must appear exactly where the count first reaches
        // n (the branch from the free orbit reaches every count from 0 to its largest).
        let most = computed
            .approach
            .points
            .iter()
            .map(|p| p.impacts_per_orbit)
            .max()
            .expect("points");
        let expected: Vec<usize> = (1..=most).collect();
        assert_eq!(orders, expected, "{name}: G_n labels vs counts reached");
        assert!(most >= 2, "{name}: G1 and G2 on every case");
        // The Biolevers reach the triple-impact regime above A/A0 = 0.3 (the paper's Fig. 1(c)
        // shows three impacts at A/A0 = 0.50 on mica); the MAClevers stop at A/A0 = 0.3 in
        // the double-impact regime.
        let expect_g3 = name.starts_with("biolever");
        assert_eq!(
            most >= 3,
            expect_g3,
            "{name}: G3 where the branch reaches it"
        );
        // Several hundred points per diagram (the issue's >= 300).
        assert!(computed.approach.points.len() >= 300, "{name}");
        assert!(
            computed.approach.error.is_none(),
            "{name}: branch ended early"
        );
    }
}

#[test]
fn g1_is_the_exact_first_contact_of_the_free_solution() {
    for (name, computed) in CASES.iter().zip(computed()) {
        let model = &computed.model;
        let g1 = &computed.approach.special_points[0];
        assert_eq!(g1.label, "G1", "{name}");
        let exact = model.grazing_separation_nm();
        // The tolerance: 1e-9 nm.
        assert!(
            (g1.z_nm - exact).abs() < 1e-9,
            "{name}: G1 at {} nm, free solution {exact} nm",
            g1.z_nm
        );
        // And the free solution's number is itself confirmed in the time domain: the free
        // orbit at Z_G1 +/- 1e-6 nm does not touch / touches the sample once per period, with
        // its lowest gap +/- 1e-6 nm (to 1e-9 nm: on the contact side the Hertz force itself
        // shifts the orbit slightly, measured 2.4e-10 nm on mica; the integration error is
        // ~1e-13 nm, seen on the free side).
        for (offset, impacts) in [(1e-6, 0), (-1e-6, 1)] {
            let run = time_domain_run(model, exact + offset, &model.free_state(), PERIODS);
            assert_eq!(run.impacts_last_period, impacts, "{name}: Z_G1 {offset:+e}");
            assert!(
                (run.lowest_gap_nm - offset).abs() < 1e-9,
                "{name}: lowest gap {} nm at Z_G1 {offset:+e}",
                run.lowest_gap_nm
            );
        }
    }
}

/// Impacts per period of the stable orbits of `diagram` at `z`: one entry per stable segment
/// (consecutive stable branch points) covering `z`, as `(index of the segment's first point,
/// impacts, state interpolated linearly along the segment)`. A segment over which the count
/// changes holds a special point; its count at `z` is that of the end on `z`'s side of it.
fn stable_orbits_at(diagram: &BifurcationDiagram, z: f64) -> Vec<(usize, usize, Vec<f64>)> {
    let mut orbits = Vec::new();
    for (i, w) in diagram.points.windows(2).enumerate() {
        let (a, b): (&DiagramPoint, &DiagramPoint) = (&w[0], &w[1]);
        let (low, high) = (a.z_nm.min(b.z_nm), a.z_nm.max(b.z_nm));
        if !(a.stable && b.stable && low <= z && z <= high) {
            continue;
        }
        let impacts = if a.impacts_per_orbit == b.impacts_per_orbit {
            a.impacts_per_orbit
        } else {
            let special = diagram
                .special_points
                .iter()
                .find(|s| low <= s.z_nm && s.z_nm <= high)
                .expect("a special point where the count changes");
            if (z - special.z_nm) * (a.z_nm - special.z_nm) > 0.0 {
                a.impacts_per_orbit
            } else {
                b.impacts_per_orbit
            }
        };
        let s = if high > low {
            (z - a.z_nm) / (b.z_nm - a.z_nm)
        } else {
            0.0
        };
        let state = a
            .state
            .iter()
            .zip(&b.state)
            .map(|(x, y)| x + s * (y - x))
            .collect();
        orbits.push((i, impacts, state));
    }
    orbits
}

/// The index `i` of the branch segment `(i, i + 1)` that holds the special point `g`: its ends
/// bracket `g`'s separation and carry its impact counts before and after.
fn segment_of(diagram: &BifurcationDiagram, g: &DiagramSpecialPoint) -> usize {
    diagram
        .points
        .windows(2)
        .position(|w| {
            let (low, high) = (w[0].z_nm.min(w[1].z_nm), w[0].z_nm.max(w[1].z_nm));
            low <= g.z_nm
                && g.z_nm <= high
                && w[0].impacts_per_orbit == g.impacts_before
                && w[1].impacts_per_orbit == g.impacts_after
        })
        .expect("the special point lies between two branch points with its counts")
}

#[test]
fn every_grazing_point_separates_n_minus_1_from_n_impacts_in_the_time_domain() {
    for (name, computed) in CASES.iter().zip(computed()) {
        let (model, approach) = (&computed.model, &computed.approach);
        for g in &approach.special_points {
            let Some(n) = grazing_order(&g.label) else {
                continue;
            };
            // On approach, G_n goes from n - 1 impacts (before) to n (after).
            assert_eq!(
                (g.impacts_before, g.impacts_after),
                (n - 1, n),
                "{name} {}",
                g.label
            );
            let segment = segment_of(approach, g);
            // The side of Z_G on which the branch has n - 1 impacts: where the point before it
            // lies (the approach runs towards lower Z there; no fold is within 1e-3 nm of a G).
            let before_side = (approach.points[segment].z_nm - g.z_nm).signum();
            for side in [1.0, -1.0] {
                let z = g.z_nm + side * OFFSET_NM;
                let run = time_domain_run(model, z, &g.state, PERIODS);
                let context = format!(
                    "{name} {} at Z_G {:+e} nm = {z} nm",
                    g.label,
                    side * OFFSET_NM
                );
                // The run settled on a period-1 orbit (integration tolerance 1e-12 per step;
                // measured drifts below 1e-10 nm).
                assert!(
                    run.period_drift() < 1e-8,
                    "{context}: drift {}",
                    run.period_drift()
                );
                // Which orbit it landed on: the nearest stable orbit of the diagram at this Z,
                // which must be on the branch through G: joined to G's segment by stable points
                // only (in the MAClever-on-mica bistable range below G1 another stable orbit
                // exists, past the unstable middle part of the S between the folds, 0.02-0.6 nm
                // away in state, and the run must not go there).
                let orbits = stable_orbits_at(approach, z);
                let (nearest_segment, branch_impacts, distance) = orbits
                    .iter()
                    .map(|(i, impacts, state)| {
                        (*i, *impacts, state_distance(state, &run.final_state))
                    })
                    .min_by(|a, b| a.2.total_cmp(&b.2))
                    .unwrap_or_else(|| panic!("{context}: no stable orbit in the diagram"));
                let (from, to) = (nearest_segment.min(segment), nearest_segment.max(segment));
                assert!(
                    approach.points[from..=to + 1].iter().all(|p| p.stable),
                    "{context}: landed near segment {nearest_segment}, not on G's stable run \
                     (G on segment {segment})"
                );
                // Linear interpolation between branch points spaced <= A0/250 in arclength:
                // its error is far below the distance to any other orbit; measured < 2e-3.
                assert!(distance < 1e-2, "{context}: {distance} from the branch");
                let expected = if side == before_side { n - 1 } else { n };
                // The count of the stable orbit(s) of the diagram at this Z ...
                assert_eq!(branch_impacts, expected, "{context}: diagram count");
                // ... confirmed by the time domain.
                assert_eq!(
                    run.impacts_last_period, expected,
                    "{context}: time-domain count"
                );
                // The grazing minimum is the gap minimum closest to zero: a near impact
                // (positive) on the n - 1 side, a shallow impact (negative) on the n side, both
                // of the order of the offset (|d(gap)/dZ| is O(1); measured |gap| <= 1.4e-3 nm).
                let grazing_gap = run
                    .gap_minima_nm
                    .iter()
                    .copied()
                    .min_by(|a, b| a.abs().total_cmp(&b.abs()))
                    .expect("gap minima");
                assert!(
                    grazing_gap.abs() < 1e-2,
                    "{context}: grazing gap {grazing_gap}"
                );
                assert_eq!(
                    grazing_gap < 0.0,
                    expected == n,
                    "{context}: grazing gap {grazing_gap} on the {} side",
                    if expected == n { "impacting" } else { "free" }
                );
                eprintln!(
                    "{context}: {} impacts, grazing gap {grazing_gap:+.3e} nm, drift {:.1e}, {distance:.1e} nm from branch segment {nearest_segment} (G on {segment}), {} stable orbit(s) here",
                    run.impacts_last_period,
                    run.period_drift(),
                    orbits.len()
                );
            }
        }
    }
}

#[test]
fn the_maclever_on_mica_retract_meets_the_same_points_in_reverse() {
    let computed = &computed()[2];
    let (model, approach) = (&computed.model, &computed.approach);
    let lowest = approach
        .points
        .iter()
        .min_by(|a, b| a.z_nm.total_cmp(&b.z_nm))
        .expect("points");
    let retract = diagram(
        model,
        &lowest.state,
        lowest.z_nm,
        &DiagramSettings::retract(model),
    )
    .expect("retract diagram");
    let forward: Vec<(&str, f64, usize, usize)> = approach
        .special_points
        .iter()
        .map(|s| (s.label.as_str(), s.z_nm, s.impacts_before, s.impacts_after))
        .collect();
    let mut backward: Vec<(&str, f64, usize, usize)> = retract
        .special_points
        .iter()
        .map(|s| (s.label.as_str(), s.z_nm, s.impacts_after, s.impacts_before))
        .collect();
    backward.reverse();
    assert_eq!(forward.len(), backward.len());
    for (f, b) in forward.iter().zip(&backward) {
        assert_eq!((f.0, f.2, f.3), (b.0, b.2, b.3));
        // Two independent locations (other branch points, other brackets), each to 1e-9 nm.
        assert!((f.1 - b.1).abs() < 2e-9, "{}: {} vs {} nm", f.0, f.1, b.1);
    }
}
