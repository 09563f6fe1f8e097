//! Snapshot files: a [`Snapshot`] saved to and loaded from a small binary file.
//!
//! # Format (version 10)
//!
//! Little-endian throughout; every float is stored as its IEEE-754 bits, so a loaded snapshot
//! is bit for bit the saved one.
//!
//! | field | type |
//! |---|---|
//! | magic `VNCLSNAP` | 8 bytes |
//! | version (10) | u32 |
//! | model fingerprint ([`crate::run::fingerprint`]), particles n, constraint equations m | 3 x u64 |
//! | time | f64 |
//! | positions, velocities, accelerations, their rates over the last step (the predictor's, `run.rs`) | 4 x (n x 3 f64) |
//! | the size of the step the accelerations' rates were measured over (0: none) | f64 |
//! | the accelerations' rates over the step before, the size of that step (0: none), and whether the predictor extrapolates with them (1) or with the last ones (0) | n x 3 f64, f64, u8 |
//! | multipliers, their rates over the last step (the predictor's, `run.rs`) | 2 x (m f64) |
//! | the time rule's state: 4 arrays of 3-vectors, each a u64 length then length x 3 f64 | |
//! | step controller tag: 0 (fixed steps) or 1 (error control), then its state (below) | u8 |
//! | accepted steps, next output, stored rows, steps taken, steps rejected, accepted step sizes, factorisations, residual evaluations | 8 x u64 |
//! | held iteration matrix: 0 (none) or 1, then its kind (bit 0: the GGL formulation's, else the index-3 one's; bit 1: the values are the factors of a solver that factorises in place, see `LinearSolver::factors`, else the matrix in the pattern's order), its key (step size and scheme coefficient), its last contraction ratio, a u64 count and that many values, a u64 count and that many values of the iterate it was assembled at | u8, then u8, 3 x f64, u64, f64s, u64, f64s |
//! | checksum: FNV-1a 64 of every byte before it | u64 |
//!
//! Fixed steps (tag 0): top u32, unit f64, units u64, level u32, t_grid f64, and the contact
//! events' state (`run.rs`): the pending event's time (NaN: none), the end of the short
//! steps after the last event (-inf: none) and that event's settling time (0: none), 3 x f64;
//! then the run's own grid: its origin f64,
//! whether the grid is it (u8), and the point of it the run is going back to, time (NaN:
//! none) and units, f64 and u64.
//!
//! Error control (tag 1, `adaptive.rs`; its scratch arrays are not saved):
//!
//! | field | type |
//! |---|---|
//! | scheme: tag (0: generalised trapezoidal, 1: generalised-alpha) and its parameter (alpha, rho_inf) | u8, f64 |
//! | options: rtol, atol, h_min, h_max, hold | 5 x f64 |
//! | error weights: time scale, atol_q, atol_v, rtol | 4 x f64 |
//! | PI controller: order k, last error norm, last attempt rejected (0 or 1), hold | f64, f64, u8, f64 |
//! | next step size h, error norm of the last judged step | 2 x f64 |
//!
//! Version 9 is version 10 without the last contact event's settling time (read as 0: the
//! steps of a transient in progress stay at their shortest until it ends). Version 8 is version
//! 9 without the rates over the step before (read as none: the predictor
//! extrapolates with the last rates until it has both). Version 7 is version 8 without the
//! accelerations' rates (read as zero: the first step after
//! restoring it predicts at constant acceleration). Version 6 is version 7 without the
//! residual evaluations (read as zero). Version 5 is version
//! 6 without the multipliers' rates (read as zero: the first step after
//! restoring it predicts the last multipliers) and without the run's own grid (read as the
//! current grid: a run restored during a contact event's transient stays on the event's grid). Version 4 is version 5 without the held iteration matrix (read as none: the first step after
//! restoring it factorises a new one). Version 3 is version 4 without the contact events' state
//! (read as none pending). Version 1
//! is version 3 with fixed steps only (tag 0). Version 2 also kept an acceleration
//! history for the error estimate, which step doubling no longer
//! needs; its files with fixed steps are still read, those of error-controlled runs refused.
//! Snapshots of runs that stopped are not saved.

