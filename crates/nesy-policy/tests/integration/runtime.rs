//! The embedded runtime against the recording test double: argument conversion, error
//! mapping, tracebacks, output capture and each in-interpreter sandbox layer.

use nesy_core::Embodiment;
use nesy_policy::RecordingRobot;
use nesy_policy::run_in_process_without_static_checks;
use nesy_policy::{ExecutionResult, Limits, Outcome, TimeLimit, check_source, run_in_process};
use nesy_sim::api::{ApiCall, Direction};

fn run_with(source: &str, embodiment: Embodiment, limits: &Limits) -> ExecutionResult {
    run_in_process(source, Box::new(RecordingRobot::new(embodiment)), limits, None)
        .expect("interpreter starts")
}

fn run(source: &str) -> ExecutionResult {
    run_with(source, Embodiment::Finger, &Limits::default())
}

/// Runs `source` without the static checks, to show what the run-time layers do with what
/// the checks would already refuse (arity errors, undefined names).
fn run_unchecked(source: &str) -> ExecutionResult {
    run_in_process_without_static_checks(
        source,
        Box::new(RecordingRobot::new(Embodiment::Finger)),
        &Limits::default(),
        None,
    )
    .expect("interpreter starts")
}

fn python_error(result: &ExecutionResult) -> &nesy_policy::PythonError {
    match &result.outcome {
        Outcome::PythonError(e) => e,
        other => panic!("expected a Python error, got {other:?}"),
    }
}

#[test]
fn pick_and_place_style_policy_runs_with_bare_names_and_module_names() {
    let source = r#"
import numpy as np
obj = "red_cube"
pos = get_obj_pos(obj)
size = robot.get_obj_size(obj)
move_gripper_to(obj, depth=size[2] / 2)
close_gripper()
above = pos + np.array([0, 0, 0.1])
move_to_position(above)
box = get_obj_pos("toy_box")
move_to_position([box[0], box[1], box[2] + 0.1], lift_clearance=0.05)
open_gripper()
print("placed", obj, "at", round(box[0], 2))
"#;
    let result = run(source);
    assert_eq!(result.outcome, Outcome::Ok, "{:#?}", result.outcome);
    let names: Vec<&str> = result.trace.iter().map(|e| e.call.name()).collect();
    assert_eq!(
        names,
        [
            "get_obj_pos",
            "get_obj_size",
            "move_gripper_to",
            "close_gripper",
            "move_to_position",
            "get_obj_pos",
            "move_to_position",
            "open_gripper"
        ]
    );
    match &result.trace[2].call {
        ApiCall::MoveGripperTo {
            obj_name,
            pointing_to,
            depth,
        } => {
            assert_eq!(obj_name, "red_cube");
            assert_eq!(*pointing_to, Direction::Down);
            assert!((depth - 0.02).abs() < 1e-9);
        }
        other => panic!("unexpected call {other:?}"),
    }
    match &result.trace[4].call {
        ApiCall::MoveToPosition {
            pos,
            lift_clearance,
            angle,
            ..
        } => {
            assert!(
                (pos[2] - 0.62).abs() < 1e-9,
                "array arithmetic is element-wise: {pos:?}"
            );
            assert_eq!(*lift_clearance, 0.12);
            assert_eq!(*angle, 0.0);
        }
        other => panic!("unexpected call {other:?}"),
    }
    match &result.trace[6].call {
        ApiCall::MoveToPosition { lift_clearance, .. } => assert_eq!(*lift_clearance, 0.05),
        other => panic!("unexpected call {other:?}"),
    }
    assert_eq!(result.stdout.text, "placed red_cube at 0.6\n");
}

