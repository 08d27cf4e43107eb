//! Operators: a name, preconditions and effects; either ground (the VLM-induced kind,
//! possibly with `forall` over the scene's objects) or lifted with typed parameters (PDDL
//! action schemas), and their compiled form.

use std::fmt;
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::atom::Atom;
use crate::formula::{Bindings, Effect, Formula, Ground, GroundEffects, GroundError, TypedVar};
use crate::state::State;
use crate::symbol::Symbol;
use crate::types::Universe;

/// An action operator `(name, pre, eff)`.
///
/// VLM-induced operators have no parameters: their atoms name objects directly, and only
/// quantified variables appear. PDDL action schemas have `params`; [`Operator::instantiate`]
/// binds them (structurally) to objects and records those in `args`.
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Operator {
    /// The action's name, e.g. `MoveGripperToSurroundOrange` or `pick-up`.
    pub name: String,
    /// Typed parameters of a lifted schema; empty for ground operators.
    #[serde(default, skip_serializing_if = "Vec::is_empty", with = "typed_vars_serde")]
    pub params: Vec<TypedVar>,
    /// The objects an instantiated schema was bound to; empty otherwise.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub args: Vec<Symbol>,
    /// Preconditions, a conjunction of formulas; empty means none. Shared (`Arc`): the
    /// adaptation loop copies whole procedures into every request and trace event, and a
    /// copy must not duplicate every formula.
    pub pre: Arc<[Formula]>,
    /// Effects; applied with PDDL semantics (deletes first, then adds). Shared like `pre`.
    pub eff: Arc<[Effect]>,
}

mod typed_vars_serde {
    use super::*;
    pub(super) fn serialize<S: serde::Serializer>(vars: &[TypedVar], s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(vars.iter().map(|v| format!("?{} - {}", v.name, v.ty)))
    }
    pub(super) fn deserialize<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Vec<TypedVar>, D::Error> {
        let items = Vec::<String>::deserialize(d)?;
        items
            .iter()
            .map(|item| {
                let (name, ty) = item.split_once(" - ").unwrap_or((item.as_str(), "thing"));
                let name = name.trim().strip_prefix('?').ok_or_else(|| {
                    serde::de::Error::custom(format!(
                        "expected a typed variable like `?x - thing`, found {item:?}"
                    ))
                })?;
                Ok(TypedVar {
                    name: Symbol::new(name),
                    ty: Symbol::new(ty.trim()),
                })
            })
            .collect()
    }
}

impl Operator {
    /// A ground operator with the given name, preconditions and effects.
    pub fn new(
        name: impl Into<String>,
        pre: impl Into<Arc<[Formula]>>,
        eff: impl Into<Arc<[Effect]>>,
    ) -> Self {
        Operator {
            name: name.into(),
            params: Vec::new(),
            args: Vec::new(),
            pre: pre.into(),
            eff: eff.into(),
        }
    }

    /// The name as shown in plans and reports: `name` for ground operators, `(name a b)`
    /// for instantiated schemas.
    pub fn display_name(&self) -> String {
        if self.args.is_empty() {
            self.name.clone()
        } else {
            let mut s = format!("({}", self.name);
            for a in &self.args {
                s.push(' ');
                s.push_str(a.as_str());
            }
            s.push(')');
            s
        }
    }

    /// Every atom pattern in the preconditions and effects, in order.
    pub fn patterns(&self) -> Vec<&crate::formula::AtomPattern> {
        let mut out = Vec::new();
        self.pre.iter().for_each(|f| f.patterns(&mut out));
        self.eff.iter().for_each(|e| e.patterns(&mut out));
        out
    }

    /// Every object constant in the preconditions and effects.
    pub fn constants(&self) -> Vec<Symbol> {
        let mut out = Vec::new();
        self.pre.iter().for_each(|f| f.constants(&mut out));
        self.eff.iter().for_each(|e| e.constants(&mut out));
        out
    }

    /// The operator named `name` with every object constant of its preconditions and
    /// effects passed through `rename` (parameters and arguments stay).
    ///
    /// ```
    /// use nesy_core::{Operator, Symbol};
    /// use nesy_core::text::parse_formula;
    ///
    /// let open = Operator::new("open-top-drawer", vec![parse_formula("(Closed top_drawer)").unwrap()], vec![]);
    /// let front = open.with_constants_renamed("open-front-top-drawer", &|c| Symbol::new(&format!("front_{c}")));
    /// assert_eq!(front.pre[0].to_string(), "(Closed front_top_drawer)");
    /// ```
    pub fn with_constants_renamed(
        &self,
        name: impl Into<String>,
        rename: &impl Fn(Symbol) -> Symbol,
    ) -> Operator {
        Operator {
            name: name.into(),
            params: self.params.clone(),
            args: self.args.clone(),
            pre: self.pre.iter().map(|f| f.rename_constants(rename)).collect(),
            eff: self.eff.iter().map(|e| e.rename_constants(rename)).collect(),
        }
    }

