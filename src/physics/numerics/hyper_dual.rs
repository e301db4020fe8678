//! Hyper-dual numbers of two variables: value, gradient and Hessian with respect to the muscle
//! length `l` and the bladder's outer diameter `x`, the second-order companion of
//! [`Dual`](super::dual::Dual). Hand-written like it: the bladder's stiffness partials run its
//! whole kernel on these numbers.

use std::ops::{Add, Mul, Sub};

/// Value, gradient `[d/dl, d/dx]` and Hessian `[d2/dl2, d2/dl dx, d2/dx2]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HyperDual {
    pub v: f64,
    pub d: [f64; 2],
    pub h: [f64; 3],
}

impl HyperDual {
    /// A seed: value, gradient and Hessian as given (a function of the variables `l`, `x`).
    pub fn seed(v: f64, d: [f64; 2], h: [f64; 3]) -> Self {
        Self { v, d, h }
    }

    /// `phi(self)` from `phi`, `phi'` and `phi''` at the value: the chain rule to second order.
    #[inline]
    fn chain(self, value: f64, first: f64, second: f64) -> Self {
        let [a, b] = self.d;
        let [aa, ab, bb] = self.h;
        Self {
            v: value,
            d: [first * a, first * b],
            h: [
                second * a * a + first * aa,
                second * a * b + first * ab,
                second * b * b + first * bb,
            ],
        }
    }

    /// A number that depends on neither variable.
    pub fn constant(v: f64) -> Self {
        Self {
            v,
            d: [0.0; 2],
            h: [0.0; 3],
        }
    }
    pub fn recip(self) -> Self {
        let r = 1.0 / self.v;
        self.chain(r, -r * r, 2.0 * r * r * r)
    }
    pub fn ln(self) -> Self {
        let r = 1.0 / self.v;
        self.chain(self.v.ln(), r, -r * r)
    }
    pub fn exp(self) -> Self {
        let e = self.v.exp();
        self.chain(e, e, e)
    }
    pub fn rsqrt(self) -> Self {
        // v^(-1/2): first -v^(-3/2)/2, second 3 v^(-5/2)/4.
        let r = 1.0 / self.v.sqrt();
        let r3 = r * r * r;
        self.chain(r, -0.5 * r3, 0.75 * r3 * r * r)
    }
    pub fn sqrt(self) -> Self {
        // v^(1/2): first v^(-1/2)/2, second -v^(-3/2)/4.
        let s = self.v.sqrt();
        let r = 1.0 / s;
        self.chain(s, 0.5 * r, -0.25 * r * r * r)
    }
}

impl Add for HyperDual {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Self {
            v: self.v + o.v,
            d: [self.d[0] + o.d[0], self.d[1] + o.d[1]],
            h: [self.h[0] + o.h[0], self.h[1] + o.h[1], self.h[2] + o.h[2]],
        }
    }
}

impl Add<f64> for HyperDual {
    type Output = Self;
    fn add(self, o: f64) -> Self {
        Self {
            v: self.v + o,
            ..self
        }
    }
}

impl Sub for HyperDual {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        self + o * -1.0
    }
}

impl Mul for HyperDual {
    type Output = Self;
    fn mul(self, o: Self) -> Self {
        let (f, g) = (self, o);
        Self {
            v: f.v * g.v,
            d: [f.d[0] * g.v + f.v * g.d[0], f.d[1] * g.v + f.v * g.d[1]],
            // (fg)_ij = f_ij g + f_i g_j + f_j g_i + f g_ij.
            h: [
                f.h[0] * g.v + 2.0 * f.d[0] * g.d[0] + f.v * g.h[0],
                f.h[1] * g.v + f.d[0] * g.d[1] + f.d[1] * g.d[0] + f.v * g.h[1],
                f.h[2] * g.v + 2.0 * f.d[1] * g.d[1] + f.v * g.h[2],
            ],
        }
    }
}

impl Mul<f64> for HyperDual {
    type Output = Self;
    fn mul(self, o: f64) -> Self {
        Self {
            v: self.v * o,
            d: self.d.map(|d| d * o),
            h: self.h.map(|h| h * o),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::numerics::dual::Dual;

    /// `f(l, x) = exp(l x) sqrt(l) / x + ln(l + x) rsqrt(x)` against its hand-derived Hessian's
    /// central differences of the exact gradient.
    #[test]
    fn hessian_of_a_composite_matches_differences_of_its_gradient() {
        fn f(l: HyperDual, x: HyperDual) -> HyperDual {
            (l * x).exp() * l.sqrt() * x.recip() + (l + x).ln() * x.rsqrt()
        }
        fn f_dual(l: Dual, x: Dual) -> Dual {
            (l * x).exp() * l.sqrt() * x.recip() + (l + x).ln() * x.rsqrt()
        }
        let at = |l: f64, x: f64| {
            f(
                HyperDual::seed(l, [1.0, 0.0], [0.0; 3]),
                HyperDual::seed(x, [0.0, 1.0], [0.0; 3]),
            )
        };
        let (l, x, h) = (0.7, 1.3, 1e-6);
        let y = at(l, x);
        let first = |l: f64, x: f64| {
            let dl = f_dual(Dual::var_l(l), Dual::constant(x)).dl;
            let dx = f_dual(Dual::constant(l), Dual::var_x(x)).dx;
            [dl, dx]
        };
        assert!((y.d[0] - first(l, x)[0]).abs() < 1e-12 * y.d[0].abs());
        assert!((y.d[1] - first(l, x)[1]).abs() < 1e-12 * y.d[1].abs());
        let by_l = |k: usize| (first(l + h, x)[k] - first(l - h, x)[k]) / (2.0 * h);
        let by_x = |k: usize| (first(l, x + h)[k] - first(l, x - h)[k]) / (2.0 * h);
        for (exact, central) in [(y.h[0], by_l(0)), (y.h[1], by_x(0)), (y.h[2], by_x(1))] {
            assert!(
                (exact - central).abs() < 1e-7 * exact.abs().max(1.0),
                "{exact} {central}"
            );
        }
        assert!((by_l(1) - y.h[1]).abs() < 1e-7 * y.h[1].abs().max(1.0));
    }
}
