//! Conversions through a `serde_json::Value`, whose objects are sorted maps: a derived
//! `Serialize` written with its keys in sorted order, and a value as a `Value`.

use serde::{ser::Error, Serialize, Serializer};
use serde_json::Value;

/// Serialize `value` through a `serde_json::Value`: the same bytes as `serde_json::json!` of
/// the value gives, every object's keys in sorted order (for `#[serde(serialize_with)]` on a
/// field whose type declares its fields in another order).
pub fn sorted_keys<T: Serialize + ?Sized, S: Serializer>(
    value: &T,
    serializer: S,
) -> Result<S::Ok, S::Error> {
    serde_json::to_value(value)
        .map_err(S::Error::custom)?
        .serialize(serializer)
}

/// `value` as a `serde_json::Value`, for a value whose objects all have string keys (the only
/// case where serde_json's conversion fails is a map with other keys).
pub fn plain_value<T: Serialize + ?Sized>(value: &T) -> Value {
    serde_json::to_value(value).expect("objects with string keys")
}
