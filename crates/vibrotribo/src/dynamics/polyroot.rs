//! First positive roots of the low-degree polynomials the event search bounds its functions
//! with ([`super::roots`]): closed forms to degree 2, and above, brackets on monotone pieces
//! (or the whole half-line, by Descartes' rule of signs) searched by safeguarded Newton.

/// Relative precision of a certified step: the step is a lower bound of the polynomial's
/// first root within this fraction (a shorter step is still safe).
pub(super) const STEP_RTOL: f64 = 1e-6;

/// Smallest positive root of `c0 + c1 h + c2 h²` (c0 ≥ 0), if any.
fn smallest_positive_quadratic_root(c0: f64, c1: f64, c2: f64) -> Option<f64> {
    if c2 == 0.0 {
        return if c1 < 0.0 { Some(-c0 / c1) } else { None };
    }
    let disc = c1 * c1 - 4.0 * c2 * c0;
    if disc < 0.0 {
        return None;
    }
    let q = -0.5 * (c1 + c1.signum() * disc.sqrt());
    let mut best: Option<f64> = None;
    for r in [q / c2, if q != 0.0 { c0 / q } else { f64::NAN }] {
        if r.is_finite() && r >= 0.0 && best.is_none_or(|b| r < b) {
            best = Some(r);
        }
    }
    best
}

/// Evaluates a polynomial with coefficients in increasing order.
#[inline]
pub(super) fn horner(c: &[f64], x: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &ci| acc * x + ci)
}

/// First positive root of the polynomial `c` (increasing order, degree ≤ 4, `c[0] ≥ 0`), or
/// a value slightly below it; `+∞` if there is none. Zero if `c[0] == 0` and the polynomial
/// decreases from 0.
pub(super) fn first_positive_root(c: &[f64]) -> f64 {
    // The quartic bound of every step, with a nonzero leading coefficient, gets its own copy
    // with the length known (Horner passes unrolled); anything else takes the general one.
    match <&[f64; 5]>::try_from(c) {
        Ok(quartic) if quartic[4] != 0.0 => first_positive_root_of(quartic),
        _ => first_positive_root_of(c),
    }
}

/// [`first_positive_root`]'s body, inlined into each caller.
#[inline(always)]
fn first_positive_root_of(c: &[f64]) -> f64 {
    let mut deg = c.len() - 1;
    while deg > 0 && c[deg] == 0.0 {
        deg -= 1;
    }
    let c = &c[..=deg];
    match deg {
        0 => f64::INFINITY,
        1 | 2 => {
            let c2 = if deg == 2 { c[2] } else { 0.0 };
            smallest_positive_quadratic_root(c[0], c[1], c2).unwrap_or(f64::INFINITY)
        }
        _ => {
            if c[0] <= 0.0 {
                // Starts at zero: the first root is 0 unless the polynomial rises first.
                let lead = c[1..].iter().copied().find(|&x| x != 0.0).unwrap_or(0.0);
                if lead < 0.0 {
                    return 0.0;
                }
            }
            if c[0] > 0.0 && sign_changes(c) == 1 {
                // Descartes' rule: one sign change, one positive root, so the whole of
                // [0, ∞) brackets it and the critical points need not be found.
                return match upper_bracket(c, 0.0) {
                    Some(hi) => bracket_root(c, 0.0, hi, true, STEP_RTOL),
                    None => f64::INFINITY,
                };
            }
            let mut crit = [0.0; 4];
            let ncrit = critical_points(c, &mut crit);
            let mut lo = 0.0;
            for &hi in crit[..ncrit].iter().chain(std::iter::once(&f64::INFINITY)) {
                let hi = if hi.is_infinite() {
                    upper_bracket(c, lo)
                } else {
                    Some(hi)
                };
                let Some(hi) = hi else {
                    return f64::INFINITY;
                };
                if horner(c, hi) <= 0.0 {
                    return bracket_root(c, lo, hi, true, STEP_RTOL);
                }
                lo = hi;
            }
            f64::INFINITY
        }
    }
}

/// Sign changes between the nonzero coefficients of `c`. By Descartes' rule of signs the
/// number of positive roots (with multiplicity) is this number or less by an even number.
fn sign_changes(c: &[f64]) -> usize {
    let mut last = 0.0f64;
    let mut n = 0;
    for &x in c {
        if x != 0.0 {
            if last != 0.0 && (x < 0.0) != (last < 0.0) {
                n += 1;
            }
            last = x;
        }
    }
    n
}

