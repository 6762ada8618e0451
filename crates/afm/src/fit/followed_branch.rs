//! The branch an instrument follows on a quasi-static approach (MODEL.md section 13.3): the
//! approach diagram's points in order, keeping only those at a `Z` below every `Z` reached
//! before. Where the diagram folds back (a fold, then an unstable part with `Z` increasing), the
//! followed branch jumps at the fold's `Z` to the sheet the diagram comes back on: a hysteretic
//! jump, as the instrument sees it. Between points the observables are cubic Hermite in `Z`
//! on each smooth stretch, never across a special point (a grazing, where the slope jumps).

use crate::diagram::bifurcation_diagram::{BifurcationDiagram, DiagramPoint};

/// One piece of the followed branch between two jumps: indices of diagram points with `Z`
/// strictly decreasing; it is valid for `Z` down to its last point's `Z` and (for every piece
/// but the first) up to the previous piece's jump.
#[derive(Debug, Clone)]
struct Piece {
    indices: Vec<usize>,
    /// For each interval `(indices[j], indices[j + 1])`: whether no special point of the diagram
    /// lies strictly inside it (a special point at an end is that point's `corner`), so that
    /// the observables are smooth there.
    smooth: Vec<bool>,
    /// For each point: whether a special point sits on it (a corner: the slope jumps there).
    corner: Vec<bool>,
}

impl Piece {
    /// The piece through `indices` of `points`, with its smooth intervals and corners from the
    /// `Z` of the diagram's special points (`special_z`, nm).
    fn new(indices: Vec<usize>, points: &[DiagramPoint], special_z: &[f64]) -> Self {
        let z = |j: usize| points[indices[j]].z_nm;
        let tolerance = |j: usize| 1e-9 * z(j).abs().max(1.0);
        let corner: Vec<bool> = (0..indices.len())
            .map(|j| special_z.iter().any(|&s| (s - z(j)).abs() <= tolerance(j)))
            .collect();
        let smooth = (0..indices.len().saturating_sub(1))
            .map(|j| {
                let (high, low) = (z(j), z(j + 1));
                !special_z
                    .iter()
                    .any(|&s| s < high - tolerance(j) && s > low + tolerance(j + 1))
            })
            .collect();
        Self {
            indices,
            smooth,
            corner,
        }
    }
}

/// The slope at `x[0]` of the parabola through three points (one-sided, exact for quadratics).
fn end_slope(x: [f64; 3], y: [f64; 3]) -> f64 {
    let (h0, h1) = (x[1] - x[0], x[2] - x[1]);
    -(2.0 * h0 + h1) / (h0 * (h0 + h1)) * y[0] + (h0 + h1) / (h0 * h1) * y[1]
        - h0 / (h1 * (h0 + h1)) * y[2]
}

/// The slope at `x[1]` of the parabola through three points (centred, exact for quadratics).
fn middle_slope(x: [f64; 3], y: [f64; 3]) -> f64 {
    let (h0, h1) = (x[1] - x[0], x[2] - x[1]);
    -h1 / (h0 * (h0 + h1)) * y[0] + (h1 - h0) / (h0 * h1) * y[1] + h0 / (h1 * (h0 + h1)) * y[2]
}

/// Which observable of a diagram point is read along the branch.
pub type Reading = fn(&DiagramPoint) -> f64;

/// The followed approach branch of a diagram.
#[derive(Debug, Clone)]
pub struct FollowedBranch {
    /// The diagram it follows.
    pub diagram: BifurcationDiagram,
    pieces: Vec<Piece>,
    /// `Z` of every jump (the fold the instrument falls off), nm, decreasing.
    pub jumps_nm: Vec<f64>,
}

/// An observable read on the branch at one `Z`: its value and its slope `d/dZ` (per nm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BranchValue {
    /// The value, linear between diagram points.
    pub value: f64,
    /// Its slope in `Z` there (0 outside the branch's range, where values are held).
    pub slope: f64,
}

