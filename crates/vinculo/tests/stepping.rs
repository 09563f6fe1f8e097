//! The stepping API: a run advanced in pieces, snapshotted and restored, is the run made in one
//! call, bit for bit (the reference is `simulate` itself: the same steps must give the same
//! floating-point numbers).

use vinculo::integrators::{Formulation, JacobianReuse, NewtonOptions, Scheme};
use vinculo::laws::{DrivenLaw, Law, VectorLaw};
use vinculo::model::System;
use vinculo::{simulate, AdaptiveOptions, Simulation, SimulationOptions, Solution, StepControl};

/// A swinging chain of 8 links from a fixed anchor, with a spring-damper across two links and
/// drag (forces and constraints of several kinds).
fn chain() -> System {
    let mut s = System::new([0.0, 0.0, -9.81]);
    let mut prev = s.add_particle(1.0, [0.0; 3], [0.0; 3], true).unwrap();
    let mut ids = vec![prev];
    for i in 1..=8 {
        let p = s
            .add_particle(0.1, [0.1 * i as f64, 0.0, 0.0], [0.0, 0.1, 0.0], false)
            .unwrap();
        s.add_distance(prev, p, None).unwrap();
        ids.push(p);
        prev = p;
    }
    s.add_spring_damper(ids[2], ids[4], 5.0, 0.1, None).unwrap();
    s.add_quadratic_drag(ids[8], 0.05).unwrap();
    s
}

/// Asserts that two runs stored the same states, bit for bit.
fn assert_same_run(a: &Solution, b: &Solution, what: &str) {
    assert_eq!(
        a.times.len(),
        b.times.len(),
        "{what}: number of stored states"
    );
    let pairs = [
        (&a.times, &b.times, "times"),
        (&a.positions, &b.positions, "positions"),
        (&a.velocities, &b.velocities, "velocities"),
        (&a.multipliers, &b.multipliers, "multipliers"),
    ];
    for (x, y, name) in pairs {
        assert_eq!(x.len(), y.len(), "{what}: {name}");
        for (k, (u, v)) in x.iter().zip(y.iter()).enumerate() {
            assert_eq!(u.to_bits(), v.to_bits(), "{what}: {name}[{k}]: {u} vs {v}");
        }
    }
    assert_eq!(
        a.accepted_step_sizes, b.accepted_step_sizes,
        "{what}: steps"
    );
    assert_eq!(a.status, b.status, "{what}: status");
}

/// The options of a run to t = 0.25 with steps of 0.01 (the first step with error control, at
/// the default tolerances).
fn run_to_025(scheme: Scheme, formulation: Formulation, adaptive: bool) -> SimulationOptions {
    SimulationOptions {
        t_end: 0.25,
        dt: 1e-2,
        scheme,
        formulation,
        step_control: if adaptive {
            StepControl::Adaptive(AdaptiveOptions::default())
        } else {
            StepControl::Fixed
        },
        ..Default::default()
    }
}

/// Stepping to t1 = 0.1, taking a snapshot, on to t2 = 0.25, restoring and stepping to t2 again
/// gives the stored states of one `simulate` to t2 (and of the stepped run before the restore),
/// bit for bit, with each time rule on both formulations, with fixed and error-controlled steps
/// (backward Euler with fixed steps only: with error control it gives up on this chain, as it
/// did before the stepping API), with Newton's default and with modified Newton (both keep an
/// iteration matrix across steps, which the snapshot holds).
#[test]
fn restored_run_is_the_uninterrupted_run_bit_for_bit() {
    let system = chain();
    let schemes = [
        Scheme::GeneralizedTrapezoidal { alpha: 0.5 },
        Scheme::GeneralizedTrapezoidal { alpha: 1.0 },
        Scheme::GeneralizedAlpha { rho_inf: 0.8 },
    ];
    for scheme in schemes {
        for formulation in [Formulation::Index3, Formulation::Ggl] {
            for adaptive in [false, true] {
                if adaptive && scheme == (Scheme::GeneralizedTrapezoidal { alpha: 1.0 }) {
                    continue; // gives up on this chain (StepSizeTooSmall at t = 0.159)
                }
                for reuse in [JacobianReuse::WhileFast, JacobianReuse::Always] {
                    let options = SimulationOptions {
                        newton: NewtonOptions {
                            jacobian_reuse: reuse,
                            ..Default::default()
                        },
                        ..run_to_025(scheme, formulation, adaptive)
                    };
                    let what = format!("{scheme:?} {formulation:?} adaptive {adaptive} {reuse:?}");
                    let mut run = Simulation::new(&system, &options).unwrap();
                    run.step_to(0.1).clone().unwrap();
                    // Fixed steps land on the grid time 0.1; error-controlled ones stop after it.
                    if adaptive {
                        assert!(run.time() >= 0.1, "{what}: stopped at {}", run.time());
                    } else {
                        assert!(
                            (run.time() - 0.1).abs() < 1e-12,
                            "{what}: stopped at {}",
                            run.time()
                        );
                    }
                    let snapshot = run.snapshot();
                    run.step_to(0.25);
                    let first = run.solution().clone();
                    run.restore(&snapshot);
                    assert_eq!(run.time(), snapshot.time());
                    run.step_to(0.25);
                    assert_same_run(&first, run.solution(), &format!("{what}, restored"));
                    let one_call = simulate(&system, &options).unwrap();
                    assert_same_run(&one_call, run.solution(), &format!("{what}, one call"));
                }
            }
        }
    }
}

