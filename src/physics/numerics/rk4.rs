//! One classical Runge-Kutta step of order 4 (hand-written: the motor takes it in inner loops on
//! fixed-size arrays, where a general solver's allocation and dispatch would dominate).

/// `y + h/6 (k1 + 2 k2 + 2 k3 + k4)` for `y' = rate(y)`: one classical RK4 step from `y` over `h`.
pub fn rk4_step<const N: usize>(
    rate: &impl Fn(&[f64; N]) -> [f64; N],
    y: &[f64; N],
    h: f64,
) -> [f64; N] {
    let k1 = rate(y);
    let k2 = rate(&std::array::from_fn(|i| y[i] + 0.5 * h * k1[i]));
    let k3 = rate(&std::array::from_fn(|i| y[i] + 0.5 * h * k2[i]));
    let k4 = rate(&std::array::from_fn(|i| y[i] + h * k3[i]));
    std::array::from_fn(|i| y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Exact for a cubic in time (`y' = 3 t^2` with `t` carried as a state), and the fourth-order
    /// truncation of `exp(h)` for `y' = y`.
    #[test]
    fn rk4_matches_its_taylor_polynomial() {
        let cubic = rk4_step(&|z: &[f64; 2]| [3.0 * z[1] * z[1], 1.0], &[0.0, 0.0], 0.5);
        assert!((cubic[0] - 0.125).abs() < 1e-15, "{cubic:?}");
        let h = 0.1_f64;
        let growth = rk4_step(&|z: &[f64; 1]| [z[0]], &[1.0], h)[0];
        let taylor = 1.0 + h + h * h / 2.0 + h.powi(3) / 6.0 + h.powi(4) / 24.0;
        assert!((growth - taylor).abs() < 1e-15, "{growth} {taylor}");
    }
}
