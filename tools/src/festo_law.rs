//! The Festo DMSP scaling law (`actuator_fmus::physics::festo`) against the datasheets: each fit's
//! accuracy, and leave-one-out, the law derived from one size's fit alone predicting the other
//! size's curves from its catalogue numbers (the error to expect for a size without curves).

use crate::calibration::{curves, errors, CurveError, Datum};
use actuator_fmus::physics::festo::{
    Catalogue, ScalingLaw, DMSP_10, DMSP_40, FIT_DMSP_10, FIT_DMSP_40,
};
use actuator_fmus::physics::muscle_params::MuscleParams;

/// The datasheets (`data/festo/`).
pub const DMSP_10_CSV: &str = include_str!("../../data/festo/festo_dmsp10.csv");
pub const DMSP_40_CSV: &str = include_str!("../../data/festo/festo_dmsp40.csv");

/// Parses a datasheet CSV (`pressure_kpa,contraction,force_n`, `#` comments) already known to be
/// well formed (the shipped ones).
pub fn datasheet(text: &str) -> Vec<Datum> {
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("pressure") && !l.trim().is_empty())
        .filter_map(|l| {
            let v: Vec<f64> = l.split(',').filter_map(|s| s.trim().parse().ok()).collect();
            (v.len() == 3).then(|| Datum {
                pressure: v[0] * 1e3,
                contraction: v[1],
                force: v[2],
            })
        })
        .collect()
}

/// One prediction of a size's curves: the size, the law's muscle and its errors per pressure.
#[derive(Clone, Debug)]
pub struct Prediction {
    pub size: Catalogue,
    /// The size whose fit alone the law was derived from (`None`: both fits).
    pub from: Option<Catalogue>,
    pub params: MuscleParams,
    pub errors: Vec<CurveError>,
}

impl Prediction {
    /// The largest RMS error over the pressures, fraction of each curve's largest force.
    pub fn worst_rms(&self) -> f64 {
        self.errors.iter().map(|e| e.rms).fold(0.0, f64::max)
    }
}

fn predict(law: &ScalingLaw, size: Catalogue, from: Option<Catalogue>, text: &str) -> Prediction {
    let params = law
        .params(&size)
        .unwrap_or_else(|e| panic!("the law describes {}: {e}", size.name));
    Prediction {
        size,
        from,
        params,
        errors: errors(&params, &curves(&datasheet(text))),
    }
}

/// The law from both fits at DMSP-10 and DMSP-40 (their fits given back), then leave-one-out:
/// DMSP-10 from the DMSP-40 fit alone and DMSP-40 from the DMSP-10 fit alone.
pub fn predictions() -> Vec<Prediction> {
    let both = ScalingLaw::festo();
    let only = |c: Catalogue, p: MuscleParams| {
        ScalingLaw::derive(&[(c, p)]).unwrap_or_else(|_| unreachable!("one fit"))
    };
    vec![
        predict(&both, DMSP_10, None, DMSP_10_CSV),
        predict(&both, DMSP_40, None, DMSP_40_CSV),
        predict(
            &only(DMSP_40, FIT_DMSP_40),
            DMSP_10,
            Some(DMSP_40),
            DMSP_10_CSV,
        ),
        predict(
            &only(DMSP_10, FIT_DMSP_10),
            DMSP_40,
            Some(DMSP_10),
            DMSP_40_CSV,
        ),
    ]
}

/// Leave-one-out's largest RMS error over the pressures, as the docs state it: DMSP-10 from the
/// DMSP-40 fit alone, and DMSP-40 from the DMSP-10 fit alone (fractions of each curve's largest
/// force).
pub const LEAVE_ONE_OUT_WORST_RMS: [f64; 2] = [0.305, 0.204];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_law_from_both_fits_matches_both_datasheets_within_two_percent_rms() {
        let all = predictions();
        for p in &all[..2] {
            assert!(p.errors.len() >= 8);
            for e in &p.errors {
                assert!(e.infeasible == 0 && e.rms < 0.02, "{}: {e:?}", p.size.name);
            }
        }
    }

    /// Leave-one-out stays what the docs and the README state (to half a percentage point), and
    /// every curve of the other size is still predicted (no point outside the muscle's range).
    #[test]
    fn leave_one_out_errors_are_the_ones_the_docs_state() {
        let all = predictions();
        for (p, stated) in all[2..].iter().zip(LEAVE_ONE_OUT_WORST_RMS) {
            assert!(p.errors.iter().all(|e| e.infeasible == 0), "{p:?}");
            let worst = p.worst_rms();
            assert!(
                (worst - stated).abs() < 0.005,
                "{}: {worst} vs {stated}",
                p.size.name
            );
        }
        let docs = include_str!("../../docs/calibration.md");
        let readme = include_str!("../../README.md");
        for stated in LEAVE_ONE_OUT_WORST_RMS {
            let text = format!("{:.1}%", 100.0 * stated);
            assert!(
                docs.contains(&text) && readme.contains(&text),
                "{text} not stated"
            );
        }
    }

    /// A number the law does not use: its DMSP-20 at 600 kPa and the nominal length pulls 1587 N,
    /// within 6% of the catalogue's 1500 N.
    #[test]
    fn the_dmsp_20_pulls_near_its_catalogue_force() {
        use actuator_fmus::physics::festo::{preset, DMSP_20};
        use actuator_fmus::physics::friction::HysteresisState;
        let (p, c) = preset(8).unwrap();
        assert_eq!(c, DMSP_20);
        let l = p.nominal_length;
        let f = p
            .muscle()
            .unwrap()
            .evaluate(6e5, l, &HysteresisState::at_rest(l))
            .unwrap()
            .force;
        assert!((f / c.max_force - 1.0).abs() < 0.06, "{f} N");
        assert!((f - 1586.65).abs() < 0.1, "{f} N");
    }
}
