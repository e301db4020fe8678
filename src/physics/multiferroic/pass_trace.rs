//! A trace of [`Motor::step`](super::Motor::step)'s passes, for tests that compare each path's
//! piece of a step with an RK4. Outside tests its calls do nothing.

use super::Vector;

/// A pass's record: its path's labels, start time and state, end time and state, and whether
/// the step was flagged by its end.
#[cfg(test)]
pub(super) type PassRecord = (String, f64, Vector, f64, Vector, bool);

#[cfg(test)]
thread_local! {
    /// Each pass of the steps taken while set (tests read it).
    pub(super) static PASS_TRACE: std::cell::RefCell<Option<Vec<PassRecord>>> =
        const { std::cell::RefCell::new(None) };
    static PENDING: std::cell::RefCell<Option<(String, f64, Vector)>> =
        const { std::cell::RefCell::new(None) };
}

/// Adds `label` (the path or solver that took the pass) to the pending pass's labels.
pub(super) fn trace_label(label: &str) {
    #[cfg(test)]
    PENDING.with(|p| {
        if let Some(p) = p.borrow_mut().as_mut() {
            p.0 += label;
            p.0 += " ";
        }
    });
    #[cfg(not(test))]
    let _ = label;
}

/// Adds a substep's error estimate (in tolerances) to the pending pass's labels.
pub(super) fn trace_error(err: f64) {
    #[cfg(test)]
    trace_label(&format!("err {err:.3}"));
    #[cfg(not(test))]
    let _ = err;
}

/// Closes the pending pass at time `t` and state `y` (`limited`: the step flagged so far) and,
/// before the step's end `t_end`, opens the next.
pub(super) fn trace_pass(t: f64, y: Vector, limited: bool, t_end: f64) {
    #[cfg(test)]
    {
        if PASS_TRACE.with(|trace| trace.borrow().is_none()) {
            return;
        }
        if let Some((label, t0, y0)) = PENDING.with(|p| p.borrow_mut().take()) {
            PASS_TRACE.with(|trace| {
                if let Some(v) = trace.borrow_mut().as_mut() {
                    v.push((label, t0, y0, t, y, limited));
                }
            });
        }
        if t < t_end {
            PENDING.with(|p| *p.borrow_mut() = Some((String::new(), t, y)));
        }
    }
    #[cfg(not(test))]
    let _ = (t, y, limited, t_end);
}
