//! Bit-exact floating point: `f64`s stored as their IEEE-754 bit patterns (16 lower-case hex digits), so that a
//! checkpoint round-trips every value (non-finite ones too) whatever a JSON reader does with decimals, and a cheap
//! fingerprint of bytes. The bottom floor of the crate: it imports nothing from it.

/// `f64` as its bit pattern in 16 hex digits, for `#[serde(with = "exact_f64")]`.
pub mod exact_f64 {
    use serde::{Deserialize, Deserializer, Serializer};

    /// The 16-hex-digit bit pattern of `x`.
    pub fn to_hex(x: f64) -> String {
        format!("{:016x}", x.to_bits())
    }

    /// Parses [`to_hex`]'s output (exactly 16 hex digits).
    pub fn from_hex(s: &str) -> Option<f64> {
        if s.len() != 16 || !s.bytes().all(|b| b.is_ascii_hexdigit()) {
            return None;
        }
        u64::from_str_radix(s, 16).ok().map(f64::from_bits)
    }

    pub(crate) fn parse<E: serde::de::Error>(s: &str) -> Result<f64, E> {
        from_hex(s).ok_or_else(|| E::custom(format!("expected an f64 as 16 hex digits of its bits, got {s:?}")))
    }

    /// Serializes `x` as [`to_hex`].
    pub fn serialize<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&to_hex(*x))
    }

    /// Deserializes [`to_hex`]'s output.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        let s = String::deserialize(d)?;
        parse::<D::Error>(&s)
    }
}

/// `Option<f64>` with [`exact_f64`] (`null` for `None`).
pub mod exact_f64_opt {
    use serde::{Deserialize, Deserializer, Serializer};

    /// Serializes `Some(x)` as [`super::exact_f64::to_hex`], `None` as `null`.
    pub fn serialize<S: Serializer>(x: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
        match x {
            Some(v) => s.serialize_some(&super::exact_f64::to_hex(*v)),
            None => s.serialize_none(),
        }
    }

    /// Deserializes what [`serialize`] writes.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
        match Option::<String>::deserialize(d)? {
            Some(s) => super::exact_f64::parse::<D::Error>(&s).map(Some),
            None => Ok(None),
        }
    }
}

/// `Vec<f64>` with [`exact_f64`] (a JSON array of hex strings).
pub mod exact_f64_vec {
    use serde::{Deserialize, Deserializer, Serializer};

    /// Serializes each element as [`super::exact_f64::to_hex`].
    pub fn serialize<S: Serializer>(x: &[f64], s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(x.iter().map(|&v| super::exact_f64::to_hex(v)))
    }

    /// Deserializes what [`serialize`] writes.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<f64>, D::Error> {
        Vec::<String>::deserialize(d)?
            .iter()
            .map(|s| super::exact_f64::parse::<D::Error>(s))
            .collect()
    }
}

/// `[f64; N]` with [`exact_f64`] (a JSON array of exactly `N` hex strings).
pub mod exact_f64_array {
    use serde::de::Error as _;
    use serde::{Deserialize, Deserializer, Serializer};

    /// Serializes each element as [`super::exact_f64::to_hex`].
    pub fn serialize<S: Serializer, const N: usize>(x: &[f64; N], s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(x.iter().map(|&v| super::exact_f64::to_hex(v)))
    }

    /// Deserializes what [`serialize`] writes.
    pub fn deserialize<'de, D: Deserializer<'de>, const N: usize>(d: D) -> Result<[f64; N], D::Error> {
        let v = Vec::<String>::deserialize(d)?;
        if v.len() != N {
            return Err(D::Error::custom(format!("expected {N} numbers, got {}", v.len())));
        }
        let mut out = [0.0; N];
        for (o, s) in out.iter_mut().zip(&v) {
            *o = super::exact_f64::parse::<D::Error>(s)?;
        }
        Ok(out)
    }
}

/// FNV-1a 64 of `bytes`, as 16 hex digits (a cheap fingerprint, not a cryptographic hash).
pub fn fnv1a_hex(bytes: &[u8]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    format!("{h:016x}")
}
