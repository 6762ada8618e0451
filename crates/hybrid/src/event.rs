//! What the solver reports about switching surfaces: events (crossings and impacts) and the
//! smooth extrema of the switching functions found inside steps.

use crate::system::{Direction, Mode};

/// A crossing of (or an impact on) a switching surface `h_k = 0`.
///
/// For the AFM model `h` is the tip-sample gap `d` (MODEL.md Sec. 1) and a [`Direction::Down`]
/// event on it is the onset of an impact (MODEL.md Sec. 5).
#[derive(Debug, Clone, PartialEq)]
pub struct Event {
    /// Time of the event (system time units), located to `Settings::event_time_tolerance`.
    pub t: f64,
    /// Index `k` of the switching function.
    pub surface: usize,
    /// `Down`: `h` goes negative (onset of contact); `Up`: `h` goes positive (release).
    pub direction: Direction,
    /// `dh/dt` just before the event (the normal velocity; units of `h` per time unit), signed.
    pub rate: f64,
    /// `|rate| < Settings::grazing_rate`: a (near-)tangential crossing.
    pub grazing: bool,
    /// A reset map `x+ = R(t, x-)` was applied.
    pub reset: bool,
    /// State just after the event (after any reset).
    pub state: Vec<f64>,
    /// The mode just before the event (a system's discrete state, such as an attachment bit
    /// that no surface's sign holds, tells what the crossing meant).
    pub mode: Mode,
}

/// Whether an extremum of a switching function is a minimum or a maximum.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ExtremumKind {
    /// `dh/dt` goes from negative to positive: for a gap, the closest approach (a near impact
    /// when the value is positive, MODEL.md Sec. 5).
    Minimum,
    /// `dh/dt` goes from positive to negative.
    Maximum,
}

/// A smooth local extremum of `h_k` (a zero of `dh_k/dt`) inside one step, reported whether
/// `h_k` is positive or negative there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Extremum {
    /// Time of the extremum (system time units), located to `Settings::event_time_tolerance`.
    pub t: f64,
    /// Index `k` of the switching function.
    pub surface: usize,
    /// Minimum or maximum.
    pub kind: ExtremumKind,
    /// `h_k` at the extremum (switching-function units); a minimum of the gap with value 0 is
    /// a grazing contact (MODEL.md Sec. 5).
    pub value: f64,
    /// The mode of the step the extremum lies in.
    pub mode: Mode,
}
