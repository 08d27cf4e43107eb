//! Collision-aware joint-space path planning: bidirectional RRT ("RRT-Connect", Kuffner and
//! LaValle 2000) followed by random shortcutting.
//!
//! The motion layer plans transits as straight tool-space lines and detours over the table.
//! From some arm configurations no such line is followable (after a lid swing the wrist is on
//! a branch whose straight path to the next object runs joints into their limits), and
//! interpolating joints instead sweeps the hand through whatever stands between. This
//! planner is the last resort for those transits: it searches joint space directly, so it
//! needs no IK along the way, and it accepts a path only if every configuration along it,
//! checked at a fixed joint spacing, passes the caller's validity test.
//!
//! The planner is independent of the simulator: configurations are `&[f64]` inside box
//! limits, and validity is a closure. Randomness comes from a seeded [`Stream`], so the same
//! problem gives the same path on every run and platform (demo hashes depend on it).

use crate::world::rng::Stream;

/// Tuning of [`plan`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct PlannerOptions {
    /// Longest joint-space step (Euclidean norm, rad) a tree grows by in one extension.
    pub step: f64,
    /// Largest joint change (max norm, rad) between two checked configurations on an edge.
    pub check_spacing: f64,
    /// Extensions tried (each followed by a connect attempt) before giving up.
    pub max_iterations: usize,
    /// Shortcut attempts on the found path.
    pub shortcut_rounds: usize,
}

impl Default for PlannerOptions {
    fn default() -> Self {
        PlannerOptions {
            step: 0.35,
            check_spacing: 0.03,
            max_iterations: 1500,
            shortcut_rounds: 80,
        }
    }
}

/// One search tree: configurations stored flat (`dof` values per node) with parent links.
struct Tree {
    dof: usize,
    values: Vec<f64>,
    parents: Vec<Option<usize>>,
}

impl Tree {
    fn new(dof: usize) -> Tree {
        Tree {
            dof,
            values: Vec::new(),
            parents: Vec::new(),
        }
    }

    fn len(&self) -> usize {
        self.parents.len()
    }

    fn node(&self, i: usize) -> &[f64] {
        &self.values[i * self.dof..(i + 1) * self.dof]
    }

    fn push(&mut self, q: &[f64], parent: Option<usize>) -> usize {
        self.values.extend_from_slice(q);
        self.parents.push(parent);
        self.parents.len() - 1
    }

