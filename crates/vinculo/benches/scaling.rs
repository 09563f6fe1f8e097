//! Scaling of the cost per step with the number of particles: hanging and swinging chains of
//! 10^3 to 10^6 point masses (0.1 m links, 0.1 kg, dt = 1e-3), seconds per step and peak memory.
//!
//! Run with `cargo bench -p vinculo --bench scaling` (all sizes, each in its own process so
//! that the peak resident memory, VmHWM, is that of one size) or
//! `cargo bench -p vinculo --bench scaling -- N [swinging]` for one size. A further argument
//! `serial` or `parallel` forces the assembly's path (`SimulationOptions::parallel_from` at
//! `usize::MAX` or 0; by default the options' threshold decides). The time per step is
//! measured between the first and the last accepted step (model analysis excluded); a run
//! stores only its first and last states. Prints the fitted exponent of time per step against N.

use std::process::Command;
mod common;

use common::{chain, Clock};
use std::time::Instant;
use vinculo::{simulate_with_observer, SimulationOptions};

fn peak_memory_mb() -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find(|l| l.starts_with("VmHWM:"))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|kb| kb.parse::<f64>().ok())
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

/// One size, in this process: prints "N seconds_per_step iterations_per_step peak_MB solver".
fn one(n: usize, hanging: bool, parallel_from: usize) {
    let steps = (2_000_000 / n).clamp(6, 200);
    let system = chain(n, 0.1, hanging);
    let options = SimulationOptions {
        t_end: steps as f64 * 1e-3,
        dt: 1e-3,
        save_every: usize::MAX,
        parallel_from,
        ..Default::default()
    };
    let mut clock = Clock(Vec::with_capacity(steps + 1));
    let begun = Instant::now();
    let sol = simulate_with_observer(&system, &options, &mut clock).unwrap();
    assert!(sol.status.is_ok(), "{:?}", sol.status);
    let per_step =
        (clock.0[clock.0.len() - 1] - clock.0[0]).as_secs_f64() / (clock.0.len() - 1) as f64;
    let last = sol.stats.last().unwrap().newton_iterations;
    // The start: checks, layout, analysis, consistent accelerations (up to the first step's
    // end, less one step).
    let start = (clock.0[0] - begun).as_secs_f64() - per_step;
    println!(
        "{n} {per_step:.6e} {last} {:.1} {} {start:.4e}",
        peak_memory_mb(),
        sol.linear_solver.replace(' ', "_")
    );
}

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| a != "--bench")
        .collect();
    let has = |word: &str| args.iter().any(|a| a == word);
    let (assembly, parallel_from) = if has("serial") {
        ("serial", usize::MAX)
    } else if has("parallel") {
        ("parallel", 0)
    } else {
        ("default", SimulationOptions::default().parallel_from)
    };
    if let Some(n) = args.first().and_then(|a| a.parse::<usize>().ok()) {
        one(n, !has("swinging"), parallel_from);
        return;
    }
    let exe = std::env::current_exe().unwrap();
    for shape in ["hanging", "swinging"] {
        println!("{shape} chains, 0.1 m links, dt = 1e-3, {assembly} assembly");
        println!(
            "{:>9} {:>14} {:>10} {:>14} {:>12} {:>10}  solver",
            "N", "s/step", "us/particle", "Newton it.", "peak MB", "start (s)"
        );
        let mut points = Vec::new();
        for n in [1_000, 10_000, 100_000, 1_000_000] {
            let out = Command::new(&exe)
                .arg(n.to_string())
                .arg(shape)
                .arg(assembly)
                .output()
                .unwrap();
            let text = String::from_utf8_lossy(&out.stdout);
            let f: Vec<&str> = text.split_whitespace().collect();
            if !out.status.success() || f.len() < 6 {
                println!("{n:>9} failed: {}", String::from_utf8_lossy(&out.stderr));
                continue;
            }
            let per_step: f64 = f[1].parse().unwrap();
            println!(
                "{n:>9} {per_step:>14.4e} {:>10.3} {:>14} {:>12} {:>10} {}",
                per_step / n as f64 * 1e6,
                f[2],
                f[3],
                f[5],
                f[4].replace('_', " ")
            );
            points.push(((n as f64).ln(), per_step.ln()));
        }
        // Least-squares slope of log(time per step) against log(N).
        let k = points.len() as f64;
        let (sx, sy) = points
            .iter()
            .fold((0.0, 0.0), |(a, b), p| (a + p.0, b + p.1));
        let (mx, my) = (sx / k, sy / k);
        let (num, den) = points.iter().fold((0.0, 0.0), |(a, b), p| {
            (a + (p.0 - mx) * (p.1 - my), b + (p.0 - mx).powi(2))
        });
        println!(
            "fitted exponent (time per step ~ N^p, 10^3..10^6): p = {:.3}\n",
            num / den
        );
    }
}
