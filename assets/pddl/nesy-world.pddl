;; nesy-world: the true operator schemas of nesy's simulated world (nesy-sim), one schema per
;; robot-API-level action, in the paper's predicate vocabulary as nesy-sim's observer emits it.
;; Finger schemas come first, then their vacuum counterparts (the same action with the vacuum
;; predicates: VacuumSuction, VacuumInactive, VacuumActive, VacuumAligned, VacuumAttached).
;; The comment above each action names the API call it stands for. See README.md next to this
;; file for the observer effects the schemas do not model.
;; PDDL is case-insensitive: nesy-core reads every name in lower case; the oracle restores the
;; predicates' CamelCase spelling from the vocabulary after parsing.
(define (domain nesy-world)
  (:requirements :strips :typing :negative-preconditions :universal-preconditions :conditional-effects)
  (:types item surface box part pieces - thing
    tool - item)
  (:constants
    floor board - surface
    hinge_body hinge_lid hinge_handle drawer_body top_drawer bottom_drawer
    top_drawer_handle bottom_drawer_handle - part)
  (:predicates
    (OverOf ?a ?b - thing) (OnTopOf ?a ?b - thing) (InsideOf ?a ?b - thing)
    (Open ?x - thing) (Closed ?x - thing)
    (FingerGripper) (VacuumSuction)
    (GripperSurrounding ?x - thing) (GripperHolding ?x - thing) (GripperOpen) (GripperClosed)
    (VacuumAligned ?x - thing) (VacuumAttached ?x - thing) (VacuumActive) (VacuumInactive)
    (Finegrained ?x - thing) (Gathered ?x - thing) (OnMagnet ?x ?h - thing))

  ;; ---------------------------------------------------------------- finger gripper
  ; move_gripper_to(?x, depth=h/2): the open tool goes around (finger) or onto (vacuum) a loose object nothing rests on
  (:action move-to-surround
    :parameters (?x - item)
    :precondition (and
      (FingerGripper)
      (GripperOpen)
      (forall (?y - thing) (not (GripperHolding ?y)))
      (forall (?y - thing) (not (OnTopOf ?y ?x)))
    )
    :effect (and
      (forall (?y - thing) (not (GripperSurrounding ?y)))
      (GripperSurrounding ?x)
    ))
  ; close_gripper / activate_vacuum: take the surrounded object
  (:action grasp
    :parameters (?x - item)
    :precondition (and
      (FingerGripper)
      (GripperOpen)
      (GripperSurrounding ?x)
    )
    :effect (and
      (GripperClosed)
      (GripperHolding ?x)
      (not (GripperOpen))
      (not (GripperSurrounding ?x))
    ))
  ; move_to_position: put the held object down on a free spot of a surface (table or board)
  (:action carry-onto
    :parameters (?x - item ?s - surface)
    :precondition (and
      (FingerGripper)
      (GripperHolding ?x)
    )
    :effect (and
      (forall (?y - thing) (not (OnTopOf ?x ?y)))
      (forall (?y - thing) (not (InsideOf ?x ?y)))
      (forall (?y - thing) (not (OverOf ?x ?y)))
      (OnTopOf ?x ?s)
    ))
  ; move_to_position: lower the held object into an open-topped box (it is inside while still held)
  (:action carry-into
    :parameters (?x - item ?b - box)
    :precondition (and
      (FingerGripper)
      (GripperHolding ?x)
    )
    :effect (and
      (forall (?y - thing) (not (OnTopOf ?x ?y)))
      (forall (?y - thing) (not (InsideOf ?x ?y)))
      (forall (?y - thing) (not (OverOf ?x ?y)))
      (InsideOf ?x ?b)
    ))
  ; move_to_position: hold the object over the open hinge box
  (:action carry-over-hinge-body
    :parameters (?x - item)
    :precondition (and
      (FingerGripper)
      (GripperHolding ?x)
      (Open hinge_lid)
    )
    :effect (and
      (forall (?y - thing) (not (OnTopOf ?x ?y)))
      (forall (?y - thing) (not (InsideOf ?x ?y)))
      (forall (?y - thing) (not (OverOf ?x ?y)))
      (OverOf ?x hinge_body)
    ))
  ; move_to_position: hold the object over the open bottom drawer
  (:action carry-over-bottom-drawer
    :parameters (?x - item)
    :precondition (and
      (FingerGripper)
      (GripperHolding ?x)
      (Open bottom_drawer)
    )
    :effect (and
      (forall (?y - thing) (not (OnTopOf ?x ?y)))
      (forall (?y - thing) (not (InsideOf ?x ?y)))
      (forall (?y - thing) (not (OverOf ?x ?y)))
      (OverOf ?x bottom_drawer)
    ))
  ; open_gripper / deactivate_vacuum: let go of an object held just above a surface; it comes to rest on it (the open tool stays around it)
  (:action put-down
    :parameters (?x - item ?s - surface)
    :precondition (and
      (FingerGripper)
      (GripperHolding ?x)
      (forall (?y - thing) (not (InsideOf ?x ?y)))
      (forall (?y - thing) (not (OverOf ?x ?y)))
    )
    :effect (and
      (forall (?y - thing) (not (OnTopOf ?x ?y)))
      (forall (?y - thing) (not (InsideOf ?x ?y)))
      (forall (?y - thing) (not (OverOf ?x ?y)))
      (OnTopOf ?x ?s)
      (GripperOpen)
      (not (GripperClosed))
      (not (GripperHolding ?x))
      (GripperSurrounding ?x)
    ))
  ; open_gripper / deactivate_vacuum: let go of an object already inside a box
  (:action release-into
    :parameters (?x - item ?b - box)
    :precondition (and
      (FingerGripper)
      (GripperHolding ?x)
      (InsideOf ?x ?b)
    )
    :effect (and
      (GripperOpen)
      (not (GripperClosed))
      (not (GripperHolding ?x))
    ))
  ; open_gripper / deactivate_vacuum: drop the object into the hinge box below it
  (:action drop-into-hinge-body
    :parameters (?x - item)
    :precondition (and
      (FingerGripper)
      (GripperHolding ?x)
      (OverOf ?x hinge_body)
    )
    :effect (and
      (GripperOpen)
      (not (GripperClosed))
      (not (GripperHolding ?x))
      (InsideOf ?x hinge_body)
      (not (OverOf ?x hinge_body))
    ))
  ; open_gripper / deactivate_vacuum: drop the object into the bottom drawer below it
  (:action drop-into-bottom-drawer
    :parameters (?x - item)
    :precondition (and
      (FingerGripper)
      (GripperHolding ?x)
      (OverOf ?x bottom_drawer)
    )
    :effect (and
      (GripperOpen)
      (not (GripperClosed))
      (not (GripperHolding ?x))
      (InsideOf ?x bottom_drawer)
      (not (OverOf ?x bottom_drawer))
    ))
  ; move_parallel(left|right): push the surrounded piece across the board into a box
  (:action sweep-into
    :parameters (?x - item ?b - box)
    :precondition (and
      (FingerGripper)
      (GripperOpen)
      (GripperSurrounding ?x)
      (OnTopOf ?x board)
    )
    :effect (and
      (InsideOf ?x ?b)
      (not (OnTopOf ?x board))
    ))
  ; move_parallel(up): lift the empty tool away from what it was around
  (:action retreat
    :parameters ()
    :precondition (and
      (FingerGripper)
      (GripperOpen)
    )
    :effect (and
      (forall (?y - thing) (not (GripperSurrounding ?y)))
    ))
  ; move_gripper_to(hinge_handle, depth=0)
  (:action move-to-hinge-handle
    :parameters ()
    :precondition (and
      (FingerGripper)
      (GripperOpen)
      (forall (?y - thing) (not (GripperHolding ?y)))
    )
    :effect (and
      (forall (?y - thing) (not (GripperSurrounding ?y)))
    ))
  ; grasp_handle / attach_vacuum_handle(hinge_handle): nothing may rest on the lid
  (:action grasp-hinge-handle
    :parameters ()
    :precondition (and
      (FingerGripper)
      (GripperOpen)
      (forall (?y - thing) (not (GripperHolding ?y)))
      (forall (?y - thing) (not (OnTopOf ?y hinge_lid)))
    )
    :effect (and
      (forall (?y - thing) (not (GripperSurrounding ?y)))
      (GripperClosed)
      (GripperHolding hinge_handle)
      (not (GripperOpen))
    ))
  ; move_to_position(lift_clearance=0): swing the lid up and over the hinge
  (:action open-hinge-lid
    :parameters ()
    :precondition (and
      (FingerGripper)
      (GripperHolding hinge_handle)
      (Closed hinge_lid)
    )
    :effect (and
      (Open hinge_lid)
      (not (Closed hinge_lid))
    ))
  ; move_to_position(lift_clearance=0): swing the lid back down onto the box
  (:action close-hinge-lid
    :parameters ()
    :precondition (and
      (FingerGripper)
      (GripperHolding hinge_handle)
      (Open hinge_lid)
    )
    :effect (and
      (Closed hinge_lid)
      (not (Open hinge_lid))
      (GripperOpen)
      (not (GripperClosed))
      (not (GripperHolding hinge_handle))
      (GripperSurrounding hinge_lid)
    ))
  ; release_handle / detach_vacuum_handle on the hinge handle
  (:action release-hinge-handle
    :parameters ()
    :precondition (and
      (FingerGripper)
      (GripperHolding hinge_handle)
    )
    :effect (and
      (GripperOpen)
      (not (GripperClosed))
      (not (GripperHolding hinge_handle))
    ))
  ; move_gripper_to(bottom_drawer_handle, depth=0)
  (:action move-to-bottom-drawer-handle
    :parameters ()
    :precondition (and
      (FingerGripper)
      (GripperOpen)
      (forall (?y - thing) (not (GripperHolding ?y)))
      (not (OnTopOf top_drawer bottom_drawer_handle))
    )
    :effect (and
      (forall (?y - thing) (not (GripperSurrounding ?y)))
      (GripperSurrounding bottom_drawer)
    ))
  ; grasp_handle / attach_vacuum_handle(bottom_drawer_handle)
  (:action grasp-bottom-drawer-handle
    :parameters ()
    :precondition (and
      (FingerGripper)
      (GripperOpen)
      (forall (?y - thing) (not (GripperHolding ?y)))
      (not (OnTopOf top_drawer bottom_drawer_handle))
    )
    :effect (and
      (forall (?y - thing) (not (GripperSurrounding ?y)))
      (GripperClosed)
      (GripperHolding bottom_drawer_handle)
      (not (GripperOpen))
    ))
  ; move_parallel(away from the cabinet): pull the bottom drawer open
  (:action open-bottom-drawer
    :parameters ()
    :precondition (and
      (FingerGripper)
      (GripperHolding bottom_drawer_handle)
      (Closed bottom_drawer)
    )
    :effect (and
      (Open bottom_drawer)
      (not (Closed bottom_drawer))
    ))
  ; move_parallel(toward the cabinet): push the bottom drawer closed
  (:action close-bottom-drawer
    :parameters ()
    :precondition (and
      (FingerGripper)
      (GripperHolding bottom_drawer_handle)
      (Open bottom_drawer)
    )
    :effect (and
      (Closed bottom_drawer)
      (not (Open bottom_drawer))
    ))
  ; release_handle / detach_vacuum_handle on the bottom drawer handle
  (:action release-bottom-drawer-handle
    :parameters ()
    :precondition (and
      (FingerGripper)
      (GripperHolding bottom_drawer_handle)
    )
    :effect (and
      (GripperOpen)
      (not (GripperClosed))
      (not (GripperHolding bottom_drawer_handle))
      (GripperSurrounding bottom_drawer)
    ))
  ; move_gripper_to(top_drawer_handle, depth=0)
  (:action move-to-top-drawer-handle
    :parameters ()
    :precondition (and
      (FingerGripper)
      (GripperOpen)
      (forall (?y - thing) (not (GripperHolding ?y)))
    )
    :effect (and
      (forall (?y - thing) (not (GripperSurrounding ?y)))
      (GripperSurrounding top_drawer)
    ))
  ; grasp_handle / attach_vacuum_handle(top_drawer_handle)
  (:action grasp-top-drawer-handle
    :parameters ()
    :precondition (and
      (FingerGripper)
      (GripperOpen)
      (forall (?y - thing) (not (GripperHolding ?y)))
    )
    :effect (and
      (forall (?y - thing) (not (GripperSurrounding ?y)))
      (GripperClosed)
      (GripperHolding top_drawer_handle)
      (not (GripperOpen))
    ))
  ; move_parallel(away from the cabinet): pull the top drawer open
  (:action open-top-drawer
    :parameters ()
    :precondition (and
      (FingerGripper)
      (GripperHolding top_drawer_handle)
      (Closed top_drawer)
    )
    :effect (and
      (Open top_drawer)
      (not (Closed top_drawer))
      (OnTopOf top_drawer bottom_drawer_handle)
    ))
  ; move_parallel(toward the cabinet): push the top drawer closed
  (:action close-top-drawer
    :parameters ()
    :precondition (and
      (FingerGripper)
      (GripperHolding top_drawer_handle)
      (Open top_drawer)
    )
    :effect (and
      (Closed top_drawer)
      (not (Open top_drawer))
      (not (OnTopOf top_drawer bottom_drawer_handle))
    ))
  ; release_handle / detach_vacuum_handle on the top drawer handle
  (:action release-top-drawer-handle
    :parameters ()
    :precondition (and
      (FingerGripper)
      (GripperHolding top_drawer_handle)
    )
    :effect (and
      (GripperOpen)
      (not (GripperClosed))
      (not (GripperHolding top_drawer_handle))
      (GripperSurrounding top_drawer)
    ))

  ;; ---------------------------------------------------------------- magnetic hook (finger gripper)
  ; gather_with_hook(?x): sweep the held hook's magnet low over the pieces of ?x; they cling to it and are lifted with it
  (:action gather-with-hook
    :parameters (?h - tool ?x - pieces)
    :precondition (and
      (FingerGripper)
      (GripperHolding ?h)
      (Finegrained ?x)
    )
    :effect (and
      (forall (?s - thing) (when (or (InsideOf ?x ?s) (OnTopOf ?x ?s)) (OverOf ?h ?s)))
      (forall (?y - thing) (not (OnTopOf ?h ?y)))
      (forall (?y - thing) (not (InsideOf ?h ?y)))
      (forall (?y - thing) (not (OverOf ?h ?y)))
      (forall (?y - thing) (not (OnTopOf ?x ?y)))
      (forall (?y - thing) (not (InsideOf ?x ?y)))
      (Gathered ?x)
      (OnMagnet ?x ?h)
    ))
  ; move_to_position: hold the hook over the open bottom drawer, the pieces on its magnet hanging under it
  (:action carry-hook-over-bottom-drawer
    :parameters (?h - tool)
    :precondition (and
      (FingerGripper)
      (GripperHolding ?h)
      (Open bottom_drawer)
    )
    :effect (and
      (forall (?y - thing) (not (OnTopOf ?h ?y)))
      (forall (?y - thing) (not (InsideOf ?h ?y)))
      (forall (?y - thing) (not (OverOf ?h ?y)))
      (OverOf ?h bottom_drawer)
      (forall (?x - thing) (when (OnMagnet ?x ?h) (and
        (forall (?y - thing) (not (OnTopOf ?x ?y)))
        (forall (?y - thing) (not (InsideOf ?x ?y))))))
    ))
  ; open_gripper: drop the hook into the bottom drawer below it; the pieces on its magnet go in with it
  (:action drop-hook-into-bottom-drawer
    :parameters (?h - tool)
    :precondition (and
      (FingerGripper)
      (GripperHolding ?h)
      (OverOf ?h bottom_drawer)
    )
    :effect (and
      (GripperOpen)
      (not (GripperClosed))
      (not (GripperHolding ?h))
      (InsideOf ?h bottom_drawer)
      (not (OverOf ?h bottom_drawer))
      (forall (?x - thing) (when (OnMagnet ?x ?h) (InsideOf ?x bottom_drawer)))
    ))

  ;; ---------------------------------------------------------------- vacuum suction tool
  ; move_gripper_to(?x, depth=h/2): the open tool goes around (finger) or onto (vacuum) a loose object nothing rests on
  (:action move-to-align
    :parameters (?x - item)
    :precondition (and
      (VacuumSuction)
      (VacuumInactive)
      (forall (?y - thing) (not (VacuumAttached ?y)))
      (forall (?y - thing) (not (OnTopOf ?y ?x)))
    )
    :effect (and
      (forall (?y - thing) (not (VacuumAligned ?y)))
      (VacuumAligned ?x)
    ))
  ; close_gripper / activate_vacuum: take the surrounded object
  (:action attach
    :parameters (?x - item)
    :precondition (and
      (VacuumSuction)
      (VacuumInactive)
      (VacuumAligned ?x)
    )
    :effect (and
      (VacuumActive)
      (VacuumAttached ?x)
      (not (VacuumInactive))
      (not (VacuumAligned ?x))
    ))
  ; move_to_position: put the held object down on a free spot of a surface (table or board)
  (:action suction-carry-onto
    :parameters (?x - item ?s - surface)
    :precondition (and
      (VacuumSuction)
      (VacuumAttached ?x)
    )
    :effect (and
      (forall (?y - thing) (not (OnTopOf ?x ?y)))
      (forall (?y - thing) (not (InsideOf ?x ?y)))
      (forall (?y - thing) (not (OverOf ?x ?y)))
      (OnTopOf ?x ?s)
    ))
  ; move_to_position: lower the held object into an open-topped box (it is inside while still held)
  (:action suction-carry-into
    :parameters (?x - item ?b - box)
    :precondition (and
      (VacuumSuction)
      (VacuumAttached ?x)
    )
    :effect (and
      (forall (?y - thing) (not (OnTopOf ?x ?y)))
      (forall (?y - thing) (not (InsideOf ?x ?y)))
      (forall (?y - thing) (not (OverOf ?x ?y)))
      (InsideOf ?x ?b)
    ))
  ; move_to_position: hold the object over the open hinge box
  (:action suction-carry-over-hinge-body
    :parameters (?x - item)
    :precondition (and
      (VacuumSuction)
      (VacuumAttached ?x)
      (Open hinge_lid)
    )
    :effect (and
      (forall (?y - thing) (not (OnTopOf ?x ?y)))
      (forall (?y - thing) (not (InsideOf ?x ?y)))
      (forall (?y - thing) (not (OverOf ?x ?y)))
      (OverOf ?x hinge_body)
    ))
  ; move_to_position: hold the object over the open bottom drawer
  (:action suction-carry-over-bottom-drawer
    :parameters (?x - item)
    :precondition (and
      (VacuumSuction)
      (VacuumAttached ?x)
      (Open bottom_drawer)
    )
    :effect (and
      (forall (?y - thing) (not (OnTopOf ?x ?y)))
      (forall (?y - thing) (not (InsideOf ?x ?y)))
      (forall (?y - thing) (not (OverOf ?x ?y)))
      (OverOf ?x bottom_drawer)
    ))
  ; open_gripper / deactivate_vacuum: let go of an object held just above a surface; it comes to rest on it (the open tool stays around it)
  (:action suction-put-down
    :parameters (?x - item ?s - surface)
    :precondition (and
      (VacuumSuction)
      (VacuumAttached ?x)
      (forall (?y - thing) (not (InsideOf ?x ?y)))
      (forall (?y - thing) (not (OverOf ?x ?y)))
    )
    :effect (and
      (forall (?y - thing) (not (OnTopOf ?x ?y)))
      (forall (?y - thing) (not (InsideOf ?x ?y)))
      (forall (?y - thing) (not (OverOf ?x ?y)))
      (OnTopOf ?x ?s)
      (VacuumInactive)
      (not (VacuumActive))
      (not (VacuumAttached ?x))
      (VacuumAligned ?x)
    ))
  ; open_gripper / deactivate_vacuum: let go of an object already inside a box
  (:action suction-release-into
    :parameters (?x - item ?b - box)
    :precondition (and
      (VacuumSuction)
      (VacuumAttached ?x)
      (InsideOf ?x ?b)
    )
    :effect (and
      (VacuumInactive)
      (not (VacuumActive))
      (not (VacuumAttached ?x))
    ))
  ; open_gripper / deactivate_vacuum: drop the object into the hinge box below it
  (:action suction-drop-into-hinge-body
    :parameters (?x - item)
    :precondition (and
      (VacuumSuction)
      (VacuumAttached ?x)
      (OverOf ?x hinge_body)
    )
    :effect (and
      (VacuumInactive)
      (not (VacuumActive))
      (not (VacuumAttached ?x))
      (InsideOf ?x hinge_body)
      (not (OverOf ?x hinge_body))
    ))
  ; open_gripper / deactivate_vacuum: drop the object into the bottom drawer below it
  (:action suction-drop-into-bottom-drawer
    :parameters (?x - item)
    :precondition (and
      (VacuumSuction)
      (VacuumAttached ?x)
      (OverOf ?x bottom_drawer)
    )
    :effect (and
      (VacuumInactive)
      (not (VacuumActive))
      (not (VacuumAttached ?x))
      (InsideOf ?x bottom_drawer)
      (not (OverOf ?x bottom_drawer))
    ))
  ; move_parallel(left|right): slide the attached piece across the board into a box
  (:action slide-into
    :parameters (?x - item ?b - box)
    :precondition (and
      (VacuumSuction)
      (VacuumAttached ?x)
      (OnTopOf ?x board)
    )
    :effect (and
      (InsideOf ?x ?b)
      (not (OnTopOf ?x board))
    ))
  ; move_parallel(up): lift the empty tool away from what it was around
  (:action suction-retreat
    :parameters ()
    :precondition (and
      (VacuumSuction)
      (VacuumInactive)
    )
    :effect (and
      (forall (?y - thing) (not (VacuumAligned ?y)))
    ))
  ; move_gripper_to(hinge_handle, depth=0)
  (:action suction-move-to-hinge-handle
    :parameters ()
    :precondition (and
      (VacuumSuction)
      (VacuumInactive)
      (forall (?y - thing) (not (VacuumAttached ?y)))
    )
    :effect (and
      (forall (?y - thing) (not (VacuumAligned ?y)))
    ))
  ; grasp_handle / attach_vacuum_handle(hinge_handle): nothing may rest on the lid
  (:action attach-hinge-handle
    :parameters ()
    :precondition (and
      (VacuumSuction)
      (VacuumInactive)
      (forall (?y - thing) (not (VacuumAttached ?y)))
      (forall (?y - thing) (not (OnTopOf ?y hinge_lid)))
    )
    :effect (and
      (forall (?y - thing) (not (VacuumAligned ?y)))
      (VacuumActive)
      (VacuumAttached hinge_handle)
      (not (VacuumInactive))
    ))
  ; move_to_position(lift_clearance=0): swing the lid up and over the hinge
  (:action suction-open-hinge-lid
    :parameters ()
    :precondition (and
      (VacuumSuction)
      (VacuumAttached hinge_handle)
      (Closed hinge_lid)
    )
    :effect (and
      (Open hinge_lid)
      (not (Closed hinge_lid))
    ))
  ; move_to_position(lift_clearance=0): swing the lid back down onto the box
  (:action suction-close-hinge-lid
    :parameters ()
    :precondition (and
      (VacuumSuction)
      (VacuumAttached hinge_handle)
      (Open hinge_lid)
    )
    :effect (and
      (Closed hinge_lid)
      (not (Open hinge_lid))
    ))
  ; release_handle / detach_vacuum_handle on the hinge handle
  (:action detach-hinge-handle
    :parameters ()
    :precondition (and
      (VacuumSuction)
      (VacuumAttached hinge_handle)
    )
    :effect (and
      (VacuumInactive)
      (not (VacuumActive))
      (not (VacuumAttached hinge_handle))
    ))
  ; move_gripper_to(bottom_drawer_handle, depth=0)
  (:action suction-move-to-bottom-drawer-handle
    :parameters ()
    :precondition (and
      (VacuumSuction)
      (VacuumInactive)
      (forall (?y - thing) (not (VacuumAttached ?y)))
      (not (OnTopOf top_drawer bottom_drawer_handle))
    )
    :effect (and
      (forall (?y - thing) (not (VacuumAligned ?y)))
    ))
  ; grasp_handle / attach_vacuum_handle(bottom_drawer_handle)
  (:action attach-bottom-drawer-handle
    :parameters ()
    :precondition (and
      (VacuumSuction)
      (VacuumInactive)
      (forall (?y - thing) (not (VacuumAttached ?y)))
      (not (OnTopOf top_drawer bottom_drawer_handle))
    )
    :effect (and
      (forall (?y - thing) (not (VacuumAligned ?y)))
      (VacuumActive)
      (VacuumAttached bottom_drawer_handle)
      (not (VacuumInactive))
    ))
  ; move_parallel(away from the cabinet): pull the bottom drawer open
  (:action suction-open-bottom-drawer
    :parameters ()
    :precondition (and
      (VacuumSuction)
      (VacuumAttached bottom_drawer_handle)
      (Closed bottom_drawer)
    )
    :effect (and
      (Open bottom_drawer)
      (not (Closed bottom_drawer))
    ))
  ; move_parallel(toward the cabinet): push the bottom drawer closed
  (:action suction-close-bottom-drawer
    :parameters ()
    :precondition (and
      (VacuumSuction)
      (VacuumAttached bottom_drawer_handle)
      (Open bottom_drawer)
    )
    :effect (and
      (Closed bottom_drawer)
      (not (Open bottom_drawer))
    ))
  ; release_handle / detach_vacuum_handle on the bottom drawer handle
  (:action detach-bottom-drawer-handle
    :parameters ()
    :precondition (and
      (VacuumSuction)
      (VacuumAttached bottom_drawer_handle)
    )
    :effect (and
      (VacuumInactive)
      (not (VacuumActive))
      (not (VacuumAttached bottom_drawer_handle))
    ))
  ; move_gripper_to(top_drawer_handle, depth=0)
  (:action suction-move-to-top-drawer-handle
    :parameters ()
    :precondition (and
      (VacuumSuction)
      (VacuumInactive)
      (forall (?y - thing) (not (VacuumAttached ?y)))
    )
    :effect (and
      (forall (?y - thing) (not (VacuumAligned ?y)))
    ))
  ; grasp_handle / attach_vacuum_handle(top_drawer_handle)
  (:action attach-top-drawer-handle
    :parameters ()
    :precondition (and
      (VacuumSuction)
      (VacuumInactive)
      (forall (?y - thing) (not (VacuumAttached ?y)))
    )
    :effect (and
      (forall (?y - thing) (not (VacuumAligned ?y)))
      (VacuumActive)
      (VacuumAttached top_drawer_handle)
      (not (VacuumInactive))
    ))
  ; move_parallel(away from the cabinet): pull the top drawer open
  (:action suction-open-top-drawer
    :parameters ()
    :precondition (and
      (VacuumSuction)
      (VacuumAttached top_drawer_handle)
      (Closed top_drawer)
    )
    :effect (and
      (Open top_drawer)
      (not (Closed top_drawer))
      (OnTopOf top_drawer bottom_drawer_handle)
    ))
  ; move_parallel(toward the cabinet): push the top drawer closed
  (:action suction-close-top-drawer
    :parameters ()
    :precondition (and
      (VacuumSuction)
      (VacuumAttached top_drawer_handle)
      (Open top_drawer)
    )
    :effect (and
      (Closed top_drawer)
      (not (Open top_drawer))
      (not (OnTopOf top_drawer bottom_drawer_handle))
    ))
  ; release_handle / detach_vacuum_handle on the top drawer handle
  (:action detach-top-drawer-handle
    :parameters ()
    :precondition (and
      (VacuumSuction)
      (VacuumAttached top_drawer_handle)
    )
    :effect (and
      (VacuumInactive)
      (not (VacuumActive))
      (not (VacuumAttached top_drawer_handle))
    ))
)
