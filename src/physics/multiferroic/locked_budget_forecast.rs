//! A locked rotor's ringing Gilbert onion, trapped in its well, whose resolution is forecast to
//! spend the budget's fine half before a step without switches ends: dropped at once into the
//! minimum that the budget's drop would reach later in the step
//! ([`Motor::locked_budget_forecast_drops`]).

use super::budget_forecast::{Spending, FORECAST_MARGIN};
use super::orbit::point;
use super::{Drive, Motor, StepRun};
use std::f64::consts::PI;

/// The floor's substep after the fine half, over the substep the error control proposes, beyond
/// which the forced substeps are taken to land beyond the tolerance.
const FORCED_RATIO: f64 = 4.0;

/// The onion's energy above its minimum at most this fraction of its well's lowest rim: trapped
/// away from the rims' knife edge.
const RIM_MARGIN: f64 = 0.999;

/// The least loss of energy per orbit of the onion's linearization at its minimum: beyond it
/// the orbit-averaged paths refuse at every energy (twice `orbit_advance.rs`'s small parameter,
/// and `locked_ringing.rs`'s).
const MIN_LOSS_PER_ORBIT: f64 = 0.1;

/// A locked rotor's step spending (see [`Motor::locked_budget_forecast_drops`]), and the budget
/// spent below which the averaged paths' refusal over the horizon is not tried again (see
/// [`Motor::averaging_refused_over`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct LockedSpending {
    spending: Spending,
    refusal_retry: u32,
}

impl LockedSpending {
    pub(super) const NONE: Self = Self {
        spending: Spending::NONE,
        refusal_retry: 0,
    };
}

#[cfg(test)]
thread_local! {
    /// Turns the forecast off (tests compare it with the budget's drop it anticipates).
    pub(super) static LOCKED_FORECAST_OFF: std::cell::Cell<bool> =
        const { std::cell::Cell::new(false) };
}

