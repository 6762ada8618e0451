//! The defining systems of codimension-one points of periodic orbits, continued in two
//! parameters `(p, q)` (MODEL.md section 8).
//!
//! * **Grazing**: unknowns `u = (x, s, p, q)`, `x` the state at the section time `t0` and `s`
//!   the time of the grazing minimum of the gap `h`; equations `P(x) - x = 0` (the period map
//!   from `t0`), `h(phi(s)) = 0` and `dh/dt(phi(s)) = 0` (`phi(s)` the state at `s`):
//!   `n + 2` equations in `n + 3` unknowns. The flow is split at `s`, so
//!   `d h(phi(s))/dx = grad h . Phi(s, t0)` and `d h/ds = dh/dt` come from the solver's own
//!   transition matrix; `grad(dh/dt)` is a central difference of the switching rate (no
//!   integration).
//! * **Fold** (multiplier `mu = +1`) and **period doubling** (`mu = -1`): unknowns
//!   `u = (x, p, q)`, equations `P(x) - x = 0` and `g(x, p, q) = 0`, the minimally augmented
//!   test function: `[[M - mu I, b], [c^T, 0]] [v; g] = [0; 1]` with the transposed system
//!   giving `w`, and `dg/dz = -w^T d(M)/dz v` (Govaerts, *Numerical Methods for Bifurcations
//!   of Dynamical Equilibria*, Sec. 4.4): the `x` and `p` parts by one forward difference of
//!   the flow along `v` (second derivatives are symmetric), the `q` part with the other
//!   `q` derivatives.
//!
//! Derivatives in `q` are forward differences of whole flows ([`crate::TwoParameterProblem`]).

use std::cell::{Cell, RefCell};

use hybrid::{FlowMap, HybridSystem, Sensitivity};

use crate::hybrid_problem::Parametrised;
use nalgebra::{DMatrix, DVector};

use crate::error::ContinuationError;
use crate::problem::OrbitStructure;
use crate::two_parameter::{SystemFamily, TwoParameterProblem};

/// Which codimension-one point a curve follows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CodimOneKind {
    /// A local minimum of the contact gap exactly at zero with zero rate.
    Grazing,
    /// A Floquet multiplier at `+1` (a turning point of the orbit branch in `p`).
    Fold,
    /// A Floquet multiplier at `-1`.
    PeriodDoubling,
}

/// Fraction of the period map's duration around the grazing time within which an event on the
/// contact surface belongs to the grazing minimum itself.
pub(crate) const GRAZING_WINDOW: f64 = 5e-3;

/// The gap `h` and its rate `dh/dt` at a state, with their partial derivatives.
struct GapAt {
    /// `[h, dh/dt]`.
    values: [f64; 2],
    /// Their gradients in the state (`2 x n`).
    gradients: DMatrix<f64>,
    /// Their derivatives along the flow in time.
    time: [f64; 2],
    /// Their explicit derivatives in `p`.
    parameter: [f64; 2],
}

/// One evaluation of a defining system at `u`.
#[derive(Debug, Clone)]
pub(crate) struct Evaluation {
    /// The equations' values (`m - 1`).
    pub residual: DVector<f64>,
    /// Their Jacobian (`(m - 1) x m`).
    pub jacobian: DMatrix<f64>,
    /// The monodromy of the period map from `t0`.
    pub monodromy: DMatrix<f64>,
    /// Structure of the contact gap over the period map (for a grazing, its impacts exclude a
    /// touch of the grazing minimum itself).
    pub structure: OrbitStructure,
    /// Whether the grazing minimum itself touches the surface (grazing curves only): such an
    /// iterate lies on the non-smooth side and is not accepted by the corrector.
    pub touching: bool,
}

/// A defining system bound to its problem, with its section time and (fold, period doubling)
/// its bordering vectors.
pub(crate) struct Defining<'a, F: SystemFamily> {
    pub problem: &'a TwoParameterProblem<F>,
    pub kind: CodimOneKind,
    /// Section time `t0` (absolute system time).
    pub section: Cell<f64>,
    /// Bordering vectors `(b, c)` of the multiplier test function.
    pub borders: RefCell<(DVector<f64>, DVector<f64>)>,
}

