//! The `robot` Python module: the paper's perception and action API (`docs/benchmark.md` §4), with the
//! same names, parameters and defaults, calling into the episode's [`RobotApi`].
//!
//! Positions and boxes come back as `np.array`s of the vetted `np` subset, as in the
//! authors' runtime; names as a `list` of `str`. Refusals raise subclasses of
//! `robot.RobotError` carrying the simulator's message.

use nesy_sim::api::{ApiError, DEFAULT_DEPTH, DEFAULT_LIFT_CLEARANCE, Direction, RobotApi};
use pyo3::exceptions::{PyBaseException, PyException};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyList, PyTuple};

use super::convert::Signature;
use super::session::{self, Refusal};

pyo3::create_exception!(
    robot,
    RobotError,
    PyException,
    "The robot refused or failed an API call."
);
pyo3::create_exception!(
    robot,
    WrongEmbodimentError,
    RobotError,
    "The call belongs to the other end effector (finger gripper vs. vacuum)."
);
pyo3::create_exception!(
    robot,
    UnknownObjectError,
    RobotError,
    "No object of that name in the scene."
);
pyo3::create_exception!(
    robot,
    InfeasibleError,
    RobotError,
    "The call cannot be carried out now: blocked, out of reach, no IK solution, no free space."
);
pyo3::create_exception!(
    robot,
    CollisionError,
    RobotError,
    "The motion was stopped by contact: a lid or drawer being moved ran into other furniture; the robot stays where it stopped."
);
pyo3::create_exception!(
    robot,
    InvalidArgumentError,
    RobotError,
    "An argument value is out of range."
);
pyo3::create_exception!(
    robot,
    BudgetExhaustedError,
    RobotError,
    "The episode's budget of robot calls is used up; the episode is terminated."
);
pyo3::create_exception!(
    robot,
    RobotStoppedError,
    RobotError,
    "The robot stopped the motion itself (protective or emergency stop, operator, time limit); it stays where it stopped."
);
pyo3::create_exception!(
    robot,
    SandboxViolation,
    PyBaseException,
    "The sandbox refused an operation; the episode is terminated."
);

/// `np.array` of the vetted numpy subset, used to return positions.
static NP_ARRAY: PyOnceLock<Py<PyAny>> = PyOnceLock::new();

/// Registers the constructor used for array return values.
pub(crate) fn set_array_constructor(py: Python<'_>, array: Py<PyAny>) {
    let _ = NP_ARRAY.set(py, array);
}

fn api_error(err: ApiError) -> PyErr {
    let message = err.to_string();
    match err {
        ApiError::WrongEmbodiment { .. } => WrongEmbodimentError::new_err(message),
        ApiError::UnknownObject { .. } => UnknownObjectError::new_err(message),
        ApiError::Infeasible { .. }
        | ApiError::OutOfWorkspace { .. }
        | ApiError::IkFailed { .. }
        | ApiError::NoEmptySpace { .. } => InfeasibleError::new_err(message),
        ApiError::Collision { .. } => CollisionError::new_err(message),
        ApiError::InvalidArgument { .. } => InvalidArgumentError::new_err(message),
        ApiError::BudgetExhausted { .. } => BudgetExhaustedError::new_err(message),
        ApiError::Stopped { .. } | ApiError::TimedOut { .. } => RobotStoppedError::new_err(message),
    }
}

fn run<T: Send>(
    py: Python<'_>,
    is_action: bool,
    f: impl FnOnce(&mut (dyn RobotApi + Send)) -> Result<T, ApiError> + Send,
) -> PyResult<T> {
    session::call(py, is_action, f)
        .map_err(Refusal::into_pyerr)?
        .map_err(api_error)
}

fn array<'py>(py: Python<'py>, values: Vec<f64>) -> PyResult<Bound<'py, PyAny>> {
    match NP_ARRAY.get(py) {
        Some(ctor) => ctor.bind(py).call1((values,)),
        None => Ok(PyList::new(py, values)?.into_any()),
    }
}

fn array2<'py>(py: Python<'py>, rows: [[f64; 3]; 2]) -> PyResult<Bound<'py, PyAny>> {
    let nested = vec![rows[0].to_vec(), rows[1].to_vec()];
    match NP_ARRAY.get(py) {
        Some(ctor) => ctor.bind(py).call1((nested,)),
        None => Ok(PyList::new(py, nested)?.into_any()),
    }
}

const OBJ: &[(&str, Option<&str>)] = &[("obj_name", None)];
const HANDLE: &[(&str, Option<&str>)] = &[("handle_name", None)];
const NONE: &[(&str, Option<&str>)] = &[];

macro_rules! sig {
    ($name:ident, $params:expr) => {
        pub(super) const $name: Signature = Signature {
            name: stringify!($name),
            params: $params,
        };
    };
}