/// A point beyond `lo` where the polynomial is negative, if the leading coefficient is
/// negative: beyond every root, by Fujiwara's bound.
///
/// The root of the local quadratic model at `lo`, or twice as far, is tried first: where the
/// polynomial is already ≤ 0 there, it is a much tighter bracket than the bound (and costs no
/// cube or fourth roots).
fn upper_bracket(c: &[f64], lo: f64) -> Option<f64> {
    let lead = c[c.len() - 1];
    if lead > 0.0 {
        return None;
    }
    if let Some(h) = quadratic_model_step(c, lo, false) {
        for x in [lo + h, lo + 2.0 * h] {
            if x > lo && x.is_finite() && horner(c, x) <= 0.0 {
                return Some(x);
            }
        }
    }
    Some(root_bound(c).max(lo) * (1.0 + 1e-12) + f64::MIN_POSITIVE)
}

/// Fujiwara's bound on the moduli of the roots of `c` (degree ≥ 1, nonzero leading
/// coefficient): `2 max(|a_{n−1}/a_n|, |a_{n−2}/a_n|^{1/2}, …, |a_0/(2a_n)|^{1/n})`. Much
/// tighter than Cauchy's when the leading coefficient is small.
fn root_bound(c: &[f64]) -> f64 {
    let n = c.len() - 1;
    let lead = c[n];
    let mut b = 0.0f64;
    for (i, &ci) in c[..n].iter().enumerate() {
        let ratio = if i == 0 {
            (ci / (2.0 * lead)).abs()
        } else {
            (ci / lead).abs()
        };
        let root = match n - i {
            1 => ratio,
            2 => ratio.sqrt(),
            3 => cbrt_above(ratio),
            4 => ratio.sqrt().sqrt(),
            k => ratio.powf(1.0 / k as f64),
        };
        b = b.max(root);
    }
    2.0 * b
}

/// A value at or slightly above `x^(1/3)` (x ≥ 0), much cheaper than `cbrt`: an exponent-based
/// start and two Newton steps `y ← (2y + x/y²)/3`, each ≥ ∛x by the inequality of arithmetic
/// and geometric means whatever the start, then a margin against rounding. Within 1e-4 of
/// ∛x after the two steps.
fn cbrt_above(x: f64) -> f64 {
    if !(x > 0.0 && x.is_finite()) {
        return x.cbrt();
    }
    // ∛x = 2^(e/3) · ∛m for x = m·2^e: the bits of x with the exponent divided by three.
    let bits = x.to_bits();
    let mut y = f64::from_bits(bits / 3 + 0x2A9F_7893_782D_A1CE);
    for _ in 0..2 {
        y = (2.0 * y + x / (y * y)) / 3.0;
    }
    y * (1.0 + 1e-12)
}

/// The positive critical points of `c` (degree 2 to 4, trimmed), in increasing order: the
/// positive roots of its derivative. Returns how many.
#[inline]
fn critical_points(c: &[f64], out: &mut [f64; 4]) -> usize {
    let deg = c.len() - 1;
    let mut dc = [0.0; 4];
    for i in 1..=deg {
        dc[i - 1] = i as f64 * c[i];
    }
    positive_roots(&dc[..deg], out)
}

/// All positive real roots of `c` (degree ≤ 3) in increasing order; returns how many.
pub(super) fn positive_roots(c: &[f64], out: &mut [f64; 4]) -> usize {
    let mut deg = c.len() - 1;
    while deg > 0 && c[deg] == 0.0 {
        deg -= 1;
    }
    let c = &c[..=deg];
    match deg {
        0 => 0,
        1 => {
            let r = -c[0] / c[1];
            if r > 0.0 {
                out[0] = r;
                1
            } else {
                0
            }
        }
        2 => {
            let disc = c[1] * c[1] - 4.0 * c[2] * c[0];
            if disc < 0.0 {
                return 0;
            }
            let q = -0.5 * (c[1] + if c[1] >= 0.0 { 1.0 } else { -1.0 } * disc.sqrt());
            let mut roots = [q / c[2], if q != 0.0 { c[0] / q } else { f64::NAN }];
            roots.sort_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal));
            let mut n = 0;
            for r in roots {
                if r.is_finite() && r > 0.0 {
                    out[n] = r;
                    n += 1;
                }
            }
            n
        }
        _ => {
            let mut crit = [0.0; 4];
            let ncrit = critical_points(c, &mut crit);
            let mut n = 0;
            let mut lo = 0.0;
            let mut plo = c[0];
            for next in crit[..ncrit]
                .iter()
                .copied()
                .map(Some)
                .chain(std::iter::once(None))
            {
                let hi = if let Some(critical) = next {
                    critical.max(lo)
                } else {
                    // Beyond the last critical point the polynomial is monotone towards the
                    // sign of its leading coefficient: no root there if it already has that
                    // sign (or is zero), and no bound (a cube root) is needed to say so.
                    if plo == 0.0 || (plo < 0.0) == (c[deg] < 0.0) {
                        break;
                    }
                    (root_bound(c) * (1.0 + 1e-12) + f64::MIN_POSITIVE).max(lo)
                };
                let phi = horner(c, hi);
                if phi == 0.0 {
                    if hi > 0.0 && n < out.len() {
                        out[n] = hi;
                        n += 1;
                    }
                } else if plo != 0.0 && (plo < 0.0) != (phi < 0.0) && n < out.len() {
                    out[n] = bracket_root(c, lo, hi, false, 1e-12);
                    n += 1;
                }
                lo = hi;
                plo = phi;
            }
            n
        }
    }
}

