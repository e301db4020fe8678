//! A locked rotor's Gilbert onion released far from its minimum, its ringing dropped by the
//! orbit-averaged decay time ([`Motor::locked_ringing_decays`]), against a fine classical RK4 of
//! the macrospin in its frozen landscape.

use super::onion_periods_tests::{case, values};
use super::tests::rk4_step;
use super::*;

/// Benchmark draws (the FMU's variables, full precision) whose onion rings for 1e3 to 6e4
/// precession periods in the first 1 us step, with the substeps the sublevel-set bound alone
/// took (it resolved the ringing until the budget ran out or the averaged advance carried it):
/// released 0.997 of the rim above the minimum at damping 1.4e-4, from the barrier's top at
/// 5.8e-4, and halfway up at 1.1e-3 (tilt 40 times stiffer than the well) and 1.4e-3.
const CASES: [(&str, u32); 4] = [
    ("strain_direction=-5.476237388102252e-2 stress=1.4690683460481352e8 load_torque=-6.127965152636325e-7 ring_outer_diameter=1.871818053695173e-2 ring_inner_diameter=7.273452913435496e-4 bar_length=2.5754910584269555e-6 bar_width=3.565788578796868e-8 thickness=2.001016409240826e-9 saturation_magnetization=4.321183312818685e5 magnetostriction=-8.41785729699855e-3 wall_volume=8.633060421268176e-11 density=3.059390663648732e3 fluid_viscosity=2.3497857942533455e-3 gilbert_damping=1.3785952885656547e-4 tolerance=1.1607952828060416e-6 step_angle=-8.225192027271508e0 step_period=2.4988170743750216e-4 stress_amplitude=1.4458867880294274e4 schedule_initial_direction=8.599594511007969e5 onion_model=1e0 max_substeps=1.7014e4 schedule=0e0 rotor_locked=1e0 initial_onion_offset=3.5163289163073103e-11 strain=-1.958969648760553e-2 youngs_modulus=2.973313296872746e8 strain_drive=0e0", 1704),
    ("strain_direction=-7.098206711667636e-3 stress=5.679882782181068e10 load_torque=1.5913820133782116e-7 ring_outer_diameter=2.918177504142952e-1 ring_inner_diameter=2.530031470328215e-1 bar_length=2.8987466908498986e-4 bar_width=2.851825564348178e-4 thickness=9.766199886350915e-8 saturation_magnetization=1.0668620301453005e5 magnetostriction=-6.113286499538171e-3 wall_volume=9.842827025596403e-11 density=1.425165461817909e3 fluid_viscosity=2.98290661561589e4 gilbert_damping=5.82020211605931e-4 tolerance=2.2246447089845374e-4 step_angle=4.726527288993891e0 step_period=5.1310462991776475e-2 stress_amplitude=4.962579151973618e1 schedule_initial_direction=-2.592264520758526e-3 onion_model=1e0 max_substeps=9.985e3 schedule=0e0 rotor_locked=1e0 initial_onion_offset=-1.7069898746360508e-8 strain=9.854783282737939e-2 youngs_modulus=1.0753677359136024e8 strain_drive=1e0", 403),
    ("strain_direction=9.784496887340901e10 stress=-3.9404897135415735e-2 load_torque=7.186477502982466e-7 ring_outer_diameter=6.060560358239472e-2 ring_inner_diameter=2.4523701228303225e-3 bar_length=6.115710217598574e-4 bar_width=6.672839096593219e-9 thickness=2.334927826267232e-9 saturation_magnetization=5.72639998896713e6 magnetostriction=1.0255149947715828e-3 wall_volume=6.661536600953052e-11 density=2.622817573882373e4 fluid_viscosity=1.7938668504951536e5 gilbert_damping=1.1284894307850531e-3 tolerance=1.4056097566532502e-6 step_angle=-4.8913916004486735e0 step_period=6.743500063127727e5 stress_amplitude=-4.2414172120579826e2 schedule_initial_direction=4.799052538512312e-6 onion_model=1e0 max_substeps=5.139e3 schedule=0e0 rotor_locked=1e0 initial_onion_offset=-1.7099709464389264e-2 strain=-2.0933487168070447e-2 youngs_modulus=1.5165159372024355e10 strain_drive=1e0", 152),
    ("strain_direction=-6.105535515574055e5 stress=3.2623339471342206e2 load_torque=9.347100690186274e-7 ring_outer_diameter=7.704647891159095e-3 ring_inner_diameter=3.143128093504638e-5 bar_length=4.651779940706727e-6 bar_width=7.99286283408513e-8 thickness=1.3882997177876869e-9 saturation_magnetization=2.051621978167461e4 magnetostriction=6.129706096192679e-3 wall_volume=6.56992415619593e-11 density=2.5184483429873208e3 fluid_viscosity=1.1550329315574604e5 gilbert_damping=1.420345166097094e-3 tolerance=1.068943205292423e-6 step_angle=-7.852369094776844e0 step_period=3.5929910982086176e2 stress_amplitude=1.8397641697204398e5 schedule_initial_direction=-6.851406513175218e5 onion_model=1e0 max_substeps=1.6356e4 schedule=1e0 rotor_locked=1e0 initial_onion_offset=2.190886902331955e0 strain=-8.559211660702531e-2 youngs_modulus=1.1923885912955494e6 strain_drive=1e0", 47),
];

