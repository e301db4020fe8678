//! The budget's charge for the Gilbert onion's linear spans ([`Motor::advance_onion_linear`]):
//! every switch chained is paid for, and `max_substeps` bounds how many the spans chain.

use super::onion_linear::{CHAINED, CHARGED, SWITCHES_PER_UNIT};
use super::onion_periods_tests::{case, values};
use super::switch_count_tests::MANY_SWITCHES;

/// [`MANY_SWITCHES`] with `max_substeps` replaced, stepped once by `h`: the step's result and
/// the switch intervals the spans chained and the units charged for them.
fn spans_of_one_step(max_substeps: f64, h: f64) -> (Result<super::StepReport, String>, u64, u64) {
    let mut kv = values(MANY_SWITCHES);
    kv.insert("max_substeps".into(), max_substeps);
    let (m, mut st, inputs) = case(&kv).unwrap();
    CHAINED.with(|c| c.set(0));
    CHARGED.with(|c| c.set(0));
    let report = m.step(&mut st, &inputs, h);
    (report, CHAINED.with(|c| c.get()), CHARGED.with(|c| c.get()))
}

/// A 1 us step of 945 switches with an ample budget: the spans chain all but the first, each
/// evaluation of a switch's flow charged (at least one unit per two), within the budget.
#[test]
fn linear_spans_charge_every_switch_they_chain() {
    let (report, chained, charged) = spans_of_one_step(20_000.0, 1e-6);
    println!("{report:?}: {chained} switches chained, {charged} units charged");
    assert!(report.is_ok() && chained >= 940, "{report:?} {chained}");
    let per_unit = SWITCHES_PER_UNIT as u64;
    assert!(charged * per_unit >= chained, "{charged} {chained}");
    // Rounded up once per try at most: a span's tries are few.
    assert!(charged <= chained / per_unit + 64, "{charged} {chained}");
}

/// A 10 us step of 9,450 switches with max_substeps 600: the spans chain no more switches than
/// the budget pays for, and the step is refused then, saying to raise max_substeps or shorten
/// the step; uncharged, they crossed all 9,450 whatever the budget.
#[test]
fn the_budget_bounds_the_switches_the_spans_chain() {
    let (report, chained, charged) = spans_of_one_step(600.0, 1e-5);
    println!("{report:?}: {chained} switches chained, {charged} units charged");
    let e = report.unwrap_err();
    assert!(e.contains("max_substeps = 600"), "{e}");
    assert!(charged <= 600, "{charged}");
    assert!(chained <= 600 * SWITCHES_PER_UNIT as u64, "{chained}");
}
