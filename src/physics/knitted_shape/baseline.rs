//! The dissertation's own one-row-at-a-time gradient exchange (section 1.3.5), the baseline.

// `!(x > y)` is deliberate: it also rejects NaN. Index loops walk several coupled arrays.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]
use super::geometry::ShapeGeometry;
use std::f64::consts::PI;

/// Options of the dissertation's gradient-exchange algorithm.
#[derive(Clone, Copy, Debug, serde::Serialize, serde::Deserialize)]
pub struct SeedAlgorithmOptions {
    /// Length steps from full extension to the end length.
    pub length_steps: usize,
    /// First radius move as a fraction of `S_row / (2 pi)`; halved when a move fails.
    pub initial_move: f64,
    /// Smallest radius move as a fraction of `S_row / (2 pi)`; the exchange stops below it.
    pub min_move: f64,
    /// Spread of `dV/dL` over the free rings, relative, at which the exchange stops.
    pub tolerance: f64,
    /// Cap on exchanges per length step.
    pub max_moves_per_step: usize,
}

impl Default for SeedAlgorithmOptions {
    fn default() -> Self {
        Self {
            length_steps: 80,
            initial_move: 1e-3,
            min_move: 1e-7,
            tolerance: 1e-4,
            max_moves_per_step: 200_000,
        }
    }
}

/// The dissertation's own algorithm (section 1.3.5), the baseline to beat: at each length step raise all
/// rings equally until the strand constraint holds, then repeatedly grow the ring of largest
/// volume gain per length lost (eq. 1.19-1.20 divided) and shrink the one of least gain (not at
/// `r_min`) to restore the length, until the gains are nearly equal. Returns `(L, V)` per step,
/// full extension first. Pocket ties break towards the middle, as in Fig. 1.12.
pub fn seed_gradient_volume_curve(
    geom: &ShapeGeometry,
    end_length: f64,
    options: &SeedAlgorithmOptions,
) -> Result<Vec<(f64, f64)>, String> {
    let l_max = geom.max_length();
    let r_min = geom.min_radius;
    let r_ceiling = geom.radius_ceiling();
    let end = crate::physics::numerics::bounds::limit(end_length, 0.0, l_max);
    let steps = options.length_steps.clamp(1, 100_000);
    let rings = geom.segments + 1;
    let r_ref = geom.row_strand_length / (2.0 * PI);
    let mut radii = vec![r_min; rings];
    let mut dl = vec![0.0; rings];
    let mut dv = vec![0.0; rings];
    let mut out = vec![(l_max, PI * r_min * r_min * l_max)];
    // Interior rings ordered from the middle outward, for tie-breaking.
    let mut order: Vec<usize> = (1..rings - 1).collect();
    let mid = 0.5 * (rings - 1) as f64;
    order.sort_by(|&a, &b| {
        (a as f64 - mid)
            .abs()
            .partial_cmp(&(b as f64 - mid).abs())
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    let length_of = |r: &[f64]| geom.length_and_volume(r).map(|x| x.0);
    for step in 1..=steps {
        let target = l_max - (l_max - end) * step as f64 / steps as f64;
        // Uniform raise of the interior rings by bisection until L = target.
        let base = radii.clone();
        let (mut lo, mut hi) = (0.0, r_ceiling - r_min);
        for _ in 0..200 {
            let mid_raise = 0.5 * (lo + hi);
            let trial: Vec<f64> = base
                .iter()
                .enumerate()
                .map(|(j, &r)| {
                    if j == 0 || j == rings - 1 {
                        r
                    } else {
                        (r + mid_raise).min(r_ceiling)
                    }
                })
                .collect();
            match length_of(&trial) {
                Some(l) if l > target => lo = mid_raise,
                _ => hi = mid_raise,
            }
            if hi - lo < 1e-15 * r_ref {
                break;
            }
        }
        for j in 1..rings - 1 {
            radii[j] = (base[j] + lo).min(r_ceiling);
        }
        let mut mv = options.initial_move * r_ref;
        let mut moves = 0;
        while moves < options.max_moves_per_step && mv > options.min_move * r_ref {
            moves += 1;
            let (_, v0) = geom
                .gradients(&radii, &mut dl, &mut dv)
                .ok_or("seed algorithm: a segment does not close")?;
            let gain = |j: usize| {
                if dl[j] < 0.0 {
                    -dv[j] / dl[j]
                } else {
                    f64::NEG_INFINITY
                }
            };
            let mut best = order[0];
            let mut worst = None::<usize>;
            for &j in &order {
                if gain(j) > gain(best) {
                    best = j;
                }
                if radii[j] > r_min && worst.is_none_or(|w| gain(j) < gain(w)) {
                    worst = Some(j);
                }
            }
            let Some(worst) = worst.filter(|&w| w != best) else {
                // Nothing to shrink yet: the first move only grows the best ring below.
                if radii.iter().skip(1).take(rings - 2).all(|&r| r <= r_min) {
                    break;
                }
                mv *= 0.5;
                continue;
            };
            let spread = gain(best) - gain(worst);
            if spread <= options.tolerance * gain(best).abs().max(f64::MIN_POSITIVE) {
                break;
            }
            let trial_best = (radii[best] + mv).min(r_ceiling);
            let shrink = mv * dl[best] / dl[worst];
            let mut trial = radii.clone();
            trial[best] = trial_best;
            trial[worst] = (radii[worst] - shrink).max(r_min);
            // Restore the length exactly on the shrinking ring (1-D Newton, capped).
            for _ in 0..8 {
                let Some((l, _)) = geom.length_and_volume(&trial) else {
                    break;
                };
                let err = l - target;
                let dlw = geom
                    .segment(trial[worst - 1], trial[worst])
                    .zip(geom.segment(trial[worst], trial[worst + 1]))
                    .map(|(a, b)| a.lb + b.la);
                match dlw {
                    Some(g) if g < 0.0 => {
                        trial[worst] = crate::physics::numerics::bounds::limit(
                            trial[worst] - err / g,
                            r_min,
                            r_ceiling,
                        )
                    }
                    _ => break,
                }
            }
            match geom.length_and_volume(&trial) {
                Some((l, v1)) if v1 > v0 && (l - target).abs() < 1e-9 * l_max => radii = trial,
                _ => mv *= 0.5,
            }
        }
        let (l, v) = geom
            .length_and_volume(&radii)
            .ok_or("seed algorithm: a segment does not close")?;
        out.push((l, v));
    }
    Ok(out)
}
