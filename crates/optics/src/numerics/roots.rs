//! A bracketed scalar root finder for the few one-dimensional inversions of the physics crates,
//! and the plain bisection that tabulation and tone-curve inversions use.
//!
//! Written by hand rather than taken from a crate: the inversions here are monotone, smooth and
//! called in hot loops (one per pixel channel in batch work), so we want an allocation-free,
//! generic-closure routine with a guaranteed bracket; the crates that offer this (`roots`) are
//! unmaintained.

/// Finds x in [lo, hi] with f(x) = 0 by the Illinois variant of regula falsi (Dowell & Jarratt 1971,
/// "A modified regula falsi method", BIT 11), which keeps the bracket and converges superlinearly.
/// Returns `None` when f(lo) and f(hi) have the same sign or are not finite.
pub fn bracketed_root<F: Fn(f64) -> f64>(f: F, lo: f64, hi: f64, x_tol: f64) -> Option<f64> {
    let (mut a, mut b) = (lo, hi);
    let (mut fa, mut fb) = (f(a), f(b));
    if !(fa.is_finite() && fb.is_finite()) || fa * fb > 0.0 {
        return None;
    }
    if fa == 0.0 {
        return Some(a);
    }
    if fb == 0.0 {
        return Some(b);
    }
    let mut side = 0i8;
    for _ in 0..200 {
        let c = (a * fb - b * fa) / (fb - fa);
        let fc = f(c);
        if fc == 0.0 || (b - a).abs() < x_tol {
            return Some(c);
        }
        if fc * fb > 0.0 {
            b = c;
            fb = fc;
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        } else {
            a = c;
            fa = fc;
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        }
        if (b - a).abs() < x_tol {
            return Some(0.5 * (a + b));
        }
    }
    Some(0.5 * (a + b))
}

/// Bisection with a fixed number of steps: halves [lo, hi] `steps` times, keeping the half where
/// `below` turns from true (at lo) to false (at hi), and returns the last bracket. For a
/// monotone predicate such as "f(x) is still above the level"; 60 steps shrink a bracket of 1 by
/// 2⁻⁶⁰, below the spacing of doubles near 1.
pub fn bisect(
    mut lo: f64,
    mut hi: f64,
    steps: usize,
    mut below: impl FnMut(f64) -> bool,
) -> (f64, f64) {
    for _ in 0..steps {
        let mid = 0.5 * (lo + hi);
        if below(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_cube_root_of_two_and_refuses_unbracketed() {
        let r = bracketed_root(|x| x * x * x - 2.0, 0.0, 2.0, 1e-14).unwrap();
        assert!((r - 2f64.cbrt()).abs() < 1e-13);
        assert!(bracketed_root(|x| x * x + 1.0, -1.0, 1.0, 1e-12).is_none());
    }
}
