//! User force and constraint groups written in Python: adapters from Python callables to the
//! core's `ForceGroup` / `ConstraintGroup` traits, and the `UserGroup` handle with the call
//! counts.
//!
//! Each batched evaluation takes the GIL (`Python::attach`; the run itself holds no GIL), copies
//! the group's inputs into new numpy arrays, calls the function once and copies its output back
//! after checking the shape. An exception is kept (the first one per system) so that the run can
//! re-raise it as the cause of `UserFunctionError`.

use crate::errors::{invalid, to_py};
use crate::reentry::{refuse_reentry, InUserFunction};
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use std::sync::{Arc, Mutex};
use vinculo::constraints::{ConstraintCall, ConstraintGroup, UserConstraints};
use vinculo::forces::{ForceGroup, UserForces};
use vinculo::user::{GroupElements, UserFailure};

/// The first exception raised by a user function of a system, kept for the run to chain.
pub type PendingError = Arc<Mutex<Option<PyErr>>>;

/// Shape of a group array: (k, 3) for arity 1, (k, a, 3) for arity a >= 2.
fn state_shape(k: usize, arity: usize) -> Vec<usize> {
    if arity == 1 {
        vec![k, 3]
    } else {
        vec![k, arity, 3]
    }
}

fn shape_text(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(|x| x.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// What every adapter shares: the group's size and where exceptions go.
struct Calling {
    k: usize,
    arity: usize,
    pending: PendingError,
}

impl Calling {
    /// The numpy array of a group's positions or velocities.
    fn state<'py>(&self, py: Python<'py>, x: &[f64]) -> PyResult<Bound<'py, PyAny>> {
        Ok(PyArray1::from_slice(py, x)
            .reshape(state_shape(self.k, self.arity))?
            .into_any())
    }

    /// Keeps the exception (the first one) and reports it.
    fn raised(&self, py: Python<'_>, e: PyErr) -> UserFailure {
        let text = match e.value(py).get_type().name() {
            Ok(name) => format!("{name}: {}", e.value(py)),
            Err(_) => e.value(py).to_string(),
        };
        let mut slot = self.pending.lock().unwrap_or_else(|p| p.into_inner());
        if slot.is_none() {
            *slot = Some(e);
        }
        UserFailure::Raised(text)
    }

    /// Copies `obj` (any float array-like) into `out` if its shape is one of `shapes` (the first
    /// is the documented one).
    fn read(
        &self,
        py: Python<'_>,
        obj: &Bound<'_, PyAny>,
        shapes: &[Vec<usize>],
        out: &mut [f64],
    ) -> Result<(), UserFailure> {
        let expected = shape_text(&shapes[0]);
        let array = match obj.extract::<PyReadonlyArrayDyn<'_, f64>>() {
            Ok(a) => a,
            Err(_) => {
                // numpy would drop the imaginary parts (with only a ComplexWarning): refuse them.
                let complex = py
                    .import("numpy")
                    .and_then(|np| np.getattr("iscomplexobj"))
                    .and_then(|f| f.call1((obj,)))
                    .and_then(|r| r.extract::<bool>())
                    .unwrap_or(false);
                if complex {
                    return Err(UserFailure::Shape {
                        returned: "a complex-valued array (its imaginary parts would be lost)"
                            .to_string(),
                        expected: format!("real floats of shape {expected}"),
                    });
                }
                let converted = py
                    .import("numpy")
                    .and_then(|np| np.getattr("asarray"))
                    .and_then(|asarray| {
                        let kw = PyDict::new(py);
                        kw.set_item("dtype", "float64")?;
                        asarray.call((obj,), Some(&kw))
                    });
                match converted.and_then(|a| a.extract::<PyReadonlyArrayDyn<'_, f64>>()) {
                    Ok(a) => a,
                    Err(_) => {
                        let kind = obj
                            .get_type()
                            .name()
                            .map(|n| n.to_string())
                            .unwrap_or_default();
                        return Err(UserFailure::Shape {
                            returned: format!("a {kind} that is not an array of floats"),
                            expected,
                        });
                    }
                }
            }
        };
        if !shapes.iter().any(|s| s.as_slice() == array.shape()) {
            return Err(UserFailure::Shape {
                returned: format!("an array of shape {}", shape_text(array.shape())),
                expected,
            });
        }
        for (o, x) in out.iter_mut().zip(array.as_array().iter()) {
            *o = *x;
        }
        Ok(())
    }
}

/// A force group's Python functions.
pub struct PyForceFunctions {
    calling: Calling,
    force: Py<PyAny>,
    jacobian: Option<Py<PyAny>>,
}

