//! Native cost of `fmi2GetDirectionalDerivative` against a co-simulation step, through the packaged
//! McKibbenMuscle's, KnittedMuscle's and FreeBladder's C ABI, for each bladder and shape model: a
//! step (set(P, L),
//! doStep, get(F)), set(P, L) and one directional derivative dF/dP, and set(P, L) and the two
//! directional derivatives dF/dP and dF/dL (one seed each, a full 1x2 Jacobian row: the second
//! call reuses the first's partials), and set(P, L) and one call for d(F, stiffness)/dP: the
//! stiffness's row is a second derivative of the force, a second-order pass through a bladder.

#[path = "../tests/common/mod.rs"]
mod common;

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use std::time::Duration;

/// One muscle configuration: its label, Integer parameters, and the pressure (Pa) at which the
/// length sweeps `range` (fractions of min_length .. max_length, or lengths in m for a model
/// without them).
struct Case {
    label: &'static str,
    integers: Vec<(usize, i32)>,
    pressure: f64,
    range: (f64, f64),
}

/// The value references a muscle bench needs.
struct Refs {
    model: &'static str,
    pressure: u32,
    length: u32,
    force: u32,
    /// min_length and max_length, for the muscles.
    limits: Option<[u32; 2]>,
    /// The muscles' `stiffness` (dF/dL), whose row is a second derivative.
    stiffness: Option<u32>,
}

fn mckibben() -> (Refs, Vec<Case>) {
    use actuator_fmus::variables::mckibben_muscle::{integer, real};
    let preset = integer::PRESET;
    // Muscle A at 400 kPa, in contact, over the middle of its stroke.
    let case = |label, wall: Vec<(usize, i32)>| Case {
        label,
        integers: wall,
        pressure: 4e5,
        range: (0.5, 0.6),
    };
    (
        Refs {
            model: "McKibbenMuscle",
            pressure: real::PRESSURE as u32,
            length: real::LENGTH as u32,
            force: real::FORCE as u32,
            limits: Some([real::MIN_LENGTH as u32, real::MAX_LENGTH as u32]),
            stiffness: Some(real::STIFFNESS as u32),
        },
        vec![
            case("ideal", vec![(preset, 1)]),
            case("thin wall", vec![(preset, 1), (integer::BLADDER_MODEL, 1)]),
            case(
                "thick wall, 16 layers",
                vec![
                    (preset, 1),
                    (integer::BLADDER_MODEL, 2),
                    (integer::BLADDER_LAYERS, 16),
                ],
            ),
            case(
                "continuum wall, 16 nodes",
                vec![
                    (preset, 1),
                    (integer::BLADDER_MODEL, 3),
                    (integer::BLADDER_LAYERS, 16),
                ],
            ),
        ],
    )
}

fn knitted() -> (Refs, Vec<Case>) {
    use actuator_fmus::variables::knitted_muscle::{integer, real};
    let sleeve = |label, shape: Vec<(usize, i32)>| Case {
        label,
        integers: shape,
        pressure: 5e4,
        range: (0.4, 0.5),
    };
    (
        Refs {
            model: "KnittedMuscle",
            pressure: real::PRESSURE as u32,
            length: real::LENGTH as u32,
            force: real::FORCE as u32,
            limits: Some([real::MIN_LENGTH as u32, real::MAX_LENGTH as u32]),
            stiffness: Some(real::STIFFNESS as u32),
        },
        vec![
            sleeve("ideal", vec![(integer::SHAPE_MODEL, 0)]),
            sleeve("tubular", vec![(integer::SHAPE_MODEL, 1)]),
            sleeve("non-cylindrical table", vec![(integer::SHAPE_MODEL, 2)]),
            Case {
                label: "Fig. 1.16 tubular, thin wall",
                integers: vec![
                    (integer::PRESET, 2),
                    (integer::SHAPE_MODEL, 1),
                    (integer::BLADDER_MODEL, 1),
                ],
                pressure: 5.5e5,
                range: (0.4, 0.5),
            },
        ],
    )
}

fn free_bladder() -> (Refs, Vec<Case>) {
    use actuator_fmus::variables::free_bladder::real;
    (
        Refs {
            model: "FreeBladder",
            pressure: real::PRESSURE as u32,
            length: real::LENGTH as u32,
            force: real::FORCE as u32,
            limits: None,
            stiffness: None,
        },
        // Muscle D's tube at 40 kPa (3/4 of its ballooning pressure), stretched 1.0-1.1 times.
        vec![Case {
            label: "muscle D's tube",
            integers: vec![],
            pressure: 4e4,
            range: (0.1336, 0.147),
        }],
    )
}

