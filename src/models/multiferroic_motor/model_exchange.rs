//! Model Exchange of the motor: four continuous states, one event indicator (the
//! quasi-static onion's fold), time events at the schedule's switches. The physics is
//! [`crate::physics::multiferroic::model_exchange`].
//!
//! States, in order: rotor angle and speed, then the onion's angle and tilt. In the Gilbert option
//! the last two are integrated (the LLG macrospin). In the quasi-static option the onion is not
//! integrated: its angle follows its branch's minimum at every evaluation (from the model's own
//! anchor, refreshed at every completed integrator step), so the last two states are held between
//! events at the onion's angle at the last event and zero tilt, with zero derivatives. The
//! description's state count is fixed, hence four in both options.

use super::{column, partial_rows, write_outputs, MultiferroicMotor};
use crate::models::{Partials, Report, Status};
use crate::physics::multiferroic::model_exchange::{MeEvaluation, MAX_RINGING_WINDOWS};
use crate::physics::multiferroic::{Motor, OnionModel};
use crate::variables::multiferroic_motor::{
    DerOnionStateAngleBy, DerOnionTiltBy, DerRotorAngleBy, DerRotorSpeedBy, Inputs, Outputs,
    Variables,
};
use crate::variables::Row as _;
use serde::{Deserialize, Serialize};

/// Model Exchange's discrete states, part of the FMU state.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(super) struct Discrete {
    /// The instance serves Model Exchange: its outputs follow the onion's branch, never jumping
    /// outside event mode. Set at the first event (the initial event iteration).
    active: bool,
    /// Time of the last event (s): the schedule's direction is the one in effect then, so it
    /// changes only at its switches, which are time events.
    schedule_time: f64,
    /// Quasi-static option: the values of the onion's two states, held between events.
    held: [f64; 2],
    /// Gilbert option: the onion's ringing after the last jump of its drive (see
    /// [`Motor::me_ringing`]): its start, window length and end (s; a zero window: none), and the
    /// drive (strain direction, stress) that started it.
    ringing: [f64; 3],
    ringing_drive: [f64; 2],
}

/// The lightest Gilbert damping CVode's defaults (variable order up to 5) were measured to run
/// through FMPy (see [`MultiferroicMotor::me_light_damping`]).
const LIGHTEST_DEFAULT_BDF_DAMPING: f64 = 0.005;

impl Discrete {
    pub(super) fn validated(self) -> Result<Self, String> {
        let finite = |x: &[f64]| x.iter().all(|x| x.is_finite());
        if self.schedule_time.is_finite()
            && finite(&self.held)
            && finite(&self.ringing)
            && finite(&self.ringing_drive)
            && self.windows_bounded()
        {
            Ok(self)
        } else {
            Err(format!(
                "Model Exchange discrete state is not finite: {self:?}"
            ))
        }
    }
}

impl Discrete {
    /// No window, or at most [`MAX_RINGING_WINDOWS`] positive ones (a restored state cannot ask
    /// for an unbounded number of time events).
    fn windows_bounded(&self) -> bool {
        let [from, window, until] = self.ringing;
        window == 0.0
            || (window > 0.0
                && until >= from
                && (until - from) / window <= MAX_RINGING_WINDOWS + 1.0)
    }
}

impl MultiferroicMotor {
    fn gilbert(&self) -> bool {
        self.motor.params.onion_model == OnionModel::Gilbert
    }

    /// At the first event of a Model Exchange run: why an importer's default BDF cannot follow a
    /// lightly damped Gilbert onion. Linearized at its minimum the macrospin precesses with
    /// eigenvalues `-alpha w +- i w` (section 3.3's LLG damping `alpha`), within `atan(alpha)` of
    /// the imaginary axis; BDF of order 3, 4 and 5 is stable only beyond 3.97, 16.6 and 38.2
    /// degrees of it, so once CVode (maximum order 5 by default, no stability limit detection in
    /// FMPy) takes steps past the precession period it grows the ringing instead of damping it.
    /// Measured under FMPy's defaults: runs at `alpha` = 0.005, stops at 0.003, 0.002, 0.001.
    pub(super) fn me_light_damping(&self) -> Option<String> {
        let alpha = self.motor.params.gilbert_damping;
        (self.gilbert() && alpha < LIGHTEST_DEFAULT_BDF_DAMPING).then(|| {
            format!(
                "gilbert_damping = {alpha} is below {LIGHTEST_DEFAULT_BDF_DAMPING}: the Gilbert \
                 onion's precession (eigenvalues within {:.2} degrees of the imaginary axis) is \
                 unstable under BDF of order 3 to 5, so a variable-order BDF such as CVode at its \
                 defaults (FMPy, OMSimulator) fails on it; run Co-Simulation, or limit the \
                 solver's order to 2",
                alpha.atan().to_degrees()
            )
        })
    }

