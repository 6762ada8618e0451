//! One row line of a grid file (docs/output-schema.md, "grid"): its checksum and its check
//! against the header. A row line is the row's JSON object with a last key `crc32`, the CRC-32
//! (IEEE 802.3, as zlib's `crc32`) of the line's bytes before `,"crc32"` followed by `}`, in
//! eight lowercase hexadecimal digits; so an edited number, a cut or a merged line is found
//! when a part is resumed or merged.

use serde_json::Value;

/// The key of a row line's checksum, always its last key.
const CHECKSUM_KEY: &str = ",\"crc32\":\"";

/// `json` (one row's object, no newline) sealed with its checksum, newline included.
pub fn seal(json: &str) -> String {
    let body = json.strip_suffix('}').unwrap_or(json);
    let checksum = crc32fast::hash(json.as_bytes());
    format!("{body}{CHECKSUM_KEY}{checksum:08x}\"}}\n")
}

/// Check a row line's checksum (the line without its newline); the reason it fails in words.
pub fn check_seal(line: &str) -> Result<(), String> {
    let Some(at) = line.rfind(CHECKSUM_KEY) else {
        return Err(String::from(
            "no `crc32` checksum (not written by this drumroll?)",
        ));
    };
    let stored = &line[at + CHECKSUM_KEY.len()..];
    let Some(stored) = stored.strip_suffix("\"}") else {
        return Err(String::from("`crc32` is not the row's last key"));
    };
    let body = format!("{}}}", &line[..at]);
    let computed = format!("{:08x}", crc32fast::hash(body.as_bytes()));
    if stored == computed {
        Ok(())
    } else {
        Err(format!(
            "checksum mismatch (stored crc32 {stored}, the line's is {computed}): the line \
             was changed or damaged after it was written"
        ))
    }
}

/// What a header says every row must be: its number of rows, the parameter's value of each row,
/// the separations of the cells and whether cells hold a retract.
#[derive(Debug, Clone, PartialEq)]
pub struct GridShape {
    /// `parameter.values`: one per row, in row order.
    pub parameter_values: Vec<f64>,
    /// `z_nm`: the cells' separations, nm, in cell order.
    pub separations: Vec<f64>,
    /// `inputs.options.retract`: each cell holds `retract` and `bistable`.
    pub retract: bool,
}

impl GridShape {
    /// The shape a header line states; the reason it cannot be read in words.
    pub fn of_header(header: &str) -> Result<Self, String> {
        let value: Value =
            serde_json::from_str(header).map_err(|e| format!("the header is not JSON ({e})"))?;
        let numbers = |value: &Value, key: &str| -> Result<Vec<f64>, String> {
            value
                .as_array()
                .and_then(|items| items.iter().map(Value::as_f64).collect::<Option<Vec<_>>>())
                .ok_or_else(|| format!("the header's `{key}` is not a list of numbers"))
        };
        let parameter_values = numbers(&value["parameter"]["values"], "parameter.values")?;
        let separations = numbers(&value["z_nm"], "z_nm")?;
        let retract = value["inputs"]["options"]["retract"]
            .as_bool()
            .ok_or("the header has no `inputs.options.retract`")?;
        let steps = value["inputs"]["options"]["steps"].as_u64();
        if steps != Some(parameter_values.len() as u64) {
            return Err(String::from(
                "the header's `inputs.options.steps` is not the number of `parameter.values`",
            ));
        }
        Ok(Self {
            parameter_values,
            separations,
            retract,
        })
    }

    /// The number of rows.
    pub fn rows(&self) -> usize {
        self.parameter_values.len()
    }

    /// Check a complete row line (without its newline) against the header: its checksum, its
    /// `row` index in range, `parameter_value` equal bit for bit to the header's value at that
    /// index, a finite `first_contact_z_nm`, one cell per separation with `z_nm` equal to the
    /// header's, an `approach` object and, with a retract, a `retract` object and a boolean
    /// `bistable`. Returns the row index; the reason it fails in words.
    pub fn check_row(&self, line: &str) -> Result<usize, String> {
        let value: Value =
            serde_json::from_str(line).map_err(|e| format!("not a JSON object ({e})"))?;
        let Some(row) = value.get("row").and_then(Value::as_u64) else {
            return Err(String::from("not a grid row (no integer `row`)"));
        };
        check_seal(line)?;
        let row = usize::try_from(row).unwrap_or(usize::MAX);
        if row >= self.rows() {
            return Err(format!(
                "row {row} is outside the grid's {} rows (0 to {})",
                self.rows(),
                self.rows().saturating_sub(1)
            ));
        }
        let number = |value: &Value, key: &str| value.get(key).and_then(Value::as_f64);
        match number(&value, "parameter_value") {
            Some(p) if p.to_bits() == self.parameter_values[row].to_bits() => {}
            Some(p) => {
                return Err(format!(
                    "row {row}: `parameter_value` {p} is not the header's value {} for that row",
                    self.parameter_values[row]
                ))
            }
            None => return Err(format!("row {row}: no number `parameter_value`")),
        }
        if !number(&value, "first_contact_z_nm").is_some_and(f64::is_finite) {
            return Err(format!("row {row}: no number `first_contact_z_nm`"));
        }
        let Some(cells) = value.get("cells").and_then(Value::as_array) else {
            return Err(format!("row {row}: no list `cells`"));
        };
        if cells.len() != self.separations.len() {
            return Err(format!(
                "row {row}: {} cells, the header has {} separations",
                cells.len(),
                self.separations.len()
            ));
        }
        for (j, (cell, z)) in cells.iter().zip(&self.separations).enumerate() {
            if number(cell, "z_nm").map(f64::to_bits) != Some(z.to_bits()) {
                return Err(format!(
                    "row {row} cell {j}: `z_nm` is not the header's separation {z}"
                ));
            }
            let mut required = vec!["approach"];
            if self.retract {
                required.push("retract");
            }
            for key in required {
                if !cell.get(key).is_some_and(Value::is_object) {
                    return Err(format!("row {row} cell {j}: no object `{key}`"));
                }
            }
            if self.retract && !cell.get("bistable").is_some_and(Value::is_boolean) {
                return Err(format!("row {row} cell {j}: no boolean `bistable`"));
            }
        }
        Ok(row)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sealed_line_checks_and_any_changed_byte_is_found() {
        let line = seal(r#"{"row":0,"parameter_value":1.5,"cells":[]}"#);
        assert!(line.ends_with("\"}\n"));
        let text = line.trim_end();
        assert_eq!(check_seal(text), Ok(()));
        // CRC-32 detects every single-byte change (every burst shorter than 32 bits).
        for at in 0..text.len() {
            let mut bytes = text.as_bytes().to_vec();
            bytes[at] = if bytes[at] == b'7' { b'8' } else { b'7' };
            let changed = String::from_utf8(bytes).expect("ASCII");
            assert!(
                check_seal(&changed).is_err(),
                "byte {at} changed: {changed}"
            );
        }
    }

    #[test]
    fn the_checksum_is_zlib_s_crc32() {
        // zlib.crc32(b"123456789") = 0xcbf43926, the CRC-32 check value.
        assert_eq!(crc32fast::hash(b"123456789"), 0xcbf4_3926);
    }
}