/// The onion of `m` (rotor locked, drive `d`) from `psi0` at rest, by RK4 at 1/100 of the
/// linearization's precession period about the minimum it settles into, over `span` (s):
/// the last time its angle or tilt was beyond the tolerance of that minimum, and the end.
fn resolved(m: &Motor, d: &Drive, psi0: f64, span: f64) -> (f64, Vector) {
    let land = m.landscape(0.0, d.direction, d.stress);
    let minimum = land.settle(psi0);
    let k = land.curvature(minimum);
    let period = 2.0 * PI / (m.llg_rate * (k * m.tilt_stiffness).sqrt());
    let h = period / 100.0;
    let steps = (span / h).ceil() as usize;
    let h = span / steps as f64;
    let rate = |z: &Vector| m.rhs_jacobian(z, d, h).0;
    let tol = m.params.tolerance;
    let mut y: Vector = [0.0, 0.0, psi0, 0.0];
    let mut last_out = 0.0;
    for n in 1..=steps {
        y = rk4_step(&rate, &y, h);
        if (y[2] - minimum).abs() > tol || y[3].abs() > tol {
            last_out = n as f64 * h;
        }
    }
    (last_out, y)
}

/// Each case's first 1 us step drops the ringing at once (a few substeps, not flagged) and ends
/// within the tolerance of the RK4 reference in the onion's angle and tilt; the reference has
/// itself decayed to the tolerance well before the step's end.
#[test]
fn locked_ringing_is_dropped_where_the_resolved_one_has_decayed() {
    for (text, old) in CASES {
        let (m, mut st, inputs) = case(&values(text)).unwrap();
        let d = m.drive_at(&inputs, 0.0);
        let psi0 = st.onion_angle;
        let rep = m.step(&mut st, &inputs, 1e-6).unwrap();
        let (decayed, y) = resolved(&m, &d, psi0, 1e-6);
        let tol = m.params.tolerance;
        println!(
            "damping {:e}, tolerance {tol:e}: {} substeps (was {old}), onion off by {:e} rad, tilt by {:e}; resolved within the tolerance from {decayed:e} s",
            m.params.gilbert_damping,
            rep.substeps,
            st.onion_angle - y[2],
            st.onion_tilt - y[3],
        );
        assert!(!rep.accuracy_limited);
        assert!(rep.substeps <= 16, "{} substeps", rep.substeps);
        assert!(
            (st.onion_angle - y[2]).abs() <= tol,
            "{}",
            st.onion_angle - y[2]
        );
        assert!(
            (st.onion_tilt - y[3]).abs() <= tol,
            "{}",
            st.onion_tilt - y[3]
        );
        assert!(decayed < 0.75e-6, "{decayed}");
    }
}

/// The averaged decay time is no shorter than the resolved one: with only the time the RK4
/// reference takes to come within the tolerance left in the segment the ringing is kept, with
/// three times that it is dropped (the bound is not empty).
#[test]
fn locked_decay_time_is_not_shorter_than_the_resolved_one() {
    for (text, _) in CASES {
        let (m, st, inputs) = case(&values(text)).unwrap();
        let d = m.drive_at(&inputs, 0.0);
        let y: Vector = [0.0, 0.0, st.onion_angle, 0.0];
        let (decayed, _) = resolved(&m, &d, st.onion_angle, 1e-6);
        let decays = |remaining: f64| {
            let mut retry = f64::INFINITY;
            let settled = m.landscape(0.0, d.direction, d.stress).settle(y[2]);
            m.locked_ringing_decays(&y, &d, settled, remaining, &mut retry, &mut 0)
        };
        // Released at or beyond 0.999 of the rim: refused whatever the time left.
        let land = m.landscape(0.0, d.direction, d.stress);
        let well = m.onion_well(&land, y[2]).unwrap();
        let high = land.energy(y[2]) - land.energy(well.minimum) > 0.999 * well.barrier;
        println!("resolved within the tolerance after {decayed:e} s, from the rim: {high}");
        assert!(!decays(decayed), "{decayed}");
        assert_eq!(decays(3.0 * decayed), !high, "{decayed}");
    }
}
