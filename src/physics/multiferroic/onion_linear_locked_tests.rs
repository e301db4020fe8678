//! A locked rotor's creeping Gilbert onion on a fast schedule, the ring's torque folded into the
//! linear macro spans ([`Motor::linear_ring_term`]), against RK4s of the macrospin.

use super::locked_accuracy_tests::converged_rk4;
use super::onion_linear::{MIN_SPAN, SPANS, SPAN_LOG};
use super::onion_linear_locked::stiffness_slope_bound;
use super::onion_periods_tests::{case, values};
use super::resolved_tests::rk4_span;
use super::*;

/// A benchmark draw (full precision): the rotor locked, a 1.47 ns schedule turning the strain
/// by -2.8 rad a switch, damping 0.22, tolerance 1.4e-6. The onion creeps (its tilt relaxes
/// faster than it turns) over microseconds, remembering thousands of switches, and the ring's
/// torque on it is not negligible over that memory ([`Motor::ring_decoupled`] fails).
pub(super) const CREEPING: &str = "strain_direction=5.135114264928168e5 stress=2.2820645588306966e5 load_torque=-9.915438607453414e-7 ring_outer_diameter=2.8469494225458643e-2 ring_inner_diameter=6.604890130437266e-3 bar_length=1.0779507175724333e-6 bar_width=4.503890913627021e-8 thickness=2.18195679941534e-8 saturation_magnetization=5.126149671924257e4 magnetostriction=-7.836896931303874e-3 wall_volume=9.347236765285793e-12 density=2.4551449322208205e3 fluid_viscosity=7.559771757926201e4 gilbert_damping=2.21062817452914e-1 tolerance=1.4276541243319657e-6 step_angle=-2.8076869365881514e0 step_period=1.474231744190367e-9 stress_amplitude=-4.209278983086497e-1 schedule_initial_direction=-2.0404417070533065e0 onion_model=1e0 max_substeps=2.488e3 schedule=1e0 rotor_locked=1e0 initial_onion_offset=1.3736214822621958e-11 strain=-6.679330975597986e-2 youngs_modulus=3.0745565676329876e6 strain_drive=1e0";

/// A benchmark draw (full precision): the rotor locked, a 1.32 ns schedule turning the strain
/// by -1.67 rad a switch, damping 0.022 and a loose tolerance, 0.55 rad. The onion stays within
/// 2e-4 rad of where it starts; resolved switch by switch within that tolerance it drifted by
/// about 0.1 rad a switch, 75 rad a step.
pub(super) const LOOSE: &str = "strain_direction=-1.0535612392453895e0 stress=-3.961210400445306e5 load_torque=-7.814790441179216e-7 ring_outer_diameter=7.398422859608355e-1 ring_inner_diameter=8.91044441285702e-3 bar_length=4.639656708876403e-4 bar_width=2.4444698418419133e-6 thickness=1.968226364393448e-6 saturation_magnetization=1.74910007621288e5 magnetostriction=-6.940916553667385e-3 wall_volume=6.373614827219518e-11 density=1.7715962462335365e3 fluid_viscosity=9.758242284399974e4 gilbert_damping=2.216716264841276e-2 tolerance=5.452540087689379e-1 step_angle=-1.6715220744944652e0 step_period=1.3246326092283046e-9 stress_amplitude=-1.4907986882368496e0 schedule_initial_direction=-1.4029170443384658e0 onion_model=1e0 max_substeps=6.44e2 schedule=1e0 rotor_locked=1e0 initial_onion_offset=-3.1926781009303563e-7 strain=2.8362029390469612e-2 youngs_modulus=2.7522548582146226e12 strain_drive=1e0";