#[test]
fn defaults_keywords_and_two_element_positions() {
    let source = r#"
move_gripper_to("red_cube", "left")
move_to_position((0.4, 0.1))
move_to_position(pos=[0.4, 0.1, 0.7], angle=1.5, pointing_to="right")
move_parallel("up", 0.05)
move_parallel(move_dir="front", offset=1)
"#;
    let result = run(source);
    assert_eq!(result.outcome, Outcome::Ok, "{:#?}", result.outcome);
    let calls: Vec<&ApiCall> = result.trace.iter().map(|e| &e.call).collect();
    assert_eq!(
        calls[0],
        &ApiCall::MoveGripperTo {
            obj_name: "red_cube".into(),
            pointing_to: Direction::Left,
            depth: 0.01
        }
    );
    assert_eq!(
        calls[1],
        &ApiCall::MoveToPosition {
            pos: [0.4, 0.1, 0.5],
            pointing_to: Direction::Down,
            lift_clearance: 0.12,
            angle: 0.0
        }
    );
    assert_eq!(
        calls[2],
        &ApiCall::MoveToPosition {
            pos: [0.4, 0.1, 0.7],
            pointing_to: Direction::Right,
            lift_clearance: 0.12,
            angle: 1.5
        }
    );
    assert_eq!(
        calls[3],
        &ApiCall::MoveParallel {
            move_dir: Direction::Up,
            offset: 0.05,
            pointing_to: Direction::Down
        }
    );
    assert_eq!(
        calls[4],
        &ApiCall::MoveParallel {
            move_dir: Direction::Front,
            offset: 1.0,
            pointing_to: Direction::Down
        }
    );
}

#[test]
fn bad_types_and_arity_raise_type_error_with_the_signature() {
    let cases = [
        ("move_gripper_to()", "missing required argument 'obj_name'"),
        (
            "move_gripper_to('a', 'down', 0.1, 4)",
            "takes at most 3 arguments (4 given)",
        ),
        (
            "move_gripper_to('red_cube', speed=3)",
            "unexpected keyword argument 'speed'",
        ),
        (
            "move_gripper_to('red_cube', obj_name='x')",
            "multiple values for argument 'obj_name'",
        ),
        ("move_gripper_to(3)", "argument 'obj_name' must be a str, not int"),
        (
            "move_gripper_to('red_cube', depth=True)",
            "argument 'depth' must be a number, not bool",
        ),
        (
            "move_to_position('abc')",
            "must be a list or tuple of 2 or 3 numbers, not str",
        ),
        (
            "move_to_position([1, 2, 3, 4])",
            "must have 2 or 3 coordinates, got 4",
        ),
        ("move_to_position([1])", "must have 2 or 3 coordinates, got 1"),
        (
            "move_to_position([1, 'x'])",
            "argument 'pos'[1] must be a number, not str",
        ),
        ("move_to_position({'x': 1, 'y': 2})", "not dict"),
        (
            "grasp_handle(None)",
            "argument 'handle_name' must be a str, not NoneType",
        ),
    ];
    for (call, expected) in cases {
        // Arity is also refused by the static checks; the run-time binding is the layer
        // under them, for calls whose arguments are only known then (`*args`).
        let result = run_unchecked(call);
        let error = python_error(&result);
        assert_eq!(error.exception, "TypeError", "{call}: {error:?}");
        assert!(error.message.contains(expected), "{call}: {}", error.message);
        assert!(
            error.message.contains("; signature: "),
            "{call}: {}",
            error.message
        );
        assert!(result.trace.is_empty(), "{call}: nothing reaches the robot");
    }
    let error = run(
        "move_to_position([0.1, 0.2, 0.3], lift_clearance=1)\nmove_to_position([0.1, 0.2])\nmove_gripper_to('red_cube', 'sideways')",
    );
    let error = python_error(&error);
    assert_eq!(error.exception, "ValueError");
    assert!(
        error
            .message
            .contains("must be one of left, right, front, back, up, down")
    );
    assert!(
        error
            .message
            .contains("signature: move_gripper_to(obj_name, pointing_to='down', depth=0.01)")
    );
    assert_eq!(error.line, Some(3));
    let nan = run("move_parallel('up', float('nan'))");
    assert_eq!(python_error(&nan).exception, "ValueError");
}