    /// Binds a lifted schema's parameters to objects, checking count and types against the
    /// universe, and substitutes them structurally.
    pub fn instantiate(&self, args: &[Symbol], universe: &Universe) -> Result<Operator, GroundError> {
        let bindings = self.check_args(args, universe)?;
        Ok(Operator {
            name: self.name.clone(),
            params: Vec::new(),
            args: args.to_vec(),
            pre: self.pre.iter().map(|f| f.substitute(&bindings)).collect(),
            eff: self.eff.iter().map(|e| e.substitute(&bindings)).collect(),
        })
    }

    fn check_args(&self, args: &[Symbol], universe: &Universe) -> Result<Vec<(Symbol, Symbol)>, GroundError> {
        if args.len() != self.params.len() {
            return Err(GroundError::WrongArgumentCount {
                action: self.name.clone(),
                expected: self.params.len(),
                found: args.len(),
            });
        }
        let mut bindings = Vec::with_capacity(args.len());
        for (p, a) in self.params.iter().zip(args) {
            universe.types.check(p.ty)?;
            let ok = universe
                .type_of(*a)
                .is_some_and(|t| universe.types.is_subtype(t, p.ty));
            if !ok {
                return Err(GroundError::BadArgument {
                    action: self.name.clone(),
                    object: a.to_string(),
                    ty: p.ty.to_string(),
                });
            }
            bindings.push((p.name, *a));
        }
        Ok(bindings)
    }

    /// Compiles a ground operator (or an instantiated schema) against a universe.
    pub fn compile(&self, universe: &Universe) -> Result<CompiledOperator, GroundError> {
        self.compile_with(&[], universe)
    }

    /// Compiles a lifted schema bound to `args` (no substitution copy is made).
    pub fn compile_with(
        &self,
        args: &[Symbol],
        universe: &Universe,
    ) -> Result<CompiledOperator, GroundError> {
        let bindings = self.check_args(args, universe)?;
        let mut env = Bindings::from_pairs(bindings);
        let mut pre = Vec::with_capacity(self.pre.len());
        for (i, f) in self.pre.iter().enumerate() {
            let g = f.ground(universe, &mut env)?;
            if g != Ground::True {
                pre.push((i, g));
            }
        }
        let mut effects = GroundEffects::default();
        for e in self.eff.iter() {
            e.ground(universe, &mut env, None, &mut effects)?;
        }
        effects.normalize();
        let name = if args.is_empty() {
            self.display_name()
        } else {
            Operator {
                args: args.to_vec(),
                ..self.clone()
            }
            .display_name()
        };
        Ok(CompiledOperator { name, pre, effects })
    }
}

/// Prints the action block of `docs/benchmark.md` §9:
///
/// ```text
/// Name
/// - Preconditions:
///     (GripperOpen)
/// - Effects:
///     (GripperClosed)
/// ```
///
/// (formula lines are indented with one tab, shown here as spaces) with `\tNone` for an
/// empty section. Lifted schemas print their name with parameters.
impl fmt::Display for Operator {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.display_name())?;
        f.write_str("\n- Preconditions:\n")?;
        if self.pre.is_empty() {
            f.write_str("\tNone\n")?;
        }
        for p in self.pre.iter() {
            writeln!(f, "\t{p}")?;
        }
        f.write_str("- Effects:")?;
        if self.eff.is_empty() {
            f.write_str("\n\tNone")?;
        }
        for e in self.eff.iter() {
            write!(f, "\n\t{e}")?;
        }
        Ok(())
    }
}

/// Prints a procedure: action blocks separated by one blank line, `None` when empty.
pub fn format_procedure(ops: &[Operator]) -> String {
    if ops.is_empty() {
        return "None".to_string();
    }
    ops.iter().map(|o| o.to_string()).collect::<Vec<_>>().join("\n\n")
}

/// An operator with every quantifier expanded and every atom interned: applying it does
/// no name resolution.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CompiledOperator {
    /// The display name.
    pub name: String,
    /// Each non-trivial precondition with the index of the conjunct it came from.
    pub pre: Vec<(usize, Ground)>,
    /// The ground effects.
    pub effects: GroundEffects,
}

impl CompiledOperator {
    /// True if every precondition holds.
    pub fn applicable(&self, state: &State) -> bool {
        self.pre.iter().all(|(_, g)| g.holds(state))
    }

    /// The successor state, without checking preconditions.
    pub fn apply_unchecked(&self, state: &State) -> State {
        self.effects.apply(state)
    }

    /// Every atom the operator may add (unconditionally or not).
    pub fn possible_adds(&self) -> impl Iterator<Item = Atom> + '_ {
        self.effects
            .adds
            .iter()
            .copied()
            .chain(self.effects.conditional.iter().filter(|c| c.add).map(|c| c.atom))
    }
}