/// A benchmark draw (full precision): the rotor locked, a 2.26 ns schedule turning the strain
/// by -0.83 rad a switch, damping 2.4e-3, tolerance 3.9e-7. Linear spans bound within a hundredth
/// of the tolerance cover at most three switches here, their errors all the same way.
const SHORT_SPANS: &str = "strain_direction=-6.936872902282588e9 stress=1.0505470781838222e0 load_torque=-1.3707521487662564e-7 ring_outer_diameter=1.929913462077736e-5 ring_inner_diameter=7.122581976727667e-6 bar_length=1.4934964702738338e-6 bar_width=9.748623461803666e-8 thickness=4.634812979254992e-9 saturation_magnetization=1.155160773901053e2 magnetostriction=-3.983583505212261e-3 wall_volume=2.3548059001258936e-11 density=1.73159519734111e4 fluid_viscosity=1.5772843657211245e3 gilbert_damping=2.434606225410316e-3 tolerance=3.863559449469517e-7 step_angle=-8.348186444088057e-1 step_period=2.2588075222562576e-9 stress_amplitude=-2.476729939074367e-1 schedule_initial_direction=8.066288260315759e-9 onion_model=1e0 max_substeps=9.639e3 schedule=1e0 rotor_locked=1e0 initial_onion_offset=-1.8461839387535274e-4 strain=-4.613195512964461e-2 youngs_modulus=2.126090503971582e7 strain_drive=1e0";

/// The onion and tilt from a span's start `y` at `t` to `t_end`: RK4 over each switch
/// interval at `n` substeps.
fn span_rk4(
    m: &Motor,
    inputs: &MotorInputs,
    mut y: Vector,
    mut t: f64,
    t_end: f64,
    n: usize,
) -> Vector {
    let s = inputs.schedule.get().unwrap();
    while t < t_end {
        let next = s.next_switch_after(t).min(t_end);
        y = rk4_span(m, &m.drive_at(inputs, t), y, next - t, n);
        t = next;
    }
    y
}

/// A benchmark draw (full precision): the rotor locked, a 3.9 ns schedule turning the strain by
/// -5.4 rad a switch, damping 0.018, tolerance 2.0e-7: its onion turns through each switch far
/// enough that eq. 3.4 linearized about a span's start ended each span within a few switches.
const TURNING: &str = "strain_direction=-5.329894581414116e6 stress=2.688543931309062e9 \
    load_torque=-3.896633403871854e-8 ring_outer_diameter=2.717014633722794e-2 \
    ring_inner_diameter=7.408445409138786e-6 bar_length=6.841987101484022e-7 \
    bar_width=6.387041762325759e-7 thickness=3.0062320544742366e-9 \
    saturation_magnetization=9.616973530409085e6 magnetostriction=1.839703204150141e-3 \
    wall_volume=5.2596852518610995e-11 density=5.857846417136614e4 \
    fluid_viscosity=3.86944949402701e-1 gilbert_damping=1.806939913821002e-2 \
    tolerance=2.0094487985789285e-7 step_angle=-5.357750812160171e0 \
    step_period=3.87588338368737e-9 stress_amplitude=3.2471333981035194e1 \
    schedule_initial_direction=-8.837653633677037e-9 onion_model=1e0 max_substeps=3.72e2 \
    schedule=1e0 rotor_locked=1e0 initial_onion_offset=4.1034502131026436e1 \
    strain=8.980118525953432e-2 youngs_modulus=1.8334259835074554e10 strain_drive=0e0";