use std::path::Path;

use crate::adaptive::ErrorControl;
use crate::error::{Error, Result};
use crate::integrators::{RuleState, Scheme};
use crate::math::Vec3;
use crate::run::{Carried, Controller, FixedSteps, Fnv, HeldMatrix, Snapshot};
use crate::step_control::{AdaptiveOptions, ErrorWeights, PiController};

const MAGIC: &[u8; 8] = b"VNCLSNAP";
const VERSION: u32 = 10;
/// The oldest format version still read.
const OLDEST: u32 = 1;

fn file_error(path: &Path, problem: impl Into<String>) -> Error {
    Error::Snapshot {
        what: format!("snapshot file {}", path.display()),
        problem: problem.into(),
    }
}

/// Appends the encoding of the values.
struct Writer(Vec<u8>);

impl Writer {
    fn u32(&mut self, x: u32) {
        self.0.extend_from_slice(&x.to_le_bytes());
    }
    fn u64(&mut self, x: u64) {
        self.0.extend_from_slice(&x.to_le_bytes());
    }
    fn f64(&mut self, x: f64) {
        self.0.extend_from_slice(&x.to_bits().to_le_bytes());
    }
    fn vecs(&mut self, xs: &[Vec3]) {
        for x in xs.iter().flatten() {
            self.f64(*x);
        }
    }
    fn sized_vecs(&mut self, xs: &[Vec3]) {
        self.u64(xs.len() as u64);
        self.vecs(xs);
    }
    fn f64s(&mut self, xs: &[f64]) {
        for &x in xs {
            self.f64(x);
        }
    }
    /// A u64 count, then that many f64.
    fn sized_f64s(&mut self, xs: &[f64]) {
        self.u64(xs.len() as u64);
        self.f64s(xs);
    }

    /// The state of the error control (module documentation).
    fn error_control(&mut self, e: &ErrorControl) {
        let (tag, parameter) = match e.scheme {
            Scheme::GeneralizedTrapezoidal { alpha } => (0, alpha),
            Scheme::GeneralizedAlpha { rho_inf } => (1, rho_inf),
        };
        self.0.push(tag);
        self.f64(parameter);
        let (c, w) = (&e.control, &e.weights);
        self.f64s(&[c.rtol, c.atol, c.h_min, c.h_max, c.hold]);
        self.f64s(&[w.time_scale, w.atol_q, w.atol_v, w.rtol]);
        self.f64s(&[e.pi.k, e.pi.previous]);
        self.0.push(e.pi.rejected as u8);
        self.f64s(&[e.pi.hold, e.h, e.err]);
    }
}

/// Reads the values back, failing on a short file.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
    path: &'a Path,
}

