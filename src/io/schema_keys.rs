//! The keys a scene schema accepts, read from its `serde::Deserialize` impl itself: [`schema_keys`] runs the impl
//! against a recording deserializer that answers each `deserialize_struct` with the field names serde passes it (the
//! `fields` list of the derive, renames applied) and recurses into every table, optional table and array of tables. It
//! is how the field reference (`io::scene_fields`, whose test reads this walk) is tested against what the TOML parser
//! really takes: a key added to a schema without a row, or a row the parser does not know, fails that test.
//!
//! Values are made up (0, `""`, `false`, one-element arrays), so a field whose own deserializer refuses them (a
//! fixed-length array read by `exact::array`) fails the walk; the walk is then run again without that field, until
//! every table has been reached. serde's data model: <https://serde.rs/data-model.html>.

use std::cell::RefCell;
use std::collections::BTreeSet;

use serde::de::{self, DeserializeOwned, DeserializeSeed, IntoDeserializer, MapAccess, SeqAccess, Visitor};

/// The keys of a schema, as dotted paths (`physics.gravity.G`; an array of tables unindexed, `body.axes`).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct SchemaKeys {
    /// Keys whose value is a table (or an array of tables), e.g. `physics`, `physics.gravity`, `body`.
    pub tables: BTreeSet<String>,
    /// Every other key: the ones that hold values.
    pub leaves: BTreeSet<String>,
}

/// Most walks [`schema_keys`] makes (each leaves out one more field that refused the made-up value); a schema
/// has far fewer fields than this.
const MAX_WALKS: usize = 10_000;

/// The keys `T` accepts (see the module header).
pub fn schema_keys<T: DeserializeOwned>() -> SchemaKeys {
    let seen = RefCell::new(Seen::default());
    for _ in 0..MAX_WALKS {
        let result = T::deserialize(Recorder {
            path: String::new(),
            seen: &seen,
        });
        let failed = match result {
            Ok(_) => None,
            Err(e) => e.at,
        };
        let left_out = failed.is_some_and(|path| seen.borrow_mut().skip.insert(path));
        if !left_out {
            break;
        }
    }
    let seen = seen.into_inner();
    SchemaKeys {
        leaves: seen.keys.difference(&seen.tables).cloned().collect(),
        tables: seen.tables,
    }
}

#[derive(Default)]
struct Seen {
    /// Every field name met, as a dotted path.
    keys: BTreeSet<String>,
    /// The paths deserialized as structs.
    tables: BTreeSet<String>,
    /// Fields left out of the next walk: their deserializer refused the made-up value.
    skip: BTreeSet<String>,
}

/// A failed walk, and the field whose value failed (set by the innermost table that saw it).
#[derive(Debug)]
struct WalkError {
    message: String,
    at: Option<String>,
}

impl std::fmt::Display for WalkError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for WalkError {}

impl de::Error for WalkError {
    fn custom<M: std::fmt::Display>(msg: M) -> Self {
        WalkError {
            message: msg.to_string(),
            at: None,
        }
    }
}

fn join(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_string()
    } else {
        format!("{path}.{key}")
    }
}

/// The recording deserializer at `path`.
struct Recorder<'a> {
    path: String,
    seen: &'a RefCell<Seen>,
}

impl<'de> de::Deserializer<'de> for Recorder<'_> {
    type Error = WalkError;

    fn deserialize_any<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, WalkError> {
        visitor.visit_unit()
    }
    fn deserialize_bool<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, WalkError> {
        visitor.visit_bool(false)
    }
    fn deserialize_i64<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, WalkError> {
        visitor.visit_i64(0)
    }
    fn deserialize_u64<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, WalkError> {
        visitor.visit_u64(0)
    }
    fn deserialize_f64<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, WalkError> {
        visitor.visit_f64(0.0)
    }
    fn deserialize_str<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, WalkError> {
        visitor.visit_str("")
    }
    fn deserialize_string<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, WalkError> {
        visitor.visit_str("")
    }
    fn deserialize_option<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, WalkError> {
        visitor.visit_some(self)
    }
    fn deserialize_seq<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, WalkError> {
        visitor.visit_seq(Elements {
            left: 1,
            recorder: self,
        })
    }
    fn deserialize_tuple<V: Visitor<'de>>(self, len: usize, visitor: V) -> Result<V::Value, WalkError> {
        visitor.visit_seq(Elements {
            left: len,
            recorder: self,
        })
    }
    fn deserialize_enum<V: Visitor<'de>>(
        self,
        _name: &'static str,
        variants: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value, WalkError> {
        let first: de::value::StrDeserializer<'_, WalkError> =
            variants.first().copied().unwrap_or("").into_deserializer();
        visitor.visit_enum(first)
    }
    fn deserialize_struct<V: Visitor<'de>>(
        self,
        _name: &'static str,
        fields: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value, WalkError> {
        let keys: Vec<&'static str> = {
            let mut seen = self.seen.borrow_mut();
            if !self.path.is_empty() {
                seen.tables.insert(self.path.clone());
            }
            for f in fields {
                seen.keys.insert(join(&self.path, f));
            }
            fields
                .iter()
                .copied()
                .filter(|f| !seen.skip.contains(&join(&self.path, f)))
                .collect()
        };
        visitor.visit_map(Fields {
            keys,
            next: 0,
            path: self.path,
            seen: self.seen,
        })
    }

    serde::forward_to_deserialize_any! {
        i8 i16 i32 i128 u8 u16 u32 u128 f32 char bytes byte_buf unit unit_struct newtype_struct tuple_struct map
        identifier ignored_any
    }
}

/// A made-up array of `left` elements.
struct Elements<'a> {
    left: usize,
    recorder: Recorder<'a>,
}

impl<'de> SeqAccess<'de> for Elements<'_> {
    type Error = WalkError;

    fn next_element_seed<T: DeserializeSeed<'de>>(&mut self, seed: T) -> Result<Option<T::Value>, WalkError> {
        if self.left == 0 {
            return Ok(None);
        }
        self.left -= 1;
        seed.deserialize(Recorder {
            path: self.recorder.path.clone(),
            seen: self.recorder.seen,
        })
        .map(Some)
    }
}

/// A table holding every field of a struct (less the skipped ones), each with a made-up value.
struct Fields<'a> {
    keys: Vec<&'static str>,
    next: usize,
    path: String,
    seen: &'a RefCell<Seen>,
}

impl<'de> MapAccess<'de> for Fields<'_> {
    type Error = WalkError;

    fn next_key_seed<K: DeserializeSeed<'de>>(&mut self, seed: K) -> Result<Option<K::Value>, WalkError> {
        match self.keys.get(self.next) {
            Some(key) => {
                let key: de::value::StrDeserializer<'_, WalkError> = (*key).into_deserializer();
                seed.deserialize(key).map(Some)
            }
            None => Ok(None),
        }
    }

    fn next_value_seed<V: DeserializeSeed<'de>>(&mut self, seed: V) -> Result<V::Value, WalkError> {
        let path = join(&self.path, self.keys[self.next]);
        self.next += 1;
        seed.deserialize(Recorder {
            path: path.clone(),
            seen: self.seen,
        })
        .map_err(|mut e| {
            e.at.get_or_insert(path);
            e
        })
    }
}
