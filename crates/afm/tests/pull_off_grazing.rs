//! The grazing of JKR's pull-off surface (MODEL.md section 8, `pull-off`; section 9, JKR) on the
//! approach of the built-in case `biolever-sticky`, against the brute force of
//! `hysteretic_reference/`: a fixed-step RK4 with its own JKR force (the contact radius by
//! bisection of `delta(a)`) and its own attachment flag (set where the gap falls below 0,
//! cleared where it rises above the pull-off gap), sharing with drumroll only the cantilever's
//! free field.

mod hysteretic_reference;

use afm::{approach_diagram, builtin_case, DiagramSettings, TappingModel};
use continuation::Parametrised;
use hysteretic_reference::{attached_force, field, rk4, Jkr};

/// The work of adhesion of the sample `sticky-soft`, mJ/m^2.
const STICKY_W_MJ: f64 = 2.0;

/// The gap's rate `sum_i q_i'` (the separation is constant).
fn gap_rate(x: &[f64]) -> f64 {
    x.iter().skip(1).step_by(2).sum()
}

/// One period of the brute force from the free state `x0` (`steps` RK4 steps, a step that
/// changes the attachment split at the change by bisection to 1e-14 us). Returns, for every
/// attached stretch, how far its highest point lies from the pull-off surface: at an interior
/// maximum of the gap (the rate changing sign between steps) `d_max - d_po` from the parabola
/// through the three samples around it; at a release the virtual maximum `v^2 / (2 |a|)` of the
/// attached flow continued through the surface (`v`, `a` the gap's rate and acceleration there).
fn attached_heights(model: &TappingModel, x0: &[f64], steps: usize) -> Vec<f64> {
    let jkr = Jkr::of(model, STICKY_W_MJ);
    let d_po = jkr.pull_off_gap();
    let period = model.period_us();
    let h = period / steps as f64;
    let (mut t, mut x, mut attached) = (0.0, x0.to_vec(), false);
    let mut heights = Vec::new();
    let mut previous_gaps: Vec<f64> = Vec::new();
    let n = x.len();
    while t < period - 1e-9 * h {
        let step = h.min(period - t);
        let next = rk4(model, attached_force(&jkr, attached), t, &x, step);
        let gap = model.gap(t + step, &next);
        let switches = if attached { gap > d_po } else { gap < 0.0 };
        if !switches {
            if attached {
                previous_gaps.push(gap);
                let m = previous_gaps.len();
                if m >= 3
                    && previous_gaps[m - 2] >= previous_gaps[m - 3]
                    && previous_gaps[m - 2] > gap
                {
                    // Parabola through the last three samples: its vertex height.
                    let (g0, g1, g2) = (previous_gaps[m - 3], previous_gaps[m - 2], gap);
                    let curvature = g0 - 2.0 * g1 + g2;
                    let vertex = g1 - (g2 - g0) * (g2 - g0) / (8.0 * curvature);
                    heights.push(vertex - d_po);
                }
            }
            x = next;
            t += step;
            continue;
        }
        let (mut lo, mut hi) = (0.0, step);
        while hi - lo > 1e-14 {
            let mid = 0.5 * (lo + hi);
            let y = rk4(model, attached_force(&jkr, attached), t, &x, mid);
            let g = model.gap(t + mid, &y);
            if (attached && g > d_po) || (!attached && g < 0.0) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        x = rk4(model, attached_force(&jkr, attached), t, &x, hi);
        t += hi;
        if attached {
            let mut f = vec![0.0; n];
            field(model, &attached_force(&jkr, true), t, &x, &mut f);
            let v = gap_rate(&x);
            let a = gap_rate(&f);
            heights.push(v * v / (2.0 * a.abs()));
        }
        previous_gaps.clear();
        attached = !attached;
    }
    heights
}

/// The approach diagram of `biolever-sticky` locates a `pull-off` point (to 1e-8 nm: its zero is
/// extrapolated past the last orbit Newton converges on, with a precision of 1.8e-9 nm, so not
/// `converged` to the 1e-9 nm tolerance) between its double-impact branch and the attached
/// orbit it jumps to. Its orbit (the releasing orbit nearest it), flowed by
/// the brute force (200 000 steps per period), has an attached stretch whose highest point
/// touches the pull-off surface: the nearest height to it is below 1e-6 nm, while the
/// diagram's own points 1e-3 nm and more above the grazing (the same branch) release with
/// virtual heights above 1e-5 nm (so the check tells the grazing from its neighbours).
/// Measured: the grazing orbit's height 2e-13 nm; the neighbour 1.4e-3 nm above, 2.4e-5 nm.
#[test]
fn approach_locates_the_pull_off_grazing() {
    let model = TappingModel::from_case(&builtin_case("biolever-sticky").unwrap()).unwrap();
    let diagram = approach_diagram(&model, &DiagramSettings::approach(&model)).unwrap();
    let point = diagram
        .special_points
        .iter()
        .find(|p| p.label == "pull-off")
        .expect("a pull-off grazing on the approach");
    assert!(point.precision_nm < 1e-8, "{point:?}");
    assert!(point.bracket_nm[0] <= point.z_nm && point.z_nm <= point.bracket_nm[1]);
    let mut at_point = model.clone();
    at_point.set_parameter(point.z_nm);
    let d_po = Jkr::of(&model, STICKY_W_MJ).pull_off_gap();
    assert!(
        at_point.gap(0.0, &point.state) > d_po,
        "the orbit starts free"
    );
    let heights = attached_heights(&at_point, &point.state, 200_000);
    let nearest = heights
        .iter()
        .map(|h| h.abs())
        .fold(f64::INFINITY, f64::min);
    println!("pull-off at Z = {} nm: heights {heights:?}", point.z_nm);
    assert!(nearest < 1e-6, "nearest height {nearest} nm");
    // A branch point above the grazing (on the approach's side) releases transversally.
    let neighbour = diagram
        .points
        .iter()
        .rfind(|p| p.z_nm > point.z_nm + 1e-3 && p.z_nm < point.z_nm + 0.2)
        .expect("a branch point above the grazing");
    let mut at_neighbour = model.clone();
    at_neighbour.set_parameter(neighbour.z_nm);
    let heights = attached_heights(&at_neighbour, &neighbour.state, 200_000);
    let nearest_neighbour = heights
        .iter()
        .map(|h| h.abs())
        .fold(f64::INFINITY, f64::min);
    println!(
        "neighbour at Z = {} nm: heights {heights:?}",
        neighbour.z_nm
    );
    assert!(
        nearest_neighbour > 1e-5,
        "neighbour height {nearest_neighbour} nm"
    );
}