impl Reader<'_> {
    fn take(&mut self, n: usize) -> Result<&[u8]> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len());
        let end = end.ok_or_else(|| {
            file_error(
                self.path,
                "the file is truncated or corrupt: save the snapshot again",
            )
        })?;
        let out = &self.bytes[self.at..end];
        self.at = end;
        Ok(out)
    }
    fn u32(&mut self) -> Result<u32> {
        Ok(u32::from_le_bytes(
            self.take(4)?.try_into().expect("4 bytes"),
        ))
    }
    fn u64(&mut self) -> Result<u64> {
        Ok(u64::from_le_bytes(
            self.take(8)?.try_into().expect("8 bytes"),
        ))
    }
    /// A u64 count, then that many f64.
    fn sized_f64s(&mut self) -> Result<Vec<f64>> {
        let count = self.usize()?;
        if count.saturating_mul(8) > self.bytes.len() - self.at {
            return Err(file_error(self.path, "the file is truncated or corrupt"));
        }
        (0..count).map(|_| self.f64()).collect()
    }
    fn usize(&mut self) -> Result<usize> {
        let x = self.u64()?;
        usize::try_from(x).map_err(|_| file_error(self.path, format!("a count of {x} is corrupt")))
    }
    fn f64(&mut self) -> Result<f64> {
        Ok(f64::from_bits(self.u64()?))
    }
    fn vecs(&mut self, n: usize) -> Result<Vec<Vec3>> {
        // The length is checked against the bytes left before anything is allocated.
        if n.saturating_mul(24) > self.bytes.len() - self.at {
            return Err(file_error(
                self.path,
                "the file is truncated or corrupt: save the snapshot again",
            ));
        }
        (0..n)
            .map(|_| Ok([self.f64()?, self.f64()?, self.f64()?]))
            .collect()
    }
    fn sized_vecs(&mut self) -> Result<Vec<Vec3>> {
        let n = self.usize()?;
        self.vecs(n)
    }
    fn f64s<const N: usize>(&mut self) -> Result<[f64; N]> {
        let mut out = [0.0; N];
        for x in &mut out {
            *x = self.f64()?;
        }
        Ok(out)
    }
    fn flag(&mut self, what: &str) -> Result<bool> {
        match self.take(1)?[0] {
            0 => Ok(false),
            1 => Ok(true),
            x => Err(file_error(
                self.path,
                format!("{what} {x} is corrupt (0 or 1)"),
            )),
        }
    }

    /// The state of the error control (module documentation), its scratch arrays empty.
    fn error_control(&mut self) -> Result<ErrorControl> {
        let tag = self.take(1)?[0];
        let parameter = self.f64()?;
        let scheme = match tag {
            0 => Scheme::GeneralizedTrapezoidal { alpha: parameter },
            1 => Scheme::GeneralizedAlpha { rho_inf: parameter },
            _ => return Err(file_error(self.path, format!("unknown time rule {tag}"))),
        };
        let [rtol, atol, h_min, h_max, hold] = self.f64s()?;
        let control = AdaptiveOptions {
            rtol,
            atol,
            h_min,
            h_max,
            hold,
        };
        let [time_scale, atol_q, atol_v, rtol] = self.f64s()?;
        let weights = ErrorWeights {
            time_scale,
            atol_q,
            atol_v,
            rtol,
        };
        let [k, previous] = self.f64s()?;
        let rejected = self.flag("the PI controller's rejected flag")?;
        let [hold, h, err] = self.f64s()?;
        let pi = PiController {
            k,
            previous,
            rejected,
            hold,
        };
        Ok(ErrorControl {
            scheme,
            rule: scheme.rule(),
            control,
            weights,
            pi,
            h,
            rule_half: None,
            err,
            free: Vec::new(),
            projection: Vec::new(),
            e_q: Vec::new(),
            e_v: Vec::new(),
            q_big: Vec::new(),
            v_big: Vec::new(),
            lambda_big: Vec::new(),
            q_mid: Vec::new(),
            v_mid: Vec::new(),
            lambda_mid: Vec::new(),
        })
    }
}

