//! Strict conversion of Python arguments for the robot API.
//!
//! Every robot function takes `*args, **kwargs` and binds them against a [`Signature`]
//! itself, so that every arity or type error quotes the function's full signature (pyo3's
//! own messages would not).

use nesy_sim::api::Direction;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::ffi;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyByteArray, PyBytes, PyDict, PyFloat, PyInt, PyString, PyTuple};

/// Height of the table surface in the world frame (`docs/benchmark.md` §1: `Z_OFFSET = 0.5`),
/// the scene format's one definition. A two-element position `(x, y)` means a point on the
/// table surface, `(x, y, TABLE_TOP_Z)`.
pub(crate) const TABLE_TOP_Z: f64 = nesy_sim::scene::TABLE_TOP;

/// A robot API function's name and parameters, in order.
#[derive(Debug)]
pub(crate) struct Signature {
    /// Function name.
    pub name: &'static str,
    /// Parameter names with their defaults rendered as Python source (`None` = required).
    pub params: &'static [(&'static str, Option<&'static str>)],
}

impl Signature {
    /// The signature as Python would print it, e.g. `move_gripper_to(obj_name, pointing_to='down', depth=0.01)`.
    pub(crate) fn render(&self) -> String {
        let params: Vec<String> = self
            .params
            .iter()
            .map(|(name, default)| match default {
                Some(d) => format!("{name}={d}"),
                None => (*name).to_string(),
            })
            .collect();
        format!("{}({})", self.name, params.join(", "))
    }

    fn type_error(&self, what: String) -> PyErr {
        PyTypeError::new_err(format!("{what}; signature: {}", self.render()))
    }

