//! Elastic segments (compliant distances whose multiplier is the tension) through the public
//! API, against closed forms (`docs/theory/moorings.md`):
//!
//! - a mass m hanging from a fixed point by one segment of unstretched length L and axial
//!   stiffness EA, released at the unstretched length, oscillates about the static stretch
//!   m g L / EA with amplitude m g L / EA at omega = sqrt(EA / (L m)) (a linear spring of
//!   stiffness EA/L), and its tension averages m g;
//! - EA = 1e15 N gives the exact distance's motion;
//! - the tree elimination gives the general sparse LU's motion on an elastic chain;
//! - a winch law pays the segment out: the static stretch follows the length;
//! - with internal axial damping c, the hanging mass is a damped oscillator
//!   m y'' + c y' + (EA/L) y = m g in its stretch y, whose closed form it follows, and a
//!   swinging chain of damped segments moves as the same chain with each segment's damping a
//!   spring-damper of zero stiffness (the reference model).

use vinculo::laws::Law;
use vinculo::linear::SparseSolver;
use vinculo::model::{ConstraintId, ParticleId, System};
use vinculo::{simulate, SimulationOptions, Solution};

const G: f64 = 9.81;

/// A mass `m` hanging from the origin by a segment of length `l` and stiffness `ea`, released at
/// rest at z = -l.
fn hanging(m: f64, l: Law, ea: f64) -> System {
    let mut s = System::new([0.0, 0.0, -G]);
    let z0 = -l.value(0.0);
    let a = s.add_particle(1.0, [0.0; 3], [0.0; 3], true).unwrap();
    let b = s.add_particle(m, [0.0, 0.0, z0], [0.0; 3], false).unwrap();
    s.add_elastic_distance(a, b, (l, 1.0), ea).unwrap();
    s
}

#[test]
fn hanging_mass_oscillates_about_the_static_stretch_at_the_axial_frequency() {
    let (m, l, ea) = (2.0, 1.5, 3.0e4);
    let stretch = m * G * l / ea;
    let omega = (ea / (l * m)).sqrt();
    let period = 2.0 * std::f64::consts::PI / omega;
    let options = SimulationOptions {
        t_end: 3.3 * period,
        dt: period / 2000.0,
        ..Default::default()
    };
    let sol = simulate(&hanging(m, Law::Constant(l), ea), &options).unwrap();
    assert!(sol.status.is_ok(), "{:?}", sol.status);
    let z: Vec<f64> = (0..sol.len()).map(|k| sol.position(k, 1)[2]).collect();
    let (lo, hi) = z
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &x| (a.min(x), b.max(x)));
    // Closed form: z(t) = -l - stretch (1 - cos omega t), between -l and -l - 2 stretch; the
    // trapezoidal rule conserves the amplitude (no numerical damping), sampling at 2000 steps
    // per period misses the extremes by (pi/2000)^2/2 ~ 1e-6 of the amplitude.
    assert!(((hi + l) / stretch).abs() < 1e-5, "top {hi}");
    assert!(
        ((lo + l + 2.0 * stretch) / stretch).abs() < 1e-5,
        "bottom {lo}"
    );
    // Upward crossings of the equilibrium, interpolated linearly: the period.
    let eq = -l - stretch;
    let crossings: Vec<f64> = (1..z.len())
        .filter(|&k| z[k - 1] < eq && z[k] >= eq)
        .map(|k| {
            let (t0, t1) = (sol.times[k - 1], sol.times[k]);
            t0 + (t1 - t0) * (eq - z[k - 1]) / (z[k] - z[k - 1])
        })
        .collect();
    assert_eq!(crossings.len(), 3, "{crossings:?}");
    let measured = (crossings[2] - crossings[0]) / 2.0;
    // Trapezoidal period error ~ (omega h)^2 / 12 ~ 1e-6.
    assert!(
        ((measured - period) / period).abs() < 1e-5,
        "period {measured} vs {period}"
    );
    // The multiplier is the tension at the step's evaluation point (the trapezoidal rule's
    // midpoint): EA (|d| - L)/L with |d| the mean of the step's end lengths, to the Newton
    // tolerance; at the start, from the initial stretch (zero).
    assert!(sol.multipliers[0].abs() < 1e-9);
    for k in 1..sol.len() {
        let stretched = -0.5 * (sol.position(k, 1)[2] + sol.position(k - 1, 1)[2]);
        let hooke = ea * (stretched - l) / l;
        let tension = sol.multipliers[k];
        assert!(
            (tension - hooke).abs() < 1e-6 * m * G,
            "step {k}: {tension} vs {hooke}"
        );
    }
}

