//! A small hand-made adaptation case: a demonstration that drops an apple into a hinge box
//! whose lid is open, and a target scene where the lid is closed. The states are written in
//! the form nesy-sim's observer gives them.

use std::sync::Arc;

use nesy_core::Atom;
use nesy_core::State;
use nesy_core::Symbol;
use nesy_core::adapt::{AdaptConfig, Demonstration, Target, TaskContext};
use nesy_core::{Tier, Vocabulary};
use nesy_reasoner::{KeyframeList, Views};
use nesy_vlm::Image;

pub(crate) const OBJECTS: [&str; 5] = ["floor", "hinge_body", "hinge_lid", "hinge_handle", "apple"];

pub(crate) fn state(atoms: &[&str]) -> State {
    State::from_atoms(atoms.iter().map(|a| a.parse::<Atom>().unwrap()))
}

pub(crate) fn task(tier: Tier) -> TaskContext {
    TaskContext {
        instruction: "Put the fruits in the hinge box.".into(),
        objects: OBJECTS.iter().map(|o| Symbol::new(o)).collect(),
        tier,
        vocabulary: Vocabulary::new(),
    }
}

pub(crate) fn demo_states() -> Vec<State> {
    let context = ["(OnTopOf hinge_body floor)", "(Open hinge_lid)"];
    let with = |atoms: &[&str]| {
        let mut all: Vec<&str> = atoms.to_vec();
        all.extend(context);
        state(&all)
    };
    vec![
        with(&["(GripperOpen)", "(OnTopOf apple floor)"]),
        with(&[
            "(GripperOpen)",
            "(GripperSurrounding apple)",
            "(OnTopOf apple floor)",
        ]),
        with(&[
            "(GripperClosed)",
            "(GripperHolding apple)",
            "(OnTopOf apple floor)",
        ]),
        with(&[
            "(GripperClosed)",
            "(GripperHolding apple)",
            "(OverOf apple hinge_body)",
        ]),
        with(&["(GripperOpen)", "(InsideOf apple hinge_body)"]),
    ]
}

pub(crate) fn demo() -> Demonstration {
    Demonstration {
        states: demo_states(),
        task: task(Tier::Full),
    }
}

pub(crate) fn target() -> Target {
    Target {
        init: state(&[
            "(Closed hinge_lid)",
            "(GripperOpen)",
            "(OnTopOf apple floor)",
            "(OnTopOf hinge_body floor)",
        ]),
        task: task(Tier::Full),
        scene_names: Vec::new(),
        goal: None,
    }
}

pub(crate) fn config() -> AdaptConfig {
    AdaptConfig {
        budget: 5,
        ..AdaptConfig::default()
    }
}

/// Five keyframes of three views each (distinct real PNGs).
pub(crate) fn keyframes() -> Arc<KeyframeList> {
    let views = (0..5u64)
        .map(|k| {
            Views::new([
                ("top", Image::png(nesy_testkit::png(24, 10 * k + 1)).unwrap()),
                ("front", Image::png(nesy_testkit::png(24, 10 * k + 2)).unwrap()),
                ("back", Image::png(nesy_testkit::png(24, 10 * k + 3)).unwrap()),
            ])
        })
        .collect();
    Arc::new(KeyframeList { views })
}

// Replies written the way real models answer: prose, markdown, odd bullets.

pub(crate) const APPROACH: &str = "**Prediction Rationale:**
* Between the two states only (GripperSurrounding apple) appeared, so the open gripper was lowered around the apple. It must be open and empty for that.

**Predicted Action:**
Action Semantic:
- Move gripper to surround apple
Precondition:
* (GripperOpen)
* (forall (?x - thing) (not (GripperHolding ?x)))
Effect:
* (GripperSurrounding apple)
";

/// Forgets that the apple is no longer merely surrounded: the verifier rejects it.
pub(crate) const GRASP_WRONG: &str = "Looking at the images, the fingers have closed on the apple.

* Prediction Rationale:
- The gripper closed and now holds the apple.
* Predicted Action:
Action Semantic:
- Close gripper to grasp apple
Precondition:
- (GripperSurrounding apple)
- (GripperOpen)
Effect:
- (GripperClosed)
- (GripperHolding apple)
- (not (GripperOpen))
";

pub(crate) const GRASP: &str = "You are right, the apple is held now, not just surrounded.

* Prediction Rationale:
- The gripper closed on the apple it surrounded; afterwards it holds the apple and no longer just surrounds it.
* Predicted Action:
Action Semantic:
- Close gripper to grasp apple
Precondition:
- (GripperSurrounding apple)
- (GripperOpen)
Effect:
- (GripperClosed)
- (GripperHolding apple)
- (not (GripperOpen))
- (not (GripperSurrounding apple))
";