    /// The node closest to `q` (Euclidean); trees stay small, so a linear scan is cheapest.
    fn nearest(&self, q: &[f64]) -> usize {
        (0..self.len())
            .map(|i| (i, squared_distance(self.node(i), q)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map_or(0, |(i, _)| i)
    }

    /// Configurations from the root down to node `i`.
    fn path_to(&self, mut i: usize) -> Vec<Vec<f64>> {
        let mut path = vec![self.node(i).to_vec()];
        while let Some(parent) = self.parents[i] {
            path.push(self.node(parent).to_vec());
            i = parent;
        }
        path.reverse();
        path
    }
}

/// What one extension of a tree toward a target did.
enum Extension {
    /// The tree reached the target (the new node is it).
    Reached(usize),
    /// The tree grew one step toward it.
    Advanced(usize),
    /// The step was blocked.
    Trapped,
}

fn squared_distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

fn max_delta(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

/// Whether every configuration on the straight joint edge `a → b` is valid, checked every
/// `spacing` rad (max norm) and at `b`; `a` is assumed valid.
pub(crate) fn edge_is_valid(
    a: &[f64],
    b: &[f64],
    spacing: f64,
    is_valid: &mut impl FnMut(&[f64]) -> bool,
) -> bool {
    let steps = (max_delta(a, b) / spacing).ceil().max(1.0) as usize;
    let mut q = vec![0.0; a.len()];
    (1..=steps).all(|k| {
        let t = k as f64 / steps as f64;
        for (v, (x, y)) in q.iter_mut().zip(a.iter().zip(b)) {
            *v = x + (y - x) * t;
        }
        is_valid(&q)
    })
}

/// A collision-free joint path from `start` to one of `goals`, or `None` when the search
/// runs out of iterations. `limits` bound every joint; `is_valid` tells whether a
/// configuration is acceptable (collision-free). `start` and the goals must be valid
/// themselves; invalid goals are dropped. The path starts at `start`, ends at a goal, and
/// has been shortcut so it carries no needless detours.
pub(crate) fn plan(
    start: &[f64],
    goals: &[Vec<f64>],
    limits: &[(f64, f64)],
    mut is_valid: impl FnMut(&[f64]) -> bool,
    rng: &mut Stream,
    options: &PlannerOptions,
) -> Option<Vec<Vec<f64>>> {
    let dof = start.len();
    let goals: Vec<&Vec<f64>> = goals.iter().filter(|g| g.len() == dof && is_valid(g)).collect();
    if goals.is_empty() || limits.len() != dof || !is_valid(start) {
        return None;
    }
    // The straight joint move first: most calls are near-trivial.
    for goal in &goals {
        if edge_is_valid(start, goal, options.check_spacing, &mut is_valid) {
            return Some(vec![start.to_vec(), goal.to_vec()]);
        }
    }
    let mut from_start = Tree::new(dof);
    from_start.push(start, None);
    let mut from_goal = Tree::new(dof);
    for goal in &goals {
        from_goal.push(goal, None);
    }
    // `forward` is true while `a` is the start tree.
    let (mut a, mut b, mut forward) = (&mut from_start, &mut from_goal, true);
    let mut sample = vec![0.0; dof];
    for _ in 0..options.max_iterations {
        for (v, &(lo, hi)) in sample.iter_mut().zip(limits) {
            *v = rng.uniform(lo, hi);
        }
        if let Extension::Advanced(new) | Extension::Reached(new) = extend(a, &sample, options, &mut is_valid)
        {
            let target = a.node(new).to_vec();
            let meet = loop {
                match extend(b, &target, options, &mut is_valid) {
                    Extension::Reached(m) => break Some(m),
                    Extension::Advanced(_) => continue,
                    Extension::Trapped => break None,
                }
            };
            if let Some(m) = meet {
                let (start_side, goal_side) = if forward {
                    (a.path_to(new), b.path_to(m))
                } else {
                    (b.path_to(m), a.path_to(new))
                };
                let mut path = start_side;
                // Both halves end at the meeting configuration; keep it once.
                path.extend(goal_side.into_iter().rev().skip(1));
                return Some(shortcut(path, options, &mut is_valid, rng));
            }
        }
        std::mem::swap(&mut a, &mut b);
        forward = !forward;
    }
    None
}

/// Grows `tree` by at most one step from its nearest node toward `target`.
fn extend(
    tree: &mut Tree,
    target: &[f64],
    options: &PlannerOptions,
    is_valid: &mut impl FnMut(&[f64]) -> bool,
) -> Extension {
    let near = tree.nearest(target);
    let from = tree.node(near).to_vec();
    let distance = squared_distance(&from, target).sqrt();
    let (to, reached) = if distance <= options.step {
        (target.to_vec(), true)
    } else {
        let s = options.step / distance;
        (
            from.iter().zip(target).map(|(x, y)| x + (y - x) * s).collect(),
            false,
        )
    };
    if !edge_is_valid(&from, &to, options.check_spacing, is_valid) {
        return Extension::Trapped;
    }
    let new = tree.push(&to, Some(near));
    if reached {
        Extension::Reached(new)
    } else {
        Extension::Advanced(new)
    }
}

/// Random shortcutting: joins two random configurations of the path directly wherever the
/// edge between them is valid, dropping what lay between.
fn shortcut(
    mut path: Vec<Vec<f64>>,
    options: &PlannerOptions,
    is_valid: &mut impl FnMut(&[f64]) -> bool,
    rng: &mut Stream,
) -> Vec<Vec<f64>> {
    for _ in 0..options.shortcut_rounds {
        if path.len() < 3 {
            break;
        }
        let i = rng.index(path.len() - 2);
        let j = i + 2 + rng.index(path.len() - i - 2);
        if edge_is_valid(&path[i], &path[j], options.check_spacing, is_valid) {
            path.drain(i + 1..j);
        }
    }
    path
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tests' joint limits: both joints in [0, 1].
    const UNIT_SQUARE: [(f64, f64); 2] = [(0.0, 1.0), (0.0, 1.0)];

    /// A 2-D world with a wall at x ∈ [0.4, 0.6] that leaves a gap only at y > 0.8.
    fn outside_wall(q: &[f64]) -> bool {
        !((0.4..=0.6).contains(&q[0]) && q[1] < 0.8)
    }

    fn options() -> PlannerOptions {
        PlannerOptions {
            step: 0.1,
            check_spacing: 0.005,
            max_iterations: 5000,
            shortcut_rounds: 50,
        }
    }

    #[test]
    fn straight_edge_when_nothing_blocks() {
        let mut rng = Stream::new("planner/test", 0);
        let path = plan(
            &[0.1, 0.1],
            &[vec![0.3, 0.2]],
            &UNIT_SQUARE,
            outside_wall,
            &mut rng,
            &options(),
        )
        .expect("a path");
        assert_eq!(path, vec![vec![0.1, 0.1], vec![0.3, 0.2]]);
    }

    #[test]
    fn goes_around_a_wall_and_every_edge_is_valid() {
        let mut rng = Stream::new("planner/test", 1);
        let start = [0.1, 0.1];
        let goal = vec![0.9, 0.1];
        let path = plan(
            &start,
            std::slice::from_ref(&goal),
            &UNIT_SQUARE,
            outside_wall,
            &mut rng,
            &options(),
        )
        .expect("a path through the gap");
        assert_eq!(path.first().map(Vec::as_slice), Some(&start[..]));
        assert_eq!(path.last(), Some(&goal));
        let mut valid = outside_wall;
        for pair in path.windows(2) {
            assert!(
                edge_is_valid(&pair[0], &pair[1], 0.005, &mut valid),
                "edge {pair:?} crosses the wall"
            );
        }
        assert!(
            path.iter().any(|q| q[1] > 0.8),
            "the path must use the gap: {path:?}"
        );
    }

    #[test]
    fn same_seed_same_path() {
        let run = || {
            let mut rng = Stream::new("planner/test", 7);
            plan(
                &[0.1, 0.1],
                &[vec![0.9, 0.1]],
                &UNIT_SQUARE,
                outside_wall,
                &mut rng,
                &options(),
            )
        };
        assert_eq!(run(), run());
    }

    #[test]
    fn no_path_when_the_goal_is_walled_off() {
        let sealed = |q: &[f64]| !(0.4..=0.6).contains(&q[0]);
        let mut rng = Stream::new("planner/test", 2);
        let quick = PlannerOptions {
            max_iterations: 300,
            ..options()
        };
        assert!(
            plan(
                &[0.1, 0.1],
                &[vec![0.9, 0.1]],
                &UNIT_SQUARE,
                sealed,
                &mut rng,
                &quick
            )
            .is_none()
        );
    }

    #[test]
    fn invalid_start_or_goals_give_none() {
        let mut rng = Stream::new("planner/test", 3);
        let limits = UNIT_SQUARE;
        assert!(
            plan(
                &[0.5, 0.1],
                &[vec![0.9, 0.1]],
                &limits,
                outside_wall,
                &mut rng,
                &options()
            )
            .is_none()
        );
        assert!(
            plan(
                &[0.1, 0.1],
                &[vec![0.5, 0.1]],
                &limits,
                outside_wall,
                &mut rng,
                &options()
            )
            .is_none()
        );
    }
}