impl ForceGroup for PyForceFunctions {
    fn force(&self, t: f64, q: &[f64], v: &[f64], f: &mut [f64]) -> Result<(), UserFailure> {
        let c = &self.calling;
        Python::attach(|py| {
            let args = (t, c.state(py, q), c.state(py, v));
            let args = match args {
                (t, Ok(q), Ok(v)) => (t, q, v),
                (_, Err(e), _) | (_, _, Err(e)) => return Err(c.raised(py, e)),
            };
            let inside = InUserFunction::enter(&c.pending);
            let out = self.force.call1(py, args).map_err(|e| c.raised(py, e));
            drop(inside);
            let out = out?;
            c.read(py, out.bind(py), &[state_shape(c.k, c.arity)], f)
        })
    }

    fn has_jacobian(&self) -> bool {
        self.jacobian.is_some()
    }

    fn jacobian(
        &self,
        t: f64,
        q: &[f64],
        v: &[f64],
        dq: &mut [f64],
        dv: &mut [f64],
    ) -> Result<(), UserFailure> {
        let c = &self.calling;
        let Some(jacobian) = &self.jacobian else {
            return Err(UserFailure::Raised("no jacobian function".into()));
        };
        let n = 3 * c.arity;
        let shape = vec![c.k, n, n];
        Python::attach(|py| {
            let (qa, va) = match (c.state(py, q), c.state(py, v)) {
                (Ok(q), Ok(v)) => (q, v),
                (Err(e), _) | (_, Err(e)) => return Err(c.raised(py, e)),
            };
            let inside = InUserFunction::enter(&c.pending);
            let out = jacobian.call1(py, (t, qa, va));
            drop(inside);
            let out = out.map_err(|e| c.raised(py, e))?;
            let pair = out.bind(py);
            let pair = match pair.cast::<PyTuple>() {
                Ok(p) if p.len() == 2 => p,
                _ => {
                    return Err(UserFailure::Shape {
                        returned: format!(
                            "a {}",
                            pair.get_type()
                                .name()
                                .map(|n| n.to_string())
                                .unwrap_or_default()
                        ),
                        expected: format!(
                            "a tuple (df_dq, df_dv) of two arrays of shape {}",
                            shape_text(&shape)
                        ),
                    })
                }
            };
            let first = pair.get_item(0).map_err(|e| c.raised(py, e))?;
            let second = pair.get_item(1).map_err(|e| c.raised(py, e))?;
            c.read(py, &first, std::slice::from_ref(&shape), dq)?;
            c.read(py, &second, std::slice::from_ref(&shape), dv)
        })
    }
}

/// A constraint group's Python functions (None: finite differences in the core).
pub struct PyConstraintFunctions {
    calling: Calling,
    functions: [Option<Py<PyAny>>; 5],
}

impl ConstraintGroup for PyConstraintFunctions {
    fn supplies(&self, call: ConstraintCall) -> bool {
        self.functions[call as usize].is_some()
    }

    fn evaluate(
        &self,
        call: ConstraintCall,
        t: f64,
        q: &[f64],
        v: &[f64],
        out: &mut [f64],
    ) -> Result<(), UserFailure> {
        let c = &self.calling;
        let Some(function) = &self.functions[call as usize] else {
            return Err(UserFailure::Raised(format!("no {} function", call.name())));
        };
        let (k, n) = (c.k, 3 * c.arity);
        let shapes: Vec<Vec<usize>> = match call {
            ConstraintCall::Gradient if c.arity == 1 => vec![vec![k, 1, 3], vec![k, 3]],
            ConstraintCall::Gradient => vec![vec![k, c.arity, 3]],
            ConstraintCall::Hessian => vec![vec![k, n, n]],
            _ => vec![vec![k]],
        };
        Python::attach(|py| {
            let qa = c.state(py, q).map_err(|e| c.raised(py, e))?;
            let _inside = InUserFunction::enter(&c.pending);
            let result = if call == ConstraintCall::Gamma {
                let va = c.state(py, v).map_err(|e| c.raised(py, e))?;
                function.call1(py, (t, qa, va))
            } else {
                function.call1(py, (t, qa))
            };
            let result = result.map_err(|e| c.raised(py, e))?;
            c.read(py, result.bind(py), &shapes, out)
        })
    }
}