#[allow(non_upper_case_globals)]
mod sigs {
    use super::*;
    sig!(is_obj_visible, OBJ);
    sig!(get_obj_names, NONE);
    sig!(get_obj_pos, OBJ);
    sig!(get_obj_bbox, OBJ);
    sig!(get_obj_size, OBJ);
    sig!(gripper_is_open, NONE);
    sig!(obj_in_gripper, OBJ);
    sig!(get_empty_floor_xy, OBJ);
    sig!(
        move_gripper_to,
        &[
            ("obj_name", None),
            ("pointing_to", Some("'down'")),
            ("depth", Some("0.01"))
        ]
    );
    sig!(
        move_to_position,
        &[
            ("pos", None),
            ("pointing_to", Some("'down'")),
            ("lift_clearance", Some("0.12")),
            ("angle", Some("0.0")),
        ]
    );
    sig!(
        move_parallel,
        &[
            ("move_dir", None),
            ("offset", None),
            ("pointing_to", Some("'down'"))
        ]
    );
    sig!(grasp_handle, HANDLE);
    sig!(release_handle, NONE);
    sig!(open_gripper, NONE);
    sig!(close_gripper, NONE);
    sig!(attach_vacuum_handle, HANDLE);
    sig!(detach_vacuum_handle, NONE);
    sig!(activate_vacuum, NONE);
    sig!(deactivate_vacuum, NONE);
    sig!(gather_with_hook, OBJ);
}

/// Every function of the module with its signature, in the order of the paper's tables.
pub(crate) const SIGNATURES: [&Signature; 20] = [
    &sigs::is_obj_visible,
    &sigs::get_obj_names,
    &sigs::get_obj_pos,
    &sigs::get_obj_bbox,
    &sigs::get_obj_size,
    &sigs::gripper_is_open,
    &sigs::obj_in_gripper,
    &sigs::get_empty_floor_xy,
    &sigs::move_gripper_to,
    &sigs::move_to_position,
    &sigs::move_parallel,
    &sigs::grasp_handle,
    &sigs::release_handle,
    &sigs::open_gripper,
    &sigs::close_gripper,
    &sigs::attach_vacuum_handle,
    &sigs::detach_vacuum_handle,
    &sigs::activate_vacuum,
    &sigs::deactivate_vacuum,
    &sigs::gather_with_hook,
];

/// Perception functions taking one object name.
macro_rules! perceive_obj {
    ($(#[$doc:meta])* $name:ident, |$r:ident, $n:ident| $call:expr, |$py:ident, $v:ident| $ret:expr) => {
        $(#[$doc])*
        #[pyfunction(signature = (*args, **kwargs), text_signature = "(obj_name)")]
        fn $name<'py>($py: Python<'py>, args: &Bound<'py, PyTuple>, kwargs: Option<&Bound<'py, PyDict>>) -> PyResult<Bound<'py, PyAny>> {
            let sig = &sigs::$name;
            let [obj] = sig.bind::<1>(args, kwargs)?;
            let $n = sig.string(0, obj.as_ref().expect("required"))?;
            let $v = run($py, false, move |$r| $call)?;
            $ret
        }
    };
}