#[test]
fn stiff_segment_moves_as_the_exact_distance() {
    // A pendulum swinging 0.5 rad from the vertical: EA = 1e15 N against Phi = L^2 - |d|^2.
    let (m, l) = (0.8, 1.2);
    let start = [l * 0.5f64.sin(), 0.0, -l * 0.5f64.cos()];
    let build = |elastic: bool| {
        let mut s = System::new([0.0, 0.0, -G]);
        let a = s.add_particle(1.0, [0.0; 3], [0.0; 3], true).unwrap();
        let b = s.add_particle(m, start, [0.0; 3], false).unwrap();
        if elastic {
            s.add_elastic_distance(a, b, (Law::Constant(l), 1.0), 1e15)
                .unwrap();
        } else {
            s.add_distance(a, b, Some(l)).unwrap();
        }
        s
    };
    let options = SimulationOptions {
        t_end: 3.0,
        dt: 1e-3,
        ..Default::default()
    };
    let exact = simulate(&build(false), &options).unwrap();
    let elastic = simulate(&build(true), &options).unwrap();
    assert!(exact.status.is_ok(), "{:?}", exact.status);
    assert!(elastic.status.is_ok(), "{:?}", elastic.status);
    assert_eq!(exact.len(), elastic.len());
    // The stretch m g L / EA ~ 1e-14 m is below the Newton tolerance: the same motion.
    let worst = exact
        .positions
        .iter()
        .zip(&elastic.positions)
        .fold(0.0f64, |w, (a, b)| w.max((a - b).abs()));
    assert!(worst < 1e-8, "largest difference {worst} m");
    // Same tension after the start: the exact distance's 2 lambda L against the elastic
    // multiplier (whose initial value is the initial stretch's, zero here).
    for k in 1..exact.len() {
        let t_exact = 2.0 * exact.multipliers[k] * l;
        let t_elastic = elastic.multipliers[k];
        // The elastic tension is stretch / compliance: a round-off of 1e-16 m in the stretch
        // is 0.1 N at c = 1.2e-15 m/N; the Newton iterate lands far closer (measured: 6.6e-4 N,
        // 0.84e-4 of m g, with the default Newton; 2.5e-4 N with full Newton).
        assert!(
            (t_exact - t_elastic).abs() < 1e-4 * m * G,
            "{t_exact} vs {t_elastic}"
        );
    }
}

/// A chain of `links` elastic segments (0.1 m, stiffness `ea`) between 0.1 kg particles,
/// released horizontally from a fixed anchor; `each(system, segment, a, b)` is called on every
/// segment (to damp it).
fn horizontal_chain(
    links: usize,
    ea: f64,
    mut each: impl FnMut(&mut System, ConstraintId, ParticleId, ParticleId),
) -> System {
    let mut s = System::new([0.0, 0.0, -G]);
    let mut prev = s.add_particle(1.0, [0.0; 3], [0.0; 3], true).unwrap();
    for i in 1..=links {
        let p = s
            .add_particle(0.1, [0.1 * i as f64, 0.0, 0.0], [0.0; 3], false)
            .unwrap();
        let c = s
            .add_elastic_distance(prev, p, (Law::Constant(0.1), 1.0), ea)
            .unwrap();
        each(&mut s, c, prev, p);
        prev = p;
    }
    s
}