/// Reads `particles`: (k,) integers (arity 1) or (k, a) integers (arity a, any a >= 1).
pub fn elements(particles: &Bound<'_, PyAny>) -> PyResult<GroupElements> {
    let py = particles.py();
    let bad = |why: &str| {
        invalid(
            "particles",
            particles
                .repr()
                .map(|r| r.to_string())
                .unwrap_or_default()
                .chars()
                .take(80)
                .collect::<String>(),
            why,
        )
    };
    let array = py
        .import("numpy")?
        .getattr("asarray")?
        .call1((particles,))
        .map_err(|_| bad("expected a (k,) or (k, a) array of particle indices"))?;
    let kind: String = array.getattr("dtype")?.getattr("kind")?.extract()?;
    if !(kind == "i" || kind == "u") {
        return Err(bad(
            "expected integer particle indices (ParticleId.index), shape (k,) or (k, a)",
        ));
    }
    let shape: Vec<usize> = array.getattr("shape")?.extract()?;
    let flat: Vec<i64> = array
        .call_method1("reshape", (-1,))?
        .call_method0("tolist")?
        .extract()?;
    if let Some(&p) = flat.iter().find(|&&p| p < 0) {
        return Err(bad(&format!(
            "particle index {p} is negative: give indices 0 .. n-1"
        )));
    }
    let flat: Vec<usize> = flat.into_iter().map(|p| p as usize).collect();
    let arity = match shape.as_slice() {
        [_] => 1,
        [_, a] if *a >= 1 => *a,
        _ => {
            return Err(bad(&format!(
                "an array of shape {} is neither (k,) (one particle per element) nor (k, a) \
                 (a >= 1 particles per element)",
                shape_text(&shape)
            )))
        }
    };
    GroupElements::new(arity, flat).map_err(to_py)
}

