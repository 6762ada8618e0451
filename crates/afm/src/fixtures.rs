//! The built-in fixtures (embedded at compile time from `fixtures/` at the workspace root, so
//! the binary works from any directory) and loading of user files by path.
//!
//! Every file is parsed with `deny_unknown_fields` and range-checked; errors name the file, the
//! field and the allowed range.

use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;

use crate::error::AfmError;
use crate::model::cantilever::Cantilever;
use crate::model::case::Case;
use crate::model::case::CaseFile;
use crate::model::sample::Sample;

/// A built-in fixture: its name, the path it was embedded from, and its text.
struct Embedded {
    name: &'static str,
    path: &'static str,
    text: &'static str,
}

macro_rules! embedded {
    ($kind:literal, $name:literal) => {
        Embedded {
            name: $name,
            path: concat!("fixtures/", $kind, "/", $name, ".json"),
            text: include_str!(concat!("../../../fixtures/", $kind, "/", $name, ".json")),
        }
    };
}

const CANTILEVERS: &[Embedded] = &[
    embedded!("cantilevers", "biolever"),
    embedded!("cantilevers", "maclever"),
    embedded!("cantilevers", "rectangular-silicon-water"),
    embedded!("cantilevers", "silicon-air"),
    embedded!("cantilevers", "rectangular-silicon-air"),
];

const SAMPLES: &[Embedded] = &[
    embedded!("samples", "mica"),
    embedded!("samples", "soft"),
    embedded!("samples", "purple-membrane"),
    embedded!("samples", "purple-membrane-film"),
    embedded!("samples", "soft-viscoelastic"),
    embedded!("samples", "mica-hydration"),
    embedded!("samples", "adhesive-soft"),
    embedded!("samples", "sticky-soft"),
    embedded!("samples", "polymer-strong-vdw"),
    embedded!("samples", "polymer-weak-vdw"),
    embedded!("samples", "mica-humid"),
];

const CASES: &[Embedded] = &[
    embedded!("cases", "biolever-mica"),
    embedded!("cases", "biolever-soft"),
    embedded!("cases", "maclever-mica"),
    embedded!("cases", "maclever-soft"),
    embedded!("cases", "maclever-mica-experiment"),
    embedded!("cases", "maclever-membrane-experiment"),
    embedded!("cases", "maclever-membrane-film"),
    embedded!("cases", "biolever-soft-viscoelastic"),
    embedded!("cases", "biolever-mica-hydration"),
    embedded!("cases", "biolever-mica-acoustic"),
    embedded!("cases", "biolever-mica-bimodal"),
    embedded!("cases", "biolever-adhesive"),
    embedded!("cases", "biolever-sticky"),
    embedded!("cases", "silicon-air-polymer"),
    embedded!("cases", "rectangular-air-mica-humid"),
];

const LINES: &[Embedded] = &[
    embedded!("lines", "membrane-patch"),
    embedded!("lines", "polymer-blend"),
];

fn names(table: &[Embedded]) -> Vec<&'static str> {
    table.iter().map(|entry| entry.name).collect()
}

/// The names of the built-in cantilevers (the files in `fixtures/cantilevers/`).
pub fn cantilever_names() -> Vec<&'static str> {
    names(CANTILEVERS)
}

/// The names of the built-in samples (the files in `fixtures/samples/`).
pub fn sample_names() -> Vec<&'static str> {
    names(SAMPLES)
}

/// The names of the built-in cases (the files in `fixtures/cases/`).
pub fn case_names() -> Vec<&'static str> {
    names(CASES)
}

/// The names of the built-in scan lines (the files in `fixtures/lines/`; MODEL.md section 12).
pub fn line_names() -> Vec<&'static str> {
    names(LINES)
}

/// The built-in scan line `name`: its path in the repository and its JSON text (parsed by
/// `crate::scan::line::ScanLine`), `None` for an unknown name.
pub fn builtin_line_text(name: &str) -> Option<(&'static str, &'static str)> {
    LINES
        .iter()
        .find(|entry| entry.name == name)
        .map(|entry| (entry.path, entry.text))
}

fn find<'a>(
    table: &'a [Embedded],
    kind: &'static str,
    name: &str,
) -> Result<&'a Embedded, AfmError> {
    table
        .iter()
        .find(|entry| entry.name == name)
        .ok_or_else(|| AfmError::UnknownFixture {
            kind,
            name: name.to_string(),
            known: names(table).join(", "),
        })
}