fn cost(c: &mut Criterion) {
    for (refs, cases) in [mckibben(), knitted(), free_bladder()] {
        let api = common::Api::load(&common::extract_binary(refs.model));
        let mut group = c.benchmark_group(refs.model);
        let inputs = [refs.pressure, refs.length];
        for case in &cases {
            let inst = api
                .instantiate("bench", &common::guid_of(refs.model))
                .unwrap_or_else(|_| panic!("instantiate"));
            for &(vr, value) in &case.integers {
                unsafe {
                    assert_eq!(
                        (api.fmi2SetInteger)(inst.c, [vr as u32].as_ptr(), 1, [value].as_ptr()),
                        common::OK
                    );
                }
            }
            inst.initialize();
            let mut limits = [0.0, 1.0];
            if let Some(vrs) = refs.limits {
                unsafe {
                    (api.fmi2GetReal)(inst.c, vrs.as_ptr(), 2, limits.as_mut_ptr());
                }
            }
            let span = limits[1] - limits[0];
            let (from, width) = (
                limits[0] + case.range.0 * span,
                (case.range.1 - case.range.0) * span,
            );
            let pressure = case.pressure;
            let (mut t, mut k) = (0.0, 0u32);
            let mut next_length = move || {
                k = k.wrapping_add(1);
                from + width * (k % 1000) as f64 / 1000.0
            };
            let label = case.label;
            let mut out = [0.0];
            group.bench_function(format!("{label}: set(P, L) + doStep + get(F)"), |bench| {
                bench.iter(|| unsafe {
                    let l = next_length();
                    (api.fmi2SetReal)(inst.c, inputs.as_ptr(), 2, [pressure, l].as_ptr());
                    (api.fmi2DoStep)(inst.c, t, 1e-3, 1);
                    t += 1e-3;
                    (api.fmi2GetReal)(inst.c, [refs.force].as_ptr(), 1, out.as_mut_ptr());
                    black_box(out[0])
                })
            });
            let derivative = |seed: [f64; 2], slot: &mut [f64]| unsafe {
                let status = (api.fmi2GetDirectionalDerivative)(
                    inst.c,
                    [refs.force].as_ptr(),
                    1,
                    inputs.as_ptr(),
                    2,
                    seed.as_ptr(),
                    slot.as_mut_ptr(),
                );
                debug_assert_eq!(status, common::OK);
            };
            group.bench_function(
                format!("{label}: set(P, L) + dF/dP (1 directional derivative)"),
                |bench| {
                    bench.iter(|| unsafe {
                        let l = next_length();
                        (api.fmi2SetReal)(inst.c, inputs.as_ptr(), 2, [pressure, l].as_ptr());
                        derivative([1.0, 0.0], &mut out);
                        black_box(out[0])
                    })
                },
            );
            let mut row = [0.0; 2];
            group.bench_function(
                format!("{label}: set(P, L) + dF/dP + dF/dL (2 directional derivatives)"),
                |bench| {
                    bench.iter(|| unsafe {
                        let l = next_length();
                        (api.fmi2SetReal)(inst.c, inputs.as_ptr(), 2, [pressure, l].as_ptr());
                        derivative([1.0, 0.0], &mut row[..1]);
                        derivative([0.0, 1.0], &mut row[1..]);
                        black_box(row)
                    })
                },
            );
            let Some(stiffness) = refs.stiffness else {
                continue;
            };
            group.bench_function(
                format!("{label}: set(P, L) + d(F, stiffness)/dP (1 call, stiffness row)"),
                |bench| {
                    bench.iter(|| unsafe {
                        let l = next_length();
                        (api.fmi2SetReal)(inst.c, inputs.as_ptr(), 2, [pressure, l].as_ptr());
                        let status = (api.fmi2GetDirectionalDerivative)(
                            inst.c,
                            [refs.force, stiffness].as_ptr(),
                            2,
                            inputs.as_ptr(),
                            2,
                            [1.0, 0.0].as_ptr(),
                            row.as_mut_ptr(),
                        );
                        debug_assert_eq!(status, common::OK);
                        black_box(row)
                    })
                },
            );
        }
        group.finish();
    }
}

fn config() -> Criterion {
    Criterion::default()
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
        .sample_size(30)
}

criterion_group! { name = benches; config = config(); targets = cost }
criterion_main!(benches);