/// A pendulum (1 m string, 1 kg) hung from an anchor moved along x by `anchor_x`, with the
/// bob started at rest below it.
fn pendulum_on(anchor_x: Law) -> System {
    let mut s = System::new([0.0, 0.0, -9.81]);
    let p = s
        .add_particle(1.0, [0.0, 0.0, -1.0], [0.0; 3], false)
        .unwrap();
    let anchor = VectorLaw([anchor_x, Law::Constant(0.0), Law::Constant(0.0)]);
    s.add_distance_to_point(p, anchor, None).unwrap();
    s
}

/// An anchor driven through the stepping API (its position set before each step_to) moves the
/// pendulum exactly as the same motion given as a law, a piecewise-linear table through the same
/// points: the stored states agree bit for bit. Times are multiples of dt = 1/64 s, exact in
/// binary, so the steps end exactly at the knots.
#[test]
fn driven_point_is_the_same_motion_given_as_a_law() {
    let dt = 1.0 / 64.0;
    let times: Vec<f64> = (0..=32).map(|k| k as f64 * dt).collect();
    let x: Vec<f64> = times
        .iter()
        .map(|t| 0.05 * (2.0 * std::f64::consts::PI * t).sin())
        .collect();
    let options = SimulationOptions {
        t_end: times[32],
        dt,
        ..Default::default()
    };
    let driven = DrivenLaw::new(times[0], x[0]).unwrap();
    let system = pendulum_on(Law::Driven(driven.clone()));
    let mut run = Simulation::new(&system, &options).unwrap();
    for k in 1..times.len() {
        driven.set(times[k], x[k]).unwrap();
        run.step_to(times[k]).clone().unwrap();
        assert_eq!(run.time(), times[k]);
    }
    let table = Law::piecewise_linear(times.clone(), x.clone()).unwrap();
    let as_law = simulate(&pendulum_on(table), &options).unwrap();
    assert!(as_law.status.is_ok());
    assert_same_run(&as_law, run.solution(), "driven anchor");
    // The anchor really moved the bob (5 cm of anchor motion, a swing of centimetres).
    let last = as_law.len() - 1;
    assert!(as_law.position(last, 0)[0].abs() > 1e-3);
}

/// The stored states at and after `t` (rows of `times >= t`), as (times, positions, velocities,
/// multipliers).
fn rows_from(s: &Solution, t: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
    let k = s.times.iter().position(|&x| x >= t).unwrap();
    let (n, m) = (s.particles, s.constraints);
    (
        s.times[k..].to_vec(),
        s.positions[k * n * 3..].to_vec(),
        s.velocities[k * n * 3..].to_vec(),
        s.multipliers[k * m..].to_vec(),
    )
}