    /// Whether the instance runs Model Exchange (see [`Discrete::active`]).
    pub(super) fn model_exchange_active(&self) -> bool {
        self.me.active
    }

    /// The continuous state vector.
    pub(super) fn me_states(&self) -> [f64; 4] {
        let s = &self.state;
        if self.gilbert() {
            [s.rotor_angle, s.rotor_speed, s.onion_angle, s.onion_tilt]
        } else {
            [
                s.rotor_angle,
                s.rotor_speed,
                self.me.held[0],
                self.me.held[1],
            ]
        }
    }

    /// Takes the importer's state vector; refuses a non-finite one or one beyond the
    /// motor's bounds ([`Motor::me_validate_state`]: a trial state's tilt may be large), keeping
    /// the old.
    pub(super) fn me_set_states(&mut self, x: &[f64; 4]) -> Result<(), String> {
        let mut next = self.state;
        next.rotor_angle = x[0];
        next.rotor_speed = x[1];
        if self.gilbert() {
            next.onion_angle = x[2];
            next.onion_tilt = x[3];
        } else if !(x[2].is_finite() && x[3].is_finite()) {
            return Err(format!(
                "the onion's states must be finite, got {} and {}",
                x[2], x[3]
            ));
        }
        Motor::me_validate_state(&next)?;
        self.state = next;
        if !self.gilbert() {
            self.me.held = [x[2], x[3]];
        }
        Ok(())
    }

    fn me_evaluation(&self, inputs: &Inputs) -> Result<MeEvaluation, String> {
        self.motor
            .me_evaluate(&self.state, &self.inputs(inputs), self.me.schedule_time)
    }

    /// Time derivatives of the states.
    pub(super) fn me_derivatives(&self, inputs: &Inputs) -> Result<[f64; 4], String> {
        self.me_evaluation(inputs).map(|e| e.derivatives)
    }

    /// The fold indicator: positive while the quasi-static onion's minimum exists.
    pub(super) fn me_event_indicators(&self, inputs: &Inputs) -> Result<[f64; 1], String> {
        self.me_evaluation(inputs).map(|e| [e.fold_indicator])
    }

    /// Outputs in continuous-time mode: on the onion's branch, never jumping.
    pub(super) fn me_outputs(&self, inputs: &Inputs, outputs: &mut Outputs, report: &mut Report) {
        match self.me_evaluation(inputs) {
            Ok(e) => write_outputs(outputs, &e.outputs),
            Err(e) => report.add(Status::Error, format!("cannot evaluate the motor: {e}")),
        }
    }

    /// Completed integrator step: the anchor moves along the branch (not past a fold).
    pub(super) fn me_completed_step(&mut self, inputs: &Inputs) -> Result<(), String> {
        let inputs = self.inputs(inputs);
        self.motor
            .me_follow_branch(&mut self.state, &inputs, self.me.schedule_time)
    }

    /// Event mode at `time`: the schedule's direction in effect then, the onion settled by the
    /// Co-Simulation rule. Returns whether a continuous state's value changed.
    pub(super) fn me_event(&mut self, inputs: &Inputs, time: f64) -> Result<bool, String> {
        let inputs = self.inputs(inputs);
        if !self.me.active {
            self.motor.me_check_schedule(&inputs)?;
        }
        let mut next = self.state;
        next.time = time;
        let mut changed = self.motor.me_event_update(&mut next, &inputs)?;
        // A jump of the drive (or the first event) starts the Gilbert onion's ringing windows;
        // the windows' own events change nothing.
        let drive = self.motor.me_drive(&inputs, time);
        if !self.me.active || drive != self.me.ringing_drive {
            let (window, length) = self.motor.me_ringing(drive[1]).unwrap_or((0.0, 0.0));
            self.me.ringing = [time, window, time + length];
            self.me.ringing_drive = drive;
        }
        self.state = next;
        self.me.active = true;
        self.me.schedule_time = time;
        if !self.gilbert() {
            let held = [next.onion_angle, 0.0];
            changed |= held != self.me.held;
            self.me.held = held;
        }
        Ok(changed)
    }

