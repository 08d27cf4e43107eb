//! Hand-written replies in the style of real models for the drawer case of
//! `fixtures/demos/adapt-realstyle` (demo: the bottom drawer is open; target: it is closed),
//! and a transport that serves them by task, step and attempt. Recorded once into
//! `fixtures/cassettes/adapt-realstyle.json` through the real request path.
//!
//! What they exercise: prose around every answer; `*`, `•`, numbered and plain bullets;
//! markdown emphasis in headers; a grasp operator that forgets an effect (the verifier rejects
//! it and the model re-predicts); a first patch whose SEARCH block misquotes the action (it
//! does not match and goes back as feedback), then a correct one; a code block between an
//! introduction and an explanation.

use nesy_reasoner::VlmTask;
use nesy_vlm::{BoxFuture, Origin, Transport, TransportError, WireRequest, WireResponse};
use serde_json::json;

/// The model name the cassette records (honest: these are not a model's answers).
pub(crate) const MODEL: &str = "hand-written-replies";

const APPROACH_CYLINDER: &str = "Looking at the before/after images, the fingers are now around the red cylinder, which still stands on the table.

**Prediction Rationale:**
* The only new atom is (GripperSurrounding red_cylinder): the open, empty gripper was lowered around the cylinder.
* Nothing may be held for that, and the cylinder must be free on the table.

**Predicted Action:**
Action Semantic:
- Move gripper to surround red cylinder
Precondition:
* (GripperOpen)
* (OnTopOf red_cylinder floor)
* (forall (?x - thing) (not (GripperHolding ?x)))
Effect:
* (GripperSurrounding red_cylinder)

Let me know if you need the next step.";

const GRASP_CYLINDER_WRONG: &str = "The gripper closed on the cylinder.

* Prediction Rationale:
- Fingers closed, so the cylinder is held.
* Predicted Action:
Action Semantic:
- close_gripper_to_grasp_red_cylinder
Precondition:
• (GripperOpen)
• (GripperSurrounding red_cylinder)
Effect:
• (GripperClosed)
• (GripperHolding red_cylinder)
• (not (GripperOpen))";

const GRASP_CYLINDER: &str =
    "You're right — once it is held the cylinder is no longer merely surrounded. Corrected:

* Prediction Rationale:
- The fingers closed on the cylinder they surrounded; it is now held, and the surrounding relation ends.
* Predicted Action:
Action Semantic:
- close_gripper_to_grasp_red_cylinder
Precondition:
• (GripperOpen)
• (GripperSurrounding red_cylinder)
Effect:
• (GripperClosed)
• (GripperHolding red_cylinder)
• (not (GripperOpen))
• (not (GripperSurrounding red_cylinder))";

const MOVE_OVER_DRAWER: &str = "### Prediction Rationale
1. The held cylinder left the table and is now above the open bottom drawer.

### Predicted Action
Action Semantic:
1. Move red cylinder over bottom drawer
Precondition:
1. (GripperHolding red_cylinder)
2. (OnTopOf red_cylinder floor)
Effect:
1. (OverOf red_cylinder bottom_drawer)
2. (not (OnTopOf red_cylinder floor))";

const DROP_INTO_DRAWER: &str = "Answer:

* Prediction Rationale:
- The gripper opened above the drawer and the cylinder fell inside. The drawer has to be open for that, otherwise the cylinder would land on its front panel.
* Predicted Action:
Action Semantic:
- Open gripper to drop red cylinder into bottom drawer
Precondition:
- (GripperHolding red_cylinder)
- (OverOf red_cylinder bottom_drawer)
- (Open bottom_drawer)
Effect:
- (InsideOf red_cylinder bottom_drawer)
- (GripperOpen)
- (not (GripperClosed))
- (not (GripperHolding red_cylinder))
- (not (OverOf red_cylinder bottom_drawer))";

const APPROACH_HANDLE: &str = "* Prediction Rationale:
- The empty gripper moved to the bottom drawer's handle; the observer reports it as surrounding the drawer.
* Predicted Action:
Action Semantic:
- Move gripper to bottom drawer handle
Precondition:
- (GripperOpen)
- (forall (?x - thing) (not (GripperHolding ?x)))
Effect:
- (GripperSurrounding bottom_drawer)";

const GRASP_HANDLE: &str = "* Prediction Rationale:
- The fingers closed on the handle.
* Predicted Action:
Action Semantic:
- Grasp bottom drawer handle
Precondition:
- (GripperOpen)
- (GripperSurrounding bottom_drawer)
Effect:
- (GripperClosed)
- (GripperHolding bottom_drawer_handle)
- (not (GripperOpen))
- (not (GripperSurrounding bottom_drawer))

