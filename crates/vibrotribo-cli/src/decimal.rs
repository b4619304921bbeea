//! Numbers as text, fast: the shortest decimal that reads back to the same `f64`, laid out
//! exactly as Rust's `{}` (`Display`) lays it out (no exponent: `0.00001`, `120000000`, `-0`),
//! so that a file written through here is byte for byte the one `format!("{x}")` would give.
//!
//! The digits come from `zmij` (Schubfach), faster than the standard library's Grisu with its
//! Dragon fallback. Both give the shortest digit string inside the value's rounding interval,
//! the one nearest the value; they differ only at an exact tie between two such strings
//! (`1658206780088562.25`: `{}` rounds the tie up, zmij to even). A tie needs a value whose
//! exact decimal expansion has at most 18 significant digits (the midpoint of two strings of
//! at most 17), which [`may_tie`] detects from the bits; those few values go through `{}`.

use std::io::Write as _;

/// Appends `x` as `format!("{x}")` would (finite `x`); nothing for NaN and ±inf, which a
/// result file leaves as an empty field.
pub fn push_f64(out: &mut Vec<u8>, x: f64) {
    if !x.is_finite() {
        return;
    }
    if may_tie(x) {
        let _ = write!(out, "{x}");
        return;
    }
    let mut buffer = zmij::Buffer::new();
    let text = buffer.format_finite(x).as_bytes();
    // zmij writes `ddd.ddd` (with `.0` for an integer) for decimal exponents −5 to 15, as `{}`
    // does but for the `.0`, and `d.ddde±x` outside them.
    let n = text.len();
    let e = text[n.saturating_sub(5)..].iter().position(|&b| b == b'e');
    match e {
        None => {
            let keep = if text.ends_with(b".0") { n - 2 } else { n };
            out.extend_from_slice(&text[..keep]);
        }
        Some(i) => {
            let e = n.saturating_sub(5) + i;
            push_scientific(out, &text[..e], parse_exponent(&text[e + 1..]));
        }
    }
}

/// Lays out `mantissa × 10^exp10` (`mantissa`: `[-]d[.ddd]`, first digit nonzero) as `{}`.
fn push_scientific(out: &mut Vec<u8>, mantissa: &[u8], exp10: i32) {
    let (negative, mantissa) = match mantissa.split_first() {
        Some((b'-', rest)) => (true, rest),
        _ => (false, mantissa),
    };
    let mut digits = [0u8; 20];
    let mut len = 0;
    for &b in mantissa {
        if b != b'.' && len < digits.len() {
            digits[len] = b;
            len += 1;
        }
    }
    while len > 1 && digits[len - 1] == b'0' {
        len -= 1;
    }
    let digits = &digits[..len];
    if negative {
        out.push(b'-');
    }
    // x = 0.DIGITS × 10^point.
    let point = exp10 + 1;
    if point <= 0 {
        out.extend_from_slice(b"0.");
        push_zeros(out, (-point) as usize);
        out.extend_from_slice(digits);
    } else if (point as usize) < len {
        let (int, frac) = digits.split_at(point as usize);
        out.extend_from_slice(int);
        out.push(b'.');
        out.extend_from_slice(frac);
    } else {
        out.extend_from_slice(digits);
        push_zeros(out, point as usize - len);
    }
}

/// Whether `x` (finite) could lie exactly halfway between two shortest decimal strings: only
/// if its exact decimal expansion has at most 18 significant digits. With `x = m·2^e`, `m` odd:
/// for `e < 0` that expansion is `m·5^(−e)` shifted, so it needs `m·5^(−e) < 10^18`; for
/// `e ≥ 0` (an integer) a tie needs two candidates at least 10 apart inside the rounding
/// interval, so an ulp of at least 16: `|x| ≥ 2^56`.
fn may_tie(x: f64) -> bool {
    let bits = x.to_bits();
    let biased = ((bits >> 52) & 0x7ff) as i32;
    let fraction = bits & ((1u64 << 52) - 1);
    let (significand, exp2) = if biased == 0 {
        (fraction, -1074)
    } else {
        (fraction | (1u64 << 52), biased - 1075)
    };
    if significand == 0 {
        return false;
    }
    let tz = significand.trailing_zeros() as i32;
    let (m, e) = (significand >> tz, exp2 + tz);
    if e >= 0 {
        return biased >= 1023 + 56;
    }
    if -e > 25 {
        return false;
    }
    u128::from(m) * 5u128.pow((-e) as u32) < 1_000_000_000_000_000_000
}

fn parse_exponent(text: &[u8]) -> i32 {
    let (sign, digits) = match text.split_first() {
        Some((b'-', rest)) => (-1, rest),
        Some((b'+', rest)) => (1, rest),
        _ => (1, text),
    };
    sign * digits.iter().fold(0i32, |acc, &d| 10 * acc + i32::from(d - b'0'))
}

fn push_zeros(out: &mut Vec<u8>, n: usize) {
    out.resize(out.len() + n, b'0');
}

#[cfg(test)]
mod tests {
    use super::push_f64;

    fn check(x: f64) {
        let mut got = Vec::new();
        push_f64(&mut got, x);
        let want = if x.is_finite() {
            format!("{x}")
        } else {
            String::new()
        };
        assert_eq!(
            String::from_utf8_lossy(&got),
            want,
            "{x:e} (bits {:#018x})",
            x.to_bits()
        );
    }

    /// The text is the standard library's `Display` (an independent implementation of the
    /// shortest digits: Grisu with the Dragon fallback), on edge cases, exact ties, random bit
    /// patterns of every exponent and values of the sizes results have.
    #[test]
    fn matches_display() {
        for x in [
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.1,
            0.25,
            1e-5,
            1e-6,
            1e-7,
            1e15,
            1e16,
            1e17,
            1e21,
            1e22,
            1e23,
            123456789012345680.0,
            1658206780088562.0 + 0.25,
            5e-324,
            -5e-324,
            f64::MIN_POSITIVE,
            f64::MAX,
            f64::MIN,
            f64::EPSILON,
            0.30000000000000004,
            9007199254740993.0,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ] {
            check(x);
        }
        // xorshift.
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for _ in 0..100_000 {
            // Uniform bit patterns: every exponent.
            check(f64::from_bits(next()));
            // Values of the sizes results have.
            let mantissa = (next() >> 11) as f64 / (1u64 << 53) as f64;
            let exp = (next() % 60) as i32 - 40;
            check(mantissa * 10f64.powi(exp));
            // Short decimals: several nearby candidates.
            check((next() % 100_000) as f64 * 10f64.powi(exp));
            // Dyadic values with few fractional bits, where exact ties live.
            let k = (next() % 24) as i32;
            let m = (next() >> 11) | 1;
            check(m as f64 * 2f64.powi(-k));
            check(m as f64 * 2f64.powi(k + 4));
        }
    }
}
