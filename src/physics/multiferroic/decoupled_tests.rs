//! Free rotors that the ring barely moves: benchmark cases whose first 1 us step is slow (the
//! Gilbert onion resolved substep by substep after its release) while the ring's torque, at most
//! `tau_max`, turns the rotor by at most `tau_max min(h^2 / (2 I), h / c)` over the step, about a
//! hundredth of the tolerance or less, and those whose trapped ringing is then dropped at once. The
//! rotor must then keep its exact motion under load and drag, `phi = L/c (t - tau (1 -
//! e^(-t/tau)))`, `tau = I/c`, whether or not the onion's ringing fits the budget (when it does
//! not, the step is flagged for the onion alone).

use super::onion_periods_tests::{case, values};
use super::orbit::point;
use super::tests::rk4_step;
use super::{Drive, Motor, Vector};

/// Load-driven rotors: weakly damped ringing (damping 6.1e-3, onion relaxation 0.28 us) that
/// outlasts the budget; a rotor at 2e8 rad/s under an onion relaxing in 15 us; an onion of
/// Ms = 7.4 A/m relaxing in 3.9 us, resolved through the whole step.
const CASES: [&str; 3] = [
    "strain_direction=4.348412889627226e6 stress=1.9573159653070974e2 \
     load_torque=-8.070960266705514e-7 ring_outer_diameter=5.818144910189025e-1 \
     ring_inner_diameter=2.0451565212652238e-2 bar_length=5.15067653755647e-4 \
     bar_width=1.1776251942244318e-4 thickness=6.658697198184579e-5 \
     saturation_magnetization=5.196469177655726e3 magnetostriction=-9.969506942915016e-3 \
     wall_volume=4.5812051580117864e-11 density=7.613190827328188e4 \
     fluid_viscosity=1.7319706556730814e-4 gilbert_damping=6.114196349121509e-3 \
     tolerance=2.413962318950689e-10 onion_model=1 max_substeps=10742 \
     initial_onion_offset=-4.201015739485816e-10",
    "strain_direction=-2.1478444320800782e-1 load_torque=6.76477542741344e-7 \
     ring_outer_diameter=2.535981365092965e-1 ring_inner_diameter=4.074077288254449e-7 \
     bar_length=3.919199457203557e-7 bar_width=4.08183712394939e-9 \
     thickness=1.2006636434075051e-9 saturation_magnetization=2.098483915888461e3 \
     magnetostriction=-9.793326336040362e-3 wall_volume=5.7040183589091213e-11 \
     density=2.1215001005328344e4 fluid_viscosity=2.2728933188253743e5 \
     gilbert_damping=2.9311561130911324e-4 tolerance=4.646719407612572e-10 \
     step_angle=6.0988194078027185e0 step_period=1.3482140563259026e-4 \
     stress_amplitude=6.499021081278089e1 schedule_initial_direction=7.201706939976832e-9 \
     onion_model=1 max_substeps=4008 schedule=1 initial_onion_offset=9.673988940251601e-6 \
     strain=-8.106170389141597e-2 youngs_modulus=1.948002627303002e6 strain_drive=1",
    "strain_direction=8.14334416407478e8 load_torque=3.911163225934517e-7 \
     ring_outer_diameter=2.7685542489325216e-1 ring_inner_diameter=4.122080991562461e-3 \
     bar_length=9.822226856020578e-4 bar_width=2.8725005756679195e-4 \
     thickness=1.2522316314408041e-8 saturation_magnetization=7.392995608827743e0 \
     magnetostriction=-4.108867245019616e-3 wall_volume=8.620477617615889e-11 \
     density=3.234891732706983e4 fluid_viscosity=4.194580505248383e0 \
     gilbert_damping=3.481842207878863e-1 tolerance=1.5040691651548198e-10 \
     step_angle=5.24899695249931e0 step_period=4.575163449371051e-6 \
     stress_amplitude=1.2823932167135819e-2 schedule_initial_direction=8.25932605067673e-3 \
     onion_model=1 max_substeps=12732 schedule=1 initial_onion_offset=-2.59575455790497e-11 \
     strain=6.0996615171473784e-2 youngs_modulus=5.100243715449669e11 strain_drive=1",
];