Note that the handle is held rather than the drawer body.";

const PUSH_CLOSED: &str = "* Prediction Rationale:
- Holding the handle, the robot pushed the drawer shut.
* Predicted Action:
Action Semantic:
- **Push bottom drawer closed**
Precondition:
- (GripperHolding bottom_drawer_handle)
- (Open bottom_drawer)
Effect:
- (Closed bottom_drawer)
- (not (Open bottom_drawer))";

const RELEASE_HANDLE: &str = "Final step of the demonstration.

* Prediction Rationale:
- The gripper let go of the handle and is open again next to the drawer.
* Predicted Action:
Action Semantic:
- Release bottom drawer handle
Precondition:
- (GripperClosed)
- (GripperHolding bottom_drawer_handle)
Effect:
- (GripperOpen)
- (GripperSurrounding bottom_drawer)
- (not (GripperClosed))
- (not (GripperHolding bottom_drawer_handle))";

/// Misquotes the first action (the forall precondition is missing): no match.
const PATCH_NO_MATCH: &str = "* Refinement rationale:
The drop needs (Open bottom_drawer) but the drawer is closed in the new scene. This is case 1: actions are missing. The gripper is busy holding the cylinder at the failing step, so the drawer has to be opened before the cylinder is picked up.

* Refinement patch:
<<<<<<< SEARCH
MoveGripperToSurroundRedCylinder
- Preconditions:
	(GripperOpen)
	(OnTopOf red_cylinder floor)
- Effects:
	(GripperSurrounding red_cylinder)
=======
MoveGripperToBottomDrawerHandle
- Preconditions:
	(GripperOpen)
	(forall (?x - thing) (not (GripperHolding ?x)))
- Effects:
	(GripperSurrounding bottom_drawer)

GraspBottomDrawerHandle
- Preconditions:
	(GripperOpen)
	(GripperSurrounding bottom_drawer)
- Effects:
	(GripperClosed)
	(GripperHolding bottom_drawer_handle)
	(not (GripperOpen))
	(not (GripperSurrounding bottom_drawer))

PullBottomDrawerOpen
- Preconditions:
	(GripperHolding bottom_drawer_handle)
	(Closed bottom_drawer)
- Effects:
	(Open bottom_drawer)
	(not (Closed bottom_drawer))

ReleaseBottomDrawerHandle
- Preconditions:
	(GripperClosed)
	(GripperHolding bottom_drawer_handle)
- Effects:
	(GripperOpen)
	(GripperSurrounding bottom_drawer)
	(not (GripperClosed))
	(not (GripperHolding bottom_drawer_handle))

MoveGripperToSurroundRedCylinder
- Preconditions:
	(GripperOpen)
	(OnTopOf red_cylinder floor)
- Effects:
	(GripperSurrounding red_cylinder)
>>>>>>> REPLACE";

const PATCH: &str = "Apologies, I left out a precondition when quoting the action. Here is the patch with the action exactly as it appears in the plan.

**Refinement rationale:**
- Case 1 (missing actions): open the bottom drawer by its handle before picking up the cylinder, reusing the handle actions the demonstration already uses.

**Refinement patch:**
```
<<<<<<< SEARCH
MoveGripperToSurroundRedCylinder
- Preconditions:
    (GripperOpen)
    (OnTopOf red_cylinder floor)
    (forall (?x - thing) (not (GripperHolding ?x)))
- Effects:
    (GripperSurrounding red_cylinder)
=======
MoveGripperToBottomDrawerHandle
- Preconditions:
    (GripperOpen)
    (forall (?x - thing) (not (GripperHolding ?x)))
- Effects:
    (GripperSurrounding bottom_drawer)

GraspBottomDrawerHandle
- Preconditions:
    (GripperOpen)
    (GripperSurrounding bottom_drawer)
- Effects:
    (GripperClosed)
    (GripperHolding bottom_drawer_handle)
    (not (GripperOpen))
    (not (GripperSurrounding bottom_drawer))

PullBottomDrawerOpen
- Preconditions:
    (GripperHolding bottom_drawer_handle)
    (Closed bottom_drawer)
- Effects:
    (Open bottom_drawer)
    (not (Closed bottom_drawer))

ReleaseBottomDrawerHandle
- Preconditions:
    (GripperClosed)
    (GripperHolding bottom_drawer_handle)
- Effects:
    (GripperOpen)
    (GripperSurrounding bottom_drawer)
    (not (GripperClosed))
    (not (GripperHolding bottom_drawer_handle))

MoveGripperToSurroundRedCylinder
- Preconditions:
    (GripperOpen)
    (OnTopOf red_cylinder floor)
    (forall (?x - thing) (not (GripperHolding ?x)))
- Effects:
    (GripperSurrounding red_cylinder)
>>>>>>> REPLACE
```
This inserts the four drawer-opening actions before the pick.";

