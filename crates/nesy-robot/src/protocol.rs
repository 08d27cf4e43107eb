//! The robot protocol's messages (`docs/robot-protocol.md`): JSON-RPC 2.0, one JSON object per
//! line, over a TCP or Unix stream. The robot API's calls are methods of the same names with
//! named parameters; `hello`, `heartbeat`, `get_tool_pos`, `finish` and `stop` complete it.

use nesy_core::Embodiment;
use nesy_sim::api::{ApiCall, ApiError, ApiValue};
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value, json};

/// The protocol's name and version, exchanged in `hello`.
pub const PROTOCOL_VERSION: &str = "nesy-robot/1";

/// Longest message line either side accepts, in bytes.
pub const MAX_MESSAGE_BYTES: u64 = 1 << 20;

/// JSON-RPC error codes the protocol uses.
pub mod codes {
    /// The line is not JSON.
    pub const PARSE_ERROR: i64 = -32700;
    /// The JSON is not a JSON-RPC 2.0 request.
    pub const INVALID_REQUEST: i64 = -32600;
    /// No such method.
    pub const METHOD_NOT_FOUND: i64 = -32601;
    /// The parameters do not fit the method.
    pub const INVALID_PARAMS: i64 = -32602;
    /// The robot refused or failed the call; `data` is the typed error (`kind` and fields).
    pub const ROBOT_ERROR: i64 = -32000;
    /// The session was stopped (by `stop`, the heartbeat watchdog or the robot); nothing more
    /// is executed on it.
    pub const SESSION_STOPPED: i64 = -32001;
    /// A robot call came before `hello`.
    pub const NO_SESSION: i64 = -32002;
}

/// `hello`'s parameters: the client introduces itself and its settings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Hello {
    /// [`PROTOCOL_VERSION`].
    pub protocol: String,
    /// The client's name and version, e.g. `nesy 0.1.0`.
    pub client: String,
    /// How often the client sends `heartbeat`, in seconds.
    pub heartbeat_period_s: f64,
    /// The fraction of the robot's nominal speed every motion must keep to, in (0, 1].
    pub speed_scale: f64,
}

/// `hello`'s result: the server introduces its robot.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Welcome {
    /// [`PROTOCOL_VERSION`].
    pub protocol: String,
    /// The robot's name, e.g. `nesy simulator: scene.json` or `fr3-lab2`.
    pub robot: String,
    /// Which tool it carries.
    pub embodiment: Embodiment,
    /// After this long without any message from the client, the server stops the robot.
    pub heartbeat_timeout_s: f64,
    /// The speed scale the robot will keep to (must equal the one asked for).
    pub speed_scale: f64,
}

/// A JSON-RPC request line.
pub(crate) fn request(id: Value, method: &str, params: Value) -> Value {
    json!({"jsonrpc": "2.0", "id": id, "method": method, "params": params})
}

/// A call's method name and named parameters (every default filled in).
pub(crate) fn call_request(call: &ApiCall) -> (&'static str, Value) {
    let mut params = match serde_json::to_value(call) {
        Ok(Value::Object(map)) => map,
        _ => Map::new(),
    };
    params.remove("call");
    (call.name(), Value::Object(params))
}

/// The call a request names, or why it does not name one.
pub(crate) fn call_from_request(method: &str, params: &Value) -> Result<ApiCall, String> {
    let mut map = match params {
        Value::Object(map) => map.clone(),
        Value::Null => Map::new(),
        _ => return Err("params must be an object of named parameters".to_owned()),
    };
    map.insert("call".to_owned(), Value::String(method.to_owned()));
    serde_json::from_value(Value::Object(map)).map_err(|e| e.to_string())
}

/// The JSON result of a successful call.
pub(crate) fn value_json(value: &ApiValue) -> Value {
    match value {
        ApiValue::None => Value::Null,
        ApiValue::Bool(b) => json!(b),
        ApiValue::Names(names) => json!(names),
        ApiValue::Vec3(v) => json!(v),
        ApiValue::Bbox(b) => json!(b),
        ApiValue::Xy(v) => json!(v),
    }
}