impl<'a, F: SystemFamily> Defining<'a, F> {
    /// Dimension `n` of the orbit state.
    pub fn n(&self) -> usize {
        self.problem.dim()
    }

    /// Number of unknowns `m`.
    pub fn unknowns(&self) -> usize {
        match self.kind {
            CodimOneKind::Grazing => self.n() + 3,
            _ => self.n() + 2,
        }
    }

    /// The multiplier of a fold or period-doubling system.
    fn mu(&self) -> f64 {
        if self.kind == CodimOneKind::PeriodDoubling {
            -1.0
        } else {
            1.0
        }
    }

    /// Step of the forward difference in `q`.
    pub fn q_step(q: f64) -> f64 {
        1e-7 * q.abs().max(1e-3)
    }

    /// Evaluate the defining system at `u`.
    pub fn evaluate(&self, u: &DVector<f64>) -> Result<Evaluation, ContinuationError> {
        match self.kind {
            CodimOneKind::Grazing => self.grazing(u),
            _ => self.multiplier(u),
        }
    }

    /// `h`, `dh/dt` at `(s, y)` and their derivatives in state, time and `p`.
    fn gap_at(
        &self,
        s: f64,
        y: &[f64],
        mode: hybrid::Mode,
        p: f64,
        q: f64,
    ) -> Result<GapAt, ContinuationError> {
        let n = y.len();
        let (h, gradient, partials, rate, rate_gradient, rate_t, field) =
            self.problem.with_system(p, q, |system| {
                let k = system.contact_surface();
                let rate_at = |t: f64, state: &[f64]| system.switching_rate(k, mode, t, state);
                let mut gradient = vec![0.0; n];
                let partials = system.switching_gradient(k, s, y, &mut gradient);
                let mut shifted = y.to_vec();
                let mut rate_gradient = vec![0.0; n];
                for i in 0..n {
                    let e = 1e-6 * y[i].abs().max(1.0);
                    shifted[i] = y[i] + e;
                    let up = rate_at(s, &shifted);
                    shifted[i] = y[i] - e;
                    let down = rate_at(s, &shifted);
                    shifted[i] = y[i];
                    rate_gradient[i] = (up - down) / (2.0 * e);
                }
                let e = 1e-6 * system.period();
                let rate_t = (rate_at(s + e, y) - rate_at(s - e, y)) / (2.0 * e);
                let mut field = vec![0.0; n];
                system.vector_field(mode, s, y, &mut field);
                (
                    system.switching(k, s, y),
                    gradient,
                    partials,
                    rate_at(s, y),
                    rate_gradient,
                    rate_t,
                    field,
                )
            })?;
        let e = 1e-6 * p.abs().max(1.0);
        let rate_p = |pp: f64| {
            self.problem.with_system(pp, q, |system| {
                let k = system.contact_surface();
                system.switching_rate(k, mode, s, y)
            })
        };
        let rate_dp = (rate_p(p + e)? - rate_p(p - e)?) / (2.0 * e);
        let mut gradients = DMatrix::zeros(2, n);
        for i in 0..n {
            gradients[(0, i)] = gradient[i];
            gradients[(1, i)] = rate_gradient[i];
        }
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
        let time = [
            dot(&gradient, &field) + partials.t,
            dot(&rate_gradient, &field) + rate_t,
        ];
        Ok(GapAt {
            values: [h, rate],
            gradients,
            time,
            parameter: [partials.p, rate_dp],
        })
    }

    /// The split flows `t0 -> s -> t0 + D` at `(x, p, q)`.
    fn split_flows(
        &self,
        x: &[f64],
        s: f64,
        p: f64,
        q: f64,
        sensitivity: Sensitivity,
    ) -> Result<(FlowMap, FlowMap, f64), ContinuationError> {
        let t0 = self.section.get();
        let d = self.problem.duration(q)?;
        if !(s > t0 && s < t0 + d) {
            return Err(ContinuationError::PeriodMapFailed {
                parameter: p,
                message: format!("grazing time {s} outside the period map [{t0}, {})", t0 + d),
            });
        }
        let a = self.problem.flow(x, p, q, t0, s - t0, sensitivity)?;
        // The second leg continues in the mode the first ended in (at the grazing `d = 0`,
        // `d' = 0` a hysteretic system's mode_of cannot tell attached from free).
        let b = self
            .problem
            .flow_in(&a.state, Some(a.mode), p, q, s, t0 + d - s, sensitivity)?;
        Ok((a, b, d))
    }

