//! The one safeguarded Newton-bisection root finder of the physics (McKibben connector, free
//! bladder diameter, onion-state minimum).
//!
//! Given a bracket `[lo, hi]` over which `f` changes sign, each iteration evaluates `f` and its
//! slope, shrinks the bracket to the side that keeps the sign change, and takes the Newton step
//! when it lands strictly inside the bracket with a slope of the bracket's sign, else bisects.
//! The bracket therefore shrinks every iteration and the loop is capped: it cannot diverge,
//! and it converges quadratically once Newton takes over. Hand-written (no allocation, no
//! closure boxing) because all three callers are on per-step paths.

/// Stopping rules of [`newton_bisection`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RootOptions {
    /// Converged when the Newton correction is at most `absolute + relative |x|` (m or rad).
    pub absolute: f64,
    pub relative: f64,
    /// Iteration cap (each iteration is one evaluation).
    pub max_iterations: usize,
    /// Below this bracket width (0: never) a sign change that the slopes cannot explain is a
    /// jump of `f`, not a root: where the values at the bracket's ends differ by more than 4
    /// times the steeper end's slope times the width, the finder stops (`Root::jump`). Across
    /// a root, even at a kink, they differ by at most about that slope times the width.
    pub jump_width: f64,
}

/// One evaluation of the function: its value, slope and whatever the caller wants back at the
/// root (e.g. the full model state there).
#[derive(Clone, Debug, PartialEq)]
pub struct Sample<T> {
    pub value: f64,
    pub slope: f64,
    pub payload: T,
}

/// Where the finder stopped.
#[derive(Clone, Debug, PartialEq)]
pub struct Root<T> {
    pub x: f64,
    /// The last successful evaluation (at `x` unless every evaluation failed).
    pub payload: Option<T>,
    /// False when the iteration cap was reached before the stopping rule held.
    pub converged: bool,
    /// The sign change is a jump of `f` (see [`RootOptions::jump_width`]): `x` is next to it,
    /// not a root.
    pub jump: bool,
}