/// Reads a call's JSON result in the shape that call returns, or says what was expected.
pub(crate) fn value_from_json(call: &ApiCall, result: &Value) -> Result<ApiValue, String> {
    let numbers = |v: &Value, n: usize| -> Option<Vec<f64>> {
        let items = v.as_array()?;
        let numbers: Vec<f64> = items.iter().filter_map(Value::as_f64).collect();
        (items.len() == n && numbers.len() == n && numbers.iter().all(|x| x.is_finite())).then_some(numbers)
    };
    let expected = |what: &str| format!("{} returns {what}, not {}", call.name(), short(result));
    match call {
        ApiCall::IsObjVisible { .. } | ApiCall::GripperIsOpen | ApiCall::ObjInGripper { .. } => result
            .as_bool()
            .map(ApiValue::Bool)
            .ok_or_else(|| expected("true or false")),
        ApiCall::GetObjNames => {
            let names = result.as_array().and_then(|items| {
                items
                    .iter()
                    .map(|v| v.as_str().map(str::to_owned))
                    .collect::<Option<Vec<_>>>()
            });
            names
                .map(ApiValue::Names)
                .ok_or_else(|| expected("a list of names"))
        }
        ApiCall::GetObjPos { .. } | ApiCall::GetObjSize { .. } => numbers(result, 3)
            .map(|v| ApiValue::Vec3([v[0], v[1], v[2]]))
            .ok_or_else(|| expected("[x, y, z]")),
        ApiCall::GetObjBbox { .. } => {
            let corners = result.as_array().filter(|a| a.len() == 2).and_then(|a| {
                let lo = numbers(&a[0], 3)?;
                let hi = numbers(&a[1], 3)?;
                Some([[lo[0], lo[1], lo[2]], [hi[0], hi[1], hi[2]]])
            });
            corners
                .map(ApiValue::Bbox)
                .ok_or_else(|| expected("[[x, y, z], [x, y, z]]"))
        }
        ApiCall::GetEmptyFloorXy { .. } => numbers(result, 2)
            .map(|v| ApiValue::Xy([v[0], v[1]]))
            .ok_or_else(|| expected("[x, y]")),
        _ if result.is_null() => Ok(ApiValue::None),
        _ => Err(expected("null")),
    }
}

/// A JSON-RPC error object; for [`codes::ROBOT_ERROR`] its `data` is the typed robot error.
pub(crate) fn error_json(code: i64, message: &str, data: Option<Value>) -> Value {
    let mut error = json!({"code": code, "message": message});
    if let Some(data) = data {
        error["data"] = data;
    }
    error
}

/// The error object a robot error travels as.
pub(crate) fn robot_error_json(error: &ApiError) -> Value {
    error_json(
        codes::ROBOT_ERROR,
        &error.to_string(),
        serde_json::to_value(error).ok(),
    )
}

/// A response line: `result` or `error`.
pub(crate) fn response(id: &Value, outcome: Result<Value, Value>) -> Value {
    match outcome {
        Ok(result) => json!({"jsonrpc": "2.0", "id": id, "result": result}),
        Err(error) => json!({"jsonrpc": "2.0", "id": id, "error": error}),
    }
}

