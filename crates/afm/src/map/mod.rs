//! Regime maps in two parameters (MODEL.md section 8): the second parameter's axis (which input
//! it sets and how the model is rebuilt at each value) and the curves of grazing, fold and
//! period-doubling points over it.
pub mod parameter_axis;
pub mod regime_map;
mod seed_order;