impl Snapshot {
    /// Saves the snapshot to a file at `path` (format in the module documentation).
    ///
    /// # Errors
    /// [`Error::Snapshot`] when the snapshot is of a run that stopped, or when the file cannot
    /// be written.
    pub fn save(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = path.as_ref();
        if let Err(e) = &self.status {
            return Err(file_error(
                path,
                format!("the run had stopped ({e}): save a snapshot taken before it stopped"),
            ));
        }
        let c = &self.carried;
        let mut w = Writer(Vec::new());
        w.0.extend_from_slice(MAGIC);
        w.u32(VERSION);
        w.u64(self.fingerprint);
        w.u64(c.q.len() as u64);
        w.u64(c.lambda.len() as u64);
        w.f64(c.t);
        w.vecs(&c.q);
        w.vecs(&c.v);
        w.vecs(&c.acc);
        w.vecs(&c.acc_rate);
        w.f64(c.acc_rate_step);
        w.vecs(&c.acc_rate_before);
        w.f64(c.acc_rate_before_step);
        w.0.push(u8::from(c.alternating));
        for &x in c.lambda.iter().chain(&c.lambda_rate) {
            w.f64(x);
        }
        w.sized_vecs(&c.rule.acceleration);
        w.sized_vecs(&c.rule.algorithmic);
        w.sized_vecs(&c.rule.predicted_q);
        w.sized_vecs(&c.rule.predicted_v);
        match &c.controller {
            Controller::Fixed(fixed) => {
                w.0.push(0);
                w.u32(fixed.top);
                w.f64(fixed.unit);
                w.u64(fixed.units);
                w.u32(fixed.level);
                w.f64(fixed.t_grid);
                w.f64(fixed.event_stop.unwrap_or(f64::NAN));
                w.f64(fixed.settle_until);
                w.f64(fixed.settle_time);
                w.f64(fixed.origin);
                w.0.push(fixed.home as u8);
                let (at, units) = fixed.rejoin.unwrap_or((f64::NAN, 0));
                w.f64(at);
                w.u64(units);
            }
            Controller::Adaptive(control) => {
                w.0.push(1);
                w.error_control(control);
            }
        }
        for x in [
            c.step,
            c.next_output,
            self.rows,
            self.steps_taken,
            self.steps_rejected,
            self.accepted,
            self.factorisations,
            self.residual_evaluations,
        ] {
            w.u64(x as u64);
        }
        match &self.matrix {
            None => w.0.push(0),
            Some(held) => {
                w.0.push(1);
                w.0.push(held.ggl as u8 | (held.factored as u8) << 1);
                w.f64s(&[held.key[0], held.key[1], held.rate]);
                w.sized_f64s(&held.values);
                w.sized_f64s(&held.point);
            }
        }
        let mut h = Fnv::new();
        h.write(&w.0);
        w.u64(h.finish());
        std::fs::write(path, &w.0).map_err(|e| file_error(path, format!("cannot be written ({e})")))
    }