    /// The next switch of the schedule, if one runs, or the end of the Gilbert onion's present
    /// ringing window, if sooner.
    pub(super) fn me_next_time_event(&self) -> Option<f64> {
        let now = self.me.schedule_time;
        let switch = self.schedule.get().map(|s| s.next_switch_after(now));
        let [from, window, until] = self.me.ringing;
        let ringing = (window > 0.0 && now < until).then(|| {
            // The next window end at least a thousandth of a window ahead (rounding).
            let n = ((now - from) / window + 1e-3).floor() + 1.0;
            from + n * window
        });
        match (switch, ringing.filter(|&t| t < until && t > now)) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }

    /// Exact partials of the outputs and of the state derivatives by the inputs and the states,
    /// on the branch the evaluation takes.
    pub(super) fn me_partials(
        &self,
        inputs: &Inputs,
        rows: &mut Partials<Variables>,
    ) -> Result<(), String> {
        let inputs = self.inputs(inputs);
        let p = self
            .motor
            .me_partials(&self.state, &inputs, self.me.schedule_time)?;
        partial_rows(&p, self.strain_drive, true, rows);
        let of = |g| move |known| column(g, known, self.strain_drive, true);
        let [angle, speed, onion, tilt] = &p.derivatives;
        rows.row(DerRotorAngleBy::from_fn(of(angle)))
            .row(DerRotorSpeedBy::from_fn(of(speed)))
            .row(DerOnionStateAngleBy::from_fn(of(onion)))
            .row(DerOnionTiltBy::from_fn(of(tilt)));
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::Model;
    use crate::variables::multiferroic_motor::{Known, Parameters, Unknown};
    use crate::variables::{ContinuousStates, Interface};

    type States = <Variables as Interface>::States;

    /// `rotor_speed`'s nominal (abstol = reltol x nominal in CVode under OMSimulator and FMPy) is
    /// its physical scale, the terminal speed at the ring's peak torque with Table 3.1's motor,
    /// within a factor of 2: with the default nominal of 1 rad/s, resolving the rotor's 2 ns
    /// start to 1e-4 rad/s needs steps below OMSimulator's minimum (1e-12 s).
    #[test]
    fn rotor_speed_nominal_is_the_terminal_speed_at_peak_torque() {
        let m = MultiferroicMotor::new(&Parameters::default(), &Inputs::default()).unwrap();
        let scale = m.motor.terminal_speed();
        let nominal = States::NOMINALS[1];
        println!("terminal speed {scale:e} rad/s, nominal {nominal:e} rad/s");
        assert_eq!(States::NAMES[1], "rotor_speed");
        assert!(
            (0.5..=2.0).contains(&(nominal / scale)),
            "{nominal} vs {scale}"
        );
    }

    /// The Gilbert onion takes any finite tilt an integrator tries (CVode's first trial under
    /// OMSimulator's settings tilts by -800 rad) and gives finite derivatives linear in it; a
    /// non-finite tilt is still refused, keeping the old state.
    #[test]
    fn model_exchange_accepts_far_trial_tilts() {
        let p = Parameters {
            onion_model: 1,
            ..Parameters::default()
        };
        let inputs = Inputs::default();
        let mut m = MultiferroicMotor::new(&p, &inputs).unwrap();
        m.me_event(&inputs, 0.0).unwrap();
        let rates = |m: &mut MultiferroicMotor, tilt: f64| {
            m.me_set_states(&[0.0, 0.0, 0.0, tilt]).unwrap();
            m.me_derivatives(&inputs).unwrap()
        };
        let (at0, at1) = (rates(&mut m, 0.0), rates(&mut m, 1.0));
        for tilt in [-801.7, 1e3, -1e9] {
            let d = rates(&mut m, tilt);
            for i in 2..4 {
                let linear = at0[i] + tilt * (at1[i] - at0[i]);
                assert!(
                    (d[i] - linear).abs() <= 1e-9 * linear.abs(),
                    "{tilt}: {d:?}"
                );
            }
        }
        assert!(m.me_set_states(&[0.0, 0.0, 0.0, f64::NAN]).is_err());
        assert_eq!(m.me_states()[3], -1e9);
        // A saved Model Exchange state with such a tilt restores; Co-Simulation's bound holds
        // for an instance that never ran Model Exchange.
        let mut restored = MultiferroicMotor::new(&p, &inputs).unwrap();
        assert!(restored.adopt_history(&m).is_ok());
        assert_eq!(restored.me_states()[3], -1e9);
        let mut co_simulation = MultiferroicMotor::new(&p, &inputs).unwrap();
        co_simulation.state.onion_tilt = 20.0;
        assert!(restored.adopt_history(&co_simulation).is_err());
    }

    /// Below the damping CVode's defaults follow, the first event of a Model Exchange run
    /// warns with the reason (not at later events, not in Co-Simulation, not at the damping it
    /// follows or with the quasi-static onion).
    #[test]
    fn light_gilbert_damping_warns_at_the_first_model_exchange_event() {
        let warned = |alpha: f64, gilbert: bool| {
            let p = Parameters {
                onion_model: i32::from(gilbert),
                gilbert_damping: alpha,
                ..Parameters::default()
            };
            let mut m = MultiferroicMotor::new(&p, &Inputs::default()).unwrap();
            let mut outputs = Outputs::default();
            let mut statuses = vec![];
            for t in [0.0, 1e-9] {
                let mut report = Report::default();
                m.update_discrete_states(&Inputs::default(), &mut outputs, t, &mut report);
                statuses.push(report.status());
            }
            statuses
        };
        assert_eq!(warned(0.002, true), [Status::Warning, Status::Ok]);
        assert_eq!(warned(0.0, true), [Status::Warning, Status::Ok]);
        assert_eq!(warned(0.005, true), [Status::Ok, Status::Ok]);
        assert_eq!(warned(0.002, false), [Status::Ok, Status::Ok]);
    }

    fn stepping(period: f64, gilbert: bool) -> MultiferroicMotor {
        let p = Parameters {
            schedule: 1,
            step_period: period,
            onion_model: i32::from(gilbert),
            ..Parameters::default()
        };
        MultiferroicMotor::new(&p, &Inputs::default()).unwrap()
    }

    /// What an importer does through the model's Model Exchange methods: the initial event, RK4
    /// steps of `h` (cut at time events), a completed step after each, an event at each switch
    /// and where the fold indicator changes sign. Returns the rotor angle at each multiple of
    /// `every`.
    fn importer(model: &mut MultiferroicMotor, h: f64, until: f64, every: f64) -> Vec<f64> {
        let inputs = Inputs::default();
        let mut t = 0.0;
        model.me_event(&inputs, t).unwrap();
        let mut angles = vec![];
        let mut next_sample = every;
        while t < until * (1.0 - 1e-12) {
            let target = model
                .me_next_time_event()
                .unwrap_or(f64::INFINITY)
                .min(next_sample);
            let dt = h.min(target - t);
            let x0 = model.me_states();
            let z0 = model.me_event_indicators(&inputs).unwrap()[0];
            let stage = |x: [f64; 4], tt: f64, m: &mut MultiferroicMotor| {
                m.set_time(tt);
                m.me_set_states(&x).unwrap();
                m.me_derivatives(&inputs).unwrap()
            };
            let add = |x: [f64; 4], k: [f64; 4], f: f64| -> [f64; 4] {
                std::array::from_fn(|i| x[i] + f * k[i])
            };
            let k1 = stage(x0, t, model);
            let k2 = stage(add(x0, k1, 0.5 * dt), t + 0.5 * dt, model);
            let k3 = stage(add(x0, k2, 0.5 * dt), t + 0.5 * dt, model);
            let k4 = stage(add(x0, k3, dt), t + dt, model);
            let k: [f64; 4] =
                std::array::from_fn(|i| (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]) / 6.0);
            t = if (target - (t + dt)).abs() < 1e-12 * target {
                target
            } else {
                t + dt
            };
            model.set_time(t);
            model.me_set_states(&add(x0, k, dt)).unwrap();
            let z1 = model.me_event_indicators(&inputs).unwrap()[0];
            model.me_completed_step(&inputs).unwrap();
            let time_event = model.me_next_time_event().is_some_and(|e| t >= e);
            if time_event || (z0 > 0.0 && z1 <= 0.0) {
                model.me_event(&inputs, t).unwrap();
            }
            if t >= next_sample * (1.0 - 1e-12) {
                angles.push(model.me_states()[0]);
                next_sample += every;
            }
        }
        angles
    }