/// At most 200 characters of a JSON value, for messages.
pub(crate) fn short(value: &Value) -> String {
    let text = value.to_string();
    match text.char_indices().nth(200) {
        Some((cut, _)) => format!("{}…", &text[..cut]),
        None => text,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nesy_sim::api::Direction;

    #[test]
    fn calls_travel_as_named_parameters() {
        let call = ApiCall::MoveToPosition {
            pos: [0.4, -0.1, 0.62],
            pointing_to: Direction::Down,
            lift_clearance: 0.12,
            angle: 0.0,
        };
        let (method, params) = call_request(&call);
        assert_eq!(method, "move_to_position");
        assert_eq!(
            params,
            json!({"pos": [0.4, -0.1, 0.62], "pointing_to": "down", "lift_clearance": 0.12, "angle": 0.0})
        );
        assert_eq!(call_from_request(method, &params).unwrap(), call);
        assert_eq!(
            call_from_request("close_gripper", &Value::Null).unwrap(),
            ApiCall::CloseGripper
        );
        let err = call_from_request("move_to_position", &json!({"pos": [1, 2, 3]})).unwrap_err();
        assert!(err.contains("pointing_to"), "{err}");
        assert!(call_from_request("fly", &json!({})).is_err());
    }

    #[test]
    fn results_are_read_in_the_shape_of_their_call() {
        let pos = ApiCall::GetObjPos {
            obj_name: "red_cube".into(),
        };
        assert_eq!(
            value_from_json(&pos, &json!([0.1, 0.2, 0.5])).unwrap(),
            ApiValue::Vec3([0.1, 0.2, 0.5])
        );
        let err = value_from_json(&pos, &json!([0.1, 0.2])).unwrap_err();
        assert_eq!(err, "get_obj_pos returns [x, y, z], not [0.1,0.2]");
        assert!(value_from_json(&ApiCall::OpenGripper, &json!(true)).is_err());
        assert_eq!(
            value_from_json(&ApiCall::OpenGripper, &Value::Null).unwrap(),
            ApiValue::None
        );
        let bbox = ApiCall::GetObjBbox {
            obj_name: "toy_box".into(),
        };
        let value = ApiValue::Bbox([[0.0, 0.1, 0.5], [0.2, 0.3, 0.6]]);
        assert_eq!(value_from_json(&bbox, &value_json(&value)).unwrap(), value);
    }
}

/// The committed JSON Schema of the messages (`assets/schema/robot-protocol.schema.json`)
/// checked against the code both ways: every robot API function is a method with exactly the
/// parameters nesy sends, and every robot error kind has exactly the fields it travels with.
#[cfg(test)]
mod schema_tests {
    use super::*;
    use nesy_core::Embodiment;
    use nesy_sim::api::Direction;
    use std::collections::BTreeSet;

    const SCHEMA: &str = include_str!("../../../assets/schema/robot-protocol.schema.json");
    const SESSION_METHODS: [&str; 5] = ["hello", "heartbeat", "get_tool_pos", "finish", "stop"];

    fn schema() -> Value {
        serde_json::from_str(SCHEMA).expect("the schema is JSON")
    }

    /// A value of the schema `property` describes.
    fn sample(property: &Value) -> Value {
        if let Some(reference) = property.get("$ref").and_then(Value::as_str) {
            return match reference {
                "#/$defs/direction" => json!("down"),
                "#/$defs/vec3" => json!([0.4, 0.0, 0.6]),
                other => panic!("unexpected reference {other}"),
            };
        }
        match property["type"].as_str() {
            Some("string") => json!("red_cube"),
            Some("number") => json!(0.05),
            other => panic!("unexpected property type {other:?}"),
        }
    }

    #[test]
    fn every_api_function_is_a_method_with_the_parameters_nesy_sends() {
        let schema = schema();
        let defs = schema["$defs"].as_object().unwrap();
        let methods: BTreeSet<&str> = defs
            .keys()
            .filter_map(|k| k.strip_prefix("params_"))
            .filter(|m| !SESSION_METHODS.contains(m))
            .collect();
        let api: BTreeSet<&str> = nesy_policy::api_function_names().into_iter().collect();
        assert_eq!(methods, api);
        for method in methods {
            let params = &defs[&format!("params_{method}")];
            let properties = params["properties"].as_object().unwrap();
            let sent: Map<String, Value> = properties.iter().map(|(k, v)| (k.clone(), sample(v))).collect();
            let call = call_from_request(method, &Value::Object(sent))
                .unwrap_or_else(|e| panic!("{method}: the schema's params do not make a call: {e}"));
            let (name, back) = call_request(&call);
            assert_eq!(name, method);
            let back: BTreeSet<&String> = back.as_object().unwrap().keys().collect();
            let required: BTreeSet<&String> = params["required"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| properties.get_key_value(v.as_str().unwrap()).unwrap().0)
                .collect();
            assert_eq!(back, properties.keys().collect(), "{method}");
            assert_eq!(required, back, "{method}: every parameter is sent");
            assert!(defs.contains_key(&format!("result_{method}")), "{method}");
        }
    }

    #[test]
    fn every_robot_error_kind_travels_with_the_fields_the_schema_names() {
        let errors = [
            ApiError::WrongEmbodiment {
                call: "close_gripper".into(),
                embodiment: Embodiment::Vacuum,
                use_instead: "activate_vacuum".into(),
            },
            ApiError::UnknownObject {
                name: "x".into(),
                known: "a, b".into(),
            },
            ApiError::Infeasible {
                call: "grasp_handle".into(),
                target: "h".into(),
                reason: "r".into(),
            },
            ApiError::OutOfWorkspace {
                target: [1.0, 0.0, 0.5],
            },
            ApiError::IkFailed {
                target: [1.0, 0.0, 0.5],
                pointing_to: Direction::Down,
            },
            ApiError::InvalidArgument {
                call: "move_parallel".into(),
                message: "m".into(),
            },
            ApiError::NoEmptySpace { obj_name: "o".into() },
            ApiError::Collision {
                call: "move_parallel".into(),
                moving: "a".into(),
                obstacle: "b".into(),
            },
            ApiError::BudgetExhausted { limit: 200 },
            ApiError::Stopped {
                call: "move_to_position".into(),
                reason: "emergency stop".into(),
            },
            ApiError::TimedOut {
                call: "move_to_position".into(),
                seconds: 30.0,
            },
        ];
        let schema = schema();
        let kinds: Vec<&Value> = schema["$defs"]["robot_error"]["oneOf"]
            .as_array()
            .unwrap()
            .iter()
            .collect();
        assert_eq!(kinds.len(), errors.len(), "one schema entry per error kind");
        for error in errors {
            let wire = serde_json::to_value(&error).unwrap();
            let kind = &wire["kind"];
            let entry = kinds
                .iter()
                .find(|k| &k["properties"]["kind"]["const"] == kind)
                .unwrap_or_else(|| panic!("no schema entry for {kind}"));
            let fields: BTreeSet<&String> = wire.as_object().unwrap().keys().collect();
            let described: BTreeSet<&String> = entry["properties"].as_object().unwrap().keys().collect();
            assert_eq!(fields, described, "{kind}");
            assert_eq!(serde_json::from_value::<ApiError>(wire).unwrap(), error);
        }
    }
}