/// The largest difference between the positions of two runs (m).
fn largest_difference(a: &Solution, b: &Solution) -> f64 {
    a.positions
        .iter()
        .zip(&b.positions)
        .fold(0.0f64, |w, (x, y)| w.max((x - y).abs()))
}

#[test]
fn tree_elimination_equals_sparse_lu_on_an_elastic_chain() {
    let s = horizontal_chain(40, 5e3, |_, _, _, _| {});
    let run = |solver: SparseSolver| {
        let options = SimulationOptions {
            t_end: 0.5,
            dt: 1e-3,
            dense_limit: 0,
            sparse_solver: solver,
            ..Default::default()
        };
        simulate(&s, &options).unwrap()
    };
    let tree = run(SparseSolver::Auto);
    let lu = run(SparseSolver::SparseLu);
    assert!(tree.status.is_ok() && lu.status.is_ok());
    assert_eq!(
        (tree.linear_solver, lu.linear_solver),
        ("tree elimination", "sparse LU")
    );
    // Two direct solvers of one linear system: the motions agree to round-off amplified over
    // the steps.
    let worst = largest_difference(&tree, &lu);
    assert!(worst < 1e-9, "largest difference {worst} m");
}

#[test]
fn winch_pays_out_the_segment() {
    // L(t) = 1 + 0.1 t, slowly (0.1 m/s against the axial period 2 pi sqrt(L m / EA) ~ 0.04 s):
    // the mass follows the static position -(L(t) + m g L(t) / EA), within the stretch's
    // quasi-static lag. Backward Euler damps the axial oscillation of the start.
    let (m, ea) = (1.0, 1e4);
    let length = Law::polynomial(vec![1.0, 0.1]).unwrap();
    let options = SimulationOptions {
        t_end: 5.0,
        dt: 1e-2,
        scheme: vinculo::integrators::Scheme::GeneralizedTrapezoidal { alpha: 1.0 },
        ..Default::default()
    };
    let sol = simulate(&hanging(m, length, ea), &options).unwrap();
    assert!(sol.status.is_ok(), "{:?}", sol.status);
    let last = sol.len() - 1;
    let l_end = 1.0 + 0.1 * 5.0;
    let expected = -(l_end + m * G * l_end / ea);
    let z = sol.position(last, 1)[2];
    assert!((z - expected).abs() < 1e-5, "z {z} vs {expected}");
    assert!((sol.multipliers[last] - m * G).abs() < 1e-3 * m * G);
}

#[test]
fn ggl_formulation_refuses_compliant_segments_with_a_typed_error() {
    // The stabilised (GGL) layout has no compliant rows: a finite EA is refused before the run,
    // naming the segment and the formulation to use; an inextensible one runs.
    let options = SimulationOptions {
        t_end: 0.01,
        formulation: vinculo::integrators::Formulation::Ggl,
        ..Default::default()
    };
    match simulate(&hanging(1.0, Law::Constant(1.0), 1e4), &options) {
        Err(vinculo::Error::InvalidParameter { name, expected, .. }) => {
            assert!(name.contains("elastic segment #0"), "{name}");
            assert!(expected.contains("index-3"), "{expected}");
        }
        other => panic!("expected InvalidParameter, got {other:?}"),
    }
    let rigid = simulate(&hanging(1.0, Law::Constant(1.0), f64::INFINITY), &options).unwrap();
    assert!(rigid.status.is_ok(), "{:?}", rigid.status);
    // Its damping force is assembled with the index-3 rows alone: a damped inextensible
    // segment is refused too (not run without its damping).
    let mut damped = hanging(1.0, Law::Constant(1.0), f64::INFINITY);
    damped.set_axial_damping(ConstraintId(0), 2.0).unwrap();
    match simulate(&damped, &options) {
        Err(vinculo::Error::InvalidParameter { name, .. }) => {
            assert!(name.contains("damped"), "{name}");
        }
        other => panic!("expected InvalidParameter, got {other:?}"),
    }
}