/// A root of `c` in `[lo, hi]` where `c` is monotone and changes sign, to relative precision
/// `rtol`. With `safe_left` the result lies on the side of `lo` (never beyond the root).
pub(super) fn bracket_root(c: &[f64], lo: f64, hi: f64, safe_left: bool, rtol: f64) -> f64 {
    // The lengths that arise (the cubic and quartic bounds and models) get their own copies
    // with the length known (Horner passes unrolled), as in `first_positive_root`.
    if let Ok(cubic) = <&[f64; 4]>::try_from(c) {
        bracket_root_of(cubic, lo, hi, safe_left, rtol)
    } else if let Ok(quartic) = <&[f64; 5]>::try_from(c) {
        bracket_root_of(quartic, lo, hi, safe_left, rtol)
    } else {
        bracket_root_of(c, lo, hi, safe_left, rtol)
    }
}

/// [`bracket_root`]'s body, inlined into each caller.
#[inline(always)]
fn bracket_root_of(c: &[f64], mut lo: f64, mut hi: f64, safe_left: bool, rtol: f64) -> f64 {
    let before_negative = horner(c, lo) < 0.0;
    // Start Newton at the root of the local quadratic model at `lo` when it falls inside the
    // bracket (within a step or two of the root when the bracket is wide, as the Fujiwara
    // bound or a far critical point make it); otherwise at the end where f·f'' > 0
    // (Fourier's condition), from where it approaches the root monotonically when the
    // convexity is constant over the bracket. Either start is only a start: the bracket
    // update below keeps every iterate safe.
    let mut x = match quadratic_model_step(c, lo, before_negative) {
        Some(h) if lo + h > lo && lo + h < hi => lo + h,
        _ => {
            if horner(c, hi) * second_derivative(c, hi) > 0.0 {
                hi
            } else {
                lo
            }
        }
    };
    for _ in 0..100 {
        let (fx, d) = horner_with_derivative(c, x);
        if fx == 0.0 {
            return x;
        }
        if (fx < 0.0) == before_negative {
            lo = x;
        } else {
            hi = x;
        }
        if hi - lo <= rtol * hi.abs() {
            break;
        }
        // Newton from x, accepted inside the bracket; converged once its step is below
        // the tolerance (the bracket itself need not shrink from both sides).
        let xn = if d != 0.0 { x - fx / d } else { f64::NAN };
        if xn > lo && xn < hi {
            if (xn - x).abs() <= 0.25 * rtol * xn.abs() {
                if !safe_left {
                    return xn;
                }
                let left = xn * (1.0 - rtol);
                if left > lo && (horner(c, left) < 0.0) == before_negative {
                    return left;
                }
                hi = hi.min(xn * (1.0 + rtol));
            }
            x = xn;
        } else if xn >= hi {
            // Newton points at or past `hi`: the root is within rounding of `hi` (as when
            // `hi` came from the quadratic model itself). Probe just inside it, which closes
            // the bracket at once if the root is there, instead of halving towards it.
            x = (hi - 0.5 * rtol * hi.abs()).max(0.5 * (lo + hi));
        } else {
            x = 0.5 * (lo + hi);
        }
    }
    if safe_left { lo } else { 0.5 * (lo + hi) }
}

/// The smallest positive root of the quadratic Taylor model of `c` at `x`,
/// `p(x) + p'(x)h + p''(x)h²/2` (sign-flipped first when `p(x) < 0`), if it has one.
#[inline]
fn quadratic_model_step(c: &[f64], x: f64, negative: bool) -> Option<f64> {
    // p, p' and p''/2 in one Horner pass (the first three coefficients of the Taylor shift).
    let n = c.len();
    let (mut p, mut d1, mut half_d2) = (c[n - 1], 0.0, 0.0);
    for &ci in c[..n - 1].iter().rev() {
        half_d2 = half_d2 * x + d1;
        d1 = d1 * x + p;
        p = p * x + ci;
    }
    let s = if negative { -1.0 } else { 1.0 };
    smallest_positive_quadratic_root(s * p, s * d1, s * half_d2)
}

