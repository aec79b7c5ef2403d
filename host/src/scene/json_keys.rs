//! Duplicate keys in a JSON object: serde keeps the last silently (a
//! scene file naming material `white` twice renders with the second), so
//! scene files and glTF JSON are read once through [`Unique`] first, which
//! refuses any object, at any depth, that names a key twice.
use std::collections::HashSet;
use std::fmt;

use serde::de::{self, Deserialize, Deserializer, MapAccess, SeqAccess, Visitor};

/// Any JSON value, read only to check that no object repeats a key.
pub struct Unique;

impl<'de> Deserialize<'de> for Unique {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(UniqueVisitor)
    }
}

struct UniqueVisitor;

impl<'de> Visitor<'de> for UniqueVisitor {
    type Value = Unique;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a JSON value")
    }
    fn visit_bool<E>(self, _: bool) -> Result<Unique, E> {
        Ok(Unique)
    }
    fn visit_i64<E>(self, _: i64) -> Result<Unique, E> {
        Ok(Unique)
    }
    fn visit_u64<E>(self, _: u64) -> Result<Unique, E> {
        Ok(Unique)
    }
    fn visit_f64<E>(self, _: f64) -> Result<Unique, E> {
        Ok(Unique)
    }
    fn visit_str<E>(self, _: &str) -> Result<Unique, E> {
        Ok(Unique)
    }
    fn visit_unit<E>(self) -> Result<Unique, E> {
        Ok(Unique)
    }
    fn visit_none<E>(self) -> Result<Unique, E> {
        Ok(Unique)
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Unique, A::Error> {
        while seq.next_element::<Unique>()?.is_some() {}
        Ok(Unique)
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Unique, A::Error> {
        let mut seen = HashSet::new();
        while let Some(key) = map.next_key::<String>()? {
            if !seen.insert(key.clone()) {
                return Err(de::Error::custom(format!("the key {key:?} appears twice in one object")));
            }
            map.next_value::<Unique>()?;
        }
        Ok(Unique)
    }
}

/// Refuses JSON `text` where an object names a key twice; the error gives
/// the key, line and column. Text that is not JSON passes (the real parse
/// that follows names its fault).
pub fn check(text: &[u8]) -> Result<(), String> {
    match serde_json::from_slice::<Unique>(text) {
        Err(e) if e.is_data() => Err(format!("line {}, column {}: {e}", e.line(), e.column())),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn repeated_keys_are_found_at_any_depth() {
        assert!(check(br#"{"a": 1, "b": [{"c": 2, "d": {"e": 3}}]}"#).is_ok());
        assert!(check(br#"{"a": 1, "b": {"x": 1}, "c": {"x": 2}}"#).is_ok(), "the same key in two objects");
        let e = check(b"{\"materials\": {\n  \"white\": {}, \"white\": {}}}").unwrap_err();
        assert!(e.contains("\"white\" appears twice") && e.contains("line 2"), "{e}");
        assert!(check(br#"[1, {"k": [{"z": 0, "z": 1}]}]"#).unwrap_err().contains("\"z\""));
        // Not JSON: left to the real parse.
        assert!(check(b"{ not json").is_ok());
    }
}