    #[test]
    fn the_model_exchange_loop_matches_co_simulation_at_every_switch() {
        // The quasi-static rotor over three 25 us periods (it follows each 60 degree step); the
        // Gilbert onion's GHz precession needs ps steps, so two 2 us periods.
        for (gilbert, period, h, periods) in [(false, 25e-6, 2e-10, 3), (true, 2e-6, 4e-12, 2)] {
            let mut me = stepping(period, gilbert);
            let angles = importer(&mut me, h, periods as f64 * period, period);
            let mut cs = stepping(period, gilbert);
            let mut out = Outputs::default();
            let mut report = Report::default();
            let steps = (period / 1e-6).round() as usize;
            for (k, angle) in angles.iter().enumerate() {
                for j in 0..steps {
                    let t = (k * steps + j) as f64 * 1e-6;
                    cs.step(&Inputs::default(), &mut out, t, 1e-6, &mut report);
                }
                assert!(
                    report.status() <= Status::Warning,
                    "{:?}",
                    report.messages()
                );
                assert!(
                    (angle - out.rotor_angle).abs() < 1e-4,
                    "gilbert {gilbert}, period {k}: {angle} {}",
                    out.rotor_angle
                );
            }
            assert_eq!(angles.len(), periods);
            if !gilbert {
                assert!(angles[periods - 1].to_degrees() > 150.0, "{angles:?}");
            }
        }
    }

