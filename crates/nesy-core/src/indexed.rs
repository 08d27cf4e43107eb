//! Ground formulas and states over dense fact indices: bitset states for the fast paths of
//! the executor and the planner.

use rustc_hash::FxHashMap;

use crate::atom::Atom;
use crate::formula::Ground;
use crate::state::State;

/// A ground formula over fact indices.
#[derive(Debug, Clone)]
pub(crate) enum Cond {
    True,
    False,
    Fact(u32),
    NotFact(u32),
    Not(Box<Cond>),
    And(Vec<Cond>),
    Or(Vec<Cond>),
}

pub(crate) type Bits = Vec<u64>;

pub(crate) fn get(bits: &Bits, i: u32) -> bool {
    bits[(i / 64) as usize] >> (i % 64) & 1 == 1
}

pub(crate) fn set(bits: &mut Bits, i: u32, v: bool) {
    let w = &mut bits[(i / 64) as usize];
    if v {
        *w |= 1 << (i % 64)
    } else {
        *w &= !(1 << (i % 64))
    }
}

impl Cond {
    pub(crate) fn holds(&self, s: &Bits) -> bool {
        match self {
            Cond::True => true,
            Cond::False => false,
            Cond::Fact(f) => get(s, *f),
            Cond::NotFact(f) => !get(s, *f),
            Cond::Not(c) => !c.holds(s),
            Cond::And(cs) => cs.iter().all(|c| c.holds(s)),
            Cond::Or(cs) => cs.iter().any(|c| c.holds(s)),
        }
    }
}

#[derive(Debug, Clone)]
pub(crate) struct Facts {
    pub(crate) index: FxHashMap<Atom, u32>,
    pub(crate) atoms: Vec<Atom>,
}

impl Facts {
    pub(crate) fn id(&mut self, a: Atom) -> u32 {
        if let Some(&i) = self.index.get(&a) {
            return i;
        }
        let i = self.atoms.len() as u32;
        self.atoms.push(a);
        self.index.insert(a, i);
        i
    }

    pub(crate) fn cond(&mut self, g: &Ground) -> Cond {
        match g {
            Ground::True => Cond::True,
            Ground::False => Cond::False,
            Ground::Atom(a) => Cond::Fact(self.id(*a)),
            Ground::Not(inner) => match &**inner {
                Ground::Atom(a) => Cond::NotFact(self.id(*a)),
                other => Cond::Not(Box::new(self.cond(other))),
            },
            Ground::And(gs) => Cond::And(gs.iter().map(|g| self.cond(g)).collect()),
            Ground::Or(gs) => Cond::Or(gs.iter().map(|g| self.cond(g)).collect()),
        }
    }
}

impl Facts {
    /// No facts yet.
    pub(crate) fn new() -> Self {
        Facts {
            index: FxHashMap::default(),
            atoms: Vec::new(),
        }
    }

    /// Number of 64-bit words a state needs.
    pub(crate) fn words(&self) -> usize {
        self.atoms.len().div_ceil(64).max(1)
    }

    /// The bitset of a state (atoms without an index are dropped).
    pub(crate) fn encode(&self, state: &State) -> Bits {
        let mut bits = vec![0; self.words()];
        for a in state.iter() {
            if let Some(&i) = self.index.get(a) {
                set(&mut bits, i, true);
            }
        }
        bits
    }

    /// The state of a bitset.
    pub(crate) fn decode(&self, bits: &Bits) -> State {
        let mut atoms = Vec::new();
        for (w, word) in bits.iter().enumerate() {
            let mut word = *word;
            while word != 0 {
                let b = word.trailing_zeros();
                atoms.push(self.atoms[w * 64 + b as usize]);
                word &= word - 1;
            }
        }
        State::from_atoms(atoms)
    }
}