    /// Loads a snapshot saved by [`Snapshot::save`]; restore it with
    /// [`crate::Simulation::try_restore`] into a simulation of the same model.
    ///
    /// # Errors
    /// [`Error::Snapshot`] when the file cannot be read, is not a snapshot file, is of a format
    /// version this vinculo does not read (1 to 9 are; of 2 only fixed steps), or is truncated or corrupt (its
    /// checksum does not match).
    pub fn load(path: impl AsRef<Path>) -> Result<Snapshot> {
        let path = path.as_ref();
        let bytes =
            std::fs::read(path).map_err(|e| file_error(path, format!("cannot be read ({e})")))?;
        if bytes.len() < MAGIC.len() + 4 + 8 || &bytes[..MAGIC.len()] != MAGIC {
            return Err(file_error(
                path,
                "not a vinculo snapshot file (no VNCLSNAP header): give a file written by \
                 save_snapshot",
            ));
        }
        let (body, sum) = bytes.split_at(bytes.len() - 8);
        let mut h = Fnv::new();
        h.write(body);
        let version = u32::from_le_bytes(body[8..12].try_into().expect("4 bytes"));
        if !(OLDEST..=VERSION).contains(&version) {
            return Err(file_error(
                path,
                format!(
                    "format version {version}; this vinculo reads versions {OLDEST} to \
                     {VERSION}: save the snapshot again with this vinculo"
                ),
            ));
        }
        if h.finish() != u64::from_le_bytes(sum.try_into().expect("8 bytes")) {
            return Err(file_error(
                path,
                "the file is corrupt (checksum mismatch): save the snapshot again",
            ));
        }
        let mut r = Reader {
            bytes: body,
            at: 12,
            path,
        };
        let fingerprint = r.u64()?;
        let n = r.usize()?;
        let m = r.usize()?;
        let t = r.f64()?;
        let q = r.vecs(n)?;
        let v = r.vecs(n)?;
        let acc = r.vecs(n)?;
        let (acc_rate, acc_rate_step) = if version >= 8 {
            (r.vecs(n)?, r.f64()?)
        } else {
            (vec![[0.0; 3]; n], 0.0)
        };
        let (acc_rate_before, acc_rate_before_step, alternating) = if version >= 9 {
            (r.vecs(n)?, r.f64()?, r.take(1)?[0] == 1)
        } else {
            (vec![[0.0; 3]; n], 0.0, false)
        };
        let rates = if version >= 6 { m } else { 0 };
        if (m + rates).saturating_mul(8) > body.len() - r.at {
            return Err(file_error(path, "the file is truncated or corrupt"));
        }
        let lambda = (0..m).map(|_| r.f64()).collect::<Result<Vec<f64>>>()?;
        let mut lambda_rate = (0..rates).map(|_| r.f64()).collect::<Result<Vec<f64>>>()?;
        lambda_rate.resize(m, 0.0);
        let rule = RuleState {
            acceleration: r.sized_vecs()?,
            algorithmic: r.sized_vecs()?,
            predicted_q: r.sized_vecs()?,
            predicted_v: r.sized_vecs()?,
        };
        let tag = r.take(1)?[0];
        let controller = match tag {
            0 => {
                let (top, unit, units, level, t_grid) =
                    (r.u32()?, r.f64()?, r.u64()?, r.u32()?, r.f64()?);
                let (event_stop, settle_until) = if version >= 4 {
                    (Some(r.f64()?).filter(|t| !t.is_nan()), r.f64()?)
                } else {
                    (None, f64::NEG_INFINITY)
                };
                let settle_time = if version >= 10 { r.f64()? } else { 0.0 };
                let (origin, home, rejoin) = if version >= 6 {
                    let (origin, home) = (r.f64()?, r.take(1)?[0] == 1);
                    let (at, units) = (r.f64()?, r.u64()?);
                    (origin, home, Some((at, units)).filter(|(t, _)| !t.is_nan()))
                } else {
                    (t_grid, true, None)
                };
                Controller::Fixed(FixedSteps {
                    top,
                    unit,
                    units,
                    level,
                    t_grid,
                    event_stop,
                    settle_until,
                    settle_time,
                    origin,
                    home,
                    rejoin,
                })
            }
            1 if version >= 3 => Controller::Adaptive(Box::new(r.error_control()?)),
            1 if version == 2 => {
                return Err(file_error(
                    path,
                    "an error-controlled run saved in format version 2, whose error estimate \
                     this vinculo no longer has: rerun it from its start",
                ))
            }
            _ => {
                return Err(file_error(
                    path,
                    format!("unknown step controller {tag} in a version {version} file"),
                ))
            }
        };
        let mut counts = [0usize; 8];
        let stored = if version >= 7 { 8 } else { 7 };
        for x in &mut counts[..stored] {
            *x = r.usize()?;
        }
        let matrix = if version >= 5 && r.take(1)?[0] == 1 {
            let kind = r.take(1)?[0];
            let (ggl, factored) = (kind & 1 == 1, kind & 2 == 2);
            let (key, rate) = ([r.f64()?, r.f64()?], r.f64()?);
            let values = r.sized_f64s()?;
            let point = r.sized_f64s()?;
            Some(HeldMatrix {
                key,
                rate,
                point,
                ggl,
                factored,
                values,
            })
        } else {
            None
        };
        if r.at != body.len() {
            return Err(file_error(path, "the file is corrupt (trailing bytes)"));
        }
        let [step, next_output, rows, steps_taken, steps_rejected, accepted, factorisations, residual_evaluations] =
            counts;
        Ok(Snapshot {
            carried: Carried {
                t,
                q,
                v,
                acc,
                acc_rate,
                acc_rate_step,
                acc_rate_before,
                acc_rate_before_step,
                alternating,
                lambda,
                lambda_rate,
                rule,
                controller,
                step,
                next_output,
            },
            rows,
            steps_taken,
            steps_rejected,
            accepted,
            factorisations,
            residual_evaluations,
            status: Ok(()),
            fingerprint,
            run: 0,
            matrix,
        })
    }
}
