//! Range checks shared by every input, files and command-line options alike: one table of
//! allowed and typical ranges ([`ranges`]), and one place that turns a bad value into an
//! [`AfmError::InvalidField`] naming the file (or option), the field and the allowed range, or
//! a valid but implausible one into a warning with the likely unit mistake.

use crate::error::AfmError;

/// An interval of allowed values with its unit, printed as e.g. `(0, 1e6] N/m`, and the
/// narrower range typical of AFM: a value outside it is accepted with a warning, and a value
/// that a factor of a unit prefix (1e3, 1e9, ...) would bring into it names that mistake.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interval {
    /// Lower bound.
    pub min: f64,
    /// Whether `min` itself is allowed.
    pub min_inclusive: bool,
    /// Upper bound.
    pub max: f64,
    /// Whether `max` itself is allowed.
    pub max_inclusive: bool,
    /// The unit (`nm`, `kHz`, `GPa`, `N/m`, `nm/s`; empty: dimensionless).
    pub unit: &'static str,
    /// The closed range typical of AFM, if the quantity has one.
    pub typical: Option<(f64, f64)>,
}

impl Interval {
    /// `(0, max]`: positive quantities with an upper sanity bound.
    pub const fn positive(max: f64, unit: &'static str) -> Self {
        Self::left_open(0.0, max, unit)
    }

    /// `[min, max]`.
    pub const fn closed(min: f64, max: f64, unit: &'static str) -> Self {
        Self {
            min,
            min_inclusive: true,
            max,
            max_inclusive: true,
            unit,
            typical: None,
        }
    }

    /// `(min, max]`.
    pub const fn left_open(min: f64, max: f64, unit: &'static str) -> Self {
        Self {
            min,
            min_inclusive: false,
            max,
            max_inclusive: true,
            unit,
            typical: None,
        }
    }

    /// `[min, max)`.
    pub const fn right_open(min: f64, max: f64, unit: &'static str) -> Self {
        Self {
            min,
            min_inclusive: true,
            max,
            max_inclusive: false,
            unit,
            typical: None,
        }
    }

    /// The same interval with the typical range `[low, high]`.
    pub const fn with_typical(self, low: f64, high: f64) -> Self {
        Self {
            typical: Some((low, high)),
            ..self
        }
    }

    /// Whether `value` is finite and allowed.
    pub fn contains(&self, value: f64) -> bool {
        let above = if self.min_inclusive {
            value >= self.min
        } else {
            value > self.min
        };
        let below = if self.max_inclusive {
            value <= self.max
        } else {
            value < self.max
        };
        value.is_finite() && above && below
    }

    /// The interval in words, e.g. `[0.1, 100000] nm (typical 1 to 1000 nm)`.
    pub fn describe(&self) -> String {
        let open = if self.min_inclusive { '[' } else { '(' };
        let close = if self.max_inclusive { ']' } else { ')' };
        let unit = self.unit_suffix();
        let typical = self.typical.map_or_else(String::new, |(low, high)| {
            format!(
                " (typical {} to {}{unit})",
                format_number(low),
                format_number(high)
            )
        });
        format!(
            "{open}{}, {}{close}{unit}{typical}",
            format_number(self.min),
            format_number(self.max)
        )
    }

    fn unit_suffix(&self) -> String {
        if self.unit.is_empty() {
            String::new()
        } else {
            format!(" {}", self.unit)
        }
    }

    /// Whether `value` is allowed but outside the typical range.
    pub fn implausible(&self, value: f64) -> bool {
        self.contains(value)
            && self
                .typical
                .is_some_and(|(low, high)| !(low..=high).contains(&value))
    }

