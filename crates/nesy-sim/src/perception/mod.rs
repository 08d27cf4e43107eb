//! What the robot and the models see of the world: the symbolic observer (ground-truth
//! states in the paper's predicates) and the CPU ray-cast renderer (the three camera views,
//! plain and labelled).

pub mod observer;
pub mod render;