/// Root of `f` in the bracket between `lo` and `hi` (either order), starting from `start`
/// (clamped into the bracket). `rising` says that `f` is negative at the lower end and positive at
/// the upper one. `eval` returns `Ok(None)` where `f` cannot be evaluated (the finder bisects) and
/// `Err` to abort.
pub fn newton_bisection<T, E>(
    lo: f64,
    hi: f64,
    start: f64,
    rising: bool,
    options: RootOptions,
    mut eval: impl FnMut(f64) -> Result<Option<Sample<T>>, E>,
) -> Result<Root<T>, E> {
    let (mut lo, mut hi) = if lo <= hi { (lo, hi) } else { (hi, lo) };
    let mut x = if start.is_finite() {
        crate::physics::numerics::bounds::limit(start, lo, hi)
    } else {
        0.5 * (lo + hi)
    };
    let orientation = if rising { 1.0 } else { -1.0 };
    let mut payload = None;
    // (value, slope) evaluated at `lo` and `hi`, once they are.
    let (mut at_lo, mut at_hi) = (None, None);
    for _ in 0..options.max_iterations {
        let Some(s) = eval(x)? else {
            x = 0.5 * (lo + hi);
            continue;
        };
        let (value, slope) = (s.value, s.slope);
        payload = Some(s.payload);
        let tolerance = options.absolute + options.relative * x.abs();
        if value == 0.0 {
            return Ok(Root {
                x,
                payload,
                converged: true,
                jump: false,
            });
        }
        if orientation * value < 0.0 {
            (lo, at_lo) = (x, Some((value, slope)));
        } else {
            (hi, at_hi) = (x, Some((value, slope)));
        }
        let newton = x - value / slope;
        let newton_ok = newton.is_finite() && orientation * slope > 0.0;
        if (newton_ok && (newton - x).abs() <= tolerance) || hi - lo <= tolerance {
            return Ok(Root {
                x,
                payload,
                converged: true,
                jump: false,
            });
        }
        if let (true, Some((v_lo, s_lo)), Some((v_hi, s_hi))) =
            (hi - lo <= options.jump_width, at_lo, at_hi)
        {
            let steeper = f64::max(s_lo.abs(), s_hi.abs());
            if (v_hi - v_lo).abs() > 4.0 * steeper * (hi - lo) {
                return Ok(Root {
                    x,
                    payload,
                    converged: false,
                    jump: true,
                });
            }
        }
        x = if newton_ok && newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
    }
    Ok(Root {
        x,
        payload,
        converged: false,
        jump: false,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn options() -> RootOptions {
        RootOptions {
            absolute: 0.0,
            relative: 1e-15,
            max_iterations: 100,
            jump_width: 0.0,
        }
    }

    fn plain(f: impl Fn(f64) -> (f64, f64)) -> impl FnMut(f64) -> Result<Option<Sample<()>>, ()> {
        move |x| {
            let (value, slope) = f(x);
            Ok(Some(Sample {
                value,
                slope,
                payload: (),
            }))
        }
    }

    #[test]
    fn square_root_of_two_both_orientations() {
        let r = newton_bisection(
            0.0,
            2.0,
            2.0,
            true,
            options(),
            plain(|x| (x * x - 2.0, 2.0 * x)),
        );
        let r = r.unwrap();
        assert!(r.converged && (r.x - 2f64.sqrt()).abs() < 4e-16, "{}", r.x);
        let r = newton_bisection(
            2.0,
            0.0,
            0.0,
            false,
            options(),
            plain(|x| (2.0 - x * x, -2.0 * x)),
        );
        let r = r.unwrap();
        assert!(r.converged && (r.x - 2f64.sqrt()).abs() < 4e-16, "{}", r.x);
    }

    #[test]
    fn newton_that_would_leave_the_bracket_bisects_instead() {
        // atan from far out: pure Newton diverges (|x0| > 1.39); the safeguard converges.
        let r = newton_bisection(
            -10.0,
            20.0,
            15.0,
            true,
            options(),
            plain(|x| (x.atan(), 1.0 / (1.0 + x * x))),
        )
        .unwrap();
        assert!(r.converged && r.x.abs() < 1e-15, "{}", r.x);
    }

    #[test]
    fn wrong_slope_sign_and_failed_evaluations_bisect() {
        // A slope of the wrong sign (a fold's) never drives the step; failures bisect.
        let mut calls = 0;
        let r = newton_bisection(0.0, 1.0, 0.9, true, options(), |x: f64| -> Result<_, ()> {
            calls += 1;
            Ok((calls % 3 != 0).then_some(Sample {
                value: x - 0.3,
                slope: -1.0,
                payload: x,
            }))
        })
        .unwrap();
        assert!(r.converged && (r.x - 0.3).abs() < 1e-15, "{}", r.x);
        assert_eq!(r.payload, Some(r.x));
    }

    /// A sign change at a jump is reported as one once the bracket is narrower than
    /// `jump_width`, a root at a kink (the slope steps from 1 to 1e6) is not, and without
    /// `jump_width` the finder narrows onto the jump as onto a root.
    #[test]
    fn a_jump_is_told_from_a_kink() {
        let jump = |x: f64| (if x < 0.3 { x - 0.5 } else { x + 0.5 }, 1.0);
        let kink = |x: f64| {
            if x < 0.3 {
                (x - 0.3, 1.0)
            } else {
                (1e6 * (x - 0.3), 1e6)
            }
        };
        let with = RootOptions {
            jump_width: 1e-9,
            ..options()
        };
        let r = newton_bisection(0.0, 1.0, 0.9, true, with, plain(jump)).unwrap();
        assert!(r.jump && !r.converged && (r.x - 0.3).abs() < 1e-9, "{r:?}");
        let r = newton_bisection(0.0, 1.0, 0.9, true, options(), plain(jump)).unwrap();
        assert!(!r.jump && r.converged && (r.x - 0.3).abs() < 1e-15, "{r:?}");
        for start in [0.0, 0.29, 0.31, 1.0] {
            let r = newton_bisection(0.0, 1.0, start, true, with, plain(kink)).unwrap();
            assert!(!r.jump && r.converged && (r.x - 0.3).abs() < 1e-15, "{r:?}");
        }
    }

    #[test]
    fn errors_abort_and_the_cap_is_reported() {
        let e = newton_bisection(
            0.0,
            1.0,
            0.5,
            true,
            options(),
            |_| -> Result<Option<Sample<()>>, &str> { Err("no") },
        );
        assert_eq!(e, Err("no"));
        let capped = RootOptions {
            max_iterations: 3,
            ..options()
        };
        // Bisection alone (no usable slope) cannot reach 1e-15 in 3 halvings.
        let r = newton_bisection(0.0, 1.0, 0.5, true, capped, plain(|x| (x - 0.3, 0.0))).unwrap();
        assert!(!r.converged && (r.x - 0.3).abs() < 0.2);
    }
}