/// Parse JSON `text` of `file` into `T`; a syntax or schema error names the file and the
/// field it is in.
pub(crate) fn parse_json<T: DeserializeOwned>(file: &str, text: &str) -> Result<T, AfmError> {
    parse(file, text)
}

/// Parse a JSON file's text; a UTF-8 byte-order mark at its start (written by some Windows
/// editors) is skipped, so the positions in errors are those of the text after it.
fn parse<T: DeserializeOwned>(file: &str, text: &str) -> Result<T, AfmError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    serde_json::from_str(text).map_err(|source| AfmError::Json {
        file: file.to_string(),
        field: crate::json_path::path_at(text, source.line(), source.column()),
        source,
    })
}

/// Read the file at `path` and parse it with `parse(file, text, directory)`: `file` names it in
/// errors, `directory` (the file's own) resolves the relative paths written in it. The one
/// loader of the files that name other files (scan lines, rasters).
pub(crate) fn load_relative<T>(
    path: &Path,
    parse: impl FnOnce(&str, &str, Option<&Path>) -> Result<T, AfmError>,
) -> Result<T, AfmError> {
    let text = read(path)?;
    parse(
        &path.display().to_string(),
        &text,
        Some(path.parent().unwrap_or_else(|| Path::new(""))),
    )
}

fn read(path: &Path) -> Result<String, AfmError> {
    read_text(path)
}

/// The text of the file at `path`. A file that is not UTF-8 (saved in another encoding, or
/// not text) is an [`AfmError::Io`] naming the file, the line and column of the first byte
/// that is not, and that byte.
pub(crate) fn read_text(path: &Path) -> Result<String, AfmError> {
    let io = |source| AfmError::Io {
        file: path.display().to_string(),
        source,
    };
    let bytes = std::fs::read(path).map_err(io)?;
    String::from_utf8(bytes).map_err(|error| {
        let at = error.utf8_error().valid_up_to();
        let bytes = error.as_bytes();
        let before = &bytes[..at];
        let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
        let line_start = before
            .iter()
            .rposition(|&b| b == b'\n')
            .map_or(0, |newline| newline + 1);
        let column = String::from_utf8_lossy(&before[line_start..])
            .chars()
            .count()
            + 1;
        io(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!(
                "not UTF-8 text at line {line}, column {column} (byte 0x{:02x}): save the file \
                 as UTF-8",
                bytes[at]
            ),
        ))
    })
}

/// Parse and validate cantilever JSON text; `file` names the source in errors.
pub fn parse_cantilever(file: &str, text: &str) -> Result<Cantilever, AfmError> {
    let cantilever: Cantilever = parse(file, text)?;
    cantilever.validate(file)?;
    Ok(cantilever)
}

/// Parse and validate sample JSON text; `file` names the source in errors.
pub fn parse_sample(file: &str, text: &str) -> Result<Sample, AfmError> {
    let sample: Sample = parse(file, text)?;
    sample.validate(file)?;
    Ok(sample)
}

/// Parse and validate case JSON text (without resolving its references); `file` names the
/// source in errors.
pub fn parse_case_file(file: &str, text: &str) -> Result<CaseFile, AfmError> {
    let case: CaseFile = parse(file, text)?;
    case.validate(file)?;
    Ok(case)
}

/// A built-in fixture file as shipped: its kind (`case`, `cantilever` or `sample`), its path
/// in the repository (`fixtures/cases/biolever-mica.json`, ...) and its JSON text, for a user
/// to copy and edit. Cases are searched first, then cantilevers, then samples, then scan
/// lines (kind `line`).
pub fn builtin_file(name: &str) -> Option<(&'static str, &'static str, &'static str)> {
    [
        ("case", CASES),
        ("cantilever", CANTILEVERS),
        ("sample", SAMPLES),
        ("line", LINES),
    ]
    .into_iter()
    .find_map(|(kind, table)| {
        table
            .iter()
            .find(|entry| entry.name == name)
            .map(|entry| (kind, entry.path, entry.text))
    })
}

/// The built-in cantilever `name`.
pub fn builtin_cantilever(name: &str) -> Result<Cantilever, AfmError> {
    let entry = find(CANTILEVERS, "cantilever", name)?;
    parse_cantilever(entry.path, entry.text)
}

