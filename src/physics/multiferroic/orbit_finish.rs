//! The rest of a locked rotor's segment after the orbit-averaged advance
//! ([`Motor::finish_locked_orbits`]): less than an orbit of the Gilbert onion's ringing,
//! resolved by classical RK4 with its error measured by step doubling.

use super::orbit::point;
use super::{Drive, Motor, Vector};
use crate::physics::numerics::rk4::rk4_step;

/// The most RK4 steps the finish takes, over all its tries (one budget unit each).
pub(super) const MAX_FINISH_STEPS: u32 = 1536;
/// RK4 steps per orbit of the first try.
const FIRST_STEPS_PER_ORBIT: f64 = 32.0;

impl Motor {
    /// The Gilbert onion under a locked rotor (drive `d`) from `y` over the `left` time (s) to
    /// its segment's end, orbits of `period` (s): classical RK4 of eq. 3.3 and 3.4 on `n` and
    /// on `2 n` equal steps, `n` doubled until the two agree within 0.15 of the tolerance in the
    /// onion's angle and tilt (RK4's error falls 16-fold as its steps halve: the finer result
    /// is then within about a hundredth of the tolerance), at most `cap` steps in all. The
    /// finer result, if found, and the RK4 steps taken either way. (The resolved substeps that end
    /// the segment otherwise are each held to the tolerance on their own, and several of them add
    /// up beyond it.)
    pub(super) fn finish_locked_orbits(
        &self,
        y: &Vector,
        d: &Drive,
        left: f64,
        period: f64,
        cap: u32,
    ) -> (Option<Vector>, u32) {
        if !(d.locked && left > 0.0 && period > 0.0 && left.is_finite()) {
            return (None, 0);
        }
        let tol = self.params.tolerance;
        // The rotor is locked: the onion's angle and tilt alone, in the frozen landscape.
        let land = self.landscape(y[0], d.direction, d.stress);
        let rate = |z: &[f64; 2]| self.onion_rate(point(&land, z[0]).1, z[1]);
        let run = |n: u32| {
            let h = left / f64::from(n);
            let mut z = [y[2], y[3]];
            for _ in 0..n {
                z = rk4_step(&rate, &z, h);
            }
            [y[0], 0.0, z[0], z[1]]
        };
        // At least two steps (the first try's coarse result is one step of its fine one's two).
        let mut n = (FIRST_STEPS_PER_ORBIT * left / period)
            .ceil()
            .clamp(2.0, 1e6) as u32;
        let mut spent = n;
        if spent > cap {
            return (None, 0);
        }
        let mut coarse = run(n);
        loop {
            n *= 2;
            spent += n;
            if spent > cap {
                return (None, spent - n);
            }
            let fine = run(n);
            let agree = (fine[2] - coarse[2]).abs() <= 0.15 * tol
                && (fine[3] - coarse[3]).abs() <= 0.15 * tol;
            if !fine.iter().all(|v| v.is_finite()) {
                return (None, spent);
            }
            if agree {
                return (Some(fine), spent);
            }
            coarse = fine;
        }
    }
}
