//! The resolved Gilbert path against independent truths: a free rotor under load and drag
//! against its exact solution.

use super::onion_periods_tests::{case, values};
use super::*;

/// The same motor with `tolerance / 100` and a budget of 1e8 substeps.
fn fine(m: &Motor) -> Motor {
    let mut p = m.params.clone();
    p.tolerance *= 0.01;
    p.max_substeps = 100_000_000;
    Motor::new(p).unwrap()
}

/// The repeated periods' free-rotor case: onion relaxed within each 2.16 ns switch, the ring's
/// torque negligible, the rotor under load and drag.
const SETTLED_FREE: &str =
    "load_torque=1e-6 ring_outer_diameter=3.253e-1 ring_inner_diameter=1.279e-1 \
         bar_length=4e-5 bar_width=1e-5 thickness=1e-6 saturation_magnetization=7.248e4 \
         magnetostriction=6.666e-3 wall_volume=3.307e-11 density=6.435e3 fluid_viscosity=1e3 \
         gilbert_damping=3.089e-3 tolerance=6.272e-4 step_angle=2.677e0 step_period=2.160e-9 \
         stress_amplitude=-2.300e9 schedule_initial_direction=8.853e2 onion_model=1 \
         max_substeps=1.795e4 initial_onion_offset=-3.639e-3 schedule=1";

/// The onion's excursion after each switch (its tilt runs past the bound of 10 rad on this steep
/// landscape, also in an RK4 of its equations) fails the Gilbert substeps at their smallest
/// size; the rotor, which the ring cannot move, must keep its speed through it. Stepped one
/// period at a time for 1 us (463 switches) with the resolved substeps at a hundredth of the
/// tolerance, it stays on the exact load-and-drag solution `phi = L/c (t - tau (1 - e^(-t/tau)))`,
/// `tau = I/c`; a speed reset at each switch loses `omega tau` a period, 1.26e-4 rad in all.
#[test]
fn free_rotor_keeps_its_speed_through_the_switches() {
    let (m, start, inputs) = case(&values(SETTLED_FREE)).unwrap();
    let fine = fine(&m);
    let s = inputs.schedule.get().unwrap();
    let (c, tau) = (m.drag, m.inertia / m.drag);
    let mut st = start;
    while st.time < 1e-6 {
        let h = s.next_switch_after(st.time).min(1e-6) - st.time;
        fine.step(&mut st, &inputs, h).unwrap();
    }
    let t = st.time;
    let exact = inputs.load_torque / c * (t + tau * (-t / tau).exp_m1());
    let speed = -inputs.load_torque / c * (-t / tau).exp_m1();
    println!(
        "rotor {} exact {exact}; speed {} exact {speed}",
        st.rotor_angle, st.rotor_speed
    );
    assert!(
        (st.rotor_angle - exact).abs() <= 1e-3 * m.params.tolerance,
        "rotor {} against {exact}",
        st.rotor_angle
    );
    assert!((st.rotor_speed - speed).abs() <= 1e-9 * speed.abs());
}