    /// The grazing system at `u = (x, s, p, q)`.
    fn grazing(&self, u: &DVector<f64>) -> Result<Evaluation, ContinuationError> {
        let n = self.n();
        let x = &u.as_slice()[..n];
        let (s, p, q) = (u[n], u[n + 1], u[n + 2]);
        let t0 = self.section.get();
        let (a, b, d) = self.split_flows(x, s, p, q, Sensitivity::TransitionAndParameter)?;
        let phi1 = &a.transition;
        let monodromy = &b.transition * phi1;
        let yp = DVector::from_column_slice(&a.parameter_sensitivity);
        let pp = &b.transition * &yp + DVector::from_column_slice(&b.parameter_sensitivity);
        let GapAt {
            values,
            gradients,
            time,
            parameter: partial_p,
        } = self.gap_at(s, &a.state, a.mode, p, q)?;
        let dq = Self::q_step(q);
        let (aq, bq, _) = self.split_flows(x, s, p, q + dq, Sensitivity::None)?;
        let values_q = self.gap_at(s, &aq.state, aq.mode, p, q + dq)?.values;
        let m = n + 3;
        let mut residual = DVector::zeros(n + 2);
        let mut jacobian = DMatrix::zeros(n + 2, m);
        for i in 0..n {
            residual[i] = b.state[i] - x[i];
            for j in 0..n {
                jacobian[(i, j)] = monodromy[(i, j)];
            }
            jacobian[(i, i)] -= 1.0;
            jacobian[(i, n + 1)] = pp[i];
            jacobian[(i, n + 2)] = (bq.state[i] - b.state[i]) / dq;
        }
        let by_state = &gradients * phi1;
        let by_p = &gradients * &yp;
        for r in 0..2 {
            residual[n + r] = values[r];
            for j in 0..n {
                jacobian[(n + r, j)] = by_state[(r, j)];
            }
            jacobian[(n + r, n)] = time[r];
            jacobian[(n + r, n + 1)] = by_p[r] + partial_p[r];
            jacobian[(n + r, n + 2)] = (values_q[r] - values[r]) / dq;
        }
        let window = GRAZING_WINDOW * d;
        let k = self
            .problem
            .with_system(p, q, |system| system.contact_surface())?;
        let own = |e: &&hybrid::Event| e.surface == k && (e.t - s).abs() < window;
        let touching = a.events.iter().chain(&b.events).any(|e| own(&e));
        let own_impacts = a
            .events
            .iter()
            .chain(&b.events)
            .filter(|e| own(e) && e.direction == hybrid::Direction::Down)
            .count();
        let mut structure = self.problem.structure(&[&a, &b], t0, d, x, p, q)?;
        // The impacts of the orbit on its free side: a touch of the grazing minimum itself
        // (numerically either side of zero at the root) is not counted.
        structure.impacts = structure.impacts.saturating_sub(own_impacts);
        Ok(Evaluation {
            residual,
            jacobian,
            monodromy,
            structure,
            touching,
        })
    }

    /// Solve the bordered system of `A = M - mu I` and its transpose: `(v, w, g)`.
    fn bordered(
        &self,
        monodromy: &DMatrix<f64>,
        p: f64,
    ) -> Result<(DVector<f64>, DVector<f64>, f64), ContinuationError> {
        let n = monodromy.nrows();
        let (b, c) = self.borders.borrow().clone();
        let mut big = DMatrix::zeros(n + 1, n + 1);
        for i in 0..n {
            for j in 0..n {
                big[(i, j)] = monodromy[(i, j)];
            }
            big[(i, i)] -= self.mu();
            big[(i, n)] = b[i];
            big[(n, i)] = c[i];
        }
        let mut rhs = DVector::zeros(n + 1);
        rhs[n] = 1.0;
        let singular = ContinuationError::SingularMatrix {
            what: "bordered multiplier matrix",
            parameter: p,
        };
        let lu = big.clone().lu();
        let vg = lu.solve(&rhs).ok_or(singular.clone())?;
        let wg = big.transpose().lu().solve(&rhs).ok_or(singular)?;
        Ok((
            vg.rows(0, n).into_owned(),
            wg.rows(0, n).into_owned(),
            vg[n],
        ))
    }