impl Motor {
    /// Whether a locked rotor's Gilbert onion at the run's state, which the budget's drop
    /// ([`Motor::locked_budget_drop`]) would put into the minimum it rings about once the
    /// budget's fine half is spent, may be put there now. The step is then flagged, as it would
    /// be.
    ///
    /// - **No switch in the step**: the landscape of eq. 3.4 stays frozen to the step's end and
    ///   the budget's drop, whenever it comes, drops the onion whatever its ringing.
    /// - **Forecast**: at the lesser of the step's spending rate (budget per second) and its rate
    ///   since the last try, the budget's fine half is spent within `1 / FORECAST_MARGIN` of the
    ///   step's time left, and the ringing persists over that horizon: every mode of the onion's
    ///   linearization at its minimum decays by at most a factor `e` over it (their rates sum to
    ///   the trace `g alpha (k + T)`). This is a forecast, not a bound, as for a free rotor
    ///   (`budget_forecast.rs`): ringing whose substeps grow much within the horizon could still
    ///   end the step resolved.
    /// - **The same minimum**: the onion lies between its well's rims with its energy
    ///   `U(psi) - U(psi*) + T theta^2 / 2` at most [`RIM_MARGIN`] of the lowest rim's height
    ///   above the minimum `psi*`. With the rotor locked and the landscape frozen, Gilbert damping
    ///   only lowers that energy (`dE/dt = -g alpha (U'^2 + T^2 theta^2)`), so the onion stays in
    ///   the well to the step's end, and the budget's drop marches it downhill to the same
    ///   minimum from wherever it then is.
    /// - **Left to that drop**: the linearization loses more than [`MIN_LOSS_PER_ORBIT`] of its
    ///   energy an orbit (the averaged advance and the averaged decay time refuse at every
    ///   energy), or both provably refuse the onion at every instant of the horizon
    ///   ([`Motor::averaging_refused_over`]), the linear ringing's wait outlasts the horizon, the
    ///   relaxed onion's check does not end the ringing now, and the substeps forced after the
    ///   fine half are at least [`FORCED_RATIO`] times the one the error control proposes.
    pub(super) fn locked_budget_forecast_drops(&self, run: &mut StepRun, d: &Drive) -> bool {
        if !d.locked || self.quasi_static() {
            return false;
        }
        #[cfg(test)]
        if LOCKED_FORECAST_OFF.with(|c| c.get()) {
            return false;
        }
        let switches = run
            .schedule
            .is_some_and(|s| s.step_index(run.t_end) > s.step_index(run.start));
        if switches {
            return false;
        }
        let budget = self.params.max_substeps;
        let spent = run.attempts.saturating_add(run.extra_cost);
        let s = &mut run.locked_spending;
        if !s.spending.started() {
            *s = LockedSpending {
                spending: Spending::starting(run.t, spent, budget),
                refusal_retry: 0,
            };
            return false;
        }
        let Some((horizon, fine_end)) = s.spending.fine_half_horizon(run.t, spent, budget) else {
            return false;
        };
        // (False for a NaN.)
        let spends = horizon <= run.t_end - run.t;
        if !spends {
            return false;
        }
        // Once the fine half is spent, the substeps' floor is the even spread of the budget left
        // over the step's time left ([`Motor::substep`]): forced there, at least
        // [`FORCED_RATIO`] times the substep the error control now proposes, they land beyond
        // the tolerance (their error grows at least as the ratio's cube) and flag the step,
        // whose next pass drops the onion.
        let forced = (run.t_end - run.t - horizon / FORECAST_MARGIN) / f64::from(budget - fine_end);
        // (False for a NaN.)
        let beyond = forced >= FORCED_RATIO * run.dt;
        if !beyond {
            return false;
        }
        let (settled, k) = self.settled_curvature(&run.settle_memo, &run.y, d);
        let t = self.tilt_stiffness;
        let trace = self.llg_rate * self.params.gilbert_damping * (k + t);
        // (False for a NaN.)
        let persists = trace * horizon <= 1.0;
        if !persists {
            return false;
        }
        // The linearization's loss per orbit, `trace` times its period: beyond twice the
        // averaging's small parameter neither the averaged advance nor the averaged decay time
        // is tried, whatever the onion's energy. Below it, both must refuse the onion
        // throughout the horizon: that check, with its search for the well's rims, is tried
        // again only once the step's spending has doubled since it failed.
        let loss = 2.0 * PI * trace / (self.llg_rate * (k * t).sqrt());
        let lossy = loss > MIN_LOSS_PER_ORBIT;
        if !lossy && spent < run.locked_spending.refusal_retry {
            return false;
        }
        let y = &run.y;
        let land = self.landscape(y[0], d.direction, d.stress);
        let remaining = run.t_end - run.t;
        let well = self.well_of_minimum(&land, settled.onion);
        let trapped = well.as_ref().and_then(|well| {
            let energy = point(&land, y[2]).0 - well.floor + 0.5 * t * y[3] * y[3];
            (well.below < y[2]
                && y[2] < well.above
                && (well.minimum - settled.onion).abs() <= 1e-9 * (1.0 + settled.onion.abs())
                && energy <= RIM_MARGIN * well.barrier)
                .then_some(energy)
        });
        let refused = |well: &super::orbit::Well, energy: f64| {
            lossy || self.averaging_refused_over(&land, well, k, energy, remaining, horizon)
        };
        // (False for a NaN.)
        let left = match (well, trapped) {
            (Some(well), Some(energy)) => refused(&well, energy),
            _ => false,
        };
        if !left {
            if !lossy {
                run.locked_spending.refusal_retry = spent.saturating_mul(2);
            }
            return false;
        }
        // Nor does the linear ringing's propagator take the onion within the horizon: its wait,
        // at the fastest decay the ringing can have, outlasts it.
        match self.linear_ringing_end(&run.y, d, remaining) {
            Err(wait) if wait >= horizon => {}
            _ => return false,
        }
        // Not where the relaxed onion's check would end the ringing now, unflagged.
        !self.locked_ringing_ends(&run.y, d, settled.onion, remaining)
    }
}
