//! The Gilbert onion's linear macro spans on fast schedules of a ring-decoupled rotor
//! ([`Motor::advance_onion_linear`]) against an onion-only RK4 with the rotor on its exact drift.

use super::decoupled::torque_bound;
use super::onion_linear::{OFF, SPANS, SPAN_LOG};
use super::onion_periods_tests::{case, values};
use super::*;

/// A rotor spinning at about 1.7e9 rad/s under a 1.9 ns schedule, its onion in eq. 3.4's linear
/// range (a benchmark draw, full precision).
const SPINNING: &str = "strain_direction=5.416034236519985e-3 stress=-1.8935161580990505e4 load_torque=-3.780642712750421e-7 ring_outer_diameter=1.2277491523858758e-4 ring_inner_diameter=2.043664860906068e-6 bar_length=8.187312765204258e-7 bar_width=1.4384923234131919e-8 thickness=1.0326203336762129e-9 saturation_magnetization=2.1134253523776326e2 magnetostriction=-1.227696333225687e-3 wall_volume=7.181119786806352e-11 density=5.689791171215569e4 fluid_viscosity=1.7250111397149556e3 gilbert_damping=4.06630237923573e-1 tolerance=4.257061893489258e-6 step_angle=-9.151819274540474e0 step_period=1.890060512407431e-9 stress_amplitude=2.661291463836606e-1 schedule_initial_direction=-3.6793789962047865e-2 onion_model=1e0 max_substeps=1.2484e4 schedule=1e0 rotor_locked=0e0 initial_onion_offset=3.0660856980590297e-4 strain=-7.036717685567834e-2 youngs_modulus=9.150112868833685e10 strain_drive=0e0";
/// A 4.2 ns schedule turning the strain by 5.9 rad a switch, the onion in its linear range.
const SLOW_RING: &str = "strain_direction=1.6321598713944845e6 stress=1.637683394787637e6 load_torque=6.931493981768827e-7 ring_outer_diameter=5.674361610276554e-3 ring_inner_diameter=4.864269434558837e-3 bar_length=2.1119197245198902e-7 bar_width=6.019664486772738e-8 thickness=5.4144313454026225e-8 saturation_magnetization=5.566300007027195e2 magnetostriction=6.838973951768893e-3 wall_volume=8.022846041332686e-11 density=3.5032889014765447e3 fluid_viscosity=3.046298817001088e3 gilbert_damping=8.300129792073127e-2 tolerance=3.6957385400066337e-3 step_angle=5.885806380480215e0 step_period=4.1532081128217125e-9 stress_amplitude=-1.208525026997357e-3 schedule_initial_direction=6.745777404761725e-8 onion_model=1e0 max_substeps=3.69e2 schedule=1e0 rotor_locked=0e0 initial_onion_offset=2.0497240219391237e-12 strain=-9.100183056977379e-2 youngs_modulus=5.921060810129724e6 strain_drive=0e0";
/// Onions swinging through eq. 3.4's nonlinear range (by radians over a step), their
/// rings as decoupled (benchmark draws).
pub(super) const SWINGING: &str = "strain_direction=7.388399247067688e0 stress=-3.373565441346766e2 load_torque=6.543439832921072e-7 ring_outer_diameter=2.328019920117382e-5 ring_inner_diameter=1.3971126118686758e-5 bar_length=1.2465065486519635e-6 bar_width=7.792947586471934e-8 thickness=4.382655488177338e-9 saturation_magnetization=1.6168645470287504e2 magnetostriction=9.668147759750336e-3 wall_volume=5.185848349922059e-11 density=5.1316092076778135e4 fluid_viscosity=3.4249442004361376e5 gilbert_damping=6.51136503669907e-2 tolerance=6.065398934711097e-9 step_angle=-6.794063281546528e0 step_period=7.895657523891588e-9 stress_amplitude=8.247097731619921e-1 schedule_initial_direction=1.4344285058682907e-1 onion_model=1e0 max_substeps=1.2253e4 schedule=1e0 rotor_locked=0e0 initial_onion_offset=3.292557356857519e-11 strain=9.312356712561762e-2 youngs_modulus=1.2567331526541545e11 strain_drive=0e0";

