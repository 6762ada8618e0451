//! Range checks shared by every input struct: one place that turns a bad value into an
//! [`AfmError::InvalidField`] naming the file, the field and the allowed range.

use crate::AfmError;

/// An interval of allowed values with its unit, printed as e.g. `(0, 1e6] N/m`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Interval {
    pub min: f64,
    pub min_inclusive: bool,
    pub max: f64,
    pub max_inclusive: bool,
    pub unit: &'static str,
}

impl Interval {
    /// `(min, max]`: positive quantities with an upper sanity bound.
    pub const fn positive(max: f64, unit: &'static str) -> Self {
        Self {
            min: 0.0,
            min_inclusive: false,
            max,
            max_inclusive: true,
            unit,
        }
    }

    /// `[min, max]`.
    pub const fn closed(min: f64, max: f64, unit: &'static str) -> Self {
        Self {
            min,
            min_inclusive: true,
            max,
            max_inclusive: true,
            unit,
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
        }
    }

    fn contains(&self, value: f64) -> bool {
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
        above && below
    }

    fn describe(&self) -> String {
        let open = if self.min_inclusive { '[' } else { '(' };
        let close = if self.max_inclusive { ']' } else { ')' };
        let unit = if self.unit.is_empty() {
            String::new()
        } else {
            format!(" {}", self.unit)
        };
        format!("{open}{}, {}{close}{unit}", self.min, self.max)
    }
}

/// Check that `value` (a finite number) lies in `interval`.
pub(crate) fn check(
    file: &str,
    field: &str,
    value: f64,
    interval: Interval,
) -> Result<(), AfmError> {
    if value.is_finite() && interval.contains(value) {
        Ok(())
    } else {
        Err(AfmError::InvalidField {
            file: file.to_string(),
            field: field.to_string(),
            value: value.to_string(),
            allowed: interval.describe(),
        })
    }
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
        value: value.to_string(),
        allowed,
    }
}
