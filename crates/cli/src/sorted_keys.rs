//! Serialize a value with its objects' keys in sorted order, as `serde_json::Value` writes them
//! (its objects are sorted maps), for a derived `Serialize` whose fields are not declared in
//! alphabetical order.

use serde::{ser::Error, Serialize, Serializer};

/// Serialize `value` through a `serde_json::Value`: the same bytes as `serde_json::json!` of
/// the value gives, every object's keys in sorted order (for `#[serde(serialize_with)]`).
pub fn sorted_keys<T: Serialize + ?Sized, S: Serializer>(
    value: &T,
    serializer: S,
) -> Result<S::Ok, S::Error> {
    serde_json::to_value(value)
        .map_err(S::Error::custom)?
        .serialize(serializer)
}
