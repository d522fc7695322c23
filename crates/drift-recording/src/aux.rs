//! Auxiliary channel names and their topics.
//!
//! The format's own channels keep their fixed topics and units: `/aux/accel` (a `Vector3Batch`)
//! holds `accel_x`, `accel_y`, `accel_z` in g; `/aux/supply_voltage` (V) and
//! `/aux/chamber_set_point` (degC) are `ScalarBatch`es. Any other channel is a *named* channel: a
//! `ScalarBatch` on its own topic `/aux/<name>`, its unit in the channel metadata `unit`. The
//! writer, the reader and the CSV importer share the naming rule below, so a name one accepts the
//! others accept too.

use crate::schema;

/// The format's own auxiliary channels and their units (the topic they are on fixes the unit).
pub const FIXED_AUX_CHANNELS: [(&str, &str); 5] = [
    ("accel_x", "g"),
    ("accel_y", "g"),
    ("accel_z", "g"),
    ("supply_voltage", "V"),
    ("chamber_set_point", "degC"),
];

/// The unit of one of the format's own channels; `None` for any other name.
pub fn fixed_aux_unit(name: &str) -> Option<&'static str> {
    FIXED_AUX_CHANNELS
        .iter()
        .find(|(fixed, _)| *fixed == name)
        .map(|(_, unit)| *unit)
}

/// The topic of a named auxiliary channel: `/aux/<name>`.
pub fn named_aux_topic(name: &str) -> String {
    format!("{}{name}", schema::AUX_PREFIX)
}

/// Checks that `name` can be a named auxiliary channel: ASCII letters, digits, `_`, `.` and `-`,
/// starting with a letter or a digit, and neither one of the format's own channels nor the
/// accelerometer's topic name. The error says what is wrong and names the channel.
///
/// The character set keeps `/aux/<name>` a single topic level that every MCAP tool, shell and file
/// system takes as it is; the leading letter or digit keeps `.`, `..` and option-like `-x` out.
pub fn check_named_aux_channel(name: &str) -> Result<(), String> {
    let rule = "a named auxiliary channel is ASCII letters, digits, `_`, `.` and `-`, \
                starting with a letter or a digit";
    // Escaped, so a control character in a bench's topic cannot garble the message.
    let shown = name.escape_debug();
    let Some(first) = name.chars().next() else {
        return Err(format!("an empty auxiliary channel name: {rule}"));
    };
    if !first.is_ascii_alphanumeric() {
        return Err(format!(
            "auxiliary channel `{shown}` starts with `{}`: {rule}",
            first.escape_debug()
        ));
    }
    if let Some((at, c)) = name
        .char_indices()
        .find(|(_, c)| !(c.is_ascii_alphanumeric() || "_.-".contains(*c)))
    {
        return Err(format!(
            "auxiliary channel `{shown}` has `{}` at byte {at}: {rule}",
            c.escape_debug()
        ));
    }
    if let Some(unit) = fixed_aux_unit(name) {
        return Err(format!(
            "auxiliary channel `{name}` is one of the format's own channels: it is recorded on its \
             fixed topic in {unit}, not as a named channel"
        ));
    }
    if named_aux_topic(name) == schema::TOPIC_ACCEL {
        return Err(format!(
            "auxiliary channel `{name}` would be recorded on {}, the accelerometer's topic \
             (accel_x, accel_y, accel_z)",
            schema::TOPIC_ACCEL
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_that_are_one_topic_level_are_accepted() {
        for name in ["humidity", "accel2_x", "v3.3", "board-temp", "0", "A_b.c-d"] {
            assert_eq!(check_named_aux_channel(name), Ok(()), "{name}");
        }
    }

    #[test]
    fn bad_and_reserved_names_are_refused_naming_the_channel() {
        let cases = [
            ("", "an empty auxiliary channel name"),
            ("a/b", "`a/b` has `/` at byte 1"),
            ("two words", "`two words` has ` ` at byte 3"),
            ("temp°", "`temp°` has `°` at byte 4"),
            ("tab\there", "`tab\\there` has `\\t` at byte 3"),
            (".hidden", "`.hidden` starts with `.`"),
            ("..", "`..` starts with `.`"),
            ("-x", "`-x` starts with `-`"),
            ("_x", "`_x` starts with `_`"),
            ("accel", "would be recorded on /aux/accel"),
            ("accel_y", "`accel_y` is one of the format's own channels"),
            ("supply_voltage", "on its fixed topic in V"),
            ("chamber_set_point", "on its fixed topic in degC"),
        ];
        for (name, expected) in cases {
            let error = check_named_aux_channel(name).unwrap_err();
            assert!(error.contains(expected), "{name:?}: {error}");
        }
    }
}