#[test]
fn refusals_raise_robot_exceptions_with_the_simulators_message() {
    let result = run("move_gripper_to('purple_cube')");
    let error = python_error(&result);
    assert_eq!(error.exception, "robot.UnknownObjectError");
    assert!(
        error
            .message
            .starts_with("unknown object \"purple_cube\"; known objects: red_cube"),
        "{}",
        error.message
    );
    assert_eq!(result.trace.len(), 1, "refused calls are traced");
    assert!(result.trace[0].result.is_err());

    let vacuum = run_with(
        "activate_vacuum()\nclose_gripper()",
        Embodiment::Vacuum,
        &Limits::default(),
    );
    let error = python_error(&vacuum);
    assert_eq!(error.exception, "robot.WrongEmbodimentError");
    assert_eq!(
        error.message,
        "close_gripper() is not available on the vacuum robot; use activate_vacuum() instead"
    );
    assert_eq!(error.line, Some(2));

    let caught = run(
        "try:\n    grasp_handle('x')\n    open_gripper()\n    move_parallel('up', -1)\nexcept robot.RobotError as err:\n    print(type_name := 'caught', err)\n",
    );
    assert_eq!(caught.outcome, Outcome::Ok, "{:#?}", caught.outcome);
    assert!(
        caught
            .stdout
            .text
            .starts_with("caught invalid argument to move_parallel()"),
        "{}",
        caught.stdout.text
    );
}

#[test]
fn tracebacks_point_into_the_policy_source() {
    let source = "def place(name):\n    pos = get_obj_pos(name)\n    return pos[5]\n\nplace('red_cube')\n";
    let result = run(source);
    let error = python_error(&result);
    assert_eq!(error.exception, "IndexError");
    assert_eq!(error.line, Some(3));
    let lines: Vec<(String, u32)> = error
        .frames
        .iter()
        .filter(|f| f.file == "policy.py")
        .map(|f| (f.function.clone(), f.line))
        .collect();
    assert_eq!(lines, [("<module>".to_owned(), 5), ("place".to_owned(), 3)]);
    assert!(
        error
            .traceback
            .contains("  File \"policy.py\", line 3, in place\n    return pos[5]\n"),
        "{}",
        error.traceback
    );
    assert!(
        error
            .traceback
            .ends_with("IndexError: index 5 is out of bounds for axis 0 with size 3")
    );
}

#[test]
fn output_is_captured_and_capped() {
    let limits = Limits {
        output_cap_bytes: 100,
        ..Limits::default()
    };
    let result = run_with(
        "for i in range(100):\n    print('line', i)\n",
        Embodiment::Finger,
        &limits,
    );
    assert_eq!(result.outcome, Outcome::Ok);
    assert_eq!(result.stdout.text.len(), 100);
    assert!(result.stdout.truncated_bytes > 0);
    let err = run("print('oops', end='')\nprint('x', 1, sep='-')");
    assert_eq!(err.stdout.text, "oopsx-1\n");
}

#[test]
fn episodes_do_not_share_globals() {
    assert_eq!(run("leftover = 42").outcome, Outcome::Ok);
    // The static checks refuse the name outright; run unchecked, it is a NameError.
    assert!(matches!(run("print(leftover)").outcome, Outcome::Rejected { .. }));
    let result = run_unchecked("print(leftover)");
    assert_eq!(python_error(&result).exception, "NameError");
}

#[test]
fn main_guard_runs_and_classes_work() {
    let source = "class Plan:\n    def __init__(self):\n        pass\n";
    assert!(matches!(run(source).outcome, Outcome::Rejected { .. }));
    let source = "class Plan:\n    steps = 0\n\ndef main():\n    Plan.steps += 1\n    print('steps', Plan.steps)\n\nif __name__ == '__main__':\n    main()\n";
    let result = run(source);
    assert_eq!(result.outcome, Outcome::Ok, "{:#?}", result.outcome);
    assert_eq!(result.stdout.text, "steps 1\n");
}

// ---- layer 1: static checks ----

