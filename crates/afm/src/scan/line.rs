//! The sample along a scan line (MODEL.md section 12): contiguous segments, each with a height
//! and a sample (a built-in name, a sample file, or an inline sample object with any contact
//! law), and an optional edge width over which a height step is smoothed into a ramp.
//!
//! A line file:
//!
//! ```json
//! {"segments": [{"from_nm": 0, "to_nm": 100, "height_nm": 0, "sample": "mica"},
//!               {"from_nm": 100, "to_nm": 200, "height_nm": 6, "sample": "purple-membrane-film"}],
//!  "edge_width_nm": 10}
//! ```
//!
//! The height `h(x)` is the segment's height, except within `edge_width_nm / 2` of a boundary
//! between segments, where it runs linearly from one height to the next. The material is the
//! segment's on each side of the boundary (the tip is a point laterally: a material interface
//! is sharp).

use std::path::Path;

use serde::Deserialize;

use crate::error::AfmError;
use crate::fixtures::{
    builtin_line_text, builtin_sample, line_names, load_relative, load_sample, parse_json,
    parse_sample, sample_names,
};
use crate::model::sample::Sample;
use crate::validation::{check, invalid, Interval};

/// The largest coordinate or height a line accepts, nm (0.1 mm).
pub const MAX_LINE_NM: f64 = 1e5;

/// A segment's sample as written: a built-in name or a path to a sample file (relative to the
/// line file's directory), or a sample object inline (kept as JSON until resolved, so that an
/// error in it names its field, not a failed guess of the variant).
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
enum SampleReference {
    Name(String),
    Inline(serde_json::Value),
}

/// One segment as written in a line file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct SegmentFile {
    from_nm: f64,
    to_nm: f64,
    height_nm: f64,
    sample: SampleReference,
}

/// A line file as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct LineFile {
    #[serde(default)]
    name: Option<String>,
    #[serde(default)]
    description: String,
    #[serde(default)]
    edge_width_nm: f64,
    segments: Vec<SegmentFile>,
}

/// One segment of a resolved scan line: `[from_nm, to_nm)` at height `height_nm` on the
/// material `material` (an index into [`ScanLine::materials`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Segment {
    /// Start of the segment along the line, nm.
    pub from_nm: f64,
    /// End of the segment, nm (the next segment's start).
    pub to_nm: f64,
    /// The sample's surface height over the segment, nm (relative to any fixed level).
    pub height_nm: f64,
    /// The index of the segment's sample in [`ScanLine::materials`].
    pub material: usize,
}

/// A resolved, checked scan line (MODEL.md section 12).
#[derive(Debug, Clone, PartialEq)]
pub struct ScanLine {
    /// The line's name (the file stem if the file gives none).
    pub name: String,
    /// Free-text description.
    pub description: String,
    /// The width over which a height step is smoothed into a linear ramp, nm, centred on the
    /// boundary; 0 for sharp steps. At most the narrowest segment's width.
    pub edge_width_nm: f64,
    /// The segments in order along `x`, contiguous.
    pub segments: Vec<Segment>,
    /// The distinct samples of the line, in order of first appearance.
    pub materials: Vec<Sample>,
}