/// p(x) and p'(x) in one Horner pass.
#[inline]
fn horner_with_derivative(c: &[f64], x: f64) -> (f64, f64) {
    let n = c.len();
    let mut p = c[n - 1];
    let mut d = 0.0;
    let mut i = n - 1;
    while i > 0 {
        i -= 1;
        d = d * x + p;
        p = p * x + c[i];
    }
    (p, d)
}

/// p''(x).
#[inline]
fn second_derivative(c: &[f64], x: f64) -> f64 {
    let mut d = 0.0;
    let mut i = c.len();
    while i > 2 {
        i -= 1;
        d = d * x + (i * (i - 1)) as f64 * c[i];
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `first_positive_root` returns a lower bound of the first root, within `STEP_RTOL`.
    fn assert_safe(c: &[f64], root: f64) {
        let r = first_positive_root(c);
        assert!(
            r <= root * (1.0 + 1e-14),
            "{c:?}: {r} beyond the first root {root}"
        );
        assert!(
            r >= root * (1.0 - 2.0 * STEP_RTOL),
            "{c:?}: {r} far below the first root {root}"
        );
    }

    #[test]
    fn polynomial_first_roots() {
        // (1 − h)(2 − h)(3 − h): first root 1.
        assert_safe(&[6.0, -11.0, 6.0, -1.0], 1.0);
        // Dips below zero between 1 and 2 and comes back: first root 1.
        assert_safe(&[2.0, -3.0, 1.0], 1.0);
        // Never zero.
        assert_eq!(first_positive_root(&[1.0, 0.0, 1.0]), f64::INFINITY);
        // −(h − 0.5)²(h + 1)(h − 3) touches zero at 0.5 (a double root).
        let c = [0.75, -2.5, 0.75, 3.0, -1.0];
        let r = first_positive_root(&c);
        assert!(r <= 0.5 + 1e-12 && r > 0.49, "{r}");
        // Starting at zero and rising, then falling: h − h³, root at 1.
        assert_safe(&[0.0, 1.0, 0.0, -1.0], 1.0);
        // A quartic lower bound with a tiny leading coefficient (Fujiwara's bound matters):
        // 0.02 − 5h − 150h²... has its root near 0.004.
        let c = [0.02, -5.0, -150.0, 1000.0, -1e5];
        let root = {
            let (mut lo, mut hi) = (0.0f64, 1.0f64);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if horner(&c, mid) > 0.0 { lo = mid } else { hi = mid }
            }
            lo
        };
        assert_safe(&c, root);
        // Lower bounds met in runs, whose first root is the root of their own quadratic
        // model to rounding (the bracket's upper end then sits on the root) or lies far inside
        // a wide bracket: the start and the probe next to `hi` must keep the result safe.
        for c in [
            vec![
                1.4296857498704243e-11,
                -10.922003136656379,
                -109.57272620912545,
                2528.9671589936142,
                -92896.1214815175,
            ],
            vec![
                7.618231593816644e-14,
                -7.181090492056494,
                -166.61381225926002,
                -11690.44411256956,
            ],
            vec![
                6.542984662268214e-16,
                -0.4955155012900079,
                -92.5002433026169,
                1276.7608389218974,
                -98244.60760505123,
            ],
            vec![
                0.019999999999996135,
                0.0,
                0.34999999999999964,
                -8020.8695977128555,
            ],
            vec![
                0.2296848864777573,
                4.804838894790922,
                -95.59959295323004,
                -9681.820468984655,
            ],
            vec![
                8.336933049292047e-14,
                4.30865429523223,
                -168.5971610618289,
                -787.9690676214647,
                -109922.81717606784,
            ],
        ] {
            let hi = (1..60)
                .map(|k| 1e-17 * 2f64.powi(k))
                .find(|&h| horner(&c, h) <= 0.0)
                .unwrap();
            let (mut lo, mut hi) = (0.0f64, hi);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if horner(&c, mid) > 0.0 { lo = mid } else { hi = mid }
            }
            assert_safe(&c, lo);
        }
    }

    #[test]
    fn cbrt_above_is_an_upper_bound_within_1e_4() {
        let mut x = 1e-300;
        while x < 1e300 {
            for m in [1.0, 1.37, 2.0, 3.99, 7.5] {
                let v = x * m;
                let (y, exact) = (cbrt_above(v), v.cbrt());
                assert!(
                    y >= exact && y <= exact * (1.0 + 1e-4),
                    "{v}: {y} against {exact}"
                );
            }
            x *= 10.0;
        }
        assert_eq!(cbrt_above(0.0), 0.0);
    }
}
