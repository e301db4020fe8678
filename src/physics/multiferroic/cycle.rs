//! The quasi-static onion's hysteresis cycle as a rotor turns under a fixed strain, marched once
//! round the turn with its snaps located (see [`Motor::onion_cycle`]), and the rotor's periodic
//! deviation from its mean motion along it.

use super::{Drive, Motor};
use std::f64::consts::PI;

/// The quasi-static onion's hysteresis cycle as the rotor turns without end in one direction.
#[derive(Clone)]
pub(super) struct OnionCycle {
    /// Whole turns of rotor and onion taken off the state the cycle was found from, so that its
    /// march works near zero (rad).
    pub(super) turns: f64,
    pub(super) onion_turns: f64,
    /// A rotor angle on the cycle and the onion angle there (rad), less `turns` and
    /// `turns + onion_turns`.
    pub(super) rotor: f64,
    pub(super) onion: f64,
    /// Onion turns per rotor turn (0 when the onion swings back and forth, +-1 when it follows).
    pub(super) winding: f64,
    /// `int tau dphi` over one turn (J): the energy the onion's snaps dissipate, `<= 0`.
    pub(super) work: f64,
    /// The ring's torque along one turn of the cycle, in the direction of motion: pairs
    /// `(s, tau_s)` with `s = dir (phi - rotor)` from 0 to 2 pi, both sides of every snap.
    pub(super) torque: Vec<(f64, f64)>,
    /// The onion angle at each of those samples (rad), less the turns as `onion`.
    pub(super) onion_samples: Vec<f64>,
    /// The rotor's deviation at its terminal mean speed (with drag and a positive mean force).
    pub(super) terminal: Option<Wobble>,
    /// Whether the cycle is its own turn by half a turn (see [`Self::half_turn_symmetric`]),
    /// once found.
    pub(super) half_turn: std::cell::Cell<Option<bool>>,
}

impl OnionCycle {
    /// Turn `s` modulo one turn.
    pub(super) fn phase(s: f64) -> f64 {
        s.rem_euclid(2.0 * PI)
    }

    /// The cycle for a strain direction turned by `angle`: eq. 3.3-3.4 depend only on `psi - phi`
    /// and `psi - gamma`, so rotor and onion turn with the strain and the torque along the cycle
    /// is the same. A schedule's segments then share one march.
    pub(super) fn rotate(&mut self, angle: f64) {
        let rotor = self.rotor + angle;
        let whole = (rotor / (2.0 * PI)).round() * 2.0 * PI;
        let shift = angle - whole;
        self.rotor += shift;
        self.onion += shift;
        for psi in &mut self.onion_samples {
            *psi += shift;
        }
        self.turns += whole;
    }

    /// Whether the state's onion is the cycle's at the state's rotor angle (modulo whole turns,
    /// within 1e-9 rad).
    pub(super) fn holds(&self, motor: &Motor, y: &super::Vector, dir: f64, d: &Drive) -> bool {
        let s = Self::phase(dir * (y[0] - self.turns - self.rotor));
        let onion = self.onion_at(motor, s, dir, d) + self.turns + self.onion_turns;
        super::wrap_angle(onion - y[2]).abs() <= 1e-9
    }

    /// Whether the cycle turned by half a turn is itself: eq. 3.4 depends on the strain direction
    /// modulo pi, so rotor and onion turned by pi make a cycle of the same drive, the same one
    /// when the onion half a turn on is the onion turned by pi (modulo a turn; checked within
    /// 1e-9 rad at 16 samples of the first half turn). Otherwise the drive may have two cycles,
    /// and which one the onion lands on after a switch depends on where the rotor is then.
    pub(super) fn half_turn_symmetric(&self, motor: &Motor, dir: f64, d: &Drive) -> bool {
        if let Some(known) = self.half_turn.get() {
            return known;
        }
        let n = self.torque.len();
        let symmetric = (0..n)
            .step_by((n / 32).max(1))
            .filter(|&j| self.torque[j].0 < PI)
            .all(|j| {
                let onion = self.onion_at(motor, self.torque[j].0 + PI, dir, d);
                super::wrap_angle(onion - self.onion_samples[j] - PI).abs() <= 1e-9
            });
        self.half_turn.set(Some(symmetric));
        symmetric
    }

