//! Seabed contact, friction and line hydrodynamics through the public API, against closed forms
//! (equations in `crates/vinculo/src/forces/seabed.rs` and `line_hydro.rs`, MoorDyn's
//! conventions, `docs/theory/seabed-and-line-loads.md`).
//!
//! Each test puts one free line node between two fixed particles along x (its tangent), a line
//! of diameter d and node length l: volume V = pi d^2/4 l, submerged weight
//! w = (m - rho V) g.

use vinculo::forces::SeabedFriction;
use vinculo::model::{LineHydroSpec, ParticleId, SeabedSpec, System};
use vinculo::water::{Current, Water};
use vinculo::{simulate, SimulationOptions, Solution};

const G: f64 = 9.80665;
const RHO: f64 = 1025.0;
const D: f64 = 0.1;
const L: f64 = 2.0;
const DEPTH: f64 = 50.0;
const MASS: f64 = 40.0;

fn volume() -> f64 {
    std::f64::consts::PI * D * D / 4.0 * L
}

/// Submerged weight of the node (N).
fn weight() -> f64 {
    (MASS - RHO * volume()) * G
}

/// A node at `z` moving at `v`, its tangent from two fixed particles along x, with buoyancy
/// and the given drag and added-mass coefficients.
fn node(z: f64, v: [f64; 3], cd: f64, ca: f64) -> (System, ParticleId, (ParticleId, ParticleId)) {
    let mut s = System::new([0.0, 0.0, -G]);
    let a = s.add_particle(1.0, [-L, 0.0, z], [0.0; 3], true).unwrap();
    let b = s.add_particle(1.0, [L, 0.0, z], [0.0; 3], true).unwrap();
    let n = s.add_particle(MASS, [0.0, 0.0, z], v, false).unwrap();
    let hydro = LineHydroSpec {
        density: RHO,
        diameter: D,
        length: L,
        cd,
        cdax: 0.0,
        ca,
        caax: 0.0,
    };
    s.add_line_hydrodynamics(n, Some((a, b)), &hydro).unwrap();
    (s, n, (a, b))
}

fn seabed(friction: SeabedFriction) -> SeabedSpec {
    SeabedSpec {
        depth: DEPTH,
        grid: None,
        diameter: D,
        length: L,
        stiffness: 3.0e6,
        damping: 3.0e5,
        damping_ramp: 0.0,
        friction,
    }
}

fn run(s: &System, t_end: f64, dt: f64) -> Solution {
    let options = SimulationOptions {
        t_end,
        dt,
        ..Default::default()
    };
    let sol = simulate(s, &options).unwrap();
    assert!(sol.status.is_ok(), "{:?}", sol.status);
    sol
}

/// A node dropped onto the seabed comes to rest at the penetration where the contact carries
/// its submerged weight: p = w / (kBot d l) (MoorDyn's normal force A kBot p, A = d l).
#[test]
fn resting_node_penetrates_by_its_weight_over_the_contact_stiffness() {
    let (mut s, n, tangent) = node(-DEPTH + 0.01, [0.0; 3], 0.0, 0.0);
    s.add_seabed_contact(n, Some(tangent), &seabed(SeabedFriction::NONE))
        .unwrap();
    let sol = run(&s, 3.0, 1e-3);
    let z = sol.position(sol.len() - 1, 2)[2];
    let expected = weight() / (3.0e6 * D * L);
    let measured = -DEPTH - z;
    assert!(
        ((measured - expected) / expected).abs() < 1e-6,
        "penetration {measured} m against {expected} m"
    );
}

/// A node sliding on the seabed faster than the friction's linear range decelerates at
/// mu |N| / m = mu w / m (Coulomb): mu_a sliding along the line, mu_t across it.
#[test]
fn sliding_node_decelerates_at_the_coulomb_rate() {
    let (mu_t, mu_a) = (0.6, 0.3);
    let p0 = weight() / (3.0e6 * D * L);
    for (direction, mu) in [(0, mu_a), (1, mu_t)] {
        let mut v0 = [0.0; 3];
        v0[direction] = 4.0;
        let (mut s, n, tangent) = node(-DEPTH - p0, v0, 0.0, 0.0);
        let friction = SeabedFriction {
            transverse: mu_t,
            axial: Some(mu_a),
            damping: 200.0,
            static_scale: 1.0,
        };
        s.add_seabed_contact(n, Some(tangent), &seabed(friction))
            .unwrap();
        let sol = run(&s, 1.0, 1e-3);
        // Speed at t = 0.2 and 0.7 s, on the kinetic branch (above w / c_v = 1.6 m/s).
        let speed = |t: f64| sol.velocity((t / 1e-3).round() as usize, 2)[direction];
        let decel = (speed(0.2) - speed(0.7)) / 0.5;
        let expected = mu * weight() / MASS;
        assert!(speed(0.7) > weight() / 200.0 * 1.1);
        assert!(
            ((decel - expected) / expected).abs() < 1e-6,
            "direction {direction}: deceleration {decel} against {expected} m/s^2"
        );
    }
}

