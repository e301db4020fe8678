//! A trace of [`Motor::step`](super::Motor::step)'s passes, for tests that compare each path's
//! piece of a step with an RK4.

use super::step::StepRun;
use super::Vector;

/// A pass's record: its path's labels, start time and state, end time and state, and whether
/// the step was flagged by its end.
pub(super) type PassRecord = (String, f64, Vector, f64, Vector, bool);

thread_local! {
    /// Each pass of the steps taken while set (tests read it).
    pub(super) static PASS_TRACE: std::cell::RefCell<Option<Vec<PassRecord>>> =
        const { std::cell::RefCell::new(None) };
    static PENDING: std::cell::RefCell<Option<(String, f64, Vector)>> =
        const { std::cell::RefCell::new(None) };
}

pub(super) fn trace_label(label: &str) {
    PENDING.with(|p| {
        if let Some(p) = p.borrow_mut().as_mut() {
            p.0 += label;
            p.0 += " ";
        }
    });
}

pub(super) fn trace_pass(run: &StepRun, _: &str) {
    if PASS_TRACE.with(|t| t.borrow().is_none()) {
        return;
    }
    if let Some((label, t0, y0)) = PENDING.with(|p| p.borrow_mut().take()) {
        PASS_TRACE.with(|t| {
            if let Some(v) = t.borrow_mut().as_mut() {
                v.push((label, t0, y0, run.t, run.y, run.limited));
            }
        });
    }
    if run.t < run.t_end {
        PENDING.with(|p| *p.borrow_mut() = Some((String::new(), run.t, run.y)));
    }
}
