//! The bounds behind [`Motor::averaging_refused_over`] against a resolved onion.

use super::locked_budget_forecast_tests::{RESOLVED_FROM_THE_RIM, SLOW_RINGING};
use super::onion_periods_tests::{case, values};
use super::orbit::point;
use super::resolved_tests::rk4_span;

/// Along a plain RK4 of the locked onion's ringing (128 substeps an orbit, 64 orbits), the
/// energy above the minimum never falls faster than `2 g alpha max(K, T)` of itself, and at the
/// turning points of a well stiffer than the tilt it comes within a fifth of that rate.
#[test]
fn energy_falls_no_faster_than_the_bound() {
    let (m, st, inputs) = case(&values(SLOW_RINGING)).unwrap();
    let d = m.drive_at(&inputs, 0.0);
    let land = m.landscape(st.rotor_angle, d.direction, d.stress);
    let minimum = land.settle(st.onion_angle);
    let (floor, k, t) = (
        point(&land, minimum).0,
        land.curvature(minimum),
        m.tilt_stiffness,
    );
    let bound = land.ring_bar.stiffness_bound() + 2.0 * land.magnetoelastic.abs();
    assert!(k > t && bound >= k);
    let fastest = 2.0 * m.llg_rate * m.params.gilbert_damping * bound.max(t);
    let energy = |y: &super::Vector| point(&land, y[2]).0 - floor + 0.5 * t * y[3] * y[3];
    let period = 2.0 * std::f64::consts::PI / (m.llg_rate * (k * t).sqrt());
    let h = period / 128.0;
    let mut y = [
        st.rotor_angle,
        st.rotor_speed,
        st.onion_angle,
        st.onion_tilt,
    ];
    let mut most: f64 = 0.0;
    for _ in 0..64 * 128 {
        let next = rk4_span(&m, &d, y, h, 4);
        let rate = (energy(&y) / energy(&next)).ln() / h;
        most = most.max(rate / fastest);
        y = next;
    }
    assert!((0.8..=1.0).contains(&most), "{most}");
}

/// Ringing that the averaged advance takes within the step is not claimed refused: near its
/// rim at the start, its energy can fall below the advance's margin within the horizon.
#[test]
fn ringing_the_averaging_takes_is_not_claimed_refused() {
    let (m, st, inputs) = case(&values(RESOLVED_FROM_THE_RIM)).unwrap();
    let d = m.drive_at(&inputs, 0.0);
    let land = m.landscape(st.rotor_angle, d.direction, d.stress);
    let minimum = land.settle(st.onion_angle);
    let well = m.well_of_minimum(&land, minimum).unwrap();
    let k = land.curvature(minimum);
    let energy = point(&land, st.onion_angle).0 - well.floor
        + 0.5 * m.tilt_stiffness * st.onion_tilt * st.onion_tilt;
    assert!(!m.averaging_refused_over(&land, &well, k, energy, 1e-6, 1e-7));
    // The slow ringing is, over the same horizon.
    let (m, st, inputs) = case(&values(SLOW_RINGING)).unwrap();
    let d = m.drive_at(&inputs, 0.0);
    let land = m.landscape(st.rotor_angle, d.direction, d.stress);
    let minimum = land.settle(st.onion_angle);
    let well = m.well_of_minimum(&land, minimum).unwrap();
    let k = land.curvature(minimum);
    let energy = point(&land, st.onion_angle).0 - well.floor
        + 0.5 * m.tilt_stiffness * st.onion_tilt * st.onion_tilt;
    assert!(m.averaging_refused_over(&land, &well, k, energy, 1e-6, 1e-7));
}
