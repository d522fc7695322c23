//! Extra CSV columns recorded as named auxiliary channels (`/aux/<channel>` in the MCAP), and the
//! `name=column[:unit]` text the command line gives them in.

/// A CSV column recorded as the named auxiliary channel `channel` (100 Hz, like the format's own
/// auxiliary channels). The name must pass [`crate::check_named_aux_channel`]; the reader checks it
/// before reading any row.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CsvAuxColumn {
    /// Channel name in the recording.
    pub channel: String,
    /// Header name of the CSV column.
    pub column: String,
    /// Physical unit written into the channel metadata; empty if not given.
    pub unit: String,
}

impl CsvAuxColumn {
    /// Parses `name=column` or `name=column:unit`. The unit follows the *last* `:`, so a column
    /// whose header has a `:` is given with its unit, or with an empty one (`name=a:b:`).
    pub fn parse(text: &str) -> Result<Self, String> {
        let expected = "expected name=column or name=column:unit";
        let (channel, rest) = text
            .split_once('=')
            .ok_or_else(|| format!("{expected}, got `{text}` (no `=`)"))?;
        let (column, unit) = rest.rsplit_once(':').unwrap_or((rest, ""));
        if channel.is_empty() || column.is_empty() {
            let missing = if channel.is_empty() { "name" } else { "column" };
            return Err(format!("{expected}, got `{text}` (no {missing})"));
        }
        Ok(Self {
            channel: channel.to_owned(),
            column: column.to_owned(),
            unit: unit.to_owned(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn aux(channel: &str, column: &str, unit: &str) -> CsvAuxColumn {
        CsvAuxColumn {
            channel: channel.into(),
            column: column.into(),
            unit: unit.into(),
        }
    }

    #[test]
    fn name_column_and_an_optional_unit() {
        let cases = [
            ("humidity=rh", aux("humidity", "rh", "")),
            ("humidity=rh:%RH", aux("humidity", "rh", "%RH")),
            ("a=m/s^2 col:m/s^2", aux("a", "m/s^2 col", "m/s^2")),
            ("t=time:s:", aux("t", "time:s", "")),
            ("x=col=2:V", aux("x", "col=2", "V")),
        ];
        for (text, expected) in cases {
            assert_eq!(CsvAuxColumn::parse(text), Ok(expected), "{text}");
        }
    }

    #[test]
    fn a_missing_part_is_named() {
        let cases = [
            ("humidity", "got `humidity` (no `=`)"),
            ("=rh:%RH", "got `=rh:%RH` (no name)"),
            ("humidity=", "got `humidity=` (no column)"),
            ("humidity=:%RH", "got `humidity=:%RH` (no column)"),
        ];
        for (text, expected) in cases {
            let error = CsvAuxColumn::parse(text).unwrap_err();
            assert!(
                error.starts_with("expected name=column or name=column:unit")
                    && error.ends_with(expected),
                "{text}: {error}"
            );
        }
    }
}