/// The built-in sample `name`.
pub fn builtin_sample(name: &str) -> Result<Sample, AfmError> {
    let entry = find(SAMPLES, "sample", name)?;
    parse_sample(entry.path, entry.text)
}

/// The built-in case `name`, with its cantilever and sample resolved.
pub fn builtin_case(name: &str) -> Result<Case, AfmError> {
    let entry = find(CASES, "case", name)?;
    let file = parse_case_file(entry.path, entry.text)?;
    resolve_case(file, None, entry.path)
}

/// Load and validate a cantilever file.
pub fn load_cantilever(path: &Path) -> Result<Cantilever, AfmError> {
    parse_cantilever(&path.display().to_string(), &read(path)?)
}

/// Load and validate a sample file.
pub fn load_sample(path: &Path) -> Result<Sample, AfmError> {
    parse_sample(&path.display().to_string(), &read(path)?)
}

/// Load and validate a case file; its `cantilever` and `sample` references are built-in names
/// or paths ending in `.json` relative to the case file's directory.
pub fn load_case(path: &Path) -> Result<Case, AfmError> {
    let file = parse_case_file(&path.display().to_string(), &read(path)?)?;
    resolve_case(
        file,
        Some(path.parent().unwrap_or_else(|| Path::new(""))),
        &path.display().to_string(),
    )
}

/// A case named on a command line: a built-in case name, or else a path to a case file.
pub fn find_case(name_or_path: &str) -> Result<Case, AfmError> {
    if CASES.iter().any(|entry| entry.name == name_or_path) {
        return builtin_case(name_or_path);
    }
    let path = Path::new(name_or_path);
    if path.extension().is_some_and(|ext| ext == "json") || path.exists() {
        load_case(path)
    } else {
        Err(AfmError::UnknownFixture {
            kind: "case",
            name: name_or_path.to_string(),
            known: case_names().join(", "),
        })
    }
}

/// Resolve a reference: a built-in name, or (with a base directory) a `.json` path. A file
/// that cannot be read is reported as the field `kind` of the case file `case_file`.
fn resolve<T>(
    reference: &str,
    base: Option<&Path>,
    table: &[Embedded],
    kind: &'static str,
    builtin: fn(&str) -> Result<T, AfmError>,
    load: fn(&Path) -> Result<T, AfmError>,
    case_file: &str,
) -> Result<T, AfmError> {
    if table.iter().any(|entry| entry.name == reference) {
        return builtin(reference);
    }
    match base {
        Some(base) if reference.ends_with(".json") => {
            let path: PathBuf = base.join(reference);
            load(&path).map_err(|error| match error {
                AfmError::Io { file, source } => AfmError::InvalidField {
                    file: case_file.to_string(),
                    field: kind.to_string(),
                    value: format!("{reference:?}"),
                    allowed: format!(
                        "a built-in {kind} ({}) or a readable {kind} file (cannot read {file}: \
                         {source})",
                        names(table).join(", ")
                    ),
                },
                other => other,
            })
        }
        Some(_) => Err(AfmError::InvalidField {
            file: case_file.to_string(),
            field: kind.to_string(),
            value: format!("{reference:?}"),
            allowed: format!(
                "a built-in {kind} ({}) or the path of a {kind} file ending in .json, relative \
                 to the case file's directory",
                names(table).join(", ")
            ),
        }),
        None => Err(AfmError::UnknownFixture {
            kind,
            name: reference.to_string(),
            known: names(table).join(", "),
        }),
    }
}

fn resolve_case(file: CaseFile, base: Option<&Path>, source: &str) -> Result<Case, AfmError> {
    let cantilever = resolve(
        &file.cantilever,
        base,
        CANTILEVERS,
        "cantilever",
        builtin_cantilever,
        load_cantilever,
        source,
    )?;
    let sample = resolve(
        &file.sample,
        base,
        SAMPLES,
        "sample",
        builtin_sample,
        load_sample,
        source,
    )?;
    // The drive against its cantilever (an incommensurate bimodal ratio, participation
    // factors per mode), blamed on the case file.
    let frequency = file
        .drive_frequency_khz
        .unwrap_or_else(|| cantilever.fundamental_frequency_khz());
    file.drive.validate(source, &cantilever, frequency)?;
    Ok(Case {
        name: file.name,
        description: file.description,
        cantilever,
        sample,
        free_amplitude_nm: file.free_amplitude_nm,
        drive_frequency_khz: file.drive_frequency_khz,
        drive: file.drive,
    })
}