#[test]
fn static_checks_reject_before_anything_runs() {
    let rejected = [
        ("().__class__", "attribute '__class__' starts with an underscore"),
        ("__import__('os')", "name '__import__' starts with an underscore"),
        ("import os", "import of 'os' is not allowed"),
        (
            "from subprocess import run",
            "import from 'subprocess' is not allowed",
        ),
        (
            "import math.something",
            "import of 'math.something' is not allowed",
        ),
        ("from . import x", "import from '.' is not allowed"),
        ("open('/etc/passwd')", "name 'open' is not available"),
        ("eval('1')", "name 'eval' is not available"),
        ("exec('1')", "name 'exec' is not available"),
        ("compile('1', 'f', 'exec')", "name 'compile' is not available"),
        ("getattr(1, 'real')", "name 'getattr' is not available"),
        ("globals()", "name 'globals' is not available"),
        ("vars()", "name 'vars' is not available"),
        (
            "def g():\n    yield 1\ng().gi_frame",
            "attribute 'gi_frame' is not available",
        ),
        ("'{0.real}'.format(1)", "str.format is only allowed on a literal"),
        (
            "fmt = '{}'\nfmt.format(1)",
            "str.format is only allowed on a literal",
        ),
        (
            "'{x}'.format_map({'x': 1})",
            "attribute 'format_map' is not available",
        ),
        ("import math\nmath.pi = 3", "modules cannot be modified"),
        ("robot.get_obj_pos = print", "modules cannot be modified"),
        ("async def f():\n    pass", "async functions are not available"),
        ("x = 1 +", "syntax error"),
        ("print('\\0')\n\0", "invalid source"),
        // Names nothing defines: each would be a NameError after the robot has moved.
        (
            "open_gripper()\ngrasp_object('red_cube')",
            "name 'grasp_object' is not defined",
        ),
        ("open_gripper()\nopen_gripp", "did you mean 'open_gripper'?"),
        ("print(cube_names)", "name 'cube_names' is not defined"),
        // Robot API calls whose arguments cannot bind.
        (
            "move_gripper_to()",
            "move_gripper_to() is missing its argument 'obj_name'",
        ),
        (
            "move_gripper_to('red_cube', dept=0.02)",
            "move_gripper_to() has no parameter 'dept'",
        ),
        (
            "close_gripper(1)",
            "close_gripper() takes at most 0 argument(s) (1 given)",
        ),
    ];
    // Nesting deep enough that CPython's parser gives up with an empty MemoryError or a
    // RecursionError: a finding with a message, never "static checker failed".
    let unary_chain = format!("x = {}1\n", "-".repeat(100_000));
    let additions = format!("x = 1{}\n", "+1".repeat(200_000));
    for source in [unary_chain, additions] {
        let found = check_source(&source).unwrap();
        assert_eq!(found.len(), 1, "{found:?}");
        assert!(found[0].message.contains("nested too deeply"), "{found:?}");
    }
    for (source, expected) in rejected {
        let result = run(source);
        match &result.outcome {
            Outcome::Rejected { violations } => assert!(
                violations.iter().any(|v| v.message.contains(expected)),
                "{source:?}: {violations:?}"
            ),
            other => panic!("{source:?} should be rejected, got {other:?}"),
        }
        assert!(result.trace.is_empty());
    }
    let violations = nesy_policy::check_source("x = 1\n\ny = ().__class__").unwrap();
    assert_eq!((violations[0].line, violations[0].column), (3, 5));
    assert_eq!(
        violations[0].to_string(),
        "policy.py:3:5: attribute '__class__' starts with an underscore"
    );
}