    /// The fold or period-doubling system at `u = (x, p, q)`.
    fn multiplier(&self, u: &DVector<f64>) -> Result<Evaluation, ContinuationError> {
        let n = self.n();
        let x = &u.as_slice()[..n];
        let (p, q) = (u[n], u[n + 1]);
        let t0 = self.section.get();
        let d = self.problem.duration(q)?;
        let full = Sensitivity::TransitionAndParameter;
        let base = self.problem.flow(x, p, q, t0, d, full)?;
        let monodromy = base.transition.clone();
        let pp = DVector::from_column_slice(&base.parameter_sensitivity);
        let (v, w, g) = self.bordered(&monodromy, p)?;
        let v_norm = v.norm().max(f64::MIN_POSITIVE);
        let scale = x.iter().fold(1.0f64, |m, xi| m.max(xi.abs()));
        let e = 1e-7 * scale;
        let shifted: Vec<f64> = x
            .iter()
            .zip(v.iter())
            .map(|(xi, vi)| xi + e * vi / v_norm)
            .collect();
        let along = self.problem.flow(&shifted, p, q, t0, d, full)?;
        let dm_v = (&along.transition - &monodromy) * (v_norm / e);
        let dpp_v = (DVector::from_column_slice(&along.parameter_sensitivity) - &pp) * (v_norm / e);
        let dq = Self::q_step(q);
        let dq_duration = self.problem.duration(q + dq)?;
        let by_q = self
            .problem
            .flow(x, p, q + dq, t0, dq_duration, Sensitivity::Transition)?;
        let g_q = -(w.transpose() * (&by_q.transition - &monodromy) * &v)[0] / dq;
        let g_x = -(w.transpose() * dm_v);
        let g_p = -w.dot(&dpp_v);
        let mut residual = DVector::zeros(n + 1);
        let mut jacobian = DMatrix::zeros(n + 1, n + 2);
        for i in 0..n {
            residual[i] = base.state[i] - x[i];
            for j in 0..n {
                jacobian[(i, j)] = monodromy[(i, j)];
            }
            jacobian[(i, i)] -= 1.0;
            jacobian[(i, n)] = pp[i];
            jacobian[(i, n + 1)] = (by_q.state[i] - base.state[i]) / dq;
            jacobian[(n, i)] = g_x[i];
        }
        residual[n] = g;
        jacobian[(n, n)] = g_p;
        jacobian[(n, n + 1)] = g_q;
        let structure = self.problem.structure(&[&base], t0, d, x, p, q)?;
        Ok(Evaluation {
            residual,
            jacobian,
            monodromy,
            structure,
            touching: false,
        })
    }

    /// After a point is accepted: new bordering vectors from the null vectors of
    /// `M - mu I` there (fold and period doubling; nothing for grazing).
    pub fn accept(&self, evaluation: &Evaluation, p: f64) -> Result<(), ContinuationError> {
        if self.kind == CodimOneKind::Grazing {
            return Ok(());
        }
        let (v, w, _) = self.bordered(&evaluation.monodromy, p)?;
        let (nv, nw) = (v.norm(), w.norm());
        if nv > 0.0 && nw > 0.0 && nv.is_finite() && nw.is_finite() {
            *self.borders.borrow_mut() = (w / nw, v / nv);
        }
        Ok(())
    }

    /// Initial bordering vectors: the left and right singular vectors of `M - mu I` of its
    /// smallest singular value.
    pub fn init_borders(&self, monodromy: &DMatrix<f64>) {
        let n = monodromy.nrows();
        let mut a = monodromy.clone();
        for i in 0..n {
            a[(i, i)] -= self.mu();
        }
        let svd = a.svd(true, true);
        let (Some(left), Some(right_t)) = (svd.u, svd.v_t) else {
            return;
        };
        let smallest = svd
            .singular_values
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(b.1))
            .map_or(0, |(i, _)| i);
        let b = left.column(smallest).into_owned();
        let c = right_t.row(smallest).transpose();
        *self.borders.borrow_mut() = (b, c);
    }
}