    /// Binds positional and keyword arguments to the parameters. `None` in the result means
    /// "use the default".
    pub(crate) fn bind<'py, const N: usize>(
        &self,
        args: &Bound<'py, PyTuple>,
        kwargs: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<[Option<Bound<'py, PyAny>>; N]> {
        debug_assert_eq!(N, self.params.len());
        let mut bound: [Option<Bound<'py, PyAny>>; N] = std::array::from_fn(|_| None);
        if args.len() > N {
            return Err(self.type_error(format!(
                "{}() takes at most {N} argument{} ({} given)",
                self.name,
                if N == 1 { "" } else { "s" },
                args.len()
            )));
        }
        for (slot, value) in bound.iter_mut().zip(args.iter()) {
            *slot = Some(value);
        }
        if let Some(kwargs) = kwargs {
            for (key, value) in kwargs.iter() {
                let key: String = key.extract()?;
                let Some(index) = self.params.iter().position(|(name, _)| *name == key) else {
                    return Err(self.type_error(format!(
                        "{}() got an unexpected keyword argument '{key}'",
                        self.name
                    )));
                };
                if bound[index].is_some() {
                    return Err(self.type_error(format!(
                        "{}() got multiple values for argument '{key}'",
                        self.name
                    )));
                }
                bound[index] = Some(value);
            }
        }
        for (index, (name, default)) in self.params.iter().enumerate() {
            if bound[index].is_none() && default.is_none() {
                return Err(self.type_error(format!("{}() missing required argument '{name}'", self.name)));
            }
        }
        Ok(bound)
    }

    /// Converts parameter `index` to a `str`.
    pub(crate) fn string(&self, index: usize, value: &Bound<'_, PyAny>) -> PyResult<String> {
        match value.cast::<PyString>() {
            Ok(s) => Ok(s.to_str()?.to_owned()),
            Err(_) => Err(self.type_error(format!(
                "{}() argument '{}' must be a str, not {}",
                self.name,
                self.params[index].0,
                type_name(value)
            ))),
        }
    }

    /// Converts parameter `index` to a finite float (Python `int` or `float`, not `bool`).
    pub(crate) fn number(&self, index: usize, value: &Bound<'_, PyAny>) -> PyResult<f64> {
        let what = format!("{}() argument '{}'", self.name, self.params[index].0);
        self.number_named(&what, value)
    }

    fn number_named(&self, what: &str, value: &Bound<'_, PyAny>) -> PyResult<f64> {
        let x = if value.is_instance_of::<PyBool>() {
            None
        } else if let Ok(f) = value.cast::<PyFloat>() {
            Some(f.value())
        } else if value.is_instance_of::<PyInt>() {
            Some(value.extract::<f64>()?)
        } else {
            None
        };
        match x {
            Some(x) if x.is_finite() => Ok(x),
            Some(x) => Err(PyValueError::new_err(format!(
                "{what} must be finite, got {x}; signature: {}",
                self.render()
            ))),
            None => Err(self.type_error(format!("{what} must be a number, not {}", type_name(value)))),
        }
    }

    /// Converts parameter `index` to a direction name (`left`, `right`, `front`, `back`,
    /// `up`, `down`). Whether the direction suits the call is the simulator's decision.
    pub(crate) fn direction(&self, index: usize, value: &Bound<'_, PyAny>) -> PyResult<Direction> {
        let name = self.string(index, value)?;
        Direction::from_name(&name).ok_or_else(|| {
            let known: Vec<&str> = Direction::ALL.iter().map(|d| d.as_str()).collect();
            PyValueError::new_err(format!(
                "{}() argument '{}' must be one of {}, got {name:?}; signature: {}",
                self.name,
                self.params[index].0,
                known.join(", "),
                self.render()
            ))
        })
    }

    /// Converts parameter `index` to a position: a list, tuple or other sequence (such as
    /// the `np` arrays the API returns) of 2 or 3 numbers. `(x, y)` means the point on the
    /// table surface, `(x, y, TABLE_TOP_Z)`.
    pub(crate) fn position(&self, index: usize, value: &Bound<'_, PyAny>) -> PyResult<[f64; 3]> {
        let param = self.params[index].0;
        let not_a_position = || {
            self.type_error(format!(
                "{}() argument '{param}' must be a list or tuple of 2 or 3 numbers, not {}",
                self.name,
                type_name(value)
            ))
        };
        if value.is_instance_of::<PyString>()
            || value.is_instance_of::<PyBytes>()
            || value.is_instance_of::<PyByteArray>()
            || value.is_instance_of::<PyDict>()
        {
            return Err(not_a_position());
        }
        // Raw sequence protocol: pyo3's `PySequence` cast imports `collections.abc`, and imports
        // made while a policy runs go through the policy's restricted `__import__`.
        // SAFETY: GIL held (we have a bound object); PySequence_* accept any object.
        let len = unsafe {
            if ffi::PySequence_Check(value.as_ptr()) == 0 {
                return Err(not_a_position());
            }
            ffi::PySequence_Size(value.as_ptr())
        };
        if len < 0 {
            // SAFETY: GIL held; clear the error left by PySequence_Size.
            unsafe { ffi::PyErr_Clear() };
            return Err(not_a_position());
        }
        let len = len as usize;
        if !(2..=3).contains(&len) {
            return Err(self.type_error(format!(
                "{}() argument '{param}' must have 2 or 3 coordinates, got {len}",
                self.name
            )));
        }
        let mut out = [0.0, 0.0, TABLE_TOP_Z];
        for (i, slot) in out.iter_mut().enumerate().take(len) {
            // SAFETY: GIL held; PySequence_GetItem returns a new reference or NULL with an error set.
            let item = unsafe {
                let raw = ffi::PySequence_GetItem(value.as_ptr(), i as ffi::Py_ssize_t);
                Bound::from_owned_ptr_or_err(value.py(), raw)?
            };
            *slot = self.number_named(&format!("{}() argument '{param}'[{i}]", self.name), &item)?;
        }
        Ok(out)
    }
}

fn type_name(value: &Bound<'_, PyAny>) -> String {
    value
        .get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "object".to_owned())
}