#[test]
fn static_checks_accept_ordinary_policy_code() {
    let accepted = [
        "import math\nfrom math import sqrt, pi\nimport numpy as np\nfrom robot import *\nimport robot",
        "for _ in range(3):\n    pass",
        "x = '{} {:.2f} {name!r}'.format(1, 2.0, name='a')\ny = f'{x} {1 + 2:>5}'",
        "names = [n for n in get_obj_names() if n.endswith('cube')]\nnames.sort(key=lambda n: n)",
        "try:\n    move_gripper_to('nothing')\nexcept robot.UnknownObjectError:\n    pass",
        // Names bound in every way Python binds them, used before or after, in any scope.
        "def place(name, depth=0.01):\n    move_gripper_to(name, depth=depth)\n    return helper()\ndef helper():\n    global count\n    count = 1\n    return count\nplace('red_cube')",
        "with_items = {k: v for k, v in zip('ab', range(2))}\nfor key, (a, *rest) in [('k', (1, 2))]:\n    print(key, a, rest)\ntry:\n    pass\nexcept ValueError as err:\n    print(err)",
        "class Plan:\n    steps = []\nif __name__ == '__main__':\n    print(Plan.steps, robot.get_obj_names, np.array([1]))",
        "from robot import *\nfrom math import *\nprint(TABLE_TOP_Z, UnknownObjectError, sqrt(4))",
        "args = ('red_cube',)\nmove_gripper_to(*args)\nopts = {'depth': 0.02}\nmove_gripper_to('red_cube', **opts)",
    ];
    for source in accepted {
        assert_eq!(nesy_policy::check_source(source).unwrap(), [], "{source}");
        assert_eq!(run(source).outcome, Outcome::Ok, "{source}");
    }
}

// ---- layer 2: curated builtins and imports (static checks off) ----

#[test]
fn curated_builtins_and_import_allowlist_hold_without_static_checks() {
    for (source, exception) in [
        ("import os", "ImportError"),
        ("import subprocess", "ImportError"),
        ("from . import x", "ImportError"),
        ("open('/etc/passwd')", "NameError"),
        ("eval('1')", "NameError"),
        ("getattr(1, 'real')", "NameError"),
        ("type(1)", "NameError"),
    ] {
        let result = run_unchecked(source);
        assert_eq!(python_error(&result).exception, exception, "{source}");
    }
    assert_eq!(
        run_unchecked("import math\nprint(math.sqrt(4))").stdout.text,
        "2.0\n"
    );
}

// ---- layer 3: the audit hook (static checks off) ----

#[test]
fn audit_hook_terminates_frame_and_code_access_even_when_caught() {
    let run_unchecked = |source: &str| {
        run_in_process_without_static_checks(
            source,
            Box::new(RecordingRobot::new(Embodiment::Finger)),
            &Limits {
                wall_time_ms: 5_000,
                ..Limits::default()
            },
            None,
        )
        .unwrap()
    };
    for (source, event) in [
        ("def g():\n    yield 1\nf = g().gi_frame", "object.__getattr__"),
        ("c = (lambda: 0).__code__", "object.__getattr__"),
        (
            "try:\n    1 / 0\nexcept Exception as e:\n    f = e.__traceback__.tb_frame",
            "object.__getattr__",
        ),
        (
            "b = ().__class__.__base__.__subclasses__()\nfor k in b:\n    if k.__name__ == 'BuiltinImporter':\n        k.load_module('posix').system('true')",
            "os.system",
        ),
        (
            "def g():\n    yield 1\ntry:\n    g().gi_frame\nexcept BaseException:\n    pass\nprint('survived')",
            "object.__getattr__",
        ),
    ] {
        let result = run_unchecked(source);
        match &result.outcome {
            Outcome::SandboxViolation { event: got, .. } => assert_eq!(got, event, "{source}"),
            other => panic!("{source}: expected a sandbox violation, got {other:?}"),
        }
        assert!(!result.stdout.text.contains("survived"), "{source}");
    }
}

// ---- layer 4: budgets ----

#[test]
fn one_line_busy_loop_is_stopped_by_the_watchdog() {
    let limits = Limits {
        wall_time_ms: 300,
        ..Limits::default()
    };
    let t0 = std::time::Instant::now();
    let result = run_with("while True: pass", Embodiment::Finger, &limits);
    assert!(
        matches!(
            result.outcome,
            Outcome::Timeout {
                limit: TimeLimit::WallClock,
                ..
            }
        ),
        "{:?}",
        result.outcome
    );
    assert!(t0.elapsed().as_millis() < 2_000);
}

