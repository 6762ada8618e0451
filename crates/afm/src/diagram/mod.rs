//! Orbits as a function of the separation `Z`: the bifurcation diagram of the paper's Fig. 2 by
//! pseudo-arclength continuation (MODEL.md section 6), and one quasi-static row of the
//! brute-force grid (a sweep by transients at fixed `Z`s).
pub mod bifurcation_diagram;
mod branch_end;
pub mod observed_problem;
pub mod period_one_budget;
pub mod quasi_static;
