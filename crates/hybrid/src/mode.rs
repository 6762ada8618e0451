//! The discrete part of a hybrid system's state: which side of every switching surface the
//! state lies on, and the direction of a crossing.

/// Which side of every switching surface a state lies on: bit `k` is set when `h_k < 0`.
///
/// With at most 32 surfaces, a `u32` names every region of state space.
pub type Mode = u32;

/// The maximum number of switching surfaces a system may declare (the bits of a [`Mode`]).
pub const MAX_SURFACES: usize = 32;

/// `+1` if `mode` has `h_k` on its positive side, `-1` if on its negative side (bit `k` set):
/// `side_sign * h_k` is positive on the current side of surface `k`.
pub(crate) fn side_sign(mode: Mode, k: usize) -> f64 {
    if mode & (1 << k) != 0 {
        -1.0
    } else {
        1.0
    }
}

/// Direction in which a trajectory crosses a switching surface `h = 0`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Direction {
    /// From `h > 0` to `h < 0` (`dh/dt < 0`): for a gap, the onset of contact.
    Down,
    /// From `h < 0` to `h > 0` (`dh/dt > 0`): for a gap, the release of contact.
    Up,
}
