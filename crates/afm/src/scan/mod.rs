//! Scans with amplitude feedback over a heterogeneous sample (MODEL.md section 12): the sample
//! line, the ideal feedback (the setpoint orbit followed along its branch pixel to pixel) and
//! the time-domain PI loop.

pub mod ideal;
pub mod line;
pub mod materials;
pub mod pi;
pub mod pixel;
pub mod raster;
pub mod setpoint_branch;
pub mod settings;
