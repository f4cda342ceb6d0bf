//! Real roots of the low-degree polynomials of the time-of-impact problems (Richardson11 §2.2; derivations in the docs
//! of `geometry::walls`, "Particle–wall").
//!
//! Quadratics use the cancellation-free form `q = −(B + sgn(B)√Δ)/2`, roots `q/A` and `C/q`, so that a root next
//! to zero (a particle that has just touched a wall) keeps full relative precision. Higher degrees (the ring's torus
//! quartic) are solved by root isolation on an interval: the real roots of the derivative split the interval into
//! pieces on which the polynomial is monotone, and each piece with a sign change holds exactly one root, found by
//! safeguarded Newton–bisection to the last bit. Unlike Laguerre's method this never converges to a complex root or
//! skips a real one, and it only looks where the answer can be (inside the step).

/// The real roots of `a t² + b t + c = 0`, ascending (`None` entries when there are fewer than two). A vanishing
/// `a` leaves the linear equation; `a = b = 0` has no roots.
pub fn quadratic(a: f64, b: f64, c: f64) -> [Option<f64>; 2] {
    if a == 0.0 {
        if b == 0.0 {
            return [None, None];
        }
        return [Some(-c / b), None];
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return [None, None];
    }
    let q = -0.5 * (b + b.signum() * disc.sqrt());
    if q == 0.0 {
        // b = 0 and disc = 0: the double root t = 0 (c = 0).
        return [Some(0.0), Some(0.0)];
    }
    let (r1, r2) = (q / a, c / q);
    if r1 <= r2 {
        [Some(r1), Some(r2)]
    } else {
        [Some(r2), Some(r1)]
    }
}

/// Value of the polynomial with ascending coefficients `c` at `t` (Horner).
pub fn eval(c: &[f64], t: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &k| acc * t + k)
}

fn derivative(c: &[f64]) -> Vec<f64> {
    c.iter().enumerate().skip(1).map(|(k, &x)| k as f64 * x).collect()
}

/// Ascending coefficients with trailing (leading-power) zeros removed.
fn trimmed(c: &[f64]) -> &[f64] {
    let mut n = c.len();
    while n > 0 && c[n - 1] == 0.0 {
        n -= 1;
    }
    &c[..n]
}

/// All real roots in `[lo, hi]` of the polynomial with ascending coefficients `c` (any degree, in practice ≤ 4),
/// ascending, where the polynomial changes sign (double roots where it only touches zero, tangencies, are not
/// reported: a sphere grazing a surface does not enter it).
pub fn real_roots_in(c: &[f64], lo: f64, hi: f64) -> Vec<f64> {
    let c = trimmed(c);
    let mut out = Vec::new();
    if c.len() < 2 || lo > hi {
        return out;
    }
    if c.len() == 2 {
        let t = -c[0] / c[1];
        if (lo..=hi).contains(&t) {
            out.push(t);
        }
        return out;
    }
    // Split points: the critical points inside (lo, hi).
    let crit = real_roots_in(&derivative(c), lo, hi);
    let mut knots = Vec::with_capacity(crit.len() + 2);
    knots.push(lo);
    knots.extend(crit.into_iter().filter(|&t| t > lo && t < hi));
    knots.push(hi);
    let dc = derivative(c);
    for w in knots.windows(2) {
        let (a, b) = (w[0], w[1]);
        let (fa, fb) = (eval(c, a), eval(c, b));
        if fa == 0.0 {
            if out.last() != Some(&a) {
                out.push(a);
            }
            continue;
        }
        if fb == 0.0 {
            out.push(b);
            continue;
        }
        if (fa < 0.0) == (fb < 0.0) {
            continue;
        }
        out.push(monotone_root(c, &dc, a, b, fa));
    }
    out
}

/// The single root of a polynomial monotone on `[a, b]` with `f(a) = fa` and a sign change on the interval:
/// Newton steps kept inside the bracket, bisection otherwise, down to adjacent floats.
fn monotone_root(c: &[f64], dc: &[f64], mut a: f64, mut b: f64, fa: f64) -> f64 {
    let neg_at_a = fa < 0.0;
    let mut t = 0.5 * (a + b);
    for _ in 0..200 {
        let f = eval(c, t);
        if f == 0.0 {
            return t;
        }
        if (f < 0.0) == neg_at_a {
            a = t;
        } else {
            b = t;
        }
        let mid = 0.5 * (a + b);
        if mid <= a || mid >= b {
            break;
        }
        let d = eval(dc, t);
        let newton = t - f / d;
        t = if d != 0.0 && newton > a && newton < b && (newton - t).abs() < 0.5 * (b - a) {
            newton
        } else {
            mid
        };
    }
    // The bracket end on the far side of the sign change: the first instant at (or past) the root.
    if (eval(c, a) < 0.0) == neg_at_a && eval(c, a) != 0.0 {
        b
    } else {
        a
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quadratic_small_root_keeps_precision() {
        // (t − 1e-12)(t − 3)
        let r = quadratic(1.0, -(3.0 + 1e-12), 3e-12);
        assert!((r[0].unwrap() - 1e-12).abs() < 1e-27);
        assert!((r[1].unwrap() - 3.0).abs() < 1e-15);
        assert_eq!(quadratic(1.0, 0.0, 1.0), [None, None]);
    }

    #[test]
    fn quartic_roots_found() {
        // (t − 0.1)(t − 0.2)(t − 0.7)(t + 2)
        let r = [0.1, 0.2, 0.7, -2.0];
        let mut c = vec![1.0];
        for x in r {
            let mut n = vec![0.0; c.len() + 1];
            for (k, &a) in c.iter().enumerate() {
                n[k] -= x * a;
                n[k + 1] += a;
            }
            c = n;
        }
        let got = real_roots_in(&c, 0.0, 1.0);
        assert_eq!(got.len(), 3);
        for (g, e) in got.iter().zip([0.1, 0.2, 0.7]) {
            assert!((g - e).abs() < 1e-15, "{g} {e}");
        }
    }
}
