//! The amplification bound ([`Motor::errors_amplified`]) carries every recorded substep's error
//! through all the resolved substeps recorded after it.

use super::amplification::Amplification;
use super::onion_periods_tests::{case, values};
use super::{Angles, Drive};
use std::f64::consts::FRAC_PI_2;

/// An error made in one substep, then a substep on a rim of the well (a saddle of eq. 3.4's
/// landscape) that the error enters after some other path has carried the state on: the
/// saddle's substep multiplies it by at least `e^{lambda dt}`, `lambda` the growing eigenvalue
/// of the onion's linearized block there (closed form from its trace and determinant), and the
/// step is flagged.
#[test]
fn an_error_passes_through_the_later_substeps() {
    let (m, _, _) = case(&values("onion_model=1")).unwrap();
    let d = Drive {
        direction: 0.0,
        applied_direction: 0.0,
        stress: 2e9,
        load: 0.0,
        locked: false,
    };
    // The onion's block `g [[-alpha c, -T], [c, -alpha T]]` at each of the landscape's axes;
    // the rim is where the curvature `c` is negative.
    let curvature = |psi: f64| {
        let a = Angles::exact(psi, 0.0, 0.0);
        let (_, k_bar) = m.ring_bar.torque_stiffness_of(a.sin_offset, a.cos_offset);
        k_bar + 2.0 * m.magnetoelastic_per_stress * d.stress * a.cos_double
    };
    let (minimum, rim) = if curvature(0.0) > 0.0 {
        (0.0, FRAC_PI_2)
    } else {
        (FRAC_PI_2, 0.0)
    };
    let c = curvature(rim);
    assert!(c < 0.0 && curvature(minimum) > 0.0, "{c}");
    let (g, alpha, t) = (m.llg_rate, m.params.gilbert_damping, m.tilt_stiffness);
    let (trace, det) = (-g * alpha * (c + t), g * g * (1.0 + alpha * alpha) * c * t);
    let lambda = 0.5 * trace + (0.25 * trace * trace - det).sqrt();
    assert!(lambda > 0.0);
    // Long enough on the rim to grow by e^20.
    let dt = 20.0 / lambda;
    let mut amp = Amplification::default();
    m.record_amplification(
        &mut amp,
        1e-3 / lambda,
        &d,
        &Angles::exact(minimum, 0.0, 0.0),
        1.0,
    );
    m.record_amplification(&mut amp, dt, &d, &Angles::exact(rim, 0.0, 0.0), 0.0);
    let bound = amp.bound();
    assert!(bound >= 0.5 * 20f64.exp(), "{bound:e}");
    assert!(m.errors_amplified(&amp));
}
