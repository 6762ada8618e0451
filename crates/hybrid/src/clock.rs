//! The independent variable of a Runge-Kutta step: time itself, or the signed square root of
//! the time from a reference instant.
//!
//! Next to a transversal crossing of a surface whose switching function enters the field
//! through half-integer powers of `|h|` (the Hertz force `c (-h)^{3/2}`), the solution is not
//! smooth in time: the force grows like `|t - t_c|^{3/2}`, the state like `|t - t_c|^{7/2}`, and
//! an 8th-order step ending or starting at `t_c` has an error of order 3.5 in its length. In
//! `sigma = sign(t - t_c) sqrt(|t - t_c|)` the same solution is smooth (`|h|` is a smooth
//! function of `sigma^2` with a simple zero, so `|h|^{1/2}` is smooth in `sigma`), and the
//! method keeps its order up to the crossing. The step integrates `dz/dsigma = (dt/dsigma)
//! f(t(sigma), z)` with `t(sigma) = t_c + sigma |sigma|`, `dt/dsigma = 2 |sigma|`; the
//! variational equations scale the same way, so the transition matrix keeps its meaning
//! `dx(t)/dx(t0)` at fixed times.

/// How a Runge-Kutta step measures its progress.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Clock {
    /// `sigma = t`.
    Time,
    /// `sigma = sign(t - reference) sqrt(|t - reference|)`: `t = reference + sigma |sigma|`.
    SquareRoot {
        /// The crossing time `t_c` the square root is taken from (system time units).
        reference: f64,
    },
}

impl Clock {
    /// The time at `sigma`.
    #[inline]
    pub fn time(self, sigma: f64) -> f64 {
        match self {
            Clock::Time => sigma,
            Clock::SquareRoot { reference } => reference + sigma * sigma.abs(),
        }
    }

    /// The clock reading `sigma` at time `t` (the inverse of [`Clock::time`]).
    #[inline]
    pub fn sigma(self, t: f64) -> f64 {
        match self {
            Clock::Time => t,
            Clock::SquareRoot { reference } => {
                let d = t - reference;
                d.signum() * d.abs().sqrt()
            }
        }
    }

    /// `dt/dsigma` at `sigma` (`2 |sigma|`; zero at the reference instant).
    #[inline]
    pub fn rate(self, sigma: f64) -> f64 {
        match self {
            Clock::Time => 1.0,
            Clock::SquareRoot { .. } => 2.0 * sigma.abs(),
        }
    }

    /// The time step from `t0` that a clock step of `dsigma` from `sigma(t0)` covers.
    #[inline]
    pub(crate) fn time_step(self, t0: f64, dsigma: f64) -> f64 {
        match self {
            Clock::Time => dsigma,
            Clock::SquareRoot { .. } => self.time(self.sigma(t0) + dsigma) - t0,
        }
    }

    /// The clock step from `t0` that covers the time step `dt > 0`.
    #[inline]
    pub(crate) fn clock_step(self, t0: f64, dt: f64) -> f64 {
        match self {
            Clock::Time => dt,
            Clock::SquareRoot { .. } => self.sigma(t0 + dt) - self.sigma(t0),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn square_root_clock_round_trips_on_both_sides_of_its_reference() {
        let clock = Clock::SquareRoot { reference: 3.0 };
        for t in [1.0, 2.5, 3.0, 3.25, 7.0] {
            let sigma = clock.sigma(t);
            assert!((clock.time(sigma) - t).abs() <= 4.0 * f64::EPSILON * t);
            // dt/dsigma against a central difference (exact for the quadratic pieces; at the
            // reference, where t = sigma |sigma|, the difference is d).
            let d = 1e-6;
            let numeric = (clock.time(sigma + d) - clock.time(sigma - d)) / (2.0 * d);
            assert!((numeric - clock.rate(sigma)).abs() <= 1e-6 + 1e-8, "t {t}");
        }
        assert_eq!(clock.sigma(3.0), 0.0);
        assert_eq!(clock.sigma(2.0), -1.0);
        assert_eq!(clock.sigma(7.0), 2.0);
        assert!((clock.time_step(2.0, 1.5) - 1.25).abs() < 1e-15);
        assert!((clock.clock_step(2.0, 1.25) - 1.5).abs() < 1e-15);
    }

    #[test]
    fn time_clock_is_the_identity() {
        let clock = Clock::Time;
        assert_eq!(clock.time(1.5), 1.5);
        assert_eq!(clock.sigma(1.5), 1.5);
        assert_eq!(clock.rate(-4.0), 1.0);
        assert_eq!(clock.time_step(2.0, 0.5), 0.5);
    }
}
