//! The engine-independent floor of file input and output: lossless float formatting ([`fmt_f64`]), the checkpoint
//! file names ([`checkpoint`]), the scene-file reading, parsing and field checks every engine's scene uses
//! ([`scene_file`]), the run's stand-alone scene copy ([`standalone`]), and the one-writer lock of the directories rubblepile writes ([`run_lock`]), the one way it writes a file there: atomically and never through a link ([`safe_write`]), the manifest of checksums that lets a run directory be verified ([`manifest`]), and the outlet of every line the library means for a person ([`messages`]). Each engine's own
//! output formats live with the engine (e.g. `ellipsoid::output`).
//!
//! Floats are written with `{:e}` (Rust's shortest representation that round-trips, in scientific notation), so a
//! snapshot re-read as an input file gives the same `f64`s bit for bit.

pub mod checkpoint;
pub mod limits;
pub mod manifest;
pub mod messages;
pub mod output_times;
pub mod particles;
pub mod run_budget;
pub mod run_lock;
pub mod safe_write;
pub mod scene_fields;
pub mod scene_file;
pub mod ss;
pub mod standalone;
pub mod table;
pub mod vtk;

/// Formats an `f64` losslessly: the shortest decimal that parses back to the same bits (`{:e}`).
pub fn fmt_f64(x: f64) -> String {
    let mut s = String::with_capacity(24);
    push_f64(&mut s, x);
    s
}

/// Appends [`fmt_f64`]`(x)` to `out` without allocating: exactly the text of `{:e}` (the shortest digits that parse
/// back to the same bits), from the shortest digits of the `ryu` crate, which is faster than `core::fmt`. Where
/// two shortest candidates are equally close to `x` (573617812358680.25), `ryu` keeps the even last digit and
/// `{:e}` the larger: [`halfway_above`] finds those cases exactly.
pub fn push_f64(out: &mut String, x: f64) {
    if !x.is_finite() {
        out.push_str(if x.is_nan() {
            "NaN"
        } else if x > 0.0 {
            "inf"
        } else {
            "-inf"
        });
        return;
    }
    if x.is_sign_negative() {
        out.push('-');
    }
    let abs = x.abs();
    let mut buffer = ryu::Buffer::new();
    let text = buffer.format_finite(abs);
    // ryu writes `a.b`, `a.beE` or `aeE`: gather the significant digits and the exponent of the first one.
    let (mantissa, exponent) = match text.split_once('e') {
        Some((m, e)) => (m, e.parse::<i32>().unwrap_or(0)),
        None => (text, 0),
    };
    let (int, frac) = mantissa.split_once('.').unwrap_or((mantissa, ""));
    let (mut digits, mut count, mut leading) = (0u64, 0i32, 0i32);
    for b in int.bytes().chain(frac.bytes()) {
        let d = u64::from(b - b'0');
        if digits == 0 && d == 0 {
            leading += 1;
            continue;
        }
        digits = digits * 10 + d;
        count += 1;
    }
    if digits == 0 {
        out.push_str("0e0");
        return;
    }
    while digits % 10 == 0 {
        digits /= 10;
        count -= 1;
    }
    let mut exp10 = int.len() as i32 - 1 - leading + exponent;
    // Equally close to `digits` and `digits + 1` in the last place: `{:e}` takes the larger, ryu the even one.
    if halfway_above(abs, digits, exp10 - count + 1) {
        let before = digits.ilog10();
        digits += 1;
        if digits.ilog10() > before {
            // 99…9 + 1: the first digit moves one place up.
            exp10 += 1;
        }
        while digits % 10 == 0 {
            digits /= 10;
        }
    }
    let mut text = [0u8; 20];
    let significant = decimal(digits, &mut text);
    out.push(significant[0] as char);
    if significant.len() > 1 {
        out.push('.');
        out.extend(significant[1..].iter().map(|&d| d as char));
    }
    out.push('e');
    if exp10 < 0 {
        out.push('-');
    }
    out.extend(
        decimal(exp10.unsigned_abs().into(), &mut text)
            .iter()
            .map(|&d| d as char),
    );
}

/// The decimal digits of `n`, most significant first, written at the end of `buffer`.
fn decimal(mut n: u64, buffer: &mut [u8; 20]) -> &[u8] {
    let mut k = buffer.len();
    loop {
        k -= 1;
        buffer[k] = b'0' + (n % 10) as u8;
        n /= 10;
        if n == 0 {
            return &buffer[k..];
        }
    }
}

/// Whether `abs` (finite, > 0) is exactly `(digits + ½)·10^k`: halfway between two decimals of as many digits.
/// With `abs = odd·2^p` (odd integer `odd`), `2·abs = odd·2^(p+1)` must equal `(2·digits + 1)·5^k·2^k`, whose odd
/// part is `(2·digits + 1)·5^k` (for k < 0, `odd·5^−k` must equal `2·digits + 1`) and whose power of two is `2^k`.
fn halfway_above(abs: f64, digits: u64, k: i32) -> bool {
    let bits = abs.to_bits();
    let (biased, fraction) = ((bits >> 52) as i32, bits & ((1 << 52) - 1));
    let (integer, e) = if biased == 0 {
        (fraction, -1074)
    } else {
        (fraction | (1 << 52), biased - 1075)
    };
    if integer == 0 {
        return false;
    }
    let zeros = integer.trailing_zeros() as i32;
    let odd = u128::from(integer >> zeros);
    if zeros + e + 1 != k {
        return false;
    }
    let m = 2 * u128::from(digits) + 1;
    let five = |n: i32| 5u128.checked_pow(n as u32);
    if k >= 0 {
        five(k).and_then(|p| m.checked_mul(p)) == Some(odd)
    } else {
        five(-k).and_then(|p| odd.checked_mul(p)) == Some(m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`push_f64`] writes exactly what `{:e}` writes: special values, zeros, subnormals, extremes, powers of ten,
    /// halfway cases (two shortest candidates equally close) and 4·10⁶ random bit patterns (a fixed xorshift
    /// stream, about 900 of them halfway cases).
    #[test]
    fn push_f64_writes_what_lower_exp_writes() {
        let mut cases = vec![
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.1,
            1e3,
            1e16,
            1e-7,
            123456.0,
            1.5e-300,
            5e-324,
            f64::MAX,
            f64::MIN_POSITIVE,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::from_bits(0xc300_4d9e_6f8a_30c2), // −573617812358680.25, halfway
            f64::from_bits(0xc310_565a_94b4_e5f5), // −1149636667324797.25, halfway
            999999999999999.5,
            0.5,
            2.5,
            1e23,
            9007199254740993.0,
        ];
        cases.extend((-320..=308).map(|k| 10f64.powi(k)));
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..4_000_000 {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            cases.push(f64::from_bits(seed));
        }
        let mut s = String::new();
        for x in cases {
            s.clear();
            push_f64(&mut s, x);
            assert_eq!(s, format!("{x:e}"), "bits {:016x}", x.to_bits());
        }
    }

    #[test]
    fn fmt_f64_round_trips() {
        for x in [
            0.0,
            -0.0,
            1.0,
            0.1,
            1.0 / 3.0,
            6.674e-11,
            1e300,
            -2.5e-310,
            f64::MAX,
            f64::MIN_POSITIVE,
        ] {
            let s = fmt_f64(x);
            let y: f64 = s.parse().unwrap();
            assert_eq!(x.to_bits(), y.to_bits(), "{x} -> {s}");
        }
    }
}
