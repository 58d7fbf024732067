//! The embedded JSON schemas: Foxglove's field layout for its well-known schemas (the
//! fields written), plain objects of numbers for the rest.

use serde_json::{json, Map, Value};

fn object(title: &str, props: Value) -> Value {
    json!({"title": title, "type": "object", "properties": props})
}

fn time() -> Value {
    object(
        "time",
        json!({"sec": {"type": "integer"}, "nsec": {"type": "integer"}}),
    )
}

fn xyz(title: &str) -> Value {
    object(
        title,
        json!({"x": {"type": "number"}, "y": {"type": "number"}, "z": {"type": "number"}}),
    )
}

fn pose() -> Value {
    let q = json!({"x": {"type": "number"}, "y": {"type": "number"},
                   "z": {"type": "number"}, "w": {"type": "number"}});
    object(
        "foxglove.Pose",
        json!({"position": xyz("foxglove.Vector3"),
               "orientation": object("foxglove.Quaternion", q)}),
    )
}

fn color() -> Value {
    object(
        "foxglove.Color",
        json!({"r": {"type": "number"}, "g": {"type": "number"},
               "b": {"type": "number"}, "a": {"type": "number"}}),
    )
}

fn array(items: Value) -> Value {
    json!({"type": "array", "items": items})
}

pub fn poses_in_frame() -> Value {
    object(
        "foxglove.PosesInFrame",
        json!({"timestamp": time(), "frame_id": {"type": "string"},
               "poses": array(pose())}),
    )
}

pub fn scene_update() -> Value {
    let sphere = object(
        "foxglove.SpherePrimitive",
        json!({"pose": pose(), "size": xyz("foxglove.Vector3"), "color": color()}),
    );
    let line = object(
        "foxglove.LinePrimitive",
        json!({"type": {"type": "integer"}, "pose": pose(), "thickness": {"type": "number"},
               "scale_invariant": {"type": "boolean"}, "points": array(xyz("foxglove.Point3")),
               "color": color(), "colors": array(color()),
               "indices": array(json!({"type": "integer"}))}),
    );
    let text = object(
        "foxglove.TextPrimitive",
        json!({"pose": pose(), "billboard": {"type": "boolean"},
               "font_size": {"type": "number"}, "scale_invariant": {"type": "boolean"},
               "color": color(), "text": {"type": "string"}}),
    );
    let any = array(json!({"type": "object"}));
    let entity = object(
        "foxglove.SceneEntity",
        json!({"timestamp": time(), "frame_id": {"type": "string"}, "id": {"type": "string"},
               "lifetime": object("duration", json!({"sec": {"type": "integer"},
                                                    "nsec": {"type": "integer"}})),
               "frame_locked": {"type": "boolean"}, "metadata": any,
               "arrows": any, "cubes": any, "spheres": array(sphere),
               "cylinders": any, "lines": array(line), "triangles": any,
               "texts": array(text), "models": any}),
    );
    object(
        "foxglove.SceneUpdate",
        json!({"deletions": any, "entities": array(entity)}),
    )
}

pub fn log() -> Value {
    object(
        "foxglove.Log",
        json!({"timestamp": time(), "level": {"type": "integer"},
               "message": {"type": "string"}, "name": {"type": "string"},
               "file": {"type": "string"}, "line": {"type": "integer"}}),
    )
}

/// An object of numbers with these keys (non-finite values are written as `null`).
pub fn numbers(keys: &[String]) -> Value {
    let props: Map<String, Value> = keys
        .iter()
        .map(|k| (k.clone(), json!({"type": ["number", "null"]})))
        .collect();
    json!({"type": "object", "properties": props})
}