pub(super) const SWINGING_FAST: &str = "strain_direction=1.4381824212544259e7 stress=1.8916646652724323e3 load_torque=-5.087095705995281e-7 ring_outer_diameter=5.587480694088768e-8 ring_inner_diameter=4.68596689409318e-8 bar_length=1.1383531449104868e-8 bar_width=7.946140025445529e-9 thickness=3.893328233080592e-9 saturation_magnetization=2.133365211398362e1 magnetostriction=3.701565270687648e-3 wall_volume=5.547686907217473e-11 density=1.839155845015076e4 fluid_viscosity=1.6518545965293494e8 gilbert_damping=9.759561218152917e-1 tolerance=3.220411691059896e-6 step_angle=9.68785452000061e0 step_period=1.9621769530891906e-9 stress_amplitude=-4.405892402342926e0 schedule_initial_direction=8.74381624462006e0 onion_model=1e0 max_substeps=2.468e3 schedule=1e0 rotor_locked=0e0 initial_onion_offset=1.1637827797907335e-9 strain=7.093111164969368e-2 youngs_modulus=6.32120973305938e11 strain_drive=1e0";
pub(super) const SWINGING_SLOW_DECAY: &str = "strain_direction=5.091460451448665e-2 stress=-5.453870993209322e-3 load_torque=-4.2776576671593847e-7 ring_outer_diameter=8.279561018784931e-1 ring_inner_diameter=5.343902628348114e-5 bar_length=6.214155388301783e-6 bar_width=7.131319720984599e-7 thickness=3.265797226777599e-8 saturation_magnetization=1.3144662086460173e2 magnetostriction=-6.069675912188905e-3 wall_volume=1.4369062132505162e-11 density=9.666057676561333e3 fluid_viscosity=3.000832621557004e6 gilbert_damping=7.212888768351577e-3 tolerance=4.6410909891213584e-4 step_angle=-5.85419686373609e0 step_period=2.373974865882472e-9 stress_amplitude=-1.7857481591449933e1 schedule_initial_direction=9.907290631260051e1 onion_model=1e0 max_substeps=6.814e3 schedule=1e0 rotor_locked=0e0 initial_onion_offset=-9.20716674225274e1 strain=4.501868537520465e-2 youngs_modulus=2.0058694896722284e8 strain_drive=0e0";

fn spans() -> u32 {
    SPANS.with(|c| c.get())
}

/// The onion and tilt at `t_end` from `state`: RK4 on the full rates (eq. 3.3's ring torque
/// included) with the rotor on its exact drift under the load ([`drifted`]), `n` substeps per
/// switch interval.
fn onion_rk4(
    m: &Motor,
    state: &MotorState,
    inputs: &MotorInputs,
    t_end: f64,
    n: usize,
) -> [f64; 2] {
    let s = inputs.schedule.get().unwrap();
    let rate = |z: [f64; 2], d: &Drive, t: f64| -> [f64; 2] {
        let rotor = drifted(m, state, inputs, t, z);
        let y = [rotor.rotor_angle, rotor.rotor_speed, z[0], z[1]];
        let f = m.rhs_jacobian(&y, d, 1e-300).0;
        [f[2], f[3]]
    };
    let mut z = [state.onion_angle, state.onion_tilt];
    let mut t = state.time;
    while t < t_end {
        let next = s.next_switch_after(t).min(t_end);
        let d = m.drive_at(inputs, t);
        let dt = (next - t) / n as f64;
        for i in 0..n {
            let tt = t + i as f64 * dt;
            let at = |z: [f64; 2], k: [f64; 2], c: f64| [z[0] + c * k[0], z[1] + c * k[1]];
            let k1 = rate(z, &d, tt);
            let k2 = rate(at(z, k1, 0.5 * dt), &d, tt + 0.5 * dt);
            let k3 = rate(at(z, k2, 0.5 * dt), &d, tt + 0.5 * dt);
            let k4 = rate(at(z, k3, dt), &d, tt + dt);
            for q in 0..2 {
                z[q] += dt / 6.0 * (k1[q] + 2.0 * k2[q] + 2.0 * k3[q] + k4[q]);
            }
        }
        t = next;
    }
    z
}

/// [`onion_rk4`] with its substeps doubled until two runs agree within a hundredth of the
/// tolerance.
pub(super) fn converged(
    m: &Motor,
    state: &MotorState,
    inputs: &MotorInputs,
    t_end: f64,
) -> [f64; 2] {
    let tol = m.params.tolerance;
    let mut n = 4;
    let mut last = onion_rk4(m, state, inputs, t_end, n);
    loop {
        n *= 2;
        let z = onion_rk4(m, state, inputs, t_end, n);
        let diff = (z[0] - last[0]).abs().max((z[1] - last[1]).abs());
        if diff <= 0.01 * tol {
            return z;
        }
        assert!(
            n < 1 << 16,
            "the RK4 did not converge: {diff:e} at {n} substeps"
        );
        last = z;
    }
}

/// The rotor on its exact drift under the load from `state` to `t` (held if locked), with the
/// onion `z`.
pub(super) fn drifted(
    m: &Motor,
    state: &MotorState,
    inputs: &MotorInputs,
    t: f64,
    z: [f64; 2],
) -> MotorState {
    if inputs.rotor_locked {
        return MotorState {
            time: t,
            rotor_speed: 0.0,
            onion_angle: z[0],
            onion_tilt: z[1],
            ..*state
        };
    }
    let (coast, torque_speed, torque_angle) = m.drift_response(t - state.time);
    let load = inputs.load_torque;
    MotorState {
        time: t,
        rotor_angle: state.rotor_angle + state.rotor_speed * coast + load * torque_angle,
        rotor_speed: state.rotor_speed * (1.0 - m.drag * torque_speed) + load * torque_speed,
        onion_angle: z[0],
        onion_tilt: z[1],
        ..*state
    }
}

