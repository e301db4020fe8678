//! The ring's torque in the Gilbert onion's linear macro spans (see
//! [`Motor::advance_onion_linear`]): dropped within a bound where it is negligible, folded into
//! the spans' affine maps where the rotor is locked.

use super::decoupled::torque_bound;
use super::magnetics::RingBar;
use super::{Motor, MotorInputs, StepRun};

/// The ring's torque on the onion (eq. 3.3's `dU_m / d psi`) over a macro span from the onion
/// angle `psi0`, as `value + stiffness delta + R` in `delta = psi - psi0`, with
/// `|R| <= curvature delta^2 + constant`.
#[derive(Clone, Copy, Debug)]
pub(super) struct RingTerm {
    /// The torque at `psi0`, added to eq. 3.4's gradient.
    pub value: f64,
    /// Its derivative in the onion angle at `psi0` (the ring-bar stiffness).
    pub stiffness: f64,
    /// The remainder's coefficient of `delta^2`.
    pub curvature: f64,
    /// The remainder's constant part.
    pub constant: f64,
    /// A bound on the rotor's speed over the span where the rotor turns under the ring (rad/s):
    /// the bar's turn `p` since the span's start moves the offset, adding `|stiffness| |p|` to
    /// the remainder and `|p|` to its `delta` (zero where the rotor stays or the ring is dropped
    /// whole).
    pub drift_speed: f64,
    /// Whether the torque's value and slope are taken afresh at each switch, at the onion's place
    /// on the maps' path there (the bar held); else they stay those at the span's start, the
    /// onion's turn since then joining the remainder's `delta`.
    pub relinearized: bool,
}

impl Motor {
    /// The ring's term for a macro span starting at `run.y`, or `None` where a span may not be
    /// tried.
    ///
    /// Where the ring's torque is negligible for the onion ([`Self::ring_decoupled`]) it is
    /// dropped whole: nothing linear, the constant its bound `tau_max` ([`torque_bound`]). Where it
    /// is not but the rotor is locked, the bar's angle `phi` stays, so the torque is a fixed
    /// function of the onion angle alone, `tau(psi - phi)` (eq. 3.3): its value and slope (the
    /// ring-bar stiffness) at each switch's start on the maps' path join that switch's affine
    /// map, and Taylor's remainder, `|tau''| / 2 delta^2`, joins the bound with `|tau''|` at
    /// most [`stiffness_slope_bound`]. A free rotor the ring couples to the onion but not to the
    /// rotor itself, see [`Self::free_ring_term`].
    pub(super) fn linear_ring_term(&self, run: &StepRun, inputs: &MotorInputs) -> Option<RingTerm> {
        match run.onion_decoupled {
            Some(true) => Some(RingTerm {
                value: 0.0,
                stiffness: 0.0,
                curvature: 0.0,
                constant: torque_bound(&self.ring_bar),
                drift_speed: 0.0,
                relinearized: false,
            }),
            Some(false) if inputs.rotor_locked => {
                let (value, stiffness) = self.ring_bar.torque_stiffness(run.y[2] - run.y[0]);
                let term = RingTerm {
                    value,
                    stiffness,
                    curvature: 0.5 * stiffness_slope_bound(&self.ring_bar),
                    constant: 0.0,
                    drift_speed: 0.0,
                    relinearized: true,
                };
                (value.is_finite() && stiffness.is_finite() && term.curvature.is_finite())
                    .then_some(term)
            }
            Some(false) => self.free_ring_term(run, inputs),
            _ => None,
        }
    }
}

/// A bound on `|d^3 U_m / d beta^3|` ([`RingBar::stiffness_slope`], N m / rad^2) at every
/// offset: with `|sin|, |cos| <= 1` and both distances `A, B` at least `r - a` (eq. 3.3), its
/// terms `-s (1/A^3 + 1/B^3)`, `9 a r s c (1/B^5 - 1/A^5)` and `15 (a r)^2 s^3 (1/A^7 + 1/B^7)`
/// are at most `2 / d^3`, `9 a r / d^5` and `30 (a r)^2 / d^7` with `d = r - a`, times `|K| a r`.
pub(super) fn stiffness_slope_bound(ring_bar: &RingBar) -> f64 {
    let (a, r) = (ring_bar.bar_charge_radius, ring_bar.wall_radius);
    let ar = a * r;
    let d = r - a;
    let d3 = d * d * d;
    let d5 = d3 * d * d;
    let d7 = d5 * d * d;
    (ring_bar.coupling * ar).abs() * (2.0 / d3 + 9.0 * ar / d5 + 30.0 * ar * ar / d7)
}