/// Three 1 us steps of a draw (as the benchmark takes them), each against a converged RK4 from
/// its start (at `per_ns` steps a nanosecond) within the tolerance (onion angle and tilt), in at
/// most `max_substeps` and `max_spans` spans; every span's end within its bound (at most a
/// hundredth of the tolerance) of an RK4 from the span's start. Returns the largest error in
/// tolerances, the largest span error over its bound and the most switches a span took.
fn three_steps(text: &str, max_substeps: u32, max_spans: usize, per_ns: f64) -> (f64, f64, f64) {
    let (m, mut st, inputs) = case(&values(text)).unwrap();
    assert!(inputs.rotor_locked);
    let s = inputs.schedule.get().unwrap();
    assert!(!m.ring_decoupled(s, true, 1e-6));
    let tol = m.params.tolerance;
    SPAN_LOG.with(|l| l.borrow_mut().clear());
    let spans_before = SPANS.with(|c| c.get());
    let mut worst_step: f64 = 0.0;
    for _ in 0..3 {
        let start = st;
        let logged = SPAN_LOG.with(|l| l.borrow().len());
        let report = m.step(&mut st, &inputs, 1e-6).unwrap();
        let spans = SPAN_LOG.with(|l| l.borrow().len()) - logged;
        assert!(spans <= max_spans, "{spans} spans");
        let truth = converged_rk4(&m, &start, &inputs, st.time, per_ns);
        let errors = [
            (st.onion_angle - truth[2]).abs() / tol,
            (st.onion_tilt - truth[3]).abs() / tol,
        ];
        println!(
            "{} substeps, errors / tolerance {errors:?}",
            report.substeps
        );
        assert_eq!(st.rotor_angle, start.rotor_angle);
        assert!(errors.iter().all(|e| *e <= 1.0), "{st:?} against {truth:?}");
        assert!(report.substeps <= max_substeps, "{report:?}");
        worst_step = worst_step.max(errors[0]).max(errors[1]);
    }
    assert!(SPANS.with(|c| c.get()) > spans_before);
    let log = SPAN_LOG.with(|l| l.borrow().clone());
    let mut worst_span: f64 = 0.0;
    let longest = log
        .iter()
        .map(|l| ((l.2 - l.1) / s.step_period).round())
        .fold(0.0, f64::max);
    for (y, t, t_end, end, bound) in log {
        // Halved until the RK4 converges within a hundredth of the bound.
        let mut n = 32;
        let (mut coarse, mut fine) = (
            span_rk4(&m, &inputs, y, t, t_end, n),
            span_rk4(&m, &inputs, y, t, t_end, 2 * n),
        );
        let gap = |a: &Vector, b: &Vector| (a[2] - b[2]).abs().max((a[3] - b[3]).abs());
        // An RK4 too coarse for a stiff tilt diverges: not finite, not converged.
        let settled = |a: &Vector, b: &Vector| gap(a, b).is_finite() && gap(a, b) <= 0.01 * bound;
        while !settled(&coarse, &fine) && n < 4096 {
            n *= 2;
            coarse = fine;
            fine = span_rk4(&m, &inputs, y, t, t_end, 2 * n);
        }
        let converged = gap(&coarse, &fine);
        let error = (end[0] - fine[2]).abs().max((end[1] - fine[3]).abs());
        assert!(
            converged <= 0.01 * bound,
            "RK4 not converged: {converged:e} against {bound:e}"
        );
        assert!(
            error <= bound,
            "span from {t:e} to {t_end:e}: {error:e} beyond {bound:e}"
        );
        assert!(bound <= 0.01 * tol);
        worst_span = worst_span.max(error / bound);
    }
    println!(
        "worst step error / tolerance {worst_step:e}, span error / bound {worst_span:.3}, \
         longest span {longest} switches"
    );
    (worst_step, worst_span, longest)
}

/// [`CREEPING`] in at most 20 substeps and 12 spans a step (11 to 14 substeps; without the
/// ring folded into the spans the onion's creep is resolved substep by substep through every
/// switch, 679 to 685), its longest span over 100 of the step's 678 switches, within the
/// tolerance of the RK4 (2.3e-4 tolerances) and its spans within their bounds. The error
/// carried from one switch to the next is bounded entry by entry through each switch's map:
/// bounded in the max norm, which the tilt's coupling into the angle puts at 5.4 a switch where
/// the exact products stay near 1, it grew geometrically and ended every span within 13
/// switches (76 spans a step).
#[test]
fn locked_creeping_onion_spans_against_rk4() {
    let (_, _, longest) = three_steps(CREEPING, 20, 12, 20.0);
    assert!(longest >= 100.0, "{longest} switches");
}