/// Each case's first 1 us step (no switch inside it) against the exact load-and-drag rotor:
/// within a tenth of the tolerance, the ring's bound being 1.04e-2 of it at most. Where the
/// step is not flagged, its onion is also that of a fine RK4 of the full macrospin and rotor
/// within the tolerance (0.72 of it for the third case, whose substeps the explicit pairs'
/// stability reach holds to about 1 ns: 869 at the tolerance, 901 at a hundredth of it).
#[test]
fn decoupled_rotor_keeps_its_load_and_drag_motion_through_the_first_step() {
    let h = 1e-6;
    for (n, text) in CASES.iter().enumerate() {
        let (m, start, inputs) = case(&values(text)).unwrap();
        if let Some(s) = inputs.schedule.get() {
            assert!(s.next_switch_after(0.0) > h, "{n}");
        }
        let tol = m.params.tolerance;
        let tau_max = m.ring_bar.max_torque().1.abs();
        let ring = tau_max * (h * h / (2.0 * m.inertia)).min(h / m.drag);
        assert!(
            ring <= 0.02 * tol,
            "{n}: the ring turns the rotor by {ring:e}"
        );
        let mut st = start;
        let report = m.step(&mut st, &inputs, h).unwrap();
        let d = m.drive_at(&inputs, 0.0);
        let (c, tau) = (m.drag, m.inertia / m.drag);
        let exact = d.load / c * (h + tau * (-h / tau).exp_m1());
        let speed = -d.load / c * (-h / tau).exp_m1();
        println!(
            "case {n}: {} substeps, flagged {}; rotor {} against {exact} ({:e} of the tolerance)",
            report.substeps,
            report.accuracy_limited,
            st.rotor_angle,
            (st.rotor_angle - exact).abs() / tol
        );
        // (A rotor at 2e8 rad/s carries rounding of its 200 rad turn, 3e-14 rad.)
        let rounding = 1e-15 * exact.abs();
        assert!(
            (st.rotor_angle - exact).abs() <= 0.1 * tol + rounding,
            "{n}: rotor {} against {exact}",
            st.rotor_angle
        );
        assert!((st.rotor_speed - speed).abs() <= 1e-6 * speed.abs(), "{n}");
        assert!(
            st.onion_angle.is_finite() && st.onion_tilt.is_finite(),
            "{n}"
        );
        if !report.accuracy_limited {
            let y0 = [start.rotor_angle, 0.0, start.onion_angle, start.onion_tilt];
            let (truth, finer) = (rk4(&m, &d, y0, h, 1), rk4(&m, &d, y0, h, 2));
            assert!(
                (truth[2] - finer[2]).abs() <= 0.01 * tol,
                "{n}: {truth:?} {finer:?}"
            );
            println!("  onion {} against {}", st.onion_angle, finer[2]);
            assert!((st.onion_angle - finer[2]).abs() <= tol, "{n}: {finer:?}");
        }
    }
}

/// Classical RK4 of the full macrospin and rotor from `y0` over `span`, `refine` times finer than
/// a two-hundredth of the onion's fastest rate per step.
fn rk4(m: &Motor, d: &Drive, y0: Vector, span: f64, refine: usize) -> Vector {
    let (_, j) = m.rhs_jacobian(&y0, d, 1e-12);
    let norm = (2..4)
        .map(|i| (2..4).map(|k| j[i][k].abs()).sum::<f64>())
        .fold(0.0, f64::max);
    let n = (span * norm / 0.005).ceil() as usize * refine;
    let h = span / n as f64;
    let rate = |z: &Vector| m.rhs_jacobian(z, d, h).0;
    (0..n).fold(y0, |z, _| rk4_step(&rate, &z, h))
}

/// Load-driven rotors of weak rings whose onion, released at the start, rings in its well: a
/// rotor at 1.2e6 rad/s in a viscous fluid (damping 4.4e-2, onion relaxation 0.38 ns), one at
/// 2e4 rad/s (damping 6.4e-2, 15 ns).
const RINGING: [&str; 2] = [
    "strain_direction=2.749e9 stress=-8.861e9 load_torque=-6.839e-7 ring_outer_diameter=1.351e-1 \
     ring_inner_diameter=7.645e-6 bar_length=1.098e-6 bar_width=1.001e-6 thickness=1.227e-8 \
     saturation_magnetization=5.479e5 magnetostriction=-7.062e-3 wall_volume=1.596e-11 \
     density=5.855e4 fluid_viscosity=2.380e7 gilbert_damping=4.403e-2 tolerance=1.388e-8 \
     step_angle=-1.820e0 step_period=6.662e3 stress_amplitude=1.454e5 \
     schedule_initial_direction=-1.083e-6 onion_model=1 max_substeps=9901 schedule=1 \
     initial_onion_offset=-5.436e-9 strain=-6.829e-2 youngs_modulus=2.540e11",
    "strain_direction=-7.643e10 stress=-2.105e3 load_torque=-7.519e-7 \
     ring_outer_diameter=2.118e-3 ring_inner_diameter=5.982e-4 bar_length=1.164e-5 \
     bar_width=1.599e-8 thickness=4.204e-9 saturation_magnetization=9.367e3 \
     magnetostriction=-3.464e-3 wall_volume=4.369e-12 density=1.696e3 fluid_viscosity=3.424e5 \
     gilbert_damping=6.430e-2 tolerance=7.356e-9 step_angle=8.026e0 step_period=4.497e-3 \
     stress_amplitude=4.346e6 schedule_initial_direction=-1.195e-5 onion_model=1 \
     max_substeps=14200 schedule=1 initial_onion_offset=5.374e-7 strain=4.656e-2 \
     youngs_modulus=2.972e7 strain_drive=1",
];