/// Checks that `f` is callable (or absent when optional).
pub fn callable(name: &str, f: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Py<PyAny>>> {
    match f {
        None => Ok(None),
        Some(f) if f.is_none() => Ok(None),
        Some(f) if f.is_callable() => Ok(Some(f.clone().unbind())),
        Some(f) => Err(invalid(
            name,
            f.repr().map(|r| r.to_string()).unwrap_or_default(),
            "expected a function (callable) of numpy arrays, or None",
        )),
    }
}

/// The adapter of a force group.
pub fn force_functions(
    k: usize,
    arity: usize,
    pending: PendingError,
    force: Py<PyAny>,
    jacobian: Option<Py<PyAny>>,
) -> PyForceFunctions {
    PyForceFunctions {
        calling: Calling { k, arity, pending },
        force,
        jacobian,
    }
}

/// The adapter of a constraint group; `functions` in the order of `ConstraintCall::ALL`.
pub fn constraint_functions(
    k: usize,
    arity: usize,
    pending: PendingError,
    functions: [Option<Py<PyAny>>; 5],
) -> PyConstraintFunctions {
    PyConstraintFunctions {
        calling: Calling { k, arity, pending },
        functions,
    }
}

enum Group {
    Force(Arc<UserForces>),
    Constraint(Arc<UserConstraints>, usize),
}

/// A group of user-defined forces or constraints in a System: its size and the calls of its
/// functions during the last run.
#[pyclass(name = "UserGroup", module = "vinculo._core", frozen)]
pub struct PyUserGroup {
    group: Group,
    /// The pending-exception slot of the group's system (which identifies the system for
    /// [`refuse_reentry`]).
    pending: PendingError,
}

impl PyUserGroup {
    pub fn force(group: Arc<UserForces>, pending: PendingError) -> PyUserGroup {
        PyUserGroup {
            group: Group::Force(group),
            pending,
        }
    }

    pub fn constraint(
        group: Arc<UserConstraints>,
        first: usize,
        pending: PendingError,
    ) -> PyUserGroup {
        PyUserGroup {
            group: Group::Constraint(group, first),
            pending,
        }
    }

    /// The call counts. Read without the GIL: a run holds a group's lock while it waits for the
    /// GIL to call the group's function (from inside such a call, where the lock is held on
    /// this thread, `ReentrantRunError`).
    fn counts(
        &self,
        py: Python<'_>,
        call: &str,
    ) -> PyResult<Vec<(&'static str, vinculo::user::CallCount)>> {
        refuse_reentry(py, &self.pending, call)?;
        Ok(py.detach(|| self.counts_now()))
    }

    fn counts_now(&self) -> Vec<(&'static str, vinculo::user::CallCount)> {
        match &self.group {
            Group::Force(g) => {
                let c = g.counts();
                vec![("force", c[0]), ("jacobian", c[1])]
            }
            Group::Constraint(g, _) => {
                let c = g.counts();
                ConstraintCall::ALL
                    .iter()
                    .map(|call| (call.name(), c[*call as usize]))
                    .collect()
            }
        }
    }
}

#[pymethods]
impl PyUserGroup {
    /// The group's name.
    #[getter]
    fn name(&self) -> String {
        match &self.group {
            Group::Force(g) => g.name.clone(),
            Group::Constraint(g, _) => g.name.clone(),
        }
    }

    /// "force" or "constraint".
    #[getter]
    fn kind(&self) -> &'static str {
        match &self.group {
            Group::Force(_) => "force",
            Group::Constraint(..) => "constraint",
        }
    }

    /// Particles per element (1 or 2).
    #[getter]
    fn arity(&self) -> usize {
        match &self.group {
            Group::Force(g) => g.elements.arity(),
            Group::Constraint(g, _) => g.elements.arity(),
        }
    }

    /// Number of elements k.
    fn __len__(&self) -> usize {
        match &self.group {
            Group::Force(g) => g.elements.len(),
            Group::Constraint(g, _) => g.elements.len(),
        }
    }

    /// Indices of the group's constraint equations (its multipliers' columns in a Solution),
    /// one per element; empty for a force group.
    #[getter]
    fn constraint_indices(&self) -> Vec<usize> {
        match &self.group {
            Group::Force(_) => Vec::new(),
            Group::Constraint(g, first) => (*first..*first + g.elements.len()).collect(),
        }
    }

    /// Calls of each function during the last run (counted from its start), by name: "force",
    /// "jacobian" for a force group; "phi", "gradient", "hessian", "phi_t", "gamma" for a
    /// constraint group. Finite-difference evaluations count as calls of the function they
    /// call.
    #[getter]
    fn calls<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (name, c) in self.counts(py, "UserGroup.calls")? {
            d.set_item(name, c.calls)?;
        }
        Ok(d)
    }

    /// Wall time (s) spent in each function during the last run, by name, including the
    /// crossing (taking the GIL, copying the arrays in and out, checking the shapes).
    #[getter]
    fn seconds<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (name, c) in self.counts(py, "UserGroup.seconds")? {
            d.set_item(name, c.seconds)?;
        }
        Ok(d)
    }

    /// Evaluates function `call` of the group at time `t` for the group's positions `q` (and
    /// velocities `v`), arrays (k, 3) or (k, 2, 3), as the core does during a run (counts and
    /// caches untouched). "force" gives the forces; "jacobian" the pair (df_dq, df_dv); "phi",
    /// "gradient", "hessian", "phi_t", "gamma" the constraint terms. `finite_differences=True`
    /// gives the core's finite-difference value instead of the user function's (also what is
    /// used when that function is not supplied): compare them to check a derivative.
    #[pyo3(signature = (call, t, q, v=None, finite_differences=false))]
    fn evaluate<'py>(
        &self,
        py: Python<'py>,
        call: &str,
        t: f64,
        q: &Bound<'py, PyAny>,
        v: Option<&Bound<'py, PyAny>>,
        finite_differences: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (k, arity) = (self.__len__(), self.arity());
        let n = 3 * arity;
        let shape = state_shape(k, arity);
        let calling = Calling {
            k,
            arity,
            pending: Default::default(),
        };
        let input = |x: Option<&Bound<'py, PyAny>>, what: &str| -> PyResult<Vec<f64>> {
            let mut out = vec![0.0; k * n];
            if let Some(x) = x {
                calling
                    .read(py, x, std::slice::from_ref(&shape), &mut out)
                    .map_err(|f| invalid(what, format!("{f:?}"), "expected the group's shape"))?;
            }
            Ok(out)
        };
        let qf = input(Some(q), "q")?;
        let vf = input(v, "v")?;
        let array = |x: Vec<f64>, shape: Vec<usize>| -> PyResult<Bound<'py, PyAny>> {
            Ok(PyArray1::from_vec(py, x).reshape(shape)?.into_any())
        };
        match (&self.group, call) {
            (Group::Force(g), "force" | "jacobian") => {
                let [f, dq, dv] = py
                    .detach(|| g.evaluate(t, &qf, &vf, finite_differences))
                    .map_err(crate::errors::to_py)?;
                if call == "force" {
                    array(f, shape)
                } else {
                    let pair = (array(dq, vec![k, n, n])?, array(dv, vec![k, n, n])?);
                    Ok(pair.into_pyobject(py)?.into_any())
                }
            }
            (Group::Constraint(g, _), name)
                if ConstraintCall::ALL.iter().any(|c| c.name() == name) =>
            {
                let which = *ConstraintCall::ALL
                    .iter()
                    .find(|c| c.name() == name)
                    .expect("found");
                let out = py
                    .detach(|| g.evaluate(which, t, &qf, &vf, finite_differences))
                    .map_err(crate::errors::to_py)?;
                let out_shape = match which {
                    ConstraintCall::Gradient => vec![k, arity, 3],
                    ConstraintCall::Hessian => vec![k, n, n],
                    _ => vec![k],
                };
                array(out, out_shape)
            }
            _ => Err(invalid(
                "call",
                call,
                match &self.group {
                    Group::Force(_) => "a force group has 'force' and 'jacobian'",
                    Group::Constraint(..) => {
                        "a constraint group has 'phi', 'gradient', 'hessian', 'phi_t' and 'gamma'"
                    }
                },
            )),
        }
    }

    fn __repr__(&self) -> String {
        format!(
            "UserGroup({:?}, {} {} elements of arity {})",
            self.name(),
            self.__len__(),
            self.kind(),
            self.arity()
        )
    }
}
