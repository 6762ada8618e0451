//! The branch an instrument follows on a quasi-static approach (MODEL.md section 13.3): the
//! approach diagram's points in order, keeping only those at a `Z` below every `Z` reached
//! before. Where the diagram folds back (a fold, then an unstable part with `Z` increasing), the
//! followed branch jumps at the fold's `Z` to the sheet the diagram comes back on: a hysteretic
//! jump, as the instrument sees it. Between points the observables are linear in `Z`.

use crate::diagram::bifurcation_diagram::{BifurcationDiagram, DiagramPoint};

/// One piece of the followed branch between two jumps: indices of diagram points with `Z`
/// strictly decreasing; it is valid for `Z` down to its last point's `Z` and (for every piece
/// but the first) up to the previous piece's jump.
#[derive(Debug, Clone)]
struct Piece {
    indices: Vec<usize>,
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
                    });
                    current.push(previous);
                }
                current.push(i);
                z_min = point.z_nm;
            } else {
                skipped_last = Some(i);
            }
        }
        pieces.push(Piece { indices: current });
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

    /// `read` at separation `z` (nm) on the followed branch: linear between the two diagram
    /// points around `z` on the piece the instrument is on; held at the end values outside the
    /// branch's range (above it the orbit is free).
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
        let (a, b) = (&points[indices[k - 1]], &points[indices[k]]);
        let slope = (read(b) - read(a)) / (b.z_nm - a.z_nm);
        BranchValue {
            value: read(a) + slope * (z - a.z_nm),
            slope,
        }
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
}