    /// After an event that moves the Gilbert onion's drive, a time event at every window's end
    /// until its ringing is over, then the schedule's switch; the windows' own events change
    /// nothing and start no new windows, the switch starts new ones.
    #[test]
    fn gilbert_ringing_windows_are_time_events_until_the_next_switch() {
        let mut m = stepping(1e-6, true);
        let (window, length) = m.motor.me_ringing(2e8).unwrap();
        let inputs = Inputs::default();
        let mut events = vec![];
        let mut t = 0.0;
        while t < 1.5e-6 {
            assert!(!m.me_event(&inputs, t).unwrap());
            t = m.me_next_time_event().unwrap();
            events.push(t);
        }
        let windows = (length / window).ceil() as usize - 1;
        for (n, t) in events[..windows].iter().enumerate() {
            assert!(
                (t - (n + 1) as f64 * window).abs() < 1e-9 * window,
                "{n}: {t}"
            );
        }
        assert_eq!(events[windows], 1e-6);
        assert!((events[windows + 1] - (1e-6 + window)).abs() < 1e-9 * window);
        // A restored state may not ask for more windows than a jump gives.
        let crafted = Discrete {
            ringing: [0.0, 1e-300, 1.0],
            ..m.me
        };
        assert!(crafted.validated().is_err());
        assert!(m.me.validated().is_ok());
        // Without the Gilbert onion, only the switches.
        let mut q = stepping(1e-6, false);
        q.me_event(&inputs, 0.0).unwrap();
        assert_eq!(q.me_next_time_event(), Some(1e-6));
    }

    #[test]
    fn partial_rows_cover_outputs_and_derivatives_by_inputs_and_states() {
        let mut m = stepping(1e-4, false);
        m.me_event(&Inputs::default(), 0.0).unwrap();
        m.set_time(1e-5);
        m.me_set_states(&[0.3, 100.0, 0.0, 0.0]).unwrap();
        let mut p = Partials::new();
        m.me_partials(&Inputs::default(), &mut p).unwrap();
        let by = |k: Known| p.partial(Unknown::DerRotorSpeed, k).unwrap();
        // I w' = tau - c w: d/dw = -c/I, and the schedule makes stress no input.
        let c_over_i = m.motor.drag / m.motor.inertia;
        assert!((by(Known::RotorSpeed) + c_over_i).abs() < 1e-9 * c_over_i);
        assert_eq!(by(Known::Stress), 0.0);
        assert!(by(Known::RotorAngle) < 0.0, "a restoring stiffness");
        assert!(p.get(Unknown::Torque).is_some() && p.get(Unknown::DerOnionTilt).is_some());
    }

    #[test]
    fn co_simulation_time_events_are_the_switches_after_the_given_time() {
        // Co-Simulation (FMI 3.0 event mode): the switches k T after `time`, Model Exchange's
        // event clock untouched; a switch at `time` is behind it.
        let period = 1e-4;
        let m = stepping(period, true);
        assert_eq!(m.next_time_event(0.0), Some(period));
        assert_eq!(m.next_time_event(period), Some(2.0 * period));
        assert_eq!(m.next_time_event(2.5 * period), Some(3.0 * period));
        // 30 communication steps of 3e-5 s end a rounding short of the ninth switch: it counts
        // as reached (the instance reports it at that step's end).
        assert_eq!(m.next_time_event(0.00087), Some(9.0 * period));
        assert_eq!(m.next_time_event(30.0 * 3e-5), Some(10.0 * period));
        assert!(!m.model_exchange_active());
        // Without the schedule, no events.
        let off = MultiferroicMotor::new(&Parameters::default(), &Inputs::default()).unwrap();
        assert_eq!(off.next_time_event(0.5), None);
        // Model Exchange keeps its own clock: the next event after its last event time.
        let mut me = stepping(1e-4, false);
        me.me_event(&Inputs::default(), 0.0).unwrap();
        assert_eq!(me.next_time_event(0.5), Some(1e-4));
    }
}