    /// The onion angle on the cycle at `s` (in the direction of motion, from `rotor`) for the
    /// drive `d`: settled from the sample at or below `s`, with no snap in between.
    pub(super) fn onion_at(&self, motor: &Motor, s: f64, dir: f64, d: &Drive) -> f64 {
        let j = self
            .torque
            .partition_point(|&(x, _)| x <= s)
            .clamp(1, self.torque.len())
            - 1;
        motor
            .landscape(self.rotor + dir * s, d.direction, d.stress)
            .settle(self.onion_samples[j])
    }
}

/// The rotor's periodic deviation from its mean motion at one mean speed, sampled where
/// [`OnionCycle::torque`] is, in the direction of motion.
#[derive(Clone)]
pub(super) struct Wobble {
    /// Angle `delta(s)` (rad, zero mean over a turn) and speed `u(s)` (rad/s) deviations.
    pub(super) angle: Vec<f64>,
    pub(super) speed: Vec<f64>,
    /// The second-order mean force `<tau'(s) delta(s)> = -<tau(s) u(s)> / Omega` (N m).
    pub(super) drift_force: f64,
    /// The mean speed (rad/s), the decay per radian `kappa` and the cycle's mean torque (N m).
    pub(super) omega: f64,
    pub(super) kappa: f64,
    pub(super) mean: f64,
}

impl Wobble {
    pub(super) fn amplitude(&self) -> f64 {
        self.angle.iter().fold(0.0, |a: f64, x| a.max(x.abs()))
    }

    /// One stride `h` (rad) of `I omega du/ds + c u = tau~(s)` for `tau~` linear over it:
    /// `u_end = e u_0 + a tau~_0 + b tau~_end`.
    pub(super) fn stride(&self, h: f64, c: f64) -> (f64, f64, f64) {
        let x = self.kappa * h;
        let one_minus_e = -(-x).exp_m1();
        // 1 - (1 - e^-x) / x, by its series where it cancels.
        let ramp = if x < 1e-3 {
            x / 2.0 - x * x / 6.0 + x * x * x / 24.0
        } else {
            1.0 - one_minus_e / x
        };
        (1.0 - one_minus_e, (one_minus_e - ramp) / c, ramp / c)
    }

    /// Angle and speed deviation at phase `s`: from the sample below it, the same exact stride
    /// (so no interpolation error between samples).
    pub(super) fn at(&self, cycle: &OnionCycle, s: f64, c: f64) -> (f64, f64) {
        let tau = &cycle.torque;
        let s = OnionCycle::phase(s);
        let j = tau
            .partition_point(|&(x, _)| x <= s)
            .clamp(1, tau.len() - 1)
            - 1;
        let (s0, t0) = tau[j];
        let (s1, t1) = tau[j + 1];
        let h = (s - s0).max(0.0);
        let t_s = if s1 > s0 {
            t0 + (t1 - t0) * (h / (s1 - s0)).min(1.0)
        } else {
            t1
        };
        let (e, a, b) = self.stride(h, c);
        let u = e * self.speed[j] + a * (t0 - self.mean) + b * (t_s - self.mean);
        let delta = self.angle[j] + 0.5 * h * (self.speed[j] + u) / self.omega;
        (delta, u)
    }
}

/// The drive of a canonical cycle ([`Motor::canonical_cycle`]): stress and load (their bits), the
/// direction of motion, and the end of the strain axis the onion starts at.
#[derive(Clone, Copy, PartialEq)]
struct CycleKey {
    stress: u64,
    load: u64,
    forward: bool,
    far_end: bool,
}

/// Canonical cycles already marched ([`Motor::canonical_cycle`]), with the settles each march
/// took (charged again at every use, so that the budget, and with it the result, does not depend
/// on what is memoized). A clone starts empty.
#[derive(Default)]
pub(super) struct CycleCache(std::sync::Mutex<Vec<(CycleKey, Option<OnionCycle>, u32)>>);

/// Canonical cycles kept: both ends of the axis in both directions of motion.
const CACHED_CYCLES: usize = 4;

