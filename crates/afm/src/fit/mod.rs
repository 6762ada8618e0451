//! Measured curves in the loop (MODEL.md section 13): reading a measured approach curve,
//! detecting its regime boundaries, and fitting the model's followed approach branch to it.
pub mod followed_branch;
pub mod kink_onset;
pub mod least_squares;
pub mod measurement;
pub mod synthetic;
pub mod transitions;
pub mod window_models;