/// Action functions without parameters.
macro_rules! act_bare {
    ($(#[$doc:meta])* $name:ident) => {
        $(#[$doc])*
        #[pyfunction(signature = (*args, **kwargs), text_signature = "()")]
        fn $name(py: Python<'_>, args: &Bound<'_, PyTuple>, kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<()> {
            sigs::$name.bind::<0>(args, kwargs)?;
            run(py, true, |r| r.$name())
        }
    };
}

/// Action functions taking one handle name.
macro_rules! act_handle {
    ($(#[$doc:meta])* $name:ident) => {
        $(#[$doc])*
        #[pyfunction(signature = (*args, **kwargs), text_signature = "(handle_name)")]
        fn $name(py: Python<'_>, args: &Bound<'_, PyTuple>, kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<()> {
            let sig = &sigs::$name;
            let [handle] = sig.bind::<1>(args, kwargs)?;
            let handle = sig.string(0, handle.as_ref().expect("required"))?;
            run(py, true, move |r| r.$name(&handle))
        }
    };
}

perceive_obj!(
    /// is_obj_visible(obj_name) -> bool: whether the object is in the scene's object list.
    is_obj_visible, |r, name| Ok(r.is_obj_visible(&name)), |py, v| Ok(pyo3::types::PyBool::new(py, v).to_owned().into_any())
);
perceive_obj!(
    /// get_obj_pos(obj_name) -> array of (x, y, z): centre of the object's bounding box.
    get_obj_pos, |r, name| r.get_obj_pos(&name), |py, v| array(py, v.to_vec())
);
perceive_obj!(
    /// get_obj_bbox(obj_name) -> array [min, max]: the object's axis-aligned bounding box.
    get_obj_bbox, |r, name| r.get_obj_bbox(&name), |py, v| array2(py, v)
);
perceive_obj!(
    /// get_obj_size(obj_name) -> array: extents of the bounding box (max - min).
    get_obj_size, |r, name| r.get_obj_size(&name), |py, v| array(py, v.to_vec())
);
perceive_obj!(
    /// obj_in_gripper(obj_name) -> bool: whether the object is in the grasp or suction region.
    obj_in_gripper, |r, name| r.obj_in_gripper(&name), |py, v| Ok(pyo3::types::PyBool::new(py, v).to_owned().into_any())
);
perceive_obj!(
    /// get_empty_floor_xy(obj_name) -> array of (x, y): a free table position for the object.
    get_empty_floor_xy, |r, name| r.get_empty_floor_xy(&name), |py, v| array(py, v.to_vec())
);

/// get_obj_names() -> list of str: every object in the scene.
#[pyfunction(signature = (*args, **kwargs), text_signature = "()")]
fn get_obj_names<'py>(
    py: Python<'py>,
    args: &Bound<'py, PyTuple>,
    kwargs: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyList>> {
    sigs::get_obj_names.bind::<0>(args, kwargs)?;
    let names = run(py, false, |r| Ok(r.get_obj_names()))?;
    PyList::new(py, names)
}

/// gripper_is_open() -> bool: whether the gripper is open (vacuum: suction off).
#[pyfunction(signature = (*args, **kwargs), text_signature = "()")]
fn gripper_is_open(
    py: Python<'_>,
    args: &Bound<'_, PyTuple>,
    kwargs: Option<&Bound<'_, PyDict>>,
) -> PyResult<bool> {
    sigs::gripper_is_open.bind::<0>(args, kwargs)?;
    run(py, false, |r| Ok(r.gripper_is_open()))
}

/// move_gripper_to(obj_name, pointing_to='down', depth=0.01): move the end effector to the object.
#[pyfunction(signature = (*args, **kwargs), text_signature = "(obj_name, pointing_to='down', depth=0.01)")]
fn move_gripper_to(
    py: Python<'_>,
    args: &Bound<'_, PyTuple>,
    kwargs: Option<&Bound<'_, PyDict>>,
) -> PyResult<()> {
    let sig = &sigs::move_gripper_to;
    let [obj, pointing, depth] = sig.bind::<3>(args, kwargs)?;
    let obj = sig.string(0, obj.as_ref().expect("required"))?;
    let pointing = pointing
        .map(|v| sig.direction(1, &v))
        .transpose()?
        .unwrap_or(Direction::Down);
    let depth = depth
        .map(|v| sig.number(2, &v))
        .transpose()?
        .unwrap_or(DEFAULT_DEPTH);
    run(py, true, move |r| r.move_gripper_to(&obj, pointing, depth))
}

/// move_to_position(pos, pointing_to='down', lift_clearance=0.12, angle=0.0): move the end
/// effector to a position; (x, y) means the point on the table surface.
#[pyfunction(
    signature = (*args, **kwargs),
    text_signature = "(pos, pointing_to='down', lift_clearance=0.12, angle=0.0)"
)]
fn move_to_position(
    py: Python<'_>,
    args: &Bound<'_, PyTuple>,
    kwargs: Option<&Bound<'_, PyDict>>,
) -> PyResult<()> {
    let sig = &sigs::move_to_position;
    let [pos, pointing, clearance, angle] = sig.bind::<4>(args, kwargs)?;
    let pos = sig.position(0, pos.as_ref().expect("required"))?;
    let pointing = pointing
        .map(|v| sig.direction(1, &v))
        .transpose()?
        .unwrap_or(Direction::Down);
    let clearance = clearance
        .map(|v| sig.number(2, &v))
        .transpose()?
        .unwrap_or(DEFAULT_LIFT_CLEARANCE);
    let angle = angle.map(|v| sig.number(3, &v)).transpose()?.unwrap_or(0.0);
    run(py, true, move |r| {
        r.move_to_position(pos, pointing, clearance, angle)
    })
}

/// move_parallel(move_dir, offset, pointing_to='down'): translate the end effector by
/// offset metres towards left/right/front/back/up.
#[pyfunction(signature = (*args, **kwargs), text_signature = "(move_dir, offset, pointing_to='down')")]
fn move_parallel(
    py: Python<'_>,
    args: &Bound<'_, PyTuple>,
    kwargs: Option<&Bound<'_, PyDict>>,
) -> PyResult<()> {
    let sig = &sigs::move_parallel;
    let [dir, offset, pointing] = sig.bind::<3>(args, kwargs)?;
    let dir = sig.direction(0, dir.as_ref().expect("required"))?;
    let offset = sig.number(1, offset.as_ref().expect("required"))?;
    let pointing = pointing
        .map(|v| sig.direction(2, &v))
        .transpose()?
        .unwrap_or(Direction::Down);
    run(py, true, move |r| r.move_parallel(dir, offset, pointing))
}

act_handle!(
    /// grasp_handle(handle_name): grasp a handle within reach (finger gripper).
    grasp_handle
);
act_bare!(
    /// release_handle(): release the grasped handle and open the gripper (finger gripper).
    release_handle
);
act_bare!(
    /// open_gripper(): open the fingers (finger gripper).
    open_gripper
);
act_bare!(
    /// close_gripper(): close the fingers, grasping what is between them (finger gripper).
    close_gripper
);
act_handle!(
    /// attach_vacuum_handle(handle_name): vacuum counterpart of grasp_handle.
    attach_vacuum_handle
);
act_bare!(
    /// detach_vacuum_handle(): vacuum counterpart of release_handle.
    detach_vacuum_handle
);
act_bare!(
    /// activate_vacuum(): vacuum counterpart of close_gripper.
    activate_vacuum
);
act_bare!(
    /// deactivate_vacuum(): vacuum counterpart of open_gripper.
    deactivate_vacuum
);

/// gather_with_hook(obj_name): sweep the held magnetic hook over a fine-grained object's
/// pieces, so that its magnet gathers them (both end effectors).
#[pyfunction(signature = (*args, **kwargs), text_signature = "(obj_name)")]
fn gather_with_hook(
    py: Python<'_>,
    args: &Bound<'_, PyTuple>,
    kwargs: Option<&Bound<'_, PyDict>>,
) -> PyResult<()> {
    let sig = &sigs::gather_with_hook;
    let [name] = sig.bind::<1>(args, kwargs)?;
    let name = sig.string(0, name.as_ref().expect("required"))?;
    run(py, true, move |r| r.gather_with_hook(&name))
}

/// The `robot` module, registered with `append_to_inittab!` before the interpreter starts.
#[pymodule]
pub(crate) fn robot(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(is_obj_visible, m)?)?;
    m.add_function(wrap_pyfunction!(get_obj_names, m)?)?;
    m.add_function(wrap_pyfunction!(get_obj_pos, m)?)?;
    m.add_function(wrap_pyfunction!(get_obj_bbox, m)?)?;
    m.add_function(wrap_pyfunction!(get_obj_size, m)?)?;
    m.add_function(wrap_pyfunction!(gripper_is_open, m)?)?;
    m.add_function(wrap_pyfunction!(obj_in_gripper, m)?)?;
    m.add_function(wrap_pyfunction!(get_empty_floor_xy, m)?)?;
    m.add_function(wrap_pyfunction!(move_gripper_to, m)?)?;
    m.add_function(wrap_pyfunction!(move_to_position, m)?)?;
    m.add_function(wrap_pyfunction!(move_parallel, m)?)?;
    m.add_function(wrap_pyfunction!(grasp_handle, m)?)?;
    m.add_function(wrap_pyfunction!(release_handle, m)?)?;
    m.add_function(wrap_pyfunction!(open_gripper, m)?)?;
    m.add_function(wrap_pyfunction!(close_gripper, m)?)?;
    m.add_function(wrap_pyfunction!(attach_vacuum_handle, m)?)?;
    m.add_function(wrap_pyfunction!(detach_vacuum_handle, m)?)?;
    m.add_function(wrap_pyfunction!(activate_vacuum, m)?)?;
    m.add_function(wrap_pyfunction!(deactivate_vacuum, m)?)?;
    m.add_function(wrap_pyfunction!(gather_with_hook, m)?)?;
    let py = m.py();
    m.add("RobotError", py.get_type::<RobotError>())?;
    m.add("WrongEmbodimentError", py.get_type::<WrongEmbodimentError>())?;
    m.add("UnknownObjectError", py.get_type::<UnknownObjectError>())?;
    m.add("InfeasibleError", py.get_type::<InfeasibleError>())?;
    m.add("CollisionError", py.get_type::<CollisionError>())?;
    m.add("InvalidArgumentError", py.get_type::<InvalidArgumentError>())?;
    m.add("BudgetExhaustedError", py.get_type::<BudgetExhaustedError>())?;
    m.add("RobotStoppedError", py.get_type::<RobotStoppedError>())?;
    m.add("SandboxViolation", py.get_type::<SandboxViolation>())?;
    m.add("TABLE_TOP_Z", super::convert::TABLE_TOP_Z)?;
    Ok(())
}
