//! Motion generation: tool-space straight segments sampled into joint paths by IK, timed
//! with the authors' quadratic ease-in/out, and played back one control step at a time.

use nalgebra::{UnitQuaternion, Vector3};

use crate::api::{ApiError, Direction, Embodiment};
use crate::geometry::array_to_na;
use crate::kinematics::{IkOptions, Iso, OrientationGoal, pointing_rotation};
use crate::sim::{CONTROL_DT, Sim};

/// The quadratic ease-in/out profile of spec §4: `2t²` below ½, `1 − 2(1 − t)²` above.
pub fn ease(t: f64) -> f64 {
    let t = t.clamp(0.0, 1.0);
    if t < 0.5 {
        2.0 * t * t
    } else {
        1.0 - 2.0 * (1.0 - t) * (1.0 - t)
    }
}

/// Average tool speed of a straight segment (m/s); the eased peak is twice this.
const TOOL_SPEED: f64 = 0.2;
/// Average joint speed (rad/s) bound of a segment.
const JOINT_SPEED: f64 = 0.8;
/// Shortest segment duration (s).
const MIN_SEGMENT: f64 = 0.25;
/// Shortest duration of a `move_parallel` (s): the authors' 80 interpolation steps. Pushes
/// (sweeping) then accelerate gently enough that tall pieces slide instead of tipping.
pub const PARALLEL_MIN_DURATION: f64 = 0.8;
/// Spacing of IK samples along a straight segment (m).
const SAMPLE_SPACING: f64 = 0.015;
/// Control steps the world runs after a motion so objects come to rest.
pub const SETTLE_STEPS: u32 = 20;

/// A tool pose to reach: position and orientation goal.
#[derive(Clone, Copy, Debug)]
pub struct ToolGoal {
    /// Tool point position (world).
    pub position: Vector3<f64>,
    /// Tool orientation (world); for the vacuum only its z axis is enforced.
    pub rotation: UnitQuaternion<f64>,
}

impl Sim {
    fn orientation_goal(&self, rotation: UnitQuaternion<f64>) -> OrientationGoal {
        let base_inv = self.base.rotation.inverse();
        match self.scene.embodiment {
            Embodiment::Finger => OrientationGoal::Full(base_inv * rotation),
            Embodiment::Vacuum => OrientationGoal::Axis(base_inv * (rotation * Vector3::z())),
        }
    }

    /// IK for a world tool goal, seeded from `seed`.
    pub(crate) fn ik(&self, goal: &ToolGoal, seed: &[f64], opts: &IkOptions) -> Option<Vec<f64>> {
        let local = self.base.inverse() * nalgebra::Point3::from(goal.position);
        self.robot
            .model
            .solve_ik(local.coords, self.orientation_goal(goal.rotation), seed, opts)
    }

    /// The tool rotation for pointing `dir` with spin `angle`.
    pub(crate) fn pointing(dir: Direction, angle: f64) -> UnitQuaternion<f64> {
        pointing_rotation(array_to_na(dir.unit()), angle)
    }

    /// Of the spins `angle + k·step`, the one whose rotation is closest to the current tool.
    pub(crate) fn nearest_spin(&self, dir: Direction, angle: f64, step: f64) -> f64 {
        let current = self.tool_pose().rotation;
        let n = (std::f64::consts::TAU / step).round().max(1.0) as usize;
        (0..n)
            .map(|k| crate::geometry::wrap_angle(angle + k as f64 * step))
            .min_by(|a, b| {
                let da = Sim::pointing(dir, *a).angle_to(&current);
                let db = Sim::pointing(dir, *b).angle_to(&current);
                da.total_cmp(&db)
            })
            .unwrap_or(angle)
    }

