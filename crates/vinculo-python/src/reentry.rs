//! Re-entrant use: a user function of a running system that calls back into a run, or an
//! evaluation of the user groups, of the same system.
//!
//! The core holds a user group's lock while it calls the group's Python function (the lock
//! guards the group's cache and call counts). A run of the same system, or of a copy of it (the
//! copies share their user groups), started from inside that function would wait for that lock
//! on the very thread that holds it: a deadlock, with the GIL released or held, that Ctrl-C
//! cannot end. Every user function call is therefore marked on its thread with the system it
//! belongs to (the slot of the system's pending exception, which the system, its copies and
//! all their groups share), and the entry points that evaluate user groups refuse, with
//! `ReentrantRunError`, a system whose function is being called on this thread. User functions
//! are only ever called on the thread of their run (models with user groups assemble serially).

use crate::errors::raise;
use crate::user_physics::PendingError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::cell::RefCell;
use std::sync::Arc;

thread_local! {
    /// The systems (their pending-exception slots' addresses) whose user function is being
    /// called on this thread, innermost last.
    static CALLING: RefCell<Vec<usize>> = const { RefCell::new(Vec::new()) };
}

/// The identity of a system and its copies: the address of their shared pending slot.
fn identity(pending: &PendingError) -> usize {
    Arc::as_ptr(pending) as *const () as usize
}

/// Marks a user function of the system of `pending` as being called on this thread, until
/// dropped.
pub struct InUserFunction(usize);

impl InUserFunction {
    /// Marks the call (the call's adapter holds the result while the function runs).
    pub fn enter(pending: &PendingError) -> InUserFunction {
        let id = identity(pending);
        CALLING.with(|c| c.borrow_mut().push(id));
        InUserFunction(id)
    }
}

impl Drop for InUserFunction {
    fn drop(&mut self) {
        CALLING.with(|c| {
            let mut c = c.borrow_mut();
            if let Some(k) = c.iter().rposition(|&x| x == self.0) {
                c.remove(k);
            }
        });
    }
}

/// `ReentrantRunError` when a user function of the system of `pending` is being called on this
/// thread (`call`: what the user function called, for the message).
pub fn refuse_reentry(py: Python<'_>, pending: &PendingError, call: &str) -> PyResult<()> {
    let id = identity(pending);
    if !CALLING.with(|c| c.borrow().contains(&id)) {
        return Ok(());
    }
    let details = PyDict::new(py);
    details.set_item("call", call)?;
    Err(raise(
        py,
        "ReentrantRunError",
        format!(
            "{call}() was called from inside a user function (force or constraint group) of the \
             system being run, or of a copy of it, which shares its user groups: the run is in the \
             middle of that function's call, which a second run or evaluation of the same groups \
             cannot share (it would wait for it forever); build a separate System for the inner \
             run, or move the inner computation out of the user function"
        ),
        details,
    ))
}
