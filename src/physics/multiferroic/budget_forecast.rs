//! A free rotor's ringing Gilbert onion whose resolution is forecast to spend the budget's fine
//! half within its segment: dropped at once, into the minimum that the budget's drop would reach
//! later in the same segment ([`Motor::budget_forecast_drops`]).

use super::{Drive, Motor, StepRun};

/// The spending of one segment, from its first pass (see [`Spending`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct SegmentSpending {
    segment_end: f64,
    spending: Spending,
}

impl SegmentSpending {
    pub(super) const NONE: Self = Self {
        segment_end: f64::NAN,
        spending: Spending::NONE,
    };
}

/// A forecast's record of spending, shared by a free rotor's segments and a locked rotor's
/// steps: the time (s) and budget spent at its start and at the last forecast tried, and the
/// budget spent at which it is tried next.
#[derive(Clone, Copy, Debug)]
pub(super) struct Spending {
    start: (f64, u32),
    last: (f64, u32),
    next_check: u32,
}

impl Spending {
    pub(super) const NONE: Self = Self {
        start: (f64::NAN, 0),
        last: (f64::NAN, 0),
        next_check: 0,
    };

    /// Spending observed from time `t`, the budget spent then.
    pub(super) fn starting(t: f64, spent: u32, budget: u32) -> Self {
        Self {
            start: (t, spent),
            last: (t, spent),
            next_check: spent.saturating_add(budget / FIRST_FORECAST_SHARE),
        }
    }

    pub(super) fn started(&self) -> bool {
        !self.start.0.is_nan()
    }

    /// At a pass at `t` with `spent` of `budget` spent: where a forecast is due, enough has been
    /// observed and the budget's fine half is not yet spent, the time (s) in which the lesser of
    /// the spending's rate since its start and since the last forecast spends that half, with
    /// the forecast's margin ([`FORECAST_MARGIN`]), and the spending at which the half ends.
    pub(super) fn fine_half_horizon(
        &mut self,
        t: f64,
        spent: u32,
        budget: u32,
    ) -> Option<(f64, u32)> {
        if spent < self.next_check {
            return None;
        }
        let used = spent - self.start.1;
        self.next_check = spent.saturating_add(1 + used / 8);
        if used < MIN_OBSERVED {
            return None;
        }
        let (last_t, last_spent) = std::mem::replace(&mut self.last, (t, spent));
        // The fine floor holds while `2 left > budget + 1`: until this spending.
        let fine_end = budget.saturating_sub(1).div_ceil(2);
        if spent >= fine_end {
            return None;
        }
        // The lesser of the two rates: ringing that decays spends less as it goes.
        let rate = (f64::from(used) / (t - self.start.0))
            .min(f64::from(spent - last_spent) / (t - last_t));
        Some((
            FORECAST_MARGIN * f64::from(fine_end - spent) / rate,
            fine_end,
        ))
    }
}

/// The forecast holds only where the spending so far (a segment's, or a locked rotor's step's),
/// kept up, reaches the budget's fine half within `1 / FORECAST_MARGIN` of the time left: the rate
/// may fall by a third over that time (the ringing decaying, its substeps growing) and the half is
/// still reached.
pub(super) const FORECAST_MARGIN: f64 = 1.5;

/// The forecast is first tried once the segment (or step) has spent this fraction of the budget,
/// and then at spending spaced by an eighth of its spending.
const FIRST_FORECAST_SHARE: u32 = 64;

/// The least budget a segment has spent before its rate forecasts anything: 64 Gilbert substeps.
const MIN_OBSERVED: u32 = 64 * super::GILBERT_SUBSTEP_WEIGHT;

impl Motor {
    /// Whether the Gilbert onion of a free rotor at the run's state, which the budget's drop
    /// ([`Motor::follows_branch`]) would put on its branch once the budget's fine half is spent
    /// (its resolved substeps then forced at the even spread of the rest, beyond the
    /// tolerance), may be dropped now, in the segment ending at `segment_end`. The step is then
    /// flagged, as it would be.
    ///
    /// - **Forecast**: at the lesser of the segment's spending rate (budget per second) and its
    ///   rate since the last try, the budget's fine half ([`super::integrator`]'s floor while
    ///   more than half is left) is spent within `1 / FORECAST_MARGIN` of the segment's time
    ///   left, and the ringing persists: every mode of the onion's linearization at its minimum
    ///   decays by at most a factor `e` over that time. This is a forecast, not a bound: ringing
    ///   whose substeps grow much within the segment could still end it resolved.
    /// - **The same minimum**: the ring cannot move the rotor and the ringing is trapped in its
    ///   well for the rest of the segment ([`Motor::decoupled_budget_drop`] over that time, with
    ///   no switch in it): whenever the budget's drop comes within the segment, the onion lies in
    ///   the same well, marches downhill to the same minimum (that of the rotor's angle then,
    ///   which the branch follows from an earlier drop), and the rotor's path differs by at most
    ///   a hundredth of the tolerance.
    ///
    /// The caller then drops as the budget's drop does (where the onion heads for its minimum
    /// within the step, [`Motor::heads_for_settled`]), and not where only the decoupled drop
    /// that follows a forced substep would take it: the forecast also holds on onions ringing
    /// 7e-4 and 1.4 rad wide at 232 and 481 ns periods whose substeps then grow and resolve the
    /// step within the budget, unflagged within 0.15 tolerances, which a drop on the forecast
    /// alone leaves 1e6 to 4e9 tolerances off.
    pub(super) fn budget_forecast_drops(
        &self,
        run: &mut StepRun,
        d: &Drive,
        segment_end: f64,
    ) -> bool {
        if d.locked || self.quasi_static() {
            return false;
        }
        #[cfg(test)]
        if FORECAST_OFF.with(|c| c.get()) {
            return false;
        }
        let budget = self.params.max_substeps;
        let spent = run.attempts.saturating_add(run.extra_cost);
        let s = &mut run.segment_spending;
        if s.segment_end != segment_end {
            *s = SegmentSpending {
                segment_end,
                spending: Spending::starting(run.t, spent, budget),
            };
            return false;
        }
        let Some((horizon, _)) = s.spending.fine_half_horizon(run.t, spent, budget) else {
            return false;
        };
        let left = segment_end - run.t;
        // (False for a NaN.)
        let forecast = horizon <= left;
        if !forecast {
            return false;
        }
        // Every mode of the onion's linearization at its minimum decays by at most a factor `e`
        // over the time left (their rates sum to the trace `g alpha (k + T)`, eq. 3.4 with the
        // LLG damping): the ringing, and the rate at which its substeps spend, persist.
        let (_, k) = self.settled_curvature(&run.settle_memo, &run.y, d);
        let trace = self.llg_rate * self.params.gilbert_damping * (k + self.tilt_stiffness);
        // (False for a NaN.)
        let persists = trace * left <= 1.0;
        let drops =
            persists && self.decoupled_budget_drop(&run.y, d, (left, left), &run.settle_memo);
        #[cfg(test)]
        FIRED.with(|c| c.set(c.get() + u32::from(drops)));
        drops
    }
}

#[cfg(test)]
thread_local! {
    /// Turns the forecast off (tests compare it with the budget's drop it anticipates).
    pub(super) static FORECAST_OFF: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
    /// Forecasts that held on this thread (tests: a forecast that holds does not drop alone).
    pub(super) static FIRED: std::cell::Cell<u32> = const { std::cell::Cell::new(0) };
}