#[test]
fn swallowing_the_timeout_does_not_help() {
    let limits = Limits {
        wall_time_ms: 300,
        ..Limits::default()
    };
    let source =
        "n = 0\nwhile True:\n    try:\n        while True: pass\n    except BaseException:\n        n += 1\n";
    let result = run_with(source, Embodiment::Finger, &limits);
    assert!(
        matches!(
            result.outcome,
            Outcome::Timeout {
                limit: TimeLimit::WallClock,
                ..
            }
        ),
        "{:?}",
        result.outcome
    );
}

#[test]
fn instruction_budget_stops_long_loops() {
    let limits = Limits {
        instruction_budget: 10_000,
        ..Limits::default()
    };
    let result = run_with(
        "x = 0\nfor i in range(10**9):\n    x += i\n",
        Embodiment::Finger,
        &limits,
    );
    assert!(
        matches!(
            result.outcome,
            Outcome::Timeout {
                limit: TimeLimit::Instructions,
                ..
            }
        ),
        "{:?}",
        result.outcome
    );
}

#[test]
fn action_and_api_budgets_stop_call_floods() {
    let limits = Limits {
        action_calls: 5,
        api_calls: 50,
        ..Limits::default()
    };
    let actions = run_with(
        "while True:\n    try:\n        open_gripper()\n    except Exception:\n        pass\n",
        Embodiment::Finger,
        &limits,
    );
    assert!(
        matches!(
            actions.outcome,
            Outcome::Timeout {
                limit: TimeLimit::ActionCalls,
                ..
            }
        ),
        "{:?}",
        actions.outcome
    );
    assert_eq!(actions.trace.len(), 5);
    let perception = run_with("while True:\n    get_obj_names()\n", Embodiment::Finger, &limits);
    assert!(
        matches!(
            perception.outcome,
            Outcome::Timeout {
                limit: TimeLimit::ApiCalls,
                ..
            }
        ),
        "{:?}",
        perception.outcome
    );
    assert_eq!(perception.trace.len(), 50);
}

#[test]
fn huge_allocations_become_memory_errors() {
    let result = run("x = [0] * 10**11");
    assert!(
        matches!(result.outcome, Outcome::Memory { .. }),
        "{:?}",
        result.outcome
    );
}

#[test]
fn api_names_match_the_paper() {
    // The paper's 19 functions, then the tool-use call.
    let names = nesy_policy::api_function_names();
    assert_eq!(names.len(), 20);
    assert_eq!(names.last(), Some(&"gather_with_hook"));
    let signatures = nesy_policy::api_signatures();
    assert!(
        signatures.contains(
            &"move_to_position(pos, pointing_to='down', lift_clearance=0.12, angle=0.0)".to_owned()
        )
    );
    assert!(signatures.contains(&"move_parallel(move_dir, offset, pointing_to='down')".to_owned()));
}

/// A drawer pulled into another cabinet's open drawer stops there, and the policy sees the
/// contact as `robot.CollisionError`, a `RobotError` it can catch.
#[test]
fn a_drawer_stopped_by_another_raises_collision_error() {
    let sim = nesy_sim::world::Sim::from_file(&nesy_testkit::scene_fixture("drawers_perpendicular_finger"))
        .unwrap();
    let source = r#"
move_gripper_to("front_top_drawer_handle")
grasp_handle("front_top_drawer_handle")
try:
    move_parallel("left", 0.12)
except robot.CollisionError as err:
    print("stopped:", err, isinstance(err, robot.RobotError))
"#;
    let result = run_in_process(source, Box::new(sim), &Limits::default(), None).expect("interpreter starts");
    assert_eq!(result.outcome, Outcome::Ok, "{:#?}", result.outcome);
    assert!(
        result.stdout.text.contains(
            "stopped: move_parallel() was stopped by contact: front_top_drawer ran into side_top_drawer True"
        ),
        "{}",
        result.stdout.text
    );
}