    /// Plans joint paths through the tool waypoints (each reached by IK, nothing moved).
    /// Each segment is a straight tool-space line sampled every 1.5 cm and solved by IK
    /// warm-started along the line; where that fails the segment falls back to straight
    /// joint interpolation between its verified endpoints.
    pub(crate) fn plan(
        &self,
        waypoints: &[ToolGoal],
        pointing: Direction,
    ) -> Result<Vec<Vec<Vec<f64>>>, ApiError> {
        let full = IkOptions::default();
        let quick = IkOptions {
            restarts: 1,
            iterations: 60,
            pos_tol: 5e-4,
            rot_tol: 5e-3,
            ..IkOptions::default()
        };
        // The final goal first, so an unreachable target is reported as such rather than
        // as one of the clearance waypoints in front of it.
        if let Some(last) = waypoints.last()
            && self.ik(last, &self.q, &full).is_none()
        {
            return Err(ApiError::IkFailed {
                target: [last.position.x, last.position.y, last.position.z],
                pointing_to: pointing,
            });
        }
        let mut segments = Vec::new();
        let mut q_from = self.q.clone();
        let mut pose_from: Iso = self.tool_pose();
        for wp in waypoints {
            let start = pose_from.translation.vector;
            let length = (wp.position - start).norm();
            let n = (length / SAMPLE_SPACING).ceil() as usize;
            let mut path = vec![q_from.clone()];
            let mut ok = true;
            let mut seed = q_from.clone();
            for i in 1..n {
                let s = i as f64 / n as f64;
                let goal = ToolGoal {
                    position: start + (wp.position - start) * s,
                    rotation: pose_from.rotation.slerp(&wp.rotation, s),
                };
                match self.ik(&goal, &seed, &quick) {
                    Some(q) if max_delta(&q, &seed) < 0.3 => {
                        seed = q.clone();
                        path.push(q);
                    }
                    _ => {
                        ok = false;
                        break;
                    }
                }
            }
            // The waypoint itself, seeded from the end of the line so the branch carries on.
            let q_to = self
                .ik(wp, &seed, &full)
                .or_else(|| self.ik(wp, &q_from, &full))
                .ok_or(ApiError::IkFailed {
                    target: [wp.position.x, wp.position.y, wp.position.z],
                    pointing_to: pointing,
                })?;
            if !ok || max_delta(&seed, &q_to) > 0.3 {
                path = vec![q_from.clone()];
            }
            path.push(q_to.clone());
            segments.push(path);
            q_from = q_to;
            pose_from = Iso::from_parts(nalgebra::Translation3::from(wp.position), wp.rotation);
        }
        Ok(segments)
    }

    /// Plays planned segments back with eased timing, then settles.
    pub(crate) fn execute(&mut self, segments: &[Vec<Vec<f64>>], settle: u32) {
        self.execute_at_least(segments, settle, MIN_SEGMENT);
    }

    /// [`Sim::execute`] with a longer shortest segment duration (s).
    pub(crate) fn execute_at_least(&mut self, segments: &[Vec<Vec<f64>>], settle: u32, min_segment: f64) {
        for path in segments {
            let (cumulative, total) = path_lengths(path);
            let tool_len = {
                let a = self.robot.model.tool_pose(&path[0]).translation.vector;
                let b = self
                    .robot
                    .model
                    .tool_pose(&path[path.len() - 1])
                    .translation
                    .vector;
                (a - b).norm()
            };
            let joint_len = path.windows(2).map(|w| max_delta(&w[0], &w[1])).sum::<f64>();
            let duration = (tool_len / TOOL_SPEED)
                .max(joint_len / JOINT_SPEED)
                .max(min_segment);
            let steps = (duration / CONTROL_DT).ceil() as usize;
            for k in 1..=steps {
                let s = ease(k as f64 / steps as f64);
                let q = sample_path(path, &cumulative, total, s);
                self.control_step(&q);
            }
        }
        self.step_idle(settle);
    }
}

fn max_delta(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

/// Cumulative joint-space arc length at each sample.
fn path_lengths(path: &[Vec<f64>]) -> (Vec<f64>, f64) {
    let mut acc = 0.0;
    let mut cumulative = vec![0.0];
    for w in path.windows(2) {
        acc += w[0]
            .iter()
            .zip(&w[1])
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f64>()
            .sqrt();
        cumulative.push(acc);
    }
    (cumulative, acc)
}

/// The configuration at fraction `s` of the path's arc length.
fn sample_path(path: &[Vec<f64>], cumulative: &[f64], total: f64, s: f64) -> Vec<f64> {
    if total <= 0.0 {
        return path[path.len() - 1].clone();
    }
    let d = s * total;
    let i = cumulative.partition_point(|&c| c < d).clamp(1, path.len() - 1);
    let span = cumulative[i] - cumulative[i - 1];
    let t = if span > 0.0 {
        (d - cumulative[i - 1]) / span
    } else {
        1.0
    };
    path[i - 1]
        .iter()
        .zip(&path[i])
        .map(|(a, b)| a + (b - a) * t)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ease_profile() {
        assert_eq!(ease(0.0), 0.0);
        assert_eq!(ease(0.25), 0.125);
        assert_eq!(ease(0.5), 0.5);
        assert_eq!(ease(0.75), 0.875);
        assert_eq!(ease(1.0), 1.0);
    }

    #[test]
    fn path_sampling_is_piecewise_linear() {
        let path = vec![vec![0.0, 0.0], vec![1.0, 0.0], vec![1.0, 1.0]];
        let (c, t) = path_lengths(&path);
        assert_eq!(t, 2.0);
        assert_eq!(sample_path(&path, &c, t, 0.25), vec![0.5, 0.0]);
        assert_eq!(sample_path(&path, &c, t, 0.75), vec![1.0, 0.5]);
        assert_eq!(sample_path(&path, &c, t, 1.0), vec![1.0, 1.0]);
    }
}
