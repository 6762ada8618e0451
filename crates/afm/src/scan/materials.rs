//! One tapping model per material of a scan line: the case's cantilever, drive and free
//! amplitude over each of the line's samples (the drive force `F_1` depends on the cantilever
//! and `A0` only, so it is the same over every material; MODEL.md sections 3 and 12).

use crate::error::AfmError;
use crate::model::case::Case;
use crate::model::TappingModel;
use crate::scan::line::ScanLine;

/// The models of `case` with its sample replaced by each of `line.materials`, in that order.
pub fn line_models(case: &Case, line: &ScanLine) -> Result<Vec<TappingModel>, AfmError> {
    line.materials
        .iter()
        .map(|sample| {
            TappingModel::from_case(&Case {
                sample: sample.clone(),
                ..case.clone()
            })
        })
        .collect()
}
