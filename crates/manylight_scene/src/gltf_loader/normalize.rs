//! Parsing the glTF JSON, with a second chance for valid files that the `gltf` crate's strict
//! serde types refuse.
//!
//! 1. The JSON is parsed straight into `gltf::json::Root`; almost every file succeeds here.
//! 2. If that fails, it is parsed into a `serde_json::Value` and normalised where the glTF 2.0
//!    specification (and the Khronos validator) allow what the crate's types do not:
//!    - a number with a zero fraction (`3.0`, `5126.0`) is an integer: it becomes one, outside
//!      `extras` (kept as written);
//!    - a scene without `nodes` gets an empty list;
//!    - an animation channel whose `target` has no `node` is dropped (the specification says
//!      such channels are ignored; the loader reads no animations anyway).
//! 3. If normalising changed nothing, the first error is reported (it has a line and column);
//!    otherwise the normalised value is deserialized, and its error, if any, is reported.

use crate::SceneError;
use serde_json::{Map, Number, Value};
use std::path::Path;

/// Parses glTF JSON `json` of file `path` (see the module documentation).
pub(super) fn parse_root(path: &Path, json: &[u8]) -> Result<gltf::json::Root, SceneError> {
    let json_err = |message: String| SceneError::Json { path: path.to_owned(), message };
    let first = match gltf::json::deserialize::from_slice::<gltf::json::Root>(json) {
        Ok(root) => return Ok(root),
        Err(e) => e,
    };
    // Not JSON at all (or too deep): the first error says where.
    let Ok(mut value) = serde_json::from_slice::<Value>(json) else {
        return Err(json_err(first.to_string()));
    };
    let changes = normalize(&mut value);
    if changes == 0 {
        return Err(json_err(first.to_string()));
    }
    tracing::debug!(file = %path.display(), changes, "glTF JSON normalised before parsing");
    serde_json::from_value(value).map_err(|e| json_err(e.to_string()))
}

/// Normalises a parsed glTF document in place; returns how many values it changed.
fn normalize(doc: &mut Value) -> usize {
    let mut changes = integral_floats_to_integers(doc);
    let Value::Object(root) = doc else { return changes };
    if let Some(Value::Array(scenes)) = root.get_mut("scenes") {
        for scene in scenes.iter_mut().filter_map(Value::as_object_mut) {
            if !scene.contains_key("nodes") {
                scene.insert("nodes".into(), Value::Array(Vec::new()));
                changes += 1;
            }
        }
    }
    if let Some(Value::Array(animations)) = root.get_mut("animations") {
        for animation in animations.iter_mut().filter_map(Value::as_object_mut) {
            if let Some(Value::Array(channels)) = animation.get_mut("channels") {
                let before = channels.len();
                channels.retain(|c| !target_without_node(c));
                changes += before - channels.len();
            }
        }
    }
    changes
}

/// Whether animation channel `channel` has a `target` object without a `node`.
fn target_without_node(channel: &Value) -> bool {
    let target = channel.get("target").and_then(Value::as_object);
    target.is_some_and(|t: &Map<String, Value>| !t.contains_key("node"))
}

/// Turns every number with a zero fraction that fits in `i64` or `u64` into an integer
/// (except `-0.0`, and except inside `extras`); returns how many it changed. Iterative, so
/// nesting costs no stack.
fn integral_floats_to_integers(doc: &mut Value) -> usize {
    let mut changes = 0;
    let mut stack = vec![doc];
    while let Some(value) = stack.pop() {
        match value {
            Value::Number(n) => {
                if let Some(i) = integral(n) {
                    *n = i;
                    changes += 1;
                }
            }
            Value::Array(items) => stack.extend(items.iter_mut()),
            Value::Object(map) => {
                stack.extend(map.iter_mut().filter(|(k, _)| *k != "extras").map(|(_, v)| v));
            }
            _ => {}
        }
    }
    changes
}

/// The integer equal to floating-point number `n`, if it has one (and is not `-0.0`).
fn integral(n: &Number) -> Option<Number> {
    if !n.is_f64() {
        return None;
    }
    let f = n.as_f64()?;
    if !f.is_finite() || f.fract() != 0.0 || (f == 0.0 && f.is_sign_negative()) {
        return None;
    }
    // 2^64 and -2^63 are exact in f64; the casts below are exact inside these bounds.
    if (0.0..18_446_744_073_709_551_616.0).contains(&f) {
        Some(Number::from(f as u64))
    } else if (-9_223_372_036_854_775_808.0..0.0).contains(&f) {
        Some(Number::from(f as i64))
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_integral_floats_outside_extras_become_integers() {
        let mut v: Value = serde_json::from_str(
            r#"{"a": 3.0, "b": [1.5, -2.0, -0.0, 1e300], "extras": {"c": 4.0}, "d": 7}"#,
        )
        .expect("json");
        assert_eq!(integral_floats_to_integers(&mut v), 2);
        assert_eq!(v["a"], Value::from(3u64));
        assert_eq!(v["b"][0], Value::from(1.5));
        assert_eq!(v["b"][1], Value::from(-2i64));
        assert!(v["b"][2].as_f64().is_some_and(|z| z == 0.0 && z.is_sign_negative()));
        assert!(v["b"][3].is_f64());
        assert!(v["extras"]["c"].is_f64());
    }

    #[test]
    fn scenes_get_nodes_and_node_less_channels_are_dropped() {
        let mut v: Value = serde_json::from_str(
            r#"{"scenes": [{}, {"nodes": [0]}], "animations": [{"channels": [
                {"sampler": 0, "target": {"path": "rotation"}},
                {"sampler": 0, "target": {"node": 0, "path": "rotation"}}]}]}"#,
        )
        .expect("json");
        assert_eq!(normalize(&mut v), 2);
        assert_eq!(v["scenes"][0]["nodes"], Value::Array(Vec::new()));
        assert_eq!(v["animations"][0]["channels"].as_array().map(Vec::len), Some(1));
    }
}
