//! Adding groups of user-defined forces and constraints to a system, and their run-time state.
//!
//! Each element of a group becomes one force element ([`Force::User`]) or one constraint
//! equation ([`Constraint::User`]), numbered after the elements already in the system, so the
//! assembly, the schemes and the analyses see them as they see the built-in kinds.
//!
//! A group is shared (`Arc`): a clone of the system shares its groups' functions, caches and
//! call counts, so runs of clones must not overlap in time if their counts are to be read.

use super::System;
use crate::constraints::{Constraint, ConstraintGroup, UserConstraint, UserConstraints};
use crate::error::{positive, Error, Result};
use crate::forces::{Force, ForceGroup, UserForce, UserForces};
use crate::user::GroupElements;
use std::sync::Arc;

impl System {
    /// Checks a group's elements: at least one element, particle indices in range, no particle
    /// twice in one element.
    fn check_elements(&self, what: &str, elements: &GroupElements) -> Result<()> {
        if elements.is_empty() {
            return Err(Error::InvalidParameter {
                name: format!("number of elements of {what}"),
                value: 0.0,
                expected: "must be >= 1: give the particles of at least one element".into(),
            });
        }
        let count = self.particles().len();
        for e in elements.iter() {
            for (x, &p) in e.iter().enumerate() {
                if p >= count {
                    return Err(Error::UnknownParticle { index: p, count });
                }
                if e[..x].contains(&p) {
                    return Err(Error::SameParticle {
                        what: what.into(),
                        particle: p,
                    });
                }
            }
        }
        Ok(())
    }

    /// Adds a group of `elements.len()` force elements, `elements.arity()` particles each
    /// (any number), computed by `functions` for the whole group at once. `name` names it in
    /// messages (default "force group N").
    pub fn add_user_force_group(
        &mut self,
        elements: GroupElements,
        functions: Box<dyn ForceGroup>,
        name: Option<String>,
    ) -> Result<Arc<UserForces>> {
        let name = name.unwrap_or_else(|| format!("force group {}", self.user_forces.len()));
        self.check_elements(&format!("user force group '{name}'"), &elements)?;
        let group = Arc::new(UserForces::new(name, elements, functions));
        for e in 0..group.elements.len() {
            self.forces
                .push(Force::User(UserForce::new(group.clone(), e)));
        }
        self.user_forces.push(group.clone());
        Ok(group)
    }

    /// Adds a group of constraint equations, one per element, computed by `functions` for the
    /// whole group at once; `scale` is s such that s Phi is a length. Returns the group and the
    /// index of its first equation (the others follow in element order).
    pub fn add_user_constraint_group(
        &mut self,
        elements: GroupElements,
        functions: Box<dyn ConstraintGroup>,
        scale: f64,
        name: Option<String>,
    ) -> Result<(Arc<UserConstraints>, usize)> {
        let name =
            name.unwrap_or_else(|| format!("constraint group {}", self.user_constraints.len()));
        let what = format!("user constraint group '{name}'");
        self.check_elements(&what, &elements)?;
        let scale = positive(format!("scale of {what}"), scale)?;
        for (e, parts) in elements.iter().enumerate() {
            if parts.iter().all(|&p| self.particles()[p].fixed) {
                return Err(Error::ConstraintOnFixedParticles {
                    what: format!("element {e} of {what}"),
                });
            }
        }
        let first = self.constraints.len();
        let group = Arc::new(UserConstraints::new(name, elements, scale, functions));
        for e in 0..group.elements.len() {
            self.push_constraint(Constraint::User(UserConstraint::new(group.clone(), e)))?;
        }
        self.user_constraints.push(group.clone());
        Ok((group, first))
    }

    /// True when the system has user force or constraint groups or user laws (whose functions
    /// are called from the run's thread only: such models assemble serially).
    pub fn has_user_groups(&self) -> bool {
        !(self.user_forces.is_empty()
            && self.user_constraints.is_empty()
            && self.user_laws.is_empty())
    }

    /// The user force groups.
    pub fn user_force_groups(&self) -> &[Arc<UserForces>] {
        &self.user_forces
    }

    /// The user constraint groups.
    pub fn user_constraint_groups(&self) -> &[Arc<UserConstraints>] {
        &self.user_constraints
    }

    /// Clears the user groups' caches, call counts and failures (done at the start of a run).
    pub fn reset_user_groups(&self) {
        self.user_forces.iter().for_each(|g| g.reset());
        self.user_constraints.iter().for_each(|g| g.reset());
        self.user_laws.iter().for_each(|(_, law)| law.reset());
    }

    /// The first failure of a user function (of a group or a law) since the last reset, as a
    /// run error.
    #[inline]
    pub fn user_failure(&self) -> Option<Error> {
        // Most models have no user functions: the run loop asks after every step, and the
        // answer for them is this test, inlined there.
        if self.user_forces.is_empty()
            && self.user_constraints.is_empty()
            && self.user_laws.is_empty()
        {
            return None;
        }
        self.user_group_failure()
    }

    /// [`System::user_failure`] of a model with user functions.
    fn user_group_failure(&self) -> Option<Error> {
        self.user_forces
            .iter()
            .find_map(|g| g.failure())
            .or_else(|| self.user_constraints.iter().find_map(|g| g.failure()))
            .or_else(|| {
                self.user_laws.iter().find_map(|(what, law)| {
                    let (t, detail) = law.failure()?;
                    Some(Error::LawNotFinite {
                        what: what.clone(),
                        t,
                        detail,
                        user: Some(law.name().to_string()),
                    })
                })
            })
    }
}
