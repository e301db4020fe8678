//! A cheap refusal of [`Motor::relaxed_onion`] for a locked rotor's ringing onion, made before
//! the settle's march to the minimum it rings about ([`Motor::ringing_outlasts_switches`]).

use super::onion::Landscape;
use super::{Motor, Vector};

impl Motor {
    /// Whether the switch test that a locked rotor's onion at `y` must pass before it is placed
    /// on its minimum (`Motor::ringing_ends_in`, its gap to the minimum decayed to the next
    /// switch times the switches it remembers, within `slack`) fails whatever minimum of eq. 3.4
    /// in `land` it settles into: every curvature there is at most
    /// `K = max |U_m''| + 2 |E|` (eq. 3.3's stiffness bound plus eq. 3.4's wall term), so the
    /// energy-norm gap is at least the tilt's `|theta| sqrt(T / K)`, and the slowest decay rate
    /// of the linearization, at most half its trace, at most `g alpha (K + T) / 2`: the gap
    /// decays no faster and the memory `1 + 1 / (lambda period)` is no shorter. The bound must
    /// exceed twice `slack`, a margin far beyond rounding on either side. `(to_switch, period)`
    /// as for `ringing_ends_in` (both infinite without a schedule: never refused here).
    pub(super) fn ringing_outlasts_switches(
        &self,
        land: &Landscape,
        y: &Vector,
        (to_switch, period): (f64, f64),
        slack: f64,
    ) -> bool {
        let t = self.tilt_stiffness;
        let k = land.ring_bar.stiffness_bound() + 2.0 * land.magnetoelastic.abs();
        let rate = 0.5 * self.llg_rate * self.params.gilbert_damping * (k + t);
        if !(k > 0.0 && t > 0.0 && rate > 0.0 && k.is_finite() && rate.is_finite()) {
            return false;
        }
        let memory = 1.0 + 1.0 / (rate * period);
        let gap = y[3].abs() * (t / k).sqrt() * (-rate * to_switch).exp();
        gap * memory > 2.0 * slack
    }
}