impl ScanLine {
    /// Parse and check a line file's text; `file` names it in errors and `base` is the
    /// directory against which sample file paths are resolved (`None`: built-in names and
    /// inline samples only).
    pub fn parse(file: &str, text: &str, base: Option<&Path>) -> Result<Self, AfmError> {
        let raw: LineFile = parse_json(file, text)?;
        if raw.segments.is_empty() {
            return Err(AfmError::InvalidField {
                file: file.to_string(),
                field: String::from("segments"),
                value: String::from("[]"),
                allowed: String::from("at least one segment"),
            });
        }
        let mut materials: Vec<Sample> = Vec::new();
        let mut segments = Vec::with_capacity(raw.segments.len());
        let coordinate = Interval::closed(-MAX_LINE_NM, MAX_LINE_NM, "nm");
        for (index, segment) in raw.segments.iter().enumerate() {
            let field = |name: &str| format!("segments[{index}].{name}");
            check(file, &field("from_nm"), segment.from_nm, coordinate)?;
            check(file, &field("height_nm"), segment.height_nm, coordinate)?;
            check(
                file,
                &field("to_nm"),
                segment.to_nm,
                Interval::left_open(segment.from_nm, MAX_LINE_NM, "nm (above from_nm)"),
            )?;
            if let Some(previous) = segments.last() {
                let previous: &Segment = previous;
                if segment.from_nm != previous.to_nm {
                    return Err(invalid(
                        file,
                        &field("from_nm"),
                        segment.from_nm,
                        format!(
                            "{} nm, the end of segments[{}] (segments are contiguous, in order)",
                            previous.to_nm,
                            index - 1
                        ),
                    ));
                }
            }
            let sample = resolve_sample(file, &field("sample"), &segment.sample, base)?;
            let material = match materials.iter().position(|m| *m == sample) {
                Some(position) => position,
                None => {
                    materials.push(sample);
                    materials.len() - 1
                }
            };
            segments.push(Segment {
                from_nm: segment.from_nm,
                to_nm: segment.to_nm,
                height_nm: segment.height_nm,
                material,
            });
        }
        let narrowest = segments
            .iter()
            .map(|s| s.to_nm - s.from_nm)
            .fold(f64::INFINITY, f64::min);
        check(
            file,
            "edge_width_nm",
            raw.edge_width_nm,
            Interval::closed(
                0.0,
                narrowest,
                "nm (at most the narrowest segment's width, so that ramps do not overlap)",
            ),
        )?;
        let name = raw.name.unwrap_or_else(|| {
            Path::new(file).file_stem().map_or_else(
                || String::from("line"),
                |s| s.to_string_lossy().into_owned(),
            )
        });
        Ok(Self {
            name,
            description: raw.description,
            edge_width_nm: raw.edge_width_nm,
            segments,
            materials,
        })
    }

    /// Load a line file from `path` (sample paths in it relative to its directory).
    pub fn load(path: &Path) -> Result<Self, AfmError> {
        load_relative(path, Self::parse)
    }

    /// The built-in line `name` (`fixtures/lines/`).
    pub fn builtin(name: &str) -> Result<Self, AfmError> {
        let (path, text) = builtin_line_text(name).ok_or_else(|| AfmError::UnknownFixture {
            kind: "line",
            name: name.to_string(),
            known: line_names().join(", "),
        })?;
        Self::parse(path, text, None)
    }

    /// A line named on a command line: a built-in line name, or else a path to a line file.
    pub fn find(name_or_path: &str) -> Result<Self, AfmError> {
        if builtin_line_text(name_or_path).is_some() {
            return Self::builtin(name_or_path);
        }
        let path = Path::new(name_or_path);
        if path.extension().is_some_and(|e| e == "json") || path.exists() {
            Self::load(path)
        } else {
            Err(AfmError::UnknownFixture {
                kind: "line",
                name: name_or_path.to_string(),
                known: line_names().join(", "),
            })
        }
    }

    /// The line's start, nm.
    pub fn start_nm(&self) -> f64 {
        self.segments[0].from_nm
    }

    /// The line's end, nm.
    pub fn end_nm(&self) -> f64 {
        self.segments[self.segments.len() - 1].to_nm
    }

    /// The index of the segment holding `x_nm` (a boundary belongs to the segment it starts;
    /// points outside the line to the nearest end segment).
    pub fn segment_at(&self, x_nm: f64) -> usize {
        self.segments
            .iter()
            .position(|s| x_nm < s.to_nm)
            .unwrap_or(self.segments.len() - 1)
    }

    /// The material (index into [`ScanLine::materials`]) under the tip at `x_nm`.
    pub fn material_at(&self, x_nm: f64) -> usize {
        self.segments[self.segment_at(x_nm)].material
    }