/// Steps a case's motor by 1 us three times (as the benchmark does), each against the RK4 from
/// the step's start: onion, tilt and rotor angle within the tolerance, the torque and energies
/// within what that moves them (their slopes' bounds times the tolerance), and every linear span
/// within its bound of the RK4 from the span's start. Returns the substeps of each step.
fn three_steps(text: &str) -> Vec<u32> {
    let (m, mut st, inputs) = case(&values(text)).unwrap();
    let tol = m.params.tolerance;
    let e = (m.magnetoelastic_per_stress * inputs.schedule.get().unwrap().stress_amplitude).abs();
    let mut substeps = vec![];
    for _ in 0..3 {
        let start = st;
        let before = spans();
        SPAN_LOG.with(|l| l.borrow_mut().clear());
        let r = m.step(&mut st, &inputs, 1e-6).unwrap();
        assert!(spans() > before, "no linear span taken");
        let truth = drifted(
            &m,
            &start,
            &inputs,
            st.time,
            converged(&m, &start, &inputs, st.time),
        );
        let err = [
            (st.onion_angle - truth.onion_angle).abs(),
            (st.onion_tilt - truth.onion_tilt).abs(),
            (st.rotor_angle - truth.rotor_angle).abs(),
        ];
        assert!(
            err.iter().all(|&x| x <= tol),
            "{err:?} against the tolerance {tol:e}"
        );
        let o = m.outputs(&truth, &inputs).unwrap();
        // Plus the rounding of the offset between two angles of many turns.
        let ulps = 8.0 * f64::EPSILON * (st.onion_angle.abs() + st.rotor_angle.abs());
        let moved = err[0] + err[2] + ulps;
        let stiffness = m.ring_bar.stiffness_bound();
        assert!((r.outputs.torque - o.torque).abs() <= stiffness * moved * 1.001);
        let tau = torque_bound(&m.ring_bar);
        assert!(
            (r.outputs.magnetostatic_energy - o.magnetostatic_energy).abs() <= tau * moved * 1.001
        );
        // Plus the energy's own rounding, where the onion is within a few ulps of the truth.
        let rounding = 8.0 * f64::EPSILON * o.magnetoelastic_energy.abs();
        assert!(
            (r.outputs.magnetoelastic_energy - o.magnetoelastic_energy).abs()
                <= e * err[0] * 1.001 + rounding
        );
        for (y, t0, t1, z, bound) in SPAN_LOG.with(|l| l.borrow_mut().split_off(0)) {
            let from = MotorState {
                time: t0,
                rotor_angle: y[0],
                rotor_speed: y[1],
                onion_angle: y[2],
                onion_tilt: y[3],
                ..start
            };
            let zt = converged(&m, &from, &inputs, t1);
            let span_err = (z[0] - zt[0]).abs().max((z[1] - zt[1]).abs());
            assert!(bound <= 0.01 * tol);
            // The truth's own error is within a hundredth of the tolerance.
            assert!(
                span_err <= bound + 0.01 * tol,
                "{span_err:e} beyond the bound {bound:e}"
            );
        }
        substeps.push(r.substeps);
    }
    substeps
}

#[test]
fn linear_spans_of_a_spinning_rotor_match_rk4() {
    // Every switch interval was resolved: 530 substeps a step.
    for n in three_steps(SPINNING) {
        assert!(n <= 60, "{n} substeps");
    }
}

#[test]
fn linear_spans_of_a_slow_ring_match_rk4() {
    // Every switch interval was resolved: 242 substeps a step.
    for n in three_steps(SLOW_RING) {
        assert!(n <= 30, "{n} substeps");
    }
}

/// Where the onion swings through eq. 3.4's nonlinear range the bound declines at once and the
/// steps are the other paths' bit for bit.
#[test]
fn swinging_onions_decline() {
    for text in [SWINGING, SWINGING_FAST, SWINGING_SLOW_DECAY] {
        let (m, st0, inputs) = case(&values(text)).unwrap();
        assert!(m.ring_decoupled(inputs.schedule.get().unwrap(), false, 1e-6));
        let run = |off: bool| {
            OFF.with(|c| c.set(off));
            let mut st = st0;
            let before = spans();
            let r: Vec<_> = (0..2)
                .map(|_| m.step(&mut st, &inputs, 1e-6).unwrap())
                .collect();
            OFF.with(|c| c.set(false));
            (st, r, spans() - before)
        };
        let (with, r_with, taken) = run(false);
        let (without, r_without, _) = run(true);
        assert_eq!(taken, 0);
        assert_eq!(
            format!("{with:?} {r_with:?}"),
            format!("{without:?} {r_without:?}")
        );
    }
}