impl FollowedBranch {
    /// The followed branch of `diagram` (an approach: `Z` decreasing from its first point).
    pub fn new(diagram: BifurcationDiagram) -> Self {
        let mut pieces: Vec<Piece> = Vec::new();
        let mut jumps_nm = Vec::new();
        let mut z_min = f64::INFINITY;
        let mut current: Vec<usize> = Vec::new();
        let mut skipped_last: Option<usize> = None;
        for (i, point) in diagram.points.iter().enumerate() {
            if point.z_nm < z_min {
                if let Some(previous) = skipped_last.take() {
                    // Back below the fold: a new piece starts at the skipped point just above.
                    jumps_nm.push(z_min);
                    pieces.push(Piece {
                        indices: std::mem::take(&mut current),
                        smooth: Vec::new(),
                        corner: Vec::new(),
                    });
                    current.push(previous);
                }
                current.push(i);
                z_min = point.z_nm;
            } else {
                skipped_last = Some(i);
            }
        }
        pieces.push(Piece {
            indices: current,
            smooth: Vec::new(),
            corner: Vec::new(),
        });
        let special_z: Vec<f64> = diagram.special_points.iter().map(|s| s.z_nm).collect();
        let pieces = pieces
            .into_iter()
            .map(|p| Piece::new(p.indices, &diagram.points, &special_z))
            .collect();
        Self {
            diagram,
            pieces,
            jumps_nm,
        }
    }

    /// The highest `Z` of the branch, nm (its first point).
    pub fn z_top(&self) -> f64 {
        self.diagram.points.first().map_or(f64::NAN, |p| p.z_nm)
    }

    /// The lowest `Z` of the branch, nm.
    pub fn z_bottom(&self) -> f64 {
        self.pieces
            .last()
            .and_then(|p| p.indices.last())
            .map_or(f64::NAN, |&i| self.diagram.points[i].z_nm)
    }