/// The first 1 us step of each [`RINGING`] case against the exact load-and-drag rotor and a fine
/// RK4 of the macrospin driven by it: the ring's impulse bound over the step is below a
/// thousandth of the tolerance (which is what the rotor's exact motion omits), so the ringing,
/// once trapped in its well, is dropped ([`Motor::decoupled_ringing`]). The step is not flagged
/// and takes at most 60 and 100 substeps (resolving the ringing took 219 and 162, the second
/// flagged when the budget ran out); the rotor is the
/// reference's within a tenth of the tolerance, the onion within the tolerance plus the
/// amplitude of what is left of the reference's ringing (its energy above the minimum bounds
/// it; the branch reports the ringing's centre).
#[test]
fn decoupled_ringing_is_dropped_once_trapped() {
    let h = 1e-6;
    for (n, text) in RINGING.iter().enumerate() {
        let (m, start, inputs) = case(&values(text)).unwrap();
        if let Some(s) = inputs.schedule.get() {
            assert!(s.next_switch_after(0.0) > h, "{n}");
        }
        let tol = m.params.tolerance;
        let tau_max = m.ring_bar.max_torque().1.abs();
        assert!(2.0 * tau_max * h <= 1e-3 * tol * m.drag, "{n}");
        // The bound used is above the largest torque, and near it for these short bars.
        let bound = super::decoupled::torque_bound(&m.ring_bar);
        assert!(
            bound >= tau_max && bound <= 1.1 * tau_max,
            "{n}: {bound:e} {tau_max:e}"
        );
        let mut st = start;
        let report = m.step(&mut st, &inputs, h).unwrap();
        let d = m.drive_at(&inputs, 0.0);
        let y0 = [start.rotor_angle, 0.0, start.onion_angle, start.onion_tilt];
        let (truth, finer) = (driven_rk4(&m, &d, y0, h, 1), driven_rk4(&m, &d, y0, h, 2));
        let end = m.landscape(finer[0], d.direction, d.stress);
        let minimum = end.settle(finer[2]);
        let excess = point(&end, finer[2]).0 - point(&end, minimum).0
            + 0.5 * m.tilt_stiffness * finer[3] * finer[3];
        let ringing = (2.4 * excess.max(0.0) / end.curvature(minimum)).sqrt();
        let (rotor, onion) = (
            (st.rotor_angle - finer[0]).abs(),
            (st.onion_angle - finer[2]).abs(),
        );
        println!(
            "case {n}: {} substeps, flagged {}; rotor {rotor:e} off, onion {onion:e} off, \
             ringing left {ringing:e}, tolerance {tol:e}",
            report.substeps, report.accuracy_limited
        );
        assert!(
            (truth[0] - finer[0]).abs() <= 0.01 * tol && (truth[2] - finer[2]).abs() <= 0.01 * tol,
            "{n}: {truth:?} {finer:?}"
        );
        assert!(!report.accuracy_limited, "{n}");
        assert!(report.substeps <= [60, 100][n], "{n}: {}", report.substeps);
        assert!(rotor <= 0.1 * tol, "{n}: rotor {rotor:e}");
        assert!(
            onion <= tol + 1.01 * ringing,
            "{n}: onion {onion:e}, ringing {ringing:e}"
        );
    }
}

/// The rotor's exact motion under load and drag from rest and a classical RK4 of the
/// macrospin driven by it, from `y0` over `span` in steps `refine` times finer than a
/// fiftieth of the onion's fastest rate (the rotor's own time `I / c`, down to 0.3 ps here,
/// is left to the exact solution).
pub(super) fn driven_rk4(m: &Motor, d: &Drive, y0: Vector, span: f64, refine: usize) -> Vector {
    let (c, tau) = (m.drag, m.inertia / m.drag);
    let rotor = |t: f64| {
        let decay = (-t / tau).exp_m1();
        [y0[0] + d.load / c * (t + tau * decay), -d.load / c * decay]
    };
    let (_, j) = m.rhs_jacobian(&y0, d, 1e-12);
    let norm = (2..4)
        .map(|i| (2..4).map(|k| j[i][k].abs()).sum::<f64>())
        .fold(0.0, f64::max);
    let n = (span * norm / 0.02).ceil() as usize * refine;
    let h = span / n as f64;
    let rate = |t: f64, z: [f64; 2]| {
        let [phi, omega] = rotor(t);
        let f = m.rhs_jacobian(&[phi, omega, z[0], z[1]], d, h).0;
        [f[2], f[3]]
    };
    let mut z = [y0[2], y0[3]];
    for i in 0..n {
        let t = i as f64 * h;
        let k1 = rate(t, z);
        let k2 = rate(
            t + 0.5 * h,
            [z[0] + 0.5 * h * k1[0], z[1] + 0.5 * h * k1[1]],
        );
        let k3 = rate(
            t + 0.5 * h,
            [z[0] + 0.5 * h * k2[0], z[1] + 0.5 * h * k2[1]],
        );
        let k4 = rate(t + h, [z[0] + h * k3[0], z[1] + h * k3[1]]);
        for k in 0..2 {
            z[k] += h / 6.0 * (k1[k] + 2.0 * k2[k] + 2.0 * k3[k] + k4[k]);
        }
    }
    let [phi, omega] = rotor(span);
    [phi, omega, z[0], z[1]]
}