pub(crate) const CARRY: &str = "### Prediction Rationale
- The held apple left the floor and is now above the hinge box.

### Predicted Action
Action Semantic:
1. Move held apple over hinge body
Precondition:
1. (GripperHolding apple)
Effect:
1. (OverOf apple hinge_body)
2. (not (OnTopOf apple floor))
";

pub(crate) const DROP: &str = "* Prediction Rationale:
- The gripper opened over the box and the apple fell in; this needs the lid open.

* Predicted Action:
Action Semantic:
- Open gripper to drop apple into hinge body
Precondition:
- (GripperHolding apple)
- (OverOf apple hinge_body)
- (Open hinge_lid)
Effect:
- (InsideOf apple hinge_body)
- (GripperOpen)
- (not (GripperClosed))
- (not (GripperHolding apple))
- (not (OverOf apple hinge_body))

This is the only action consistent with the state difference.
";

/// The SEARCH block misremembers a precondition, so it matches nothing.
pub(crate) const PATCH_NO_MATCH: &str = "* Refinement rationale:
- The lid is closed, so the apple cannot be dropped in. Open the lid before picking up the apple.

* Refinement patch:
```
<<<<<<< SEARCH
MoveGripperToSurroundApple
- Preconditions:
	(GripperOpen)
- Effects:
	(GripperSurrounding apple)
=======
MoveGripperToHingeHandle
- Preconditions:
	(GripperOpen)
- Effects:
	(GripperSurrounding hinge_handle)

MoveGripperToSurroundApple
- Preconditions:
	(GripperOpen)
- Effects:
	(GripperSurrounding apple)
>>>>>>> REPLACE
```
";

pub(crate) const PATCH: &str = "* Refinement rationale:
- Case 1, missing actions: the lid of the hinge box is closed in this scene, so (Open hinge_lid) fails when the apple is dropped. The gripper is free only before the apple is picked up, so the lid is opened by its handle first and the plan continues as before.

* Refinement patch:
<<<<<<< SEARCH
MoveGripperToSurroundApple
- Preconditions:
	(GripperOpen)
	(forall (?x - thing) (not (GripperHolding ?x)))
- Effects:
	(GripperSurrounding apple)
=======
GraspHingeHandle
- Preconditions:
	(GripperOpen)
	(forall (?x - thing) (not (GripperHolding ?x)))
- Effects:
	(GripperClosed)
	(GripperHolding hinge_handle)
	(not (GripperOpen))

SwingHingeLidOpen
- Preconditions:
	(GripperHolding hinge_handle)
	(Closed hinge_lid)
- Effects:
	(Open hinge_lid)
	(not (Closed hinge_lid))

ReleaseHingeHandle
- Preconditions:
	(GripperHolding hinge_handle)
- Effects:
	(GripperOpen)
	(not (GripperClosed))
	(not (GripperHolding hinge_handle))

MoveGripperToSurroundApple
- Preconditions:
	(GripperOpen)
	(forall (?x - thing) (not (GripperHolding ?x)))
- Effects:
	(GripperSurrounding apple)
>>>>>>> REPLACE
";

pub(crate) const CODE: &str =
    "Here is a program that follows the summary. It opens the lid first, since the lid starts closed.

```python
from robot_api import move_gripper_to, grasp_handle, release_handle, close_gripper, open_gripper
import numpy as np

move_gripper_to(\"hinge_handle\", depth=0.0)
grasp_handle(\"hinge_handle\")
lid = get_obj_pos(\"hinge_lid\")
r = get_obj_size(\"hinge_lid\")[0]
move_to_position([lid[0] + 0.5 * r, lid[1], lid[2] + r], lift_clearance=0.0)
release_handle()
h = get_obj_size(\"apple\")[2]
move_gripper_to(\"apple\", depth=h / 2)
close_gripper()
body = get_obj_pos(\"hinge_body\")
top = get_obj_bbox(\"hinge_body\")[1][2]
move_to_position([body[0], body[1], top + h / 2 + 0.03])
open_gripper()
```

The lid is swung open with `lift_clearance=0.0` so the handle is not pulled out of the grasp.
";

pub(crate) const TRANSLATION: &str = "From the three views I can see the following:

- (OnTopOf apple floor)
- (Closed hinge_lid)
- (OnTopOf hinge_body floor)
- (OnTopOf banana floor)

The gripper state was already given.
";