    /// `read` at separation `z` (nm) on the followed branch, between the two diagram points
    /// around `z` on the piece the instrument is on: cubic Hermite with the slopes of the
    /// parabolas through each end and its neighbours on the same smooth stretch (centred inside
    /// a stretch, one-sided at its ends and at corners), linear on an interval that holds a
    /// special point or on a stretch of two points; held at the end values outside the
    /// branch's range (above it the orbit is free). MODEL.md section 13.3.
    pub fn value(&self, z: f64, read: Reading) -> BranchValue {
        let points = &self.diagram.points;
        let piece_index = self
            .jumps_nm
            .iter()
            .position(|&jump| z >= jump)
            .unwrap_or(self.jumps_nm.len());
        let indices = &self.pieces[piece_index].indices;
        let first = points[indices[0]].z_nm;
        if z >= first {
            return BranchValue {
                value: read(&points[indices[0]]),
                slope: 0.0,
            };
        }
        // Z strictly decreasing along `indices`: find k with z_k >= z > z_{k+1}.
        let k = indices.partition_point(|&i| points[i].z_nm >= z);
        if k >= indices.len() {
            return BranchValue {
                value: read(&points[*indices.last().expect("non-empty piece")]),
                slope: 0.0,
            };
        }
        let piece = &self.pieces[piece_index];
        let j = k - 1;
        let (a, b) = (&points[indices[j]], &points[indices[k]]);
        let (ya, yb) = (read(a), read(b));
        let h = b.z_nm - a.z_nm;
        let chord = (yb - ya) / h;
        if !piece.smooth[j] {
            return BranchValue {
                value: ya + chord * (z - a.z_nm),
                slope: chord,
            };
        }
        let at = |m: usize| (points[indices[m]].z_nm, read(&points[indices[m]]));
        // Whether interval m exists and is on the same smooth stretch.
        let smooth = |m: usize| piece.smooth.get(m).copied().unwrap_or(false);
        let three = |m: [usize; 3]| {
            let (p, q, r) = (at(m[0]), at(m[1]), at(m[2]));
            ([p.0, q.0, r.0], [p.1, q.1, r.1])
        };
        let slope_a = if j >= 1 && smooth(j - 1) && !piece.corner[j] {
            let (x, y) = three([j - 1, j, k]);
            middle_slope(x, y)
        } else if smooth(k) && !piece.corner[k] {
            let (x, y) = three([j, k, k + 1]);
            end_slope(x, y)
        } else {
            chord
        };
        let slope_b = if smooth(k) && !piece.corner[k] {
            let (x, y) = three([j, k, k + 1]);
            middle_slope(x, y)
        } else if j >= 1 && smooth(j - 1) && !piece.corner[j] {
            let (x, y) = three([k, j, j - 1]);
            end_slope(x, y)
        } else {
            chord
        };
        let t = (z - a.z_nm) / h;
        let (t2, t3) = (t * t, t * t * t);
        let value = (2.0 * t3 - 3.0 * t2 + 1.0) * ya
            + (t3 - 2.0 * t2 + t) * h * slope_a
            + (-2.0 * t3 + 3.0 * t2) * yb
            + (t3 - t2) * h * slope_b;
        let slope = ((6.0 * t2 - 6.0 * t) * ya
            + (3.0 * t2 - 4.0 * t + 1.0) * h * slope_a
            + (-6.0 * t2 + 6.0 * t) * yb
            + (3.0 * t2 - 2.0 * t) * h * slope_b)
            / h;
        BranchValue { value, slope }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(z: f64, ratio: f64) -> DiagramPoint {
        DiagramPoint {
            z_nm: z,
            amplitude_ratio: ratio,
            phase_deg: 0.0,
            multiplicity: 1,
            impacts_per_period: 1.0,
            impacts_per_orbit: 1,
            gap_minima: Vec::new(),
            min_gap_nm: None,
            peak_force_nn: 0.0,
            mean_force_nn: 0.0,
            impulse_nn_us: 0.0,
            contact_time_periods: 0.0,
            harmonics: Vec::new(),
            dissipated_ev: 0.0,
            virial_ev: 0.0,
            max_indentation_nm: 0.0,
            mean_indentation_nm: 0.0,
            energy_balance_residual: 0.0,
            floquet_multipliers: Vec::new(),
            spectral_radius: 0.0,
            stable: true,
            state: Vec::new(),
            iterations: 0,
            residual: 0.0,
        }
    }

    /// An S-shaped branch: upper sheet down to a fold at Z = 5, back up to 7, lower sheet
    /// down. The instrument jumps at Z = 5 from the upper sheet (ratio 0.5) to the lower one.
    #[test]
    fn a_fold_becomes_a_jump_at_its_separation() {
        let points = [
            (10.0, 1.0),
            (8.0, 0.8),
            (5.0, 0.5),
            (6.0, 0.45),
            (7.0, 0.4),
            (6.0, 0.3),
            (4.0, 0.2),
        ]
        .iter()
        .map(|&(z, r)| point(z, r))
        .collect();
        let diagram = BifurcationDiagram {
            points,
            special_points: Vec::new(),
            stop: String::new(),
            completed: true,
            error: None,
        };
        let branch = FollowedBranch::new(diagram);
        let ratio: Reading = |p| p.amplitude_ratio;
        assert_eq!(branch.jumps_nm, vec![5.0]);
        // Upper sheet above the fold: linear between (8, 0.8) and (5, 0.5).
        let above = branch.value(5.5, ratio);
        assert!((above.value - 0.55).abs() < 1e-12 && (above.slope - 0.1).abs() < 1e-12);
        // Just below the fold: the lower sheet between (6, 0.3) and (4, 0.2): 0.3 - 0.05 * 1.1.
        let below = branch.value(4.9, ratio);
        assert!((below.value - 0.245).abs() < 1e-12, "{below:?}");
        // Held outside the range.
        assert_eq!(branch.value(12.0, ratio).value, 1.0);
        assert_eq!(branch.value(1.0, ratio).value, 0.2);
    }

    fn special(z: f64) -> crate::diagram::bifurcation_diagram::DiagramSpecialPoint {
        crate::diagram::bifurcation_diagram::DiagramSpecialPoint {
            label: String::from("G2"),
            z_nm: z,
            amplitude_ratio: 0.0,
            phase_deg: 0.0,
            impacts_before: 1,
            impacts_after: 2,
            bracket_nm: [z, z],
            precision_nm: 0.0,
            converged: true,
            state: Vec::new(),
            harmonics: Vec::new(),
            dissipated_ev: 0.0,
            virial_ev: 0.0,
            max_indentation_nm: 0.0,
            mean_indentation_nm: 0.0,
        }
    }

    /// `y = 0.3 + 0.02 Z + 0.004 Z^2` above `kink`, plus `0.05 s + 0.01 s^2` below it
    /// (`s = kink - Z`), and its slope `dy/dZ`.
    fn kinked_curve(kink: f64, z: f64) -> (f64, f64) {
        let s = (kink - z).max(0.0);
        let below = if s > 0.0 { 0.05 + 0.02 * s } else { 0.0 };
        (
            0.3 + 0.02 * z + 0.004 * z * z + 0.05 * s + 0.01 * s * s,
            0.02 + 0.008 * z - below,
        )
    }

    /// Cubic Hermite with parabola slopes reproduces a quadratic exactly (to rounding, 1e-12)
    /// on every interval of a smooth stretch, on both sides of a corner at a special point,
    /// whether the corner lies inside an interval (that interval is linear, within the
    /// chord's error) or on a diagram point.
    #[test]
    fn quadratics_on_each_side_of_a_corner_are_exact() {
        let zs = [10.0, 9.1, 8.3, 7.0, 6.2, 5.5, 4.1, 3.0, 2.2];
        let ratio: Reading = |p| p.amplitude_ratio;
        for kink in [6.6, 6.2] {
            let diagram = BifurcationDiagram {
                points: zs
                    .iter()
                    .map(|&z| point(z, kinked_curve(kink, z).0))
                    .collect(),
                special_points: vec![special(kink)],
                stop: String::new(),
                completed: true,
                error: None,
            };
            let branch = FollowedBranch::new(diagram);
            // Inside the branch's range (outside it the values are held, slope 0).
            for i in 1..156 {
                let z = 10.0 - 0.05 * f64::from(i);
                let (value, slope) = kinked_curve(kink, z);
                let got = branch.value(z, ratio);
                if kink == 6.6 && z < 7.0 && z > 6.2 {
                    // The chord across the corner: its error is below the largest slope
                    // change (0.05 + 0.02 * 0.4) times the interval (0.8) over 4, plus the
                    // curvature's 0.01 * 0.8^2 / 8.
                    assert!((got.value - value).abs() < 0.013, "{z}: {got:?} vs {value}");
                    continue;
                }
                assert!(
                    (got.value - value).abs() < 1e-12,
                    "{kink} {z}: {got:?} vs {value}"
                );
                // The slope between points (at a point it is the next interval's).
                if zs.iter().all(|&x| (z - x).abs() > 1e-9) {
                    assert!((got.slope - slope).abs() < 1e-11, "{kink} {z}: {got:?}");
                }
            }
        }
    }

    /// On a smooth curve (`sin(0.7 Z)`, 40 points 0.2 nm apart) the error is far below the
    /// linear interpolation's `h^2 max|y''| / 8 = 2.5e-3`: at most
    /// `h (4/27) |slope error| + h^4 max|y''''| / 384` with the one-sided parabola's slope error
    /// `h (2h) max|y'''| / 6 = 4.6e-3` at the ends: 1.4e-4.
    #[test]
    fn smooth_curves_interpolate_far_better_than_linearly() {
        let zs: Vec<f64> = (0..40).map(|i| 10.0 - 0.2 * f64::from(i)).collect();
        let diagram = BifurcationDiagram {
            points: zs.iter().map(|&z| point(z, (0.7 * z).sin())).collect(),
            special_points: Vec::new(),
            stop: String::new(),
            completed: true,
            error: None,
        };
        let branch = FollowedBranch::new(diagram);
        let worst = (0..=780)
            .map(|i| 10.0 - 0.01 * f64::from(i))
            .map(|z| (branch.value(z, |p| p.amplitude_ratio).value - (0.7 * z).sin()).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1.5e-4, "worst error {worst}");
    }
}