    /// The likely unit mistake behind `value` (outside the typical range), when one factor of
    /// [`unit_mistakes`] brings it into the typical range: e.g. `1e-08 looks like metres:
    /// 1e-08 m = 10 nm`.
    pub fn unit_hint(&self, value: f64) -> Option<String> {
        let (low, high) = self.typical?;
        if !value.is_finite() || (low..=high).contains(&value) {
            return None;
        }
        unit_mistakes(self.unit)
            .iter()
            .find(|(factor, _)| (low..=high).contains(&(value * factor)))
            .map(|(factor, name)| {
                let typed = format_number(value);
                format!(
                    "{typed} looks like a value in {name}: {typed} {name} = {} {}",
                    format_number(value * factor),
                    self.unit
                )
            })
    }
}

/// A number as a user would type it: plain decimals from 1e-4 to 1e9 (`0.001`, `3500`),
/// exponent notation beyond (`1e-8`, `2e-14`), the shortest form that reads back exactly.
pub fn format_number(value: f64) -> String {
    let value = round_to_significant(value);
    let magnitude = value.abs();
    if value == 0.0 || !value.is_finite() || (1e-4..1e9).contains(&magnitude) {
        value.to_string()
    } else {
        format!("{value:e}")
    }
}

/// The unit mistakes checked for values in `unit`: (factor to `unit`, the other unit).
pub fn unit_mistakes(unit: &str) -> &'static [(f64, &'static str)] {
    match unit {
        "nm" => &[(1e9, "m"), (1e6, "mm"), (1e3, "um"), (0.1, "angstrom")],
        "kHz" => &[(1e-3, "Hz"), (1e3, "MHz")],
        "GPa" => &[(1e-9, "Pa"), (1e-6, "kPa"), (1e-3, "MPa")],
        "nm/s" => &[(1e9, "m/s"), (1e3, "um/s")],
        _ => &[],
    }
}

/// The table of ranges of every physical input (files and command-line options): allowed
/// (an error outside) and typical of AFM (a warning outside, with the likely unit mistake).
pub mod ranges {
    use super::Interval;

    /// Free amplitude `A0` of `u`, nm: from a picometre (below thermal noise) to 100 um.
    pub const FREE_AMPLITUDE_NM: Interval =
        Interval::closed(1e-3, 1e5, "nm").with_typical(0.1, 1e3);
    /// Drive or natural frequency, kHz: 10 Hz to 1 GHz (the paper's: 3.5 to 72 kHz). A drive
    /// period of a slower one takes millions of steps at the contact's time scale.
    pub const FREQUENCY_KHZ: Interval = Interval::closed(1e-2, 1e6, "kHz").with_typical(0.1, 1e5);
    /// Tip radius `R`, nm: from an atom to 100 um (colloidal probes).
    pub const TIP_RADIUS_NM: Interval = Interval::closed(0.1, 1e5, "nm").with_typical(1.0, 1e4);
    /// Young's modulus of tip or sample, GPa: 100 Pa (the softest gels) to 10 TPa.
    pub const YOUNGS_MODULUS_GPA: Interval =
        Interval::closed(1e-7, 1e4, "GPa").with_typical(1e-6, 1.5e3);
    /// Poisson ratio of tip or sample: the thermodynamic range `(-1, 0.5]`.
    pub const POISSON_RATIO: Interval = Interval::left_open(-1.0, 0.5, "");
    /// Tip mass over cantilever mass in a cantilever file.
    pub const TIP_MASS_RATIO: Interval = Interval::closed(0.0, 100.0, "");
    /// Modal stiffness `k_i`, N/m: a thousandth of the softest cantilevers made (the
    /// Biolever's 0.036 N/m is among them) to 1e6 N/m. Far below it the contact is so stiff
    /// against the lever that steps underflow.
    pub const STIFFNESS_N_PER_M: Interval =
        Interval::closed(1e-6, 1e6, "N/m").with_typical(1e-3, 1e3);
    /// Quality factor `Q_i`: from 1e-3 (a damping ratio `1/(2Q)` of 500) to 1e6 (vacuum).
    pub const QUALITY_FACTOR: Interval = Interval::closed(1e-3, 1e6, "").with_typical(0.1, 1e5);
    /// Optical sensitivity `chi_i` or forcing ratio `F_i / F_1` of a higher mode.
    pub const MODE_RATIO: Interval = Interval::closed(-1e3, 1e3, "");
}