/// Without an axial coefficient (MoorDyn-C's single coefficient) the friction is isotropic: a
/// node sliding obliquely to the line decelerates at mu w / m along its velocity.
#[test]
fn isotropic_friction_decelerates_obliquely_sliding_node_at_the_coulomb_rate() {
    let mu = 0.5;
    let p0 = weight() / (3.0e6 * D * L);
    let (c, s30) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    let (mut s, n, tangent) = node(-DEPTH - p0, [4.0 * c, 4.0 * s30, 0.0], 0.0, 0.0);
    let friction = SeabedFriction {
        transverse: mu,
        axial: None,
        damping: 200.0,
        static_scale: 1.0,
    };
    s.add_seabed_contact(n, Some(tangent), &seabed(friction))
        .unwrap();
    let sol = run(&s, 1.0, 1e-3);
    let velocity = |t: f64| sol.velocity((t / 1e-3).round() as usize, 2);
    let (v1, v2) = (velocity(0.2), velocity(0.7));
    let expected = mu * weight() / MASS;
    for (k, dir) in [(0, c), (1, s30)] {
        let decel = (v1[k] - v2[k]) / 0.5;
        assert!(
            ((decel - expected * dir) / expected).abs() < 1e-6,
            "component {k}: deceleration {decel} against {} m/s^2",
            expected * dir
        );
    }
}

/// A segment sinking broadside (normal to its tangent) reaches the speed where the normal drag
/// carries its submerged weight: w = 1/2 rho Cd d l v^2.
#[test]
fn sinking_segment_reaches_the_normal_drag_terminal_velocity() {
    let cd = 1.2;
    let (s, _, _) = node(-10.0, [0.0; 3], cd, 0.0);
    let sol = run(&s, 6.0, 2e-3);
    let v = -sol.velocity(sol.len() - 1, 2)[2];
    let expected = (2.0 * weight() / (RHO * cd * D * L)).sqrt();
    assert!(
        ((v - expected) / expected).abs() < 1e-6,
        "terminal velocity {v} against {expected} m/s"
    );
}

/// A node hanging from a spring k heaves (normal to the line) with the period
/// 2 pi sqrt((m + Ca rho V) / k): the added mass joins its inertia.
#[test]
fn added_mass_lengthens_the_heave_period() {
    let (ca, k) = (1.0, 4.0e3);
    let (mut s, n, _) = node(-10.0, [0.0, 0.0, 0.05], 0.0, ca);
    let top = s
        .add_particle(1.0, [0.0, 0.0, -5.0], [0.0; 3], true)
        .unwrap();
    // Rest length such that the node is at equilibrium at z = -10.
    s.add_spring_damper(top, n, k, 0.0, Some(5.0 - weight() / k))
        .unwrap();
    let inertia = MASS + ca * RHO * volume();
    let period = 2.0 * std::f64::consts::PI * (inertia / k).sqrt();
    let dt = period / 4000.0;
    let sol = run(&s, 2.3 * period, dt);
    let z: Vec<f64> = (0..sol.len())
        .map(|k| sol.position(k, 2)[2] + 10.0)
        .collect();
    let crossings: Vec<f64> = (1..z.len())
        .filter(|&k| z[k - 1] > 0.0 && z[k] <= 0.0)
        .map(|k| {
            let (t0, t1) = (sol.times[k - 1], sol.times[k]);
            t0 + (t1 - t0) * z[k - 1] / (z[k - 1] - z[k])
        })
        .collect();
    assert_eq!(crossings.len(), 2);
    let measured = crossings[1] - crossings[0];
    // Trapezoidal rule at 4000 steps per period: period error ~ (omega h)^2 / 12 ~ 2e-7.
    assert!(
        ((measured - period) / period).abs() < 1e-5,
        "period {measured} s against {period} s"
    );
}

/// A node held by a spring k in a uniform current U settles where the spring carries the drag
/// of the current: k x = 1/2 rho Cd d l U^2 across the line, 1/2 rho CdAx pi d l U^2 along it
/// (no gravity, so only the drag and the spring act; the drag damps the motion with
/// c = rho C A U, a damping ratio of about 0.7, so it has settled to round-off in 20 s).
#[test]
fn node_in_a_current_settles_where_the_spring_carries_the_drag() {
    let (cd, cdax, k, u) = (1.2, 0.4, 500.0, 0.8);
    for (direction, area_coefficient) in [(1, cd * D * L), (0, cdax * std::f64::consts::PI * D * L)]
    {
        let mut s = System::new([0.0; 3]);
        let a = s.add_particle(1.0, [-L, 0.0, 0.0], [0.0; 3], true).unwrap();
        let b = s.add_particle(1.0, [L, 0.0, 0.0], [0.0; 3], true).unwrap();
        let n = s.add_particle(MASS, [0.0; 3], [0.0; 3], false).unwrap();
        let mut anchor_at = [0.0; 3];
        anchor_at[direction] = -1.0;
        let anchor = s.add_particle(1.0, anchor_at, [0.0; 3], true).unwrap();
        s.add_spring_damper(anchor, n, k, 0.0, Some(1.0)).unwrap();
        let mut current = [0.0; 3];
        current[direction] = u;
        let hydro = LineHydroSpec {
            density: RHO,
            diameter: D,
            length: L,
            cd,
            cdax,
            ca: 0.0,
            caax: 0.0,
        };
        s.add_line_hydrodynamics(n, Some((a, b)), &hydro).unwrap();
        // Water everywhere (no surface at the node's z = 0), moving at U.
        let mut water = Water::everywhere(G);
        water.current = Current::Uniform(current);
        s.set_water(water);
        let sol = run(&s, 20.0, 1e-2);
        let x = sol.position(sol.len() - 1, 2)[direction];
        // The drag on the node at rest in the current U: 1/2 rho C A U^2.
        let expected = 0.5 * RHO * area_coefficient * u * u / k;
        assert!(
            ((x - expected) / expected).abs() < 1e-6,
            "direction {direction}: displacement {x} m against {expected} m"
        );
    }
}