/// [`LOOSE`] within the tolerance of the RK4 (5e-9 tolerances) in at most 20 substeps and 12
/// spans a step (10 to 12; resolved switch by switch the onion ended 139 tolerances off in 757,
/// the step flagged as limited by its budget of 644), its longest span over 200 of the step's
/// 755 switches. With the carried error bounded in the max norm (31.6 a switch) its spans
/// ended within 6 switches, 189 a step, their bounds at most 7e-6 of the tolerance.
#[test]
fn locked_onion_at_a_loose_tolerance_against_rk4() {
    let (_, _, longest) = three_steps(LOOSE, 20, 12, 20.0);
    assert!(longest >= 200.0, "{longest} switches");
}

/// [`SHORT_SPANS`] over five 1 us steps against [`converged_rk4`] from the start: no span
/// shorter than four switches is taken, and each step ends within 0.05 tolerances (the spans of
/// four switches the fourth and fifth steps take, each within a hundredth of the tolerance, leave
/// 3.8e-3 and 1.3e-2). Taken, about 300 spans a step of two or three switches each, each within
/// its bound, drifted the onion 0.36 tolerances off by the third step and 1.8 by the fifth.
#[test]
fn short_locked_spans_are_not_taken() {
    let (m, mut st, inputs) = case(&values(SHORT_SPANS)).unwrap();
    let start = st;
    let tol = m.params.tolerance;
    let switch = inputs.schedule.get().unwrap().step_period;
    for _ in 0..5 {
        SPAN_LOG.with(|l| l.borrow_mut().clear());
        let report = m.step(&mut st, &inputs, 1e-6).unwrap();
        assert!(!report.accuracy_limited, "{report:?}");
        for (_, t0, t1, _, _) in SPAN_LOG.with(|l| l.borrow_mut().split_off(0)) {
            let switches = ((t1 - t0) / switch).round() as usize;
            assert!(switches >= MIN_SPAN || t1 >= st.time, "{switches} switches");
        }
        let truth = converged_rk4(&m, &start, &inputs, st.time, 50.0);
        let error = (st.onion_angle - truth[2])
            .abs()
            .max((st.onion_tilt - truth[3]).abs());
        println!(
            "{} substeps, error / tolerance {:e}",
            report.substeps,
            error / tol
        );
        assert!(error <= 0.05 * tol, "{error:e} against {tol:e}");
    }
}

/// [`stiffness_slope_bound`] bounds eq. 3.3's third derivative ([`RingBar::stiffness_slope`])
/// at every offset, and that slope is the stiffness' derivative (central differences).
#[test]
fn ring_stiffness_slope_bounded() {
    let (m, _, _) = case(&values(CREEPING)).unwrap();
    let ring = &m.ring_bar;
    let bound = stiffness_slope_bound(ring);
    let mut largest: f64 = 0.0;
    for i in 0..=2000 {
        let beta = -std::f64::consts::PI + i as f64 * std::f64::consts::PI / 1000.0;
        let slope = ring.stiffness_slope(beta);
        largest = largest.max(slope.abs());
        let h = 1e-5;
        let numeric = (ring.stiffness(beta + h) - ring.stiffness(beta - h)) / (2.0 * h);
        assert!(
            (numeric - slope).abs() <= 1e-6 * bound,
            "{beta}: {numeric:e} against {slope:e}"
        );
    }
    assert!(
        largest <= bound && largest >= 0.1 * bound,
        "{largest:e} against {bound:e}"
    );
}

/// [`TURNING`] in at most 40 substeps a step (25 to 28; 136 to 152 where each switch's map was
/// linearized about its span's start), within the tolerance of the RK4 and its spans within
/// their bounds.
#[test]
fn locked_onion_turning_through_its_spans_against_rk4() {
    three_steps(TURNING, 40, 40, 200.0);
}
