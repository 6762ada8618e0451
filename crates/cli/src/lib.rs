//! The `drumroll` command line: argument parsing, output formatting and figures. The physics
//! lives in the library crates (`hybrid`, `continuation`, `afm`, `beam`).
#![warn(missing_docs)]

pub mod approach;
pub mod cantilever;
pub mod cantilever_file;
pub mod cantilever_geometry;
pub mod cases;
pub mod continue_diagram;
pub mod continue_figure;
pub mod detect;
pub mod diagram_json;
pub mod digits;
pub mod exit_status;
pub mod file_lock;
pub mod fit;
pub mod fit_figure;
pub mod grid;
pub mod grid_file;
pub mod grid_overlay;
pub mod grid_row;
pub mod inputs;
pub mod json_value;
pub mod map;
pub mod map_plot;
pub mod measurement_args;
pub mod model_args;
pub mod observable_records_json;
pub mod option_ranges;
pub mod orbit_json;
pub mod output;
pub mod plot;
pub mod progress;
pub mod scan;
pub mod scan_image;
pub mod scan_plot;
pub mod shell;
pub mod simulate;
pub mod theory;
pub mod trajectory_plot;
