//! The drumroll explorer page's WebAssembly module (`web/`, MODEL.md for the physics): a thin
//! binding of `afm` and the `drumroll` command line's JSON, CSV and SVG builders, so that the
//! page's numbers and exports are the CLI's own (`drumroll continue --json`, `--csv`, `--plot`;
//! `simulate`; `map`).
//!
//! Every entry point takes and returns JSON text: [`Explorer`] holds the last diagram, orbit
//! and regime map for the exports; [`case_request`] turns the page's case (a built-in name or
//! the case with its cantilever and sample inline) into the tapping model. On wasm32 the
//! [`Explorer`] is exported to JavaScript by wasm-bindgen (`scripts/build-web.sh`); natively
//! the same code is tested by `cargo test -p drumroll-web`.
#![warn(missing_docs)]

pub mod case_request;
pub mod catalogue;
pub mod diagram_request;
pub mod explorer;
pub mod map_request;
pub mod orbit_request;

pub use explorer::Explorer;