/// Check that `value` (a finite number) lies in `interval`; the error names `file`, `field`,
/// the allowed range and, when one fits, the likely unit mistake.
pub fn check(file: &str, field: &str, value: f64, interval: Interval) -> Result<(), AfmError> {
    if interval.contains(value) {
        Ok(())
    } else {
        let hint = interval
            .unit_hint(value)
            .map_or_else(String::new, |hint| format!("; {hint}"));
        Err(AfmError::InvalidField {
            file: file.to_string(),
            field: field.to_string(),
            value: format_number(value),
            allowed: format!("{}{hint}", interval.describe()),
        })
    }
}

/// The warning for an allowed but implausible `value` of `field` in `file`, `None` for a
/// typical one.
pub fn plausibility_warning(
    file: &str,
    field: &str,
    value: f64,
    interval: Interval,
) -> Option<String> {
    interval.implausible(value).then(|| {
        let hint = interval
            .unit_hint(value)
            .map_or_else(String::new, |hint| format!("; {hint}"));
        format!(
            "{file}: field `{field}` = {} is unusual for AFM (allowed {}){hint}",
            format_number(value),
            interval.describe()
        )
    })
}

/// A field's path in its file: `name` at the top level, or `list[index].name` for a field of
/// the `index`-th entry (from 0) of a list (e.g. `modes[1].quality_factor`); written out only
/// for a message.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct FieldPath {
    /// The list and the entry's index, for a field of a list entry.
    entry: Option<(&'static str, usize)>,
    /// The field's own name.
    name: &'static str,
}

impl FieldPath {
    /// The top-level field `name`.
    pub(crate) const fn top(name: &'static str) -> Self {
        Self { entry: None, name }
    }

    /// The field `name` of entry `index` (from 0) of the list `list`.
    pub(crate) const fn entry(list: &'static str, index: usize, name: &'static str) -> Self {
        Self {
            entry: Some((list, index)),
            name,
        }
    }
}

impl std::fmt::Display for FieldPath {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.entry {
            Some((list, index)) => write!(f, "{list}[{index}].{}", self.name),
            None => f.write_str(self.name),
        }
    }
}

/// A field to check: its path, value and interval.
pub(crate) type NumericField = (FieldPath, f64, Interval);

/// Check every field of `fields` (the first failure is returned).
pub(crate) fn check_all(file: &str, fields: &[NumericField]) -> Result<(), AfmError> {
    for (field, value, interval) in fields {
        if !interval.contains(*value) {
            check(file, &field.to_string(), *value, *interval)?;
        }
    }
    Ok(())
}

/// The plausibility warnings of `fields`.
pub(crate) fn warnings_of(file: &str, fields: &[NumericField]) -> Vec<String> {
    fields
        .iter()
        .filter(|(_, value, interval)| interval.implausible(*value))
        .filter_map(|(field, value, interval)| {
            plausibility_warning(file, &field.to_string(), *value, *interval)
        })
        .collect()
}

/// The plausibility warnings of `fields`, those of one kind gathered into one line: fields
/// whose paths differ only in their list indices (`modes[3].stiffness_n_per_m`,
/// `modes[4].stiffness_n_per_m`) give one warning with their count, the first and last path
/// and the range of their values, in the order of their first occurrence.
pub(crate) fn gathered_warnings(file: &str, fields: &[NumericField]) -> Vec<String> {
    let mut kinds: Vec<(String, Vec<&NumericField>)> = Vec::new();
    for field in fields {
        if !field.2.implausible(field.1) {
            continue;
        }
        let kind = without_indices(&field.0.to_string());
        match kinds.iter_mut().find(|(k, _)| *k == kind) {
            Some((_, members)) => members.push(field),
            None => kinds.push((kind, vec![field])),
        }
    }
    kinds
        .into_iter()
        .filter_map(|(kind, members)| match members.as_slice() {
            [(field, value, interval)] => {
                plausibility_warning(file, &field.to_string(), *value, *interval)
            }
            [first, .., last] => {
                let low = members.iter().map(|f| f.1).fold(f64::INFINITY, f64::min);
                let high = members
                    .iter()
                    .map(|f| f.1)
                    .fold(f64::NEG_INFINITY, f64::max);
                Some(format!(
                    "{file}: field `{kind}` is unusual for AFM in {} entries (`{}` to `{}`, \
                     values {} to {}; allowed {})",
                    members.len(),
                    first.0,
                    last.0,
                    format_number(low),
                    format_number(high),
                    first.2.describe()
                ))
            }
            [] => None,
        })
        .collect()
}