#[test]
fn damped_segment_follows_the_damped_oscillator() {
    // m y'' + c y' + k y = m g, y(0) = y'(0) = 0 (released at the unstretched length), with
    // k = EA / L, omega = sqrt(k / m), zeta = c / (2 m omega), omega_d = omega sqrt(1 - zeta^2):
    // y(t) = s (1 - e^(-zeta omega t) (cos omega_d t + zeta omega / omega_d sin omega_d t)),
    // s = m g / k (any text on the damped harmonic oscillator, e.g. Meirovitch, Fundamentals
    // of Vibrations, sec. 2.2). The motion stays on the vertical, where u.w is the stretch rate.
    let (m, l, ea): (f64, f64, f64) = (2.0, 1.5, 3.0e4);
    let k = ea / l;
    let omega = (k / m).sqrt();
    let zeta: f64 = 0.1;
    let c = 2.0 * zeta * m * omega;
    let wd = omega * (1.0 - zeta * zeta).sqrt();
    let stretch = m * G / k;
    let period = 2.0 * std::f64::consts::PI / omega;
    let mut system = hanging(m, Law::Constant(l), ea);
    system.set_axial_damping(ConstraintId(0), c).unwrap();
    let options = SimulationOptions {
        t_end: 3.0 * period,
        dt: period / 2000.0,
        ..Default::default()
    };
    let sol = simulate(&system, &options).unwrap();
    assert!(sol.status.is_ok(), "{:?}", sol.status);
    let mut worst = 0.0f64;
    for kk in 0..sol.len() {
        let t = sol.times[kk];
        let decay = (-zeta * omega * t).exp();
        let y = stretch * (1.0 - decay * ((wd * t).cos() + zeta * omega / wd * (wd * t).sin()));
        let measured = -sol.position(kk, 1)[2] - l;
        worst = worst.max((measured - y).abs());
    }
    // The trapezoidal rule's error at 2000 steps a period: a frequency error of
    // (omega h)^2 / 12 = 8e-7, 1.5e-5 rad of phase over three periods (measured: 3.0e-6 s);
    // without the damping the motion would differ by s (1 - e^(-2 pi zeta)) = 0.47 s after
    // one period.
    assert!(
        worst < 2e-5 * stretch,
        "largest difference {worst} m of {stretch} m"
    );
}

#[test]
fn damped_segments_move_as_segments_with_zero_stiffness_spring_dampers() {
    // A 20-link elastic chain released horizontally: its segments stretch and turn, so that
    // both terms of the damping's Jacobian act. Reference: the same chain with each segment's
    // damping as a separate spring-damper of zero stiffness (`forces/spring_damper.rs`).
    let chain = |separate: bool| {
        horizontal_chain(20, 2e3, |s, c, a, b| {
            if separate {
                s.add_spring_damper(a, b, 0.0, 3.0, Some(0.1)).unwrap();
            } else {
                s.set_axial_damping(c, 3.0).unwrap();
            }
        })
    };
    let options = SimulationOptions {
        t_end: 0.5,
        dt: 1e-3,
        ..Default::default()
    };
    let (one, two) = (
        simulate(&chain(false), &options).unwrap(),
        simulate(&chain(true), &options).unwrap(),
    );
    assert!(one.status.is_ok() && two.status.is_ok());
    // The same equations: the runs differ by round-off within Newton's tolerance (1e-10 m;
    // measured 3.9e-14 m), where the same chain without damping moves 8.0e-5 m away
    // (measured).
    let worst = largest_difference(&one, &two);
    assert!(worst < 1e-10, "largest difference {worst} m");
}

#[test]
fn axial_damping_is_refused_where_it_does_not_apply() {
    let mut s = hanging(1.0, Law::Constant(1.0), 1e4);
    let err = s.set_axial_damping(ConstraintId(0), -1.0).unwrap_err();
    assert!(err.to_string().contains("axial damping"), "{err}");
    let a = s.particle_id(0).unwrap();
    let b = s.particle_id(1).unwrap();
    let d = s.add_distance(a, b, None).unwrap();
    let err = s.set_axial_damping(d, 1.0).unwrap_err();
    assert!(err.to_string().contains("elastic segment"), "{err}");
}
