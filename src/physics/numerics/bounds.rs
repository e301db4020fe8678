//! Limiting a value to computed bounds without a panic path.

/// `x` limited to `[lo, hi]`, like `f64::clamp` but without its panic when the bounds are
/// unordered or NaN: these bounds are computed (from parameters, caches or a restored state) and a
/// panic must never be the answer to bad data. Unordered bounds give `hi`; a NaN bound is
/// ignored; a NaN `x` stays NaN, for the caller's own check (as with `clamp`).
#[inline]
pub fn limit(x: f64, lo: f64, hi: f64) -> f64 {
    if x.is_nan() {
        x
    } else {
        x.max(lo).min(hi)
    }
}

#[cfg(test)]
mod tests {
    use super::limit;

    #[test]
    fn limit_is_clamp_for_ordered_bounds_and_never_panics() {
        for (x, lo, hi) in [(0.5, 0.0, 1.0), (-3.0, -1.0, 2.0), (9.0, -1.0, 2.0)] {
            assert_eq!(limit(x, lo, hi), x.clamp(lo, hi));
        }
        assert!(limit(f64::NAN, 0.0, 1.0).is_nan());
        // Where clamp panics ("min > max, or either was NaN").
        assert_eq!(limit(0.5, 2.0, 1.0), 1.0);
        assert_eq!(limit(0.5, f64::NAN, 1.0), 0.5);
        assert_eq!(limit(5.0, 0.0, f64::NAN), 5.0);
    }
}
