//! Errors of a log (a PX4 ULog, a ROS 2 bag) in the log's own terms. A log's messages are read
//! through the CSV reader, one row per message; its errors would otherwise speak of a CSV text the
//! user never saw ("row 2 (line 3), column `t_s`"). Here they name the topic, the message and its
//! field, and the option that sets the limit a message broke.

use drift_recording::CsvError;

/// Where a log's rows come from: `describe` names the file and topic, the first row is message
/// number `first_message`, and `field` names the log field of a CSV column.
pub(super) struct LogRows<'a> {
    pub describe: String,
    pub first_message: u64,
    pub field: &'a dyn Fn(&str) -> String,
}

/// `error`, from reading the rows of `rows`, told in messages and fields.
pub(super) fn in_log_terms(error: CsvError, rows: &LogRows<'_>) -> anyhow::Error {
    match error {
        CsvError::Row {
            row,
            column,
            reason,
            ..
        } => {
            let message = rows.first_message + row.saturating_sub(1);
            let field = column.map_or(String::new(), |c| format!(", field `{}`", (rows.field)(&c)));
            let mut reason = reason
                .replace("previous row", "previous message")
                .replace("rows", "messages");
            if reason.starts_with("gap:") {
                reason.push_str(
                    "; `--max-gap <s>` sets the longest step between messages interpolated across",
                );
            }
            anyhow::anyhow!("{}, message {message}{field}: {reason}", rows.describe)
        }
        CsvError::Empty { .. } => anyhow::anyhow!("{}: no messages", rows.describe),
        other => anyhow::anyhow!("{}: {other}", rows.describe),
    }
}
