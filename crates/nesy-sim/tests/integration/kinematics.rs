//! Forward kinematics against published check poses and an independent DH reference;
//! inverse kinematics accuracy and joint limits over the workspace.

use nalgebra::{Matrix3, Vector3};
use nesy_core::Embodiment;
use nesy_sim::robot::kinematics::{IkOptions, OrientationGoal, pointing_rotation};
use nesy_sim::robot::model::{HOME_ARM, base_pose, load_model};

#[test]
fn fk_matches_published_check_poses() {
    for embodiment in [Embodiment::Finger, Embodiment::Vacuum] {
        let m = load_model(embodiment).unwrap();
        assert_eq!(m.arm_dofs(), 7);
        let link8 = m.pose_of("panda_link8", &[0.0; 7], 0.0).unwrap();
        let p = link8.translation.vector;
        assert!((p - Vector3::new(0.088, 0.0, 0.926)).norm() < 1e-4, "{p}");
    }
    let m = load_model(Embodiment::Finger).unwrap();
    let hand = m.pose_of("panda_hand", &HOME_ARM, 0.04).unwrap();
    let p = hand.translation.vector;
    assert!((p - Vector3::new(0.30689, 0.0, 0.59028)).norm() < 1e-4, "{p}");
    // Pointing down: the hand's z axis is world −z.
    assert!((hand.rotation * Vector3::z() - Vector3::new(0.0, 0.0, -1.0)).norm() < 1e-9);
    // Fingers: prismatic, coupled, at hand z 0.0584.
    let left = m.pose_of("panda_leftfinger", &HOME_ARM, 0.03).unwrap();
    let right = m.pose_of("panda_rightfinger", &HOME_ARM, 0.03).unwrap();
    assert!(((left.translation.vector - right.translation.vector).norm() - 0.06).abs() < 1e-9);
    // The vacuum tip is 0.215 m from link7 along its axis.
    let v = load_model(Embodiment::Vacuum).unwrap();
    let l7 = v.pose_of("panda_link7", &HOME_ARM, 0.0).unwrap();
    let tip = v.tool_pose(&HOME_ARM);
    assert!(((l7.inverse() * tip).translation.vector - Vector3::new(0.0, 0.0, 0.215)).norm() < 1e-9);
}

#[test]
fn fk_matches_dh_reference_on_50_configurations() {
    let path = nesy_testkit::workspace_root().join("fixtures/fk/panda_flange_reference.json");
    let text = std::fs::read_to_string(path).unwrap();
    let doc: serde_json::Value = serde_json::from_str(&text).unwrap();
    let samples = doc["samples"].as_array().unwrap();
    assert_eq!(samples.len(), 50);
    let m = load_model(Embodiment::Finger).unwrap();
    let mut worst = (0.0_f64, 0.0_f64);
    for s in samples {
        let q: Vec<f64> = s["q"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        let want_p: Vec<f64> = s["position"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        let rows: Vec<Vec<f64>> = s["rotation"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| {
                r.as_array()
                    .unwrap()
                    .iter()
                    .map(|v| v.as_f64().unwrap())
                    .collect()
            })
            .collect();
        let want_r = Matrix3::from_fn(|i, j| rows[i][j]);
        let got = m.pose_of("panda_link8", &q, 0.0).unwrap();
        let dp = (got.translation.vector - Vector3::from_column_slice(&want_p)).norm();
        let dr = (got.rotation.to_rotation_matrix().matrix() - want_r).abs().max();
        worst = (worst.0.max(dp), worst.1.max(dr));
    }
    eprintln!(
        "FK vs DH reference: worst position {:.2e} m, rotation entry {:.2e}",
        worst.0, worst.1
    );
    assert!(
        worst.0 < 1e-4 && worst.1 < 1e-4,
        "worst position {:.2e} m, rotation entry {:.2e}",
        worst.0,
        worst.1
    );
}

#[test]
fn ik_reaches_workspace_poses_within_1mm_and_half_a_degree() {
    for embodiment in [Embodiment::Finger, Embodiment::Vacuum] {
        let m = load_model(embodiment).unwrap();
        let base = base_pose();
        let mut solved = 0;
        for &x in &[0.3, 0.45, 0.6] {
            for &y in &[-0.3, 0.0, 0.3] {
                for &z in &[0.52, 0.65, 0.8] {
                    for &yaw in &[-1.2, 0.0, 0.7] {
                        let world = Vector3::new(x, y, z);
                        let target = world - base.translation.vector;
                        let rotation = pointing_rotation(Vector3::new(0.0, 0.0, -1.0), yaw);
                        let goal = match embodiment {
                            Embodiment::Finger => OrientationGoal::Full(rotation),
                            Embodiment::Vacuum => OrientationGoal::Axis(Vector3::new(0.0, 0.0, -1.0)),
                        };
                        let q = m
                            .solve_ik(target, goal, &HOME_ARM, &IkOptions::default())
                            .unwrap_or_else(|| panic!("{embodiment}: no IK for {world} yaw {yaw}"));
                        assert!(m.within_limits(&q));
                        let pose = m.tool_pose(&q);
                        assert!((pose.translation.vector - target).norm() < 1e-3);
                        let angle = match goal {
                            OrientationGoal::Full(r) => pose.rotation.angle_to(&r),
                            OrientationGoal::Axis(a) => (pose.rotation * Vector3::z()).angle(&a),
                        };
                        assert!(angle < 0.5_f64.to_radians(), "{angle}");
                        solved += 1;
                    }
                }
            }
        }
        assert_eq!(solved, 81);
    }
}

#[test]
fn ik_refuses_unreachable_targets() {
    let m = load_model(Embodiment::Finger).unwrap();
    let goal = OrientationGoal::Full(pointing_rotation(Vector3::new(0.0, 0.0, -1.0), 0.0));
    assert!(
        m.solve_ik(
            Vector3::new(1.2, 0.0, 0.0),
            goal,
            &HOME_ARM,
            &IkOptions::default()
        )
        .is_none()
    );
}