impl Clone for CycleCache {
    fn clone(&self) -> Self {
        Self::default()
    }
}

impl std::fmt::Debug for CycleCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("CycleCache")
    }
}

impl Motor {
    /// The onion's cycle through the state `y` taken from a canonical march: rotor from 0 with
    /// the onion at the end of the strain's axis (direction 0; the minima of eq. 3.4's term)
    /// nearest the state's, its
    /// landing turn and its measured turn as in [`Self::onion_cycle`], then turned with the
    /// strain (eq. 3.3-3.4 depend on `psi - phi` and `psi - gamma` only, see
    /// [`OnionCycle::rotate`]) and given the state's whole turns; `None` when the state's onion
    /// is not on it (then the caller marches from the state). The march is a function of the
    /// drive alone, so it is memoized across steps (a spinning rotor without switches within a
    /// step marched its cycle again at every step, 40-120 us) while a step's result stays a
    /// function of its state and inputs (restoring a saved state repeats a step bit for bit).
    /// `settles` receives the march's settles whether memoized or not.
    pub(super) fn canonical_cycle(
        &self,
        y: &super::Vector,
        d: &Drive,
        dir: f64,
        settles: &mut u32,
    ) -> Option<OnionCycle> {
        // The ends of the axis, the minima of eq. 3.4's `E sin^2(psi - gamma)`: along the strain
        // for `E > 0`, across it for `E < 0`.
        let axis = if self.magnetoelastic_per_stress * d.stress < 0.0 {
            0.5 * PI
        } else {
            0.0
        };
        // Where the strain holds the onion at an end, its cycle is the one from that end (it
        // never reaches the other); otherwise the cycle from the near end, then the far one, so
        // that a cycle which winds (passing both ends) is found from the first at any phase.
        let nearer = ((y[2] - d.direction - axis) / PI).round().rem_euclid(2.0) == 1.0;
        let ends: &[bool] = if self.strain_held_reach(d).is_some() {
            &[nearer]
        } else {
            &[false, true]
        };
        ends.iter()
            .find_map(|&far_end| self.canonical_cycle_from(y, d, dir, axis, far_end, settles))
    }

    /// [`Self::canonical_cycle`] from the end `far_end` of the axis (`axis` from the strain).
    fn canonical_cycle_from(
        &self,
        y: &super::Vector,
        d: &Drive,
        dir: f64,
        axis: f64,
        far_end: bool,
        settles: &mut u32,
    ) -> Option<OnionCycle> {
        let key = CycleKey {
            stress: d.stress.to_bits(),
            load: d.load.to_bits(),
            forward: dir > 0.0,
            far_end,
        };
        let memo = |cache: &mut Vec<(CycleKey, Option<OnionCycle>, u32)>| {
            cache
                .iter()
                .find(|entry| entry.0 == key)
                .map(|entry| (entry.1.clone(), entry.2))
        };
        let known = match self.cycles.0.lock() {
            Ok(mut cache) => memo(&mut cache),
            Err(_) => None,
        };
        let (cycle, marched) = match known {
            Some(found) => found,
            None => {
                let canonical = Drive {
                    direction: 0.0,
                    applied_direction: 0.0,
                    ..*d
                };
                let start = [0.0, 0.0, axis + if far_end { PI } else { 0.0 }, 0.0];
                let mut marched = 0;
                let cycle = self.onion_cycle(&start, &canonical, dir, &mut marched);
                if let Ok(mut cache) = self.cycles.0.lock() {
                    if cache.len() >= CACHED_CYCLES {
                        cache.remove(0);
                    }
                    cache.push((key, cycle.clone(), marched));
                }
                (cycle, marched)
            }
        };
        *settles = settles.saturating_add(marched);
        let mut cycle = cycle?;
        cycle.rotate(d.direction);
        cycle.turns += ((y[0] - cycle.turns - cycle.rotor) / (2.0 * PI)).round() * 2.0 * PI;
        *settles = settles.saturating_add(1);
        let s = OnionCycle::phase(dir * (y[0] - cycle.turns - cycle.rotor));
        let onion = cycle.onion_at(self, s, dir, d) + cycle.turns + cycle.onion_turns;
        let whole = ((y[2] - onion) / (2.0 * PI)).round() * 2.0 * PI;
        if !((y[2] - onion - whole).abs() <= 1e-9 && whole.is_finite()) {
            return None;
        }
        cycle.onion_turns += whole;
        Some(cycle)
    }