const CODE: &str = "Here is a program that follows the demonstration summary step by step.

```python
# The bottom drawer slides out toward the side its handle is on.
handle = get_obj_pos(\"bottom_drawer_handle\")
cabinet = get_obj_pos(\"drawer_body\")
open_dir = \"left\" if handle[1] < cabinet[1] else \"right\"
close_dir = \"right\" if open_dir == \"left\" else \"left\"
travel = get_obj_size(\"bottom_drawer\")[1] * 0.85

# 1-4: open the bottom drawer by its handle.
move_gripper_to(\"bottom_drawer_handle\", depth=0.0)
grasp_handle(\"bottom_drawer_handle\")
move_parallel(open_dir, travel)
release_handle()
move_parallel(\"up\", 0.05)

# 5-8: put the red cylinder into the drawer.
height = get_obj_size(\"red_cylinder\")[2]
move_gripper_to(\"red_cylinder\", depth=height / 2)
close_gripper()
drawer = get_obj_pos(\"bottom_drawer\")
drawer_size = get_obj_size(\"bottom_drawer\")
move_to_position([drawer[0], drawer[1], drawer[2] + drawer_size[2] + height])
open_gripper()

# 9-12: push the drawer closed again.
move_gripper_to(\"bottom_drawer_handle\", depth=0.0)
grasp_handle(\"bottom_drawer_handle\")
move_parallel(close_dir, travel)
release_handle()
```

Explanation: the drawer is opened first because it is closed in this scene; the direction is worked out from where the handle sits relative to the cabinet, so the same program works for a mirrored layout. The cylinder is lowered by half its height before grasping, released above the drawer's centre, and the drawer is pushed back closed.";

/// The reply for one request, by task.
pub(crate) fn reply(task: &VlmTask) -> Result<&'static str, String> {
    match task {
        VlmTask::Induction(c) => Ok(match (c.request.step, c.request.attempt) {
            (0, _) => APPROACH_CYLINDER,
            (1, 0) => GRASP_CYLINDER_WRONG,
            (1, _) => GRASP_CYLINDER,
            (2, _) => MOVE_OVER_DRAWER,
            (3, _) => DROP_INTO_DRAWER,
            (4, _) => APPROACH_HANDLE,
            (5, _) => GRASP_HANDLE,
            (6, _) => PUSH_CLOSED,
            (7, _) => RELEASE_HANDLE,
            (step, attempt) => return Err(format!("no reply for transition {step} attempt {attempt}")),
        }),
        VlmTask::Patch(c) => Ok(match c.request.iteration {
            0 => PATCH_NO_MATCH,
            1 => PATCH,
            i => return Err(format!("no reply for patch iteration {i}")),
        }),
        VlmTask::CodeGeneration(_) => Ok(CODE),
        VlmTask::StateTranslation(_) => Err("no state-translation replies are scripted".into()),
    }
}

/// Serves [`reply`] as chat completions.
#[derive(Debug, Default)]
pub(crate) struct HandWritten;

impl Transport for HandWritten {
    fn send<'a>(&'a self, request: &'a WireRequest) -> BoxFuture<'a, Result<WireResponse, TransportError>> {
        Box::pin(async move {
            let text = request
                .task
                .as_ref()
                .ok_or_else(|| "request without task context".to_owned())
                .and_then(|t| VlmTask::from_task_context(t).map_err(|e| e.to_string()))
                .and_then(|t| reply(&t));
            let (status, body) = match text {
                Ok(text) => (
                    200,
                    json!({
                        "id": "chatcmpl-handwritten",
                        "object": "chat.completion",
                        "model": MODEL,
                        "choices": [{"index": 0, "message": {"role": "assistant", "content": text}, "finish_reason": "stop"}],
                        "usage": {"prompt_tokens": 0, "completion_tokens": 0}
                    }),
                ),
                Err(message) => (
                    400,
                    json!({"error": {"message": message, "type": "invalid_request_error"}}),
                ),
            };
            Ok(WireResponse::new(
                status,
                serde_json::to_vec(&body).unwrap_or_default(),
                Origin::Live,
            ))
        })
    }

    fn label(&self) -> String {
        "hand-written".into()
    }
}