/// A field path with every list index replaced by `[i]`: `modes[3].stiffness_n_per_m` ->
/// `modes[i].stiffness_n_per_m`.
fn without_indices(field: &str) -> String {
    let mut kind = String::with_capacity(field.len());
    let mut in_index = false;
    for c in field.chars() {
        match c {
            '[' => {
                in_index = true;
                kind.push_str("[i");
            }
            ']' => {
                in_index = false;
                kind.push(']');
            }
            _ if in_index => {}
            _ => kind.push(c),
        }
    }
    kind
}

/// Check that a name is a non-empty string without surrounding whitespace.
pub(crate) fn check_name(file: &str, field: &str, name: &str) -> Result<(), AfmError> {
    if !name.is_empty() && name.trim() == name {
        Ok(())
    } else {
        Err(AfmError::InvalidField {
            file: file.to_string(),
            field: field.to_string(),
            value: format!("{name:?}"),
            allowed: "a non-empty name without surrounding whitespace".to_string(),
        })
    }
}

/// An error for a value that violates a rule other than a plain interval.
pub(crate) fn invalid(file: &str, field: &str, value: f64, allowed: String) -> AfmError {
    AfmError::InvalidField {
        file: file.to_string(),
        field: field.to_string(),
        value: format_number(value),
        allowed,
    }
}

/// `value` rounded to 12 significant digits, so that a product reads cleanly (`2e-8 * 1e9`
/// prints as `20`, not `20.000000000000004`; `0.01 * 9.3` as `0.093`).
fn round_to_significant(value: f64) -> f64 {
    if value == 0.0 || !value.is_finite() {
        return value;
    }
    format!("{value:.11e}").parse().unwrap_or(value)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn warnings_of_one_kind_are_gathered_and_a_single_one_is_kept_as_it_is() {
        let stiffness = ranges::STIFFNESS_N_PER_M;
        let field = |i: usize, value: f64| {
            (
                FieldPath::entry("modes", i, "stiffness_n_per_m"),
                value,
                stiffness,
            )
        };
        // Typical up to 1e3 N/m: modes 1 and 3 to 5 are above it, mode 2 is not.
        let mut fields = vec![
            (FieldPath::top("tip_radius_nm"), 2e4, ranges::TIP_RADIUS_NM),
            field(0, 1.0),
            field(1, 2e3),
            field(2, 5.0),
            field(3, 7e4),
            field(4, 3e3),
        ];
        let warnings = gathered_warnings("lever.json", &fields);
        assert_eq!(warnings.len(), 2, "{warnings:?}");
        assert_eq!(
            warnings[0],
            plausibility_warning("lever.json", "tip_radius_nm", 2e4, ranges::TIP_RADIUS_NM)
                .expect("a warning")
        );
        assert!(
            warnings[1].starts_with(
                "lever.json: field `modes[i].stiffness_n_per_m` is unusual for AFM in 3 entries \
                 (`modes[1].stiffness_n_per_m` to `modes[4].stiffness_n_per_m`, values 2000 to \
                 70000;"
            ),
            "{}",
            warnings[1]
        );
        fields.truncate(3);
        assert_eq!(
            gathered_warnings("lever.json", &fields)[1],
            plausibility_warning("lever.json", "modes[1].stiffness_n_per_m", 2e3, stiffness)
                .expect("a warning")
        );
    }
}
