//! `ros2msg` definitions: parsed to the primitive fields they put on the wire, and a channel's
//! schema checked against a standard one.

use std::collections::HashMap;

use crate::messages::ChannelInfo;

/// A field of a `.msg` definition: type (normalised) and name.
type Field = (String, String);

/// A parsed definition: the message's own fields, and the fields of each type it defines.
type Definition = (Vec<Field>, HashMap<String, Vec<Field>>);

const PRIMITIVES: [&str; 17] = [
    "bool", "byte", "char", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64",
    "uint64", "float32", "float64", "string", "wstring", "float", "double",
];

/// `pkg/msg/Name` → `pkg/Name`; `Header` → `std_msgs/Header` (the one type ROS names without its
/// package); anything else as written.
fn normalise_type(ty: &str) -> String {
    let (base, array) = match ty.find('[') {
        Some(i) => ty.split_at(i),
        None => (ty, ""),
    };
    let base = match base.split('/').collect::<Vec<_>>().as_slice() {
        [pkg, "msg", name] => format!("{pkg}/{name}"),
        ["Header"] => "std_msgs/Header".to_owned(),
        _ => base.to_owned(),
    };
    format!("{base}{array}")
}

/// Parses a `ros2msg` definition as rosbag2 stores it: the message's fields, then, after each
/// separator line of `=`, `MSG: <type>` and that type's fields. Comments, blank lines and
/// constants (`TYPE NAME=value`) are skipped; default values after a field's name are ignored.
fn parse_definition(text: &str) -> Result<Definition, String> {
    let mut main = Vec::new();
    let mut types: HashMap<String, Vec<Field>> = HashMap::new();
    let mut current: Option<String> = None;
    for (n, line) in text.lines().enumerate() {
        let code = line.split('#').next().unwrap_or("").trim();
        if code.len() >= 3 && code.chars().all(|c| c == '=') {
            current = None;
            continue;
        }
        if code.is_empty() {
            continue;
        }
        if let Some(name) = code.strip_prefix("MSG:") {
            let name = normalise_type(name.trim());
            types.entry(name.clone()).or_default();
            current = Some(name);
            continue;
        }
        let mut tokens = code.split_whitespace();
        let (Some(ty), Some(name)) = (tokens.next(), tokens.next()) else {
            return Err(format!("line {}: `{code}` is not `TYPE NAME`", n + 1));
        };
        if name.contains('=') || tokens.next().is_some_and(|t| t.starts_with('=')) {
            continue; // a constant: not on the wire
        }
        let field = (normalise_type(ty), name.to_owned());
        match &current {
            Some(t) => types.entry(t.clone()).or_default().push(field),
            None => main.push(field),
        }
    }
    Ok((main, types))
}

/// The primitive fields a definition puts on the wire, in order, as `type path`.
fn flatten(
    fields: &[Field],
    types: &HashMap<String, Vec<Field>>,
    prefix: &str,
    out: &mut Vec<String>,
    depth: usize,
) -> Result<(), String> {
    if depth > 8 {
        return Err("types nest deeper than 8 levels".into());
    }
    for (ty, name) in fields {
        let base = ty.split('[').next().unwrap_or(ty);
        let is_primitive = PRIMITIVES.contains(&base)
            || base.starts_with("string<=")
            || base.starts_with("wstring<=");
        if is_primitive || ty.contains('[') {
            out.push(format!("{ty} {prefix}{name}"));
            continue;
        }
        let inner = types.get(base).ok_or_else(|| {
            format!("field `{prefix}{name}` has type {base}, which the schema text does not define")
        })?;
        flatten(inner, types, &format!("{prefix}{name}."), out, depth + 1)?;
    }
    Ok(())
}

pub(super) fn wire_fields(text: &str) -> Result<Vec<String>, String> {
    let (main, types) = parse_definition(text)?;
    let mut out = Vec::new();
    flatten(&main, &types, "", &mut out, 0)?;
    Ok(out)
}

/// Why a topic's channel is not `expected` (schema name and standard definition), or `None`.
pub(super) fn check_channel(channel: &ChannelInfo, expected: (&str, &str)) -> Option<String> {
    let (name, definition) = expected;
    let found = channel.schema.as_deref().unwrap_or("no schema");
    let encoding = channel.schema_encoding.as_deref().unwrap_or("none");
    let standard = name.replace("/msg/", "/");
    if channel.schema.as_deref() != Some(name) && channel.schema.as_deref() != Some(&standard) {
        return Some(format!(
            "schema `{found}` ({encoding}, {} messages), expected {name}; name the right topic with the option",
            channel.message_encoding
        ));
    }
    if encoding != "ros2msg" || channel.message_encoding != "cdr" {
        let hint = if encoding.starts_with("ros1") || channel.message_encoding == "ros1" {
            " (a ROS 1 bag: convert it to ROS 2 first, e.g. with `rosbags-convert`)"
        } else {
            ""
        };
        return Some(format!(
            "schema encoding `{encoding}` with `{}` messages, but only ROS 2's `ros2msg` with `cdr` is read{hint}",
            channel.message_encoding
        ));
    }
    let text = String::from_utf8_lossy(&channel.schema_data);
    let standard_fields = wire_fields(definition).unwrap_or_default();
    let found_fields = match wire_fields(&text) {
        Ok(f) => f,
        Err(e) => {
            return Some(format!(
                "schema `{found}`: its definition cannot be read: {e}"
            ))
        }
    };
    if found_fields == standard_fields {
        return None;
    }
    let k = found_fields
        .iter()
        .zip(&standard_fields)
        .position(|(a, b)| a != b)
        .unwrap_or(found_fields.len().min(standard_fields.len()));
    Some(format!(
        "schema `{found}`: its definition is not the standard one: wire field #{k} is {}, the standard {name} has {} (a custom message under a standard name is not read)",
        found_fields
            .get(k)
            .map_or("missing".to_owned(), |f| format!("`{f}`")),
        standard_fields
            .get(k)
            .map_or("no more fields".to_owned(), |f| format!("`{f}`"))
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ros2::{IMU_DEFINITION, TEMPERATURE_DEFINITION};

    #[test]
    fn the_standard_definitions_flatten_to_their_wire_fields() {
        let imu = wire_fields(IMU_DEFINITION).unwrap();
        assert_eq!(
            imu.len(),
            3 + 4 + 1 + 3 + 1 + 3 + 1,
            "arrays are one wire field each"
        );
        assert_eq!(imu[0], "int32 header.stamp.sec");
        assert_eq!(imu[2], "string header.frame_id");
        assert_eq!(imu[7], "float64[9] orientation_covariance");
        assert_eq!(imu[8], "float64 angular_velocity.x");
        let t = wire_fields(TEMPERATURE_DEFINITION).unwrap();
        assert_eq!(t[3..], ["float64 temperature", "float64 variance"]);
        // The long type names, `Header` without its package, constants and comments change nothing.
        let other = "Header header # c\nint8 KIND=3\nfloat64 temperature 0.0\nfloat64 variance\n\
=====\nMSG: std_msgs/msg/Header\nbuiltin_interfaces/msg/Time stamp\nstring frame_id\n\
=====\nMSG: builtin_interfaces/msg/Time\nint32 sec\nuint32 nanosec\n";
        assert_eq!(wire_fields(other).unwrap(), t);
        let missing = "std_msgs/Header header\nfloat64 temperature\nfloat64 variance\n";
        assert!(wire_fields(missing)
            .unwrap_err()
            .contains("std_msgs/Header"));
    }
}