    /// The onion's cycle for a rotor turning in direction `dir` from `phi0` with the onion at
    /// `psi0`: a landing march up to the onion's first snap or over one turn (none where the
    /// strain holds the onion), then one turn to measure it (and sample its torque) from there.
    /// `None` if that turn does not close (the onion not back where it started, modulo turns).
    pub(super) fn onion_cycle(
        &self,
        y: &super::Vector,
        d: &Drive,
        dir: f64,
        settles: &mut u32,
    ) -> Option<OnionCycle> {
        // The landscape depends on psi - phi and psi - gamma (mod pi): turn rotor and onion back
        // by whole turns so that the march works near zero (the onion by its own turns too, for
        // a state whose onion is far from its rotor).
        let turns = (y[0] / (2.0 * PI)).round() * 2.0 * PI;
        let onion_turns = ((y[2] - y[0]) / (2.0 * PI)).round() * 2.0 * PI;
        let phi0 = y[0] - turns;
        let psi0 = self
            .landscape(phi0, d.direction, d.stress)
            .settle(y[2] - turns - onion_turns);
        *settles += 1;
        // A turn to land on the cycle; none where the strain holds the onion, whose minimum then
        // follows the rotor without a snap (the cycle is where the onion is).
        let (start, psi1) = if self.strain_held_reach(d).is_some() {
            (phi0, psi0)
        } else {
            let (start, psi1, _) =
                self.march_onion(phi0, psi0, phi0 + dir * 2.0 * PI, d, None, settles)?;
            (start, psi1)
        };
        let mut samples = Vec::with_capacity(160);
        let (_, psi2, work) = self.march_onion(
            start,
            psi1,
            start + dir * 2.0 * PI,
            d,
            Some(&mut samples),
            settles,
        )?;
        let winding = ((psi2 - psi1) / (2.0 * PI)).round();
        if (psi2 - psi1 - winding * 2.0 * PI).abs() > 1e-6 {
            return None;
        }
        let torque = samples
            .iter()
            .map(|&(phi, _, tau)| (dir * (phi - start), dir * tau))
            .collect();
        let onion_samples = samples.iter().map(|&(_, psi, _)| psi).collect();
        let mut cycle = OnionCycle {
            turns,
            onion_turns,
            rotor: start,
            onion: psi1,
            winding: winding * dir,
            work,
            torque,
            onion_samples,
            terminal: None,
            half_turn: std::cell::Cell::new(None),
        };
        let force = d.load.abs() + work / (2.0 * PI);
        if self.drag > 0.0 && force > 0.0 {
            cycle.terminal = Some(self.wobble(&cycle, force / self.drag));
        }
        Some(cycle)
    }

