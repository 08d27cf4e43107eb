//! The two Panda variants: their URDFs (embedded from `assets/robots/`), tool links, home
//! configuration and mounting pose.

use nalgebra::{Translation3, UnitQuaternion};

use crate::api::Embodiment;
use crate::robot::kinematics::{Iso, ModelError, RobotModel};

/// `assets/robots/panda_finger.urdf`.
pub const FINGER_URDF: &str = include_str!("../../../../assets/robots/panda_finger.urdf");
/// `assets/robots/panda_vacuum.urdf`.
pub const VACUUM_URDF: &str = include_str!("../../../../assets/robots/panda_vacuum.urdf");

/// The arm's initial joint configuration (`docs/benchmark.md` §1).
pub const HOME_ARM: [f64; 7] = [
    0.0,
    -std::f64::consts::FRAC_PI_4,
    0.0,
    -3.0 * std::f64::consts::FRAC_PI_4,
    0.0,
    std::f64::consts::FRAC_PI_2,
    std::f64::consts::FRAC_PI_4,
];

/// Height (m) of the finger hand's palm underside above its tool point (the grasp point
/// between the pads).
pub const PALM_ABOVE_TOOL: f64 = 0.034;

/// Half the finger hand's length along the fingers' travel, seen from above (m): the
/// hand's 20 cm box and a little margin. At the API's default angle the fingers travel
/// along y.
pub const HAND_HALF_LENGTH: f64 = 0.105;

/// Half the finger hand's width across the fingers' travel, seen from above (m): the wrist
/// flange's round cover, wider than the hand's box.
pub const HAND_HALF_WIDTH: f64 = 0.035;

/// Initial and maximum finger travel (each finger) of the finger gripper.
pub const FINGER_OPEN: f64 = 0.04;

/// Where the robot base stands: on the pedestal at (0, 0, 0.5), facing +x.
pub fn base_pose() -> Iso {
    Iso::from_parts(Translation3::new(0.0, 0.0, 0.5), UnitQuaternion::identity())
}

/// URDF, tool link and the link that carries held objects, per embodiment.
pub fn variant(embodiment: Embodiment) -> (&'static str, &'static str, &'static str) {
    match embodiment {
        Embodiment::Finger => (FINGER_URDF, "panda_grasp_point", "panda_hand"),
        Embodiment::Vacuum => (VACUUM_URDF, "vacuum_tip", "vacuum_tool"),
    }
}

/// Loads the kinematic model of a variant.
pub fn load_model(embodiment: Embodiment) -> Result<RobotModel, ModelError> {
    let (urdf, tool, _) = variant(embodiment);
    RobotModel::from_urdf_str(urdf, tool)
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector3;

    use super::*;
    use crate::robot::kinematics::{IkOptions, OrientationGoal, pointing_rotation};

    #[test]
    fn ik_round_trip_from_home() {
        let m = load_model(Embodiment::Finger).unwrap();
        let home = HOME_ARM.to_vec();
        let target = Vector3::new(0.45, 0.1, 0.05);
        let goal = OrientationGoal::Full(pointing_rotation(Vector3::new(0.0, 0.0, -1.0), 0.4));
        let q = m
            .solve_ik(target, goal, &home, &IkOptions::default())
            .expect("reachable");
        assert!(m.within_limits(&q));
        let p = m.tool_pose(&q);
        assert!((p.translation.vector - target).norm() < 1e-3);
    }
}
