//! Forward-mode dual numbers for the bladder's analytic stiffness and Newton slope.

use std::ops::{Add, Mul, Sub};

/// Forward-mode dual number: value and partial derivatives with respect to the muscle length
/// (`dl`) and the bladder's outer diameter (`dx`). Hand-written for speed on the hot path.
#[derive(Clone, Copy, Debug)]
pub struct Dual {
    pub v: f64,
    pub dl: f64,
    pub dx: f64,
}

impl Dual {
    #[inline]
    pub fn constant(v: f64) -> Self {
        Self {
            v,
            dl: 0.0,
            dx: 0.0,
        }
    }
    #[inline]
    pub fn var_l(v: f64) -> Self {
        Self {
            v,
            dl: 1.0,
            dx: 0.0,
        }
    }
    #[inline]
    pub fn var_x(v: f64) -> Self {
        Self {
            v,
            dl: 0.0,
            dx: 1.0,
        }
    }
    #[inline]
    pub fn ln(self) -> Self {
        let d = 1.0 / self.v;
        Self {
            v: self.v.ln(),
            dl: self.dl * d,
            dx: self.dx * d,
        }
    }
    #[inline]
    pub fn exp(self) -> Self {
        let e = self.v.exp();
        Self {
            v: e,
            dl: self.dl * e,
            dx: self.dx * e,
        }
    }
    #[inline]
    pub fn rsqrt(self) -> Self {
        let r = 1.0 / self.v.sqrt();
        let d = -0.5 * r * r * r;
        Self {
            v: r,
            dl: self.dl * d,
            dx: self.dx * d,
        }
    }
    #[inline]
    pub fn sqrt(self) -> Self {
        let r = self.v.sqrt();
        let d = 0.5 / r;
        Self {
            v: r,
            dl: self.dl * d,
            dx: self.dx * d,
        }
    }
    #[inline]
    pub fn recip(self) -> Self {
        let r = 1.0 / self.v;
        let d = -r * r;
        Self {
            v: r,
            dl: self.dl * d,
            dx: self.dx * d,
        }
    }
}

impl Add for Dual {
    type Output = Dual;
    #[inline]
    fn add(self, o: Dual) -> Dual {
        Dual {
            v: self.v + o.v,
            dl: self.dl + o.dl,
            dx: self.dx + o.dx,
        }
    }
}

impl Add<f64> for Dual {
    type Output = Dual;
    #[inline]
    fn add(self, o: f64) -> Dual {
        Dual {
            v: self.v + o,
            ..self
        }
    }
}

impl Sub for Dual {
    type Output = Dual;
    #[inline]
    fn sub(self, o: Dual) -> Dual {
        Dual {
            v: self.v - o.v,
            dl: self.dl - o.dl,
            dx: self.dx - o.dx,
        }
    }
}

impl Mul for Dual {
    type Output = Dual;
    #[inline]
    fn mul(self, o: Dual) -> Dual {
        Dual {
            v: self.v * o.v,
            dl: self.dl * o.v + self.v * o.dl,
            dx: self.dx * o.v + self.v * o.dx,
        }
    }
}

impl Mul<f64> for Dual {
    type Output = Dual;
    #[inline]
    fn mul(self, o: f64) -> Dual {
        Dual {
            v: self.v * o,
            dl: self.dl * o,
            dx: self.dx * o,
        }
    }
}