/// A snapshot saved to a file at t1 (0.1 with fixed steps; with error control, the end of the
/// step that passes 0.1, the file then holding the error control's state), loaded and restored
/// into a new simulation of the same model and stepped to t2 = 0.25 gives the states
/// (positions, velocities, multipliers) and accepted step sizes of one `simulate` to t2 from t1
/// on, bit for bit (the reference: `simulate` itself), with each time rule on both formulations,
/// with fixed and error-controlled steps; the loaded snapshot is the saved one bit for bit
/// (saved again, the same bytes).
#[test]
fn snapshot_file_continues_the_run_bit_for_bit() {
    let system = chain();
    let dir = unique_dir("snapshot");
    let schemes = [
        Scheme::GeneralizedTrapezoidal { alpha: 0.5 },
        Scheme::GeneralizedAlpha { rho_inf: 0.8 },
    ];
    for scheme in schemes {
        for formulation in [Formulation::Index3, Formulation::Ggl] {
            for adaptive in [false, true] {
                let options = run_to_025(scheme, formulation, adaptive);
                let what = format!("{scheme:?} {formulation:?} adaptive {adaptive}");
                let path = dir.join(format!("{scheme:?}-{formulation:?}-{adaptive}.snap"));
                let mut run = Simulation::new(&system, &options).unwrap();
                run.step_to(0.1).clone().unwrap();
                let before = run.solution().accepted_step_sizes.clone();
                assert!(before.len() > 3, "{what}: {} steps to t1", before.len());
                run.snapshot().save(&path).unwrap();
                let loaded = vinculo::Snapshot::load(&path).unwrap();
                let again = dir.join("again.snap");
                loaded.save(&again).unwrap();
                assert_eq!(
                    std::fs::read(&path).unwrap(),
                    std::fs::read(&again).unwrap(),
                    "{what}: saved again"
                );
                let mut fresh = Simulation::new(&system, &options).unwrap();
                fresh.try_restore(&loaded).unwrap();
                assert_eq!(fresh.time().to_bits(), run.time().to_bits(), "{what}");
                fresh.step_to(0.25).clone().unwrap();
                let one_call = simulate(&system, &options).unwrap();
                let continued = rows_from(fresh.solution(), run.time());
                assert!(continued.0.len() > 3, "{what}: {} rows", continued.0.len());
                assert_eq!(
                    continued,
                    rows_from(&one_call, run.time()),
                    "{what}: continued from the file"
                );
                let steps = [before, fresh.solution().accepted_step_sizes.clone()].concat();
                let bits = |x: &[f64]| x.iter().map(|h| h.to_bits()).collect::<Vec<u64>>();
                assert_eq!(
                    bits(&steps),
                    bits(&one_call.accepted_step_sizes),
                    "{what}: accepted step sizes"
                );
            }
        }
    }
    // A corrupt file (one byte flipped), a file of another kind and a snapshot of another
    // model are refused with the snapshot error.
    let path = dir.join("corrupt.snap");
    let mut run = Simulation::new(&system, &SimulationOptions::default()).unwrap();
    run.step_to(0.05);
    run.snapshot().save(&path).unwrap();
    let mut bytes = std::fs::read(&path).unwrap();
    bytes[40] ^= 1;
    std::fs::write(&path, &bytes).unwrap();
    let err = vinculo::Snapshot::load(&path).unwrap_err();
    assert!(err.to_string().contains("checksum"), "{err}");
    std::fs::write(&path, b"not a snapshot").unwrap();
    let err = vinculo::Snapshot::load(&path).unwrap_err();
    assert!(err.to_string().contains("VNCLSNAP"), "{err}");
    let other = pendulum_on(Law::Constant(0.0));
    let mut foreign = Simulation::new(&other, &SimulationOptions::default()).unwrap();
    let err = foreign.try_restore(&run.snapshot()).unwrap_err();
    assert!(err.to_string().contains("another system"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A new directory under the system's temporary directory, named after `what`, this process
/// and the time (tests running at once do not share it).
fn unique_dir(what: &str) -> std::path::PathBuf {
    let now = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap()
        .as_nanos();
    let dir = std::env::temp_dir().join(format!("vinculo-{what}-{}-{now}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// 64-bit FNV-1a (the snapshot file's checksum, as published by Fowler, Noll and Vo), to write
/// files that pass the checksum but not the decoder.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0100_0000_01b3)
    })
}

/// `body` (a snapshot file without its checksum) with its checksum appended.
fn with_checksum(mut body: Vec<u8>) -> Vec<u8> {
    let sum = fnv1a(&body);
    body.extend_from_slice(&sum.to_le_bytes());
    body
}

/// A version 6 file of an error-controlled run that is truncated, or whose error-control part
/// is cut short or carries an unknown time rule under a valid checksum, or that claims to be of
/// version 1 (which has fixed steps only) or 2 (whose error control kept an acceleration
/// history), is refused with the snapshot error, and so is the
/// snapshot restored into a fixed-step run or a run of another time rule; a fixed-step
/// file written as version 1 (version 6 without the multipliers' rates, read as zero, without the
/// contact events' state, none pending, without the run's own grid, read as the current grid,
/// and without the held iteration matrix, none held) is still read, to the same snapshot
/// (saved again, the version 6 file with zero rates and no matrix held), and so is one written
/// as version 5 (without the rates and the run's own grid), 6 (without the residual
/// evaluations), 7 (without the accelerations' rates, read as zero: saved again, the
/// version 10 file with zero rates), 8 (without the rates over the step before, read as none)
/// or 9 (without the last contact event's settling time, read as none).
#[test]
fn damaged_adaptive_snapshot_files_are_refused_and_version_1_is_read() {
    let system = chain();
    let dir = unique_dir("damaged-snapshot");
    let adaptive = SimulationOptions {
        t_end: 0.25,
        dt: 1e-2,
        step_control: StepControl::Adaptive(AdaptiveOptions::default()),
        ..Default::default()
    };
    let path = dir.join("adaptive.snap");
    let mut run = Simulation::new(&system, &adaptive).unwrap();
    run.step_to(0.05).clone().unwrap();
    run.snapshot().save(&path).unwrap();
    let good = std::fs::read(&path).unwrap();
    assert_eq!(&good[8..12], &10u32.to_le_bytes());
    let n = system.particles().len();
    // Version 8 keeps the accelerations' rates and their step after the accelerations, version
    // 9 then the rates over the step before, their step and the predictor's choice (a byte);
    // the files below are written from version 7's layout (without them) and read back as
    // version 9 (zero rates, no steps, the last rates chosen).
    let acc_rates_at = 8 + 4 + 24 + 8 + 3 * 24 * n;
    let before_at = acc_rates_at + 24 * n + 8;
    let before_end = before_at + 24 * n + 8 + 1;
    let v7 = |v9: &[u8]| {
        let mut b = [&v9[..acc_rates_at], &v9[before_end..]].concat();
        b[8..12].copy_from_slice(&7u32.to_le_bytes());
        b
    };
    let v9 = |v7: Vec<u8>| {
        let mut b = [
            &v7[..acc_rates_at],
            &vec![0u8; before_end - acc_rates_at],
            &v7[acc_rates_at..],
        ]
        .concat();
        b[8..12].copy_from_slice(&9u32.to_le_bytes());
        with_checksum(b)
    };
    let refused = |bytes: &[u8], expected: &str| {
        let damaged = dir.join("damaged.snap");
        std::fs::write(&damaged, bytes).unwrap();
        match vinculo::Snapshot::load(&damaged) {
            Err(e @ vinculo::Error::Snapshot { .. }) => {
                assert!(e.to_string().contains(expected), "{e}")
            }
            other => panic!("expected the snapshot error, got {other:?}"),
        }
    };
    // Truncated: the checksum no longer matches.
    refused(&good[..good.len() - 20], "checksum");
    // Cut short inside the error control's state, with a checksum of what is left.
    let body = &v7(&good[..good.len() - 8]);
    refused(
        &with_checksum(body[..body.len() - 60].to_vec()),
        "truncated",
    );
    // The time rule's tag (right after the step controller's tag 1) made unknown.
    let m = run.snapshot().constraints();
    // Header, counts, time, q, v, acc, lambda, its rates, then the rule's four sized arrays
    // (empty for the default trapezoidal rule: their lengths alone).
    let rates_at = 8 + 4 + 24 + 8 + 3 * 24 * n + 8 * m;
    let tag_at = rates_at + 8 * m + 4 * 8;
    assert_eq!(body[tag_at], 1, "the step controller's tag");
    let mut unknown = body.to_vec();
    unknown[tag_at + 1] = 7;
    refused(&with_checksum(unknown), "unknown time rule 7");
    // Version 1 has no error control (the versions before 6 have no multipliers' rates).
    let without_rates = [&body[..rates_at], &body[rates_at + 8 * m..]].concat();
    let mut as_v1 = without_rates.clone();
    as_v1[8..12].copy_from_slice(&1u32.to_le_bytes());
    refused(&with_checksum(as_v1), "unknown step controller 1");
    // Version 2's error control is not read.
    let mut as_v2 = without_rates;
    as_v2[8..12].copy_from_slice(&2u32.to_le_bytes());
    refused(&with_checksum(as_v2), "format version 2");

    // A snapshot restored into a run of another kind: fixed steps, or another time rule.
    let loaded = vinculo::Snapshot::load(&path).unwrap();
    let mut fixed_run = Simulation::new(&system, &SimulationOptions::default()).unwrap();
    let err = fixed_run.try_restore(&loaded).unwrap_err();
    assert!(err.to_string().contains("error-controlled steps"), "{err}");
    let other_rule = SimulationOptions {
        scheme: Scheme::GeneralizedAlpha { rho_inf: 0.8 },
        ..adaptive.clone()
    };
    let mut alpha_run = Simulation::new(&system, &other_rule).unwrap();
    let err = alpha_run.try_restore(&loaded).unwrap_err();
    assert!(err.to_string().contains("snapshot's scheme"), "{err}");
    let fixed_alpha = SimulationOptions {
        scheme: Scheme::GeneralizedAlpha { rho_inf: 0.8 },
        ..Default::default()
    };
    let mut alpha_run = Simulation::new(&system, &fixed_alpha).unwrap();
    let err = alpha_run.try_restore(&fixed_run.snapshot()).unwrap_err();
    assert!(err.to_string().contains("carries 0 accelerations"), "{err}");

    // A fixed-step file written as version 1 is read.
    let mut fixed = Simulation::new(&system, &SimulationOptions::default()).unwrap();
    fixed.step_to(0.05).clone().unwrap();
    let v2 = dir.join("fixed.snap");
    fixed.snapshot().save(&v2).unwrap();
    // Version 10 keeps the last contact event's settling time (0: none) after the fixed
    // steps' two numbers of the contact events' state; the files below are written from
    // version 9's layout (this file less it), and what is saved again is compared with version
    // 9's bytes given it back (`v10`).
    let v10_bytes = std::fs::read(&v2).unwrap();
    let settle_at = tag_at + (before_end - acc_rates_at) + 1 + 32 + 16;
    assert_eq!(v10_bytes[settle_at - 49], 0, "the step controller's tag");
    assert_eq!(&v10_bytes[settle_at..settle_at + 8], &0f64.to_le_bytes());
    let v10 = |v9: Vec<u8>| {
        let mut b = [
            &v9[..settle_at],
            &[0u8; 8][..],
            &v9[settle_at..v9.len() - 8],
        ]
        .concat();
        b[8..12].copy_from_slice(&10u32.to_le_bytes());
        with_checksum(b)
    };
    let mut v9_body = [
        &v10_bytes[..settle_at],
        &v10_bytes[settle_at + 8..v10_bytes.len() - 8],
    ]
    .concat();
    v9_body[8..12].copy_from_slice(&9u32.to_le_bytes());
    let v2_bytes = with_checksum(v9_body);
    assert_eq!(v10(v2_bytes.clone()), v10_bytes);
    assert!(
        v2_bytes[acc_rates_at..acc_rates_at + 24 * n]
            .iter()
            .any(|&b| b != 0),
        "the chain swings: non-zero accelerations' rates"
    );
    let body = &v7(&v2_bytes[..v2_bytes.len() - 8]);
    // The fixed-step state (top, unit, units, level, t_grid: 32 bytes after the controller's
    // tag) without the contact events' two numbers after it.
    assert_eq!(body[tag_at], 0, "the step controller's tag");
    let events_at = tag_at + 1 + 32;
    // Version 6 keeps the run's own grid after the events' state (origin, flag, the point to
    // go back to, 25 bytes); the seven counts after them end the version 1 file; version 7
    // has an eighth (the residual evaluations) and goes on with the held iteration matrix (the
    // run holds one: its flag is 1).
    let grid_at = events_at + 16;
    let counts_end = grid_at + 25 + 8 * 8;
    assert_eq!(body[counts_end], 1, "the held matrix's flag");
    let rates_end = rates_at + 8 * m;
    assert!(
        body[rates_at..rates_end].iter().any(|&b| b != 0),
        "the chain's tensions change: non-zero rates"
    );
    let zero_rates = vec![0u8; 8 * m];
    let mut v1_body = [
        &body[..rates_at],
        &body[rates_end..events_at],
        &body[grid_at + 25..counts_end - 8],
    ]
    .concat();
    v1_body[8..12].copy_from_slice(&1u32.to_le_bytes());
    let v1 = dir.join("fixed-v1.snap");
    std::fs::write(&v1, with_checksum(v1_body)).unwrap();
    let loaded = vinculo::Snapshot::load(&v1).unwrap();
    let again = dir.join("fixed-again.snap");
    loaded.save(&again).unwrap();
    let without_matrix = v9([
        &body[..rates_at],
        &zero_rates,
        &body[rates_end..counts_end - 8],
        &[0u8; 8][..],
        &[0u8][..],
    ]
    .concat());
    assert_eq!(std::fs::read(&again).unwrap(), v10(without_matrix));
    // A version 5 file: without the rates, the run's own grid (read as the current one) and
    // the residual evaluations (read as zero).
    let mut v5_body = [
        &body[..rates_at],
        &body[rates_end..grid_at],
        &body[grid_at + 25..counts_end - 8],
        &body[counts_end..],
    ]
    .concat();
    v5_body[8..12].copy_from_slice(&5u32.to_le_bytes());
    let v5 = dir.join("fixed-v5.snap");
    std::fs::write(&v5, with_checksum(v5_body)).unwrap();
    vinculo::Snapshot::load(&v5).unwrap().save(&again).unwrap();
    let zeroed = v9([
        &body[..rates_at],
        &zero_rates,
        &body[rates_end..counts_end - 8],
        &[0u8; 8][..],
        &body[counts_end..],
    ]
    .concat());
    assert_eq!(std::fs::read(&again).unwrap(), v10(zeroed));
    // A version 6 file: without the residual evaluations.
    let mut v6_body = [&body[..counts_end - 8], &body[counts_end..]].concat();
    v6_body[8..12].copy_from_slice(&6u32.to_le_bytes());
    let v6 = dir.join("fixed-v6.snap");
    std::fs::write(&v6, with_checksum(v6_body)).unwrap();
    let restored = vinculo::Snapshot::load(&v6).unwrap();
    restored.save(&again).unwrap();
    let counted_zero = v9([&body[..counts_end - 8], &[0u8; 8][..], &body[counts_end..]].concat());
    assert_eq!(std::fs::read(&again).unwrap(), v10(counted_zero));
    // A version 7 file: without the accelerations' rates.
    let v7_path = dir.join("fixed-v7.snap");
    std::fs::write(&v7_path, with_checksum(body.to_vec())).unwrap();
    vinculo::Snapshot::load(&v7_path)
        .unwrap()
        .save(&again)
        .unwrap();
    assert_eq!(std::fs::read(&again).unwrap(), v10(v9(body.to_vec())));
    // A version 8 file: without the rates over the step before (the chain's run had them).
    assert!(
        v2_bytes[before_at..before_end - 1].iter().any(|&b| b != 0),
        "the rates over the step before are kept"
    );
    let unsummed = &v2_bytes[..v2_bytes.len() - 8];
    let mut v8_body = [&unsummed[..before_at], &unsummed[before_end..]].concat();
    v8_body[8..12].copy_from_slice(&8u32.to_le_bytes());
    let v8_path = dir.join("fixed-v8.snap");
    std::fs::write(&v8_path, with_checksum(v8_body)).unwrap();
    vinculo::Snapshot::load(&v8_path)
        .unwrap()
        .save(&again)
        .unwrap();
    let none_before = with_checksum(
        [
            &unsummed[..before_at],
            &vec![0u8; before_end - before_at],
            &unsummed[before_end..],
        ]
        .concat(),
    );
    assert_eq!(std::fs::read(&again).unwrap(), v10(none_before));
    // A version 9 file: without the settling time (none), read and saved again as this run's.
    let v9_path = dir.join("fixed-v9.snap");
    std::fs::write(&v9_path, &v2_bytes).unwrap();
    vinculo::Snapshot::load(&v9_path)
        .unwrap()
        .save(&again)
        .unwrap();
    assert_eq!(std::fs::read(&again).unwrap(), v10_bytes);
    std::fs::remove_dir_all(&dir).ok();
}

/// Stops computed by the caller as k * 0.05 (3 * 0.05 = 0.15000000000000002, one bit past the
/// grid time 0.15 of 15 steps of 0.01) land on the grid and count as reached: the run is one
/// `simulate` call bit for bit (without the tolerance, a second step of ~1e-17 s would follow);
/// so does a stop a few bits before the end.
#[test]
fn stops_a_few_bits_off_the_grid_change_no_step() {
    let system = chain();
    let options = SimulationOptions {
        t_end: 0.25,
        dt: 1e-2,
        ..Default::default()
    };
    assert_ne!(3.0 * 0.05, 0.15);
    let mut run = Simulation::new(&system, &options).unwrap();
    for k in 1..=4 {
        run.step_to(k as f64 * 0.05).clone().unwrap();
    }
    // A stop a few bits before the end is the end (the last step lands on t_end).
    run.step_to(0.25 - 1e-15).clone().unwrap();
    assert_eq!(run.time(), 0.25);
    run.step_to(0.25).clone().unwrap();
    let one_call = simulate(&system, &options).unwrap();
    assert_same_run(&one_call, run.solution(), "stops at k * 0.05");
}