    /// The quasi-static onion while the rotor turns from `from` to `to` (its memory rule, snaps
    /// included): the rotor and onion angles at the end and the energy the snaps changed `U` by
    /// on the way (J). Strides of at most [`CYCLE_STRIDE`]; a snap is placed within
    /// [`SNAP_PLACEMENT`] rad, where its energy change is taken. `samples`, if given, receives
    /// `(phi, psi, tau)`, the ring's torque at every stride's end and on both sides of every
    /// snap; without it (a landing march) the march ends just past the first snap, placed within
    /// [`LANDING_SNAP_PLACEMENT`].
    pub(super) fn march_onion(
        &self,
        from: f64,
        psi: f64,
        to: f64,
        d: &Drive,
        mut samples: Option<&mut Vec<(f64, f64, f64)>>,
        settles: &mut u32,
    ) -> Option<(f64, f64, f64)> {
        let count = std::cell::Cell::new(0u32);
        let settle = |at: f64, onion: f64| {
            count.set(count.get() + 1);
            self.landscape(at, d.direction, d.stress).settle(onion)
        };
        let energy = |at: f64, onion: f64| self.landscape(at, d.direction, d.stress).energy(onion);
        let landing = samples.is_none();
        let placement = if landing {
            LANDING_SNAP_PLACEMENT
        } else {
            SNAP_PLACEMENT
        };
        let mut record = |at: f64, onion: f64| {
            if let Some(s) = samples.as_deref_mut() {
                s.push((at, onion, self.ring_bar.torque_stiffness(onion - at).0));
            }
        };
        let strides = ((to - from).abs() / CYCLE_STRIDE).ceil().max(1.0);
        if strides > 1e6 {
            return None;
        }
        let (mut phi, mut psi, mut work) = (from, psi, 0.0);
        record(phi, psi);
        for k in 1..=strides as usize {
            let next = from + (to - from) * k as f64 / strides;
            let psi_next = settle(next, psi);
            if (psi_next - psi).abs() <= ONION_JUMP + 4.0 * (next - phi).abs() {
                (phi, psi) = (next, psi_next);
                record(phi, psi);
                continue;
            }
            // A snap inside the stride: the fold where the branch's minimum vanishes, bracketed
            // on the rotor angle. Its curvature there falls like the square root of the
            // distance to the fold, so the squared curvature at the last two angles on the
            // branch extrapolates linearly to it (secant steps, a bisection when they leave the
            // bracket); once the step is within the placement, the angle just past it is tried.
            let (mut lo, mut psi_lo, mut hi, mut psi_hi) = (phi, psi, next, psi_next);
            let squared_curvature = |at: f64, onion: f64| {
                self.landscape(at, d.direction, d.stress)
                    .curvature(onion)
                    .max(0.0)
                    .powi(2)
            };
            let mut g_lo = squared_curvature(lo, psi_lo);
            let mut previous: Option<(f64, f64)> = None;
            for _ in 0..64 {
                let width = hi - lo;
                if width.abs() <= placement {
                    break;
                }
                // The curvature no longer falls: the fold is within rounding of `lo`.
                let at_fold = previous.is_some_and(|(_, g_p)| {
                    let falling = g_p > 1.5 * g_lo;
                    !falling
                });
                let secant = previous.and_then(|(p, g_p)| {
                    let x = lo + g_lo * (lo - p) / (g_p - g_lo);
                    let t = (x - lo) / width;
                    (t.is_finite() && t > 0.0 && t < 0.9).then_some(x)
                });
                let just_past = lo + 0.9 * placement * width.signum();
                let mid = match secant {
                    _ if at_fold => just_past,
                    Some(x) if (x - lo).abs() < 0.5 * placement => just_past,
                    Some(x) => x,
                    None => 0.5 * (lo + hi),
                };
                let psi_mid = settle(mid, psi_lo);
                if (psi_mid - psi_lo).abs() <= ONION_JUMP + 4.0 * (mid - lo).abs() {
                    previous = Some((lo, g_lo));
                    (lo, psi_lo) = (mid, psi_mid);
                    g_lo = squared_curvature(lo, psi_lo);
                } else {
                    (hi, psi_hi) = (mid, psi_mid);
                }
            }
            work += energy(hi, psi_hi) - energy(lo, psi_lo);
            record(lo, psi_lo);
            record(hi, psi_hi);
            if landing {
                // The snap has set the onion on the branch it jumped to.
                (phi, psi) = (hi, psi_hi);
                break;
            }
            (phi, psi) = (next, settle(next, psi_hi));
            record(phi, psi);
        }
        *settles = settles.saturating_add(count.get());
        (psi.is_finite() && work.is_finite()).then_some((phi, psi, work))
    }
}

/// Rotor stride of the onion's cycle march (rad), and the placement of its snaps.
const CYCLE_STRIDE: f64 = 0.05;
const SNAP_PLACEMENT: f64 = 1e-10;
/// The placement of a snap on the landing turn of [`Motor::onion_cycle`], which only needs the
/// branch the onion lands on.
const LANDING_SNAP_PLACEMENT: f64 = 1e-4;
/// An onion turn beyond its branch's that marks a snap (rad), as in the integrator.
const ONION_JUMP: f64 = 0.05;