    /// The surface height `h(x)` at `x_nm`, nm: the segment's height, ramped linearly over
    /// `edge_width_nm` centred on each boundary (MODEL.md section 12).
    pub fn height_at(&self, x_nm: f64) -> f64 {
        let index = self.segment_at(x_nm);
        let segment = &self.segments[index];
        let half = 0.5 * self.edge_width_nm;
        if half > 0.0 {
            if index > 0 && x_nm < segment.from_nm + half {
                let left = self.segments[index - 1].height_nm;
                let s = (x_nm - (segment.from_nm - half)) / self.edge_width_nm;
                return left + (segment.height_nm - left) * s;
            }
            if index + 1 < self.segments.len() && x_nm >= segment.to_nm - half {
                let right = self.segments[index + 1].height_nm;
                let s = (x_nm - (segment.to_nm - half)) / self.edge_width_nm;
                return segment.height_nm + (right - segment.height_nm) * s;
            }
        }
        segment.height_nm
    }

    /// How much the surface height jumps on the way from `from_nm` to `to_nm` (either
    /// direction), nm: the sum over the segment boundaries between them of the height after the
    /// boundary less the height before it. Zero where `edge_width_nm > 0` (the height is then
    /// continuous: a ramp).
    pub fn height_step_between(&self, from_nm: f64, to_nm: f64) -> f64 {
        if self.edge_width_nm > 0.0 {
            return 0.0;
        }
        let (low, high) = (from_nm.min(to_nm), from_nm.max(to_nm));
        let rise: f64 = self
            .segments
            .windows(2)
            .filter(|pair| pair[0].to_nm > low && pair[0].to_nm <= high)
            .map(|pair| pair[1].height_nm - pair[0].height_nm)
            .sum();
        if to_nm >= from_nm {
            rise
        } else {
            -rise
        }
    }

    /// The centres of `pixels` equal pixels covering the line, nm: `x_i = start + (i + 1/2)
    /// L / pixels`.
    pub fn pixel_centres(&self, pixels: usize) -> Vec<f64> {
        let (start, length) = (self.start_nm(), self.end_nm() - self.start_nm());
        (0..pixels)
            .map(|i| start + (i as f64 + 0.5) * length / pixels as f64)
            .collect()
    }
}

/// Resolve a segment's sample reference (errors name the line file and the field).
fn resolve_sample(
    file: &str,
    field: &str,
    reference: &SampleReference,
    base: Option<&Path>,
) -> Result<Sample, AfmError> {
    match reference {
        SampleReference::Inline(value) if value.is_object() => {
            parse_sample(&format!("{file}: {field}"), &value.to_string())
        }
        SampleReference::Inline(value) => Err(AfmError::InvalidField {
            file: file.to_string(),
            field: field.to_string(),
            value: value.to_string(),
            allowed: format!(
                "a built-in sample ({}), a sample file path ending in .json, or a sample object",
                sample_names().join(", ")
            ),
        }),
        SampleReference::Name(name) if sample_names().contains(&name.as_str()) => {
            builtin_sample(name)
        }
        SampleReference::Name(name) => {
            let path = Path::new(name);
            let is_path = path.extension().is_some_and(|e| e == "json");
            let not_found = |detail: String| AfmError::InvalidField {
                file: file.to_string(),
                field: field.to_string(),
                value: format!("{name:?}"),
                allowed: format!(
                    "a built-in sample ({}), a sample file path ending in .json, or a sample \
                     object{detail}",
                    sample_names().join(", ")
                ),
            };
            if !is_path {
                return Err(not_found(String::new()));
            }
            let full = base.map_or_else(|| path.to_path_buf(), |b| b.join(path));
            load_sample(&full).map_err(|error| match error {
                AfmError::Io { file, source } => {
                    not_found(format!(" (cannot read {file}: {source})"))
                }
                other => other,
            })
        }
    }
}