/// A policy gathers scattered screws with the magnetic hook: `gather_with_hook` is in the
/// `robot` module, refuses without a hook in hand, and after the sweep the screws travel
/// with the hook.
#[test]
fn a_policy_gathers_screws_with_the_magnetic_hook() {
    let sim = nesy_sim::world::Sim::from_file(&nesy_testkit::scene_fixture("hook_screws_finger")).unwrap();
    let source = r#"
try:
    gather_with_hook("black_screws")
except robot.InfeasibleError as err:
    print("refused:", err)
move_gripper_to("magnetic_hook")
close_gripper()
gather_with_hook(obj_name="black_screws")
print("in gripper:", obj_in_gripper("magnetic_hook"))
"#;
    let result = run_in_process(source, Box::new(sim), &Limits::default(), None).expect("interpreter starts");
    assert_eq!(result.outcome, Outcome::Ok, "{:#?}", result.outcome);
    let out = &result.stdout.text;
    assert!(
        out.contains("refused: gather_with_hook(black_screws) is infeasible: nothing is held"),
        "{out}"
    );
    assert!(out.contains("in gripper: True"), "{out}");
    let state = format!("{:?}", result.final_state);
    assert!(state.contains("(Gathered black_screws)"), "{state}");
}

/// A template-compiled fruit pick beside the hinge box, on a robot whose protective stop is
/// on: the turn away from the nearest fruit would lay the hand's length across the hinge
/// box's wall, where the stop ends the descent; compiled for the stop, the program turns
/// the wrist further, until the hand is clear, and takes the fruit.
#[test]
fn a_fruit_pick_compiled_for_the_protective_stop_keeps_the_hand_off_the_hinge_box() {
    let scene = r#"{
      "schema_version": 1, "embodiment": "finger", "protective_stop": true,
      "objects": [
        {"name": "hinge_body", "kind": "hinge_box", "pose": {"position": [0.65, 0.18, 0.5]}},
        {"name": "apple", "kind": "apple", "pose": {"position": [0.51, 0.2, 0.5]}},
        {"name": "orange", "kind": "orange", "pose": {"position": [0.51, 0.12, 0.5]}}
      ],
      "goals": []
    }"#;
    let scene = nesy_sim::scene::SceneSpec::from_json_str(scene, "apple by the hinge box").unwrap();
    let objects: Vec<String> = [
        "floor",
        "hinge_body",
        "hinge_lid",
        "hinge_handle",
        "apple",
        "orange",
    ]
    .map(String::from)
    .to_vec();
    let procedure: Vec<nesy_core::Operator> = [
        "MoveToSurroundApple",
        "GraspApple",
        "CarryOverHingeBodyApple",
        "DropIntoHingeBodyApple",
    ]
    .into_iter()
    .map(|name| nesy_core::Operator::new(name, vec![], vec![]))
    .collect();
    let pick = |protective_stop: bool| {
        let code =
            nesy_sim::codegen::compile_policy(&procedure, &objects, Embodiment::Finger, protective_stop)
                .unwrap()
                .code;
        // The program up to the grasp, then a report of what the hand holds.
        let end = code.find("# 3. ").expect("a third action");
        let source = format!("{}print(\"holding:\", obj_in_gripper(\"apple\"))\n", &code[..end]);
        let sim = nesy_sim::world::Sim::new(&scene).unwrap();
        run_in_process(&source, Box::new(sim), &Limits::default(), None).expect("interpreter starts")
    };

    let unaware = pick(false);
    let err = python_error(&unaware);
    assert_eq!(err.exception, "robot.CollisionError", "{err:#?}");
    assert!(err.message.contains("ran into hinge_"), "{err:#?}");

    let aware = pick(true);
    assert_eq!(aware.outcome, Outcome::Ok, "{:#?}", aware.outcome);
    assert!(
        aware.stdout.text.contains("holding: True"),
        "{}",
        aware.stdout.text
    );
}
