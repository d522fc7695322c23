//! The MCAP message stream of a recording, with a bound on record sizes.
//!
//! `mcap::MessageStream` (0.26) reserves whatever length a record or a chunk's inner record
//! declares before reading it, so a few corrupt bytes ask for exabytes and abort the process (found
//! by fuzzing, `docs/reliability.md`). This drives mcap's sans-io reader with a record length
//! limit instead: an oversized declared length becomes an error naming the file. It also checks
//! the chunk and data-section CRCs, which `MessageStream` does not by default.

use std::collections::{BTreeMap, HashMap};

use mcap::records::Record;
use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};
use mcap::McapError;

/// Largest record accepted, bytes: a message, or a whole uncompressed chunk. A gyrodrift message
/// (100 ms at 1 kHz) is 1.2 KB and a chunk 512 KiB; benches writing bigger batches have room.
pub const RECORD_LENGTH_LIMIT: usize = 64 << 20;

/// A channel as the data section declares it.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ChannelInfo {
    pub topic: String,
    /// Name of its schema; `None` for a channel without one (schema id 0) or whose schema record
    /// did not come before it.
    pub schema: Option<String>,
    /// Encoding of its schema (`ros2msg` for the format's own); `None` with no schema.
    pub schema_encoding: Option<String>,
    /// Its schema's text (a `.msg` definition for `ros2msg`); empty with no schema.
    pub schema_data: Vec<u8>,
    /// Encoding of its messages (`cdr` for the format's own).
    pub message_encoding: String,
    /// Channel metadata (e.g. `unit`).
    pub metadata: BTreeMap<String, String>,
}

/// Calls `each(channel, log_time_ns, data, bytes_in)` for every message of the data section, in
/// file order; `bytes_in` is how much of `buf` the reader has taken so far (for progress).
/// Errors of `each` are passed through; container errors come back as `Err(Ok(mcap error))`.
///
/// Channels and schemas are taken from the data section, not the summary: they are then covered
/// by the same chunk CRCs as the messages.
pub(crate) fn for_each_message<E>(
    buf: &[u8],
    mut each: impl FnMut(&ChannelInfo, u64, &[u8], usize) -> Result<(), E>,
) -> Result<(), Result<McapError, E>> {
    // CRCs too: a flipped bit in a chunk or in the data section is then a CRC error naming the
    // file, not a plausible wrong sample (chunks are checked before any of their messages is used).
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_record_length_limit(RECORD_LENGTH_LIMIT)
            .with_prevalidate_chunk_crcs(true)
            .with_validate_data_section_crc(true),
    );
    let mut rest = buf;
    let mut schemas: HashMap<u16, (String, String, Vec<u8>)> = HashMap::new();
    let mut channels: HashMap<u16, ChannelInfo> = HashMap::new();
    while let Some(event) = reader.next_event() {
        let (opcode, data) = match event.map_err(Ok)? {
            LinearReadEvent::ReadRequest(need) => {
                let n = need.min(rest.len());
                reader.insert(n).copy_from_slice(&rest[..n]);
                reader.notify_read(n);
                rest = &rest[n..];
                continue;
            }
            LinearReadEvent::Record { data, opcode } => (opcode, data),
        };
        match mcap::parse_record(opcode, data).map_err(Ok)? {
            Record::Schema { header, data } => {
                schemas.insert(header.id, (header.name, header.encoding, data.into_owned()));
            }
            Record::Channel(channel) => {
                if let Some(known) = channels.get(&channel.id) {
                    if known.topic != channel.topic {
                        return Err(Ok(McapError::ConflictingChannels(channel.topic)));
                    }
                }
                let schema = schemas.get(&channel.schema_id).cloned();
                let info = ChannelInfo {
                    schema_encoding: schema.as_ref().map(|(_, encoding, _)| encoding.clone()),
                    schema_data: schema
                        .as_ref()
                        .map(|(_, _, data)| data.clone())
                        .unwrap_or_default(),
                    schema: schema.map(|(name, _, _)| name),
                    message_encoding: channel.message_encoding,
                    topic: channel.topic,
                    metadata: channel.metadata,
                };
                channels.insert(channel.id, info);
            }
            Record::Message { header, data } => {
                let channel =
                    channels
                        .get(&header.channel_id)
                        .ok_or(Ok(McapError::UnknownChannel(
                            header.sequence,
                            header.channel_id,
                        )))?;
                each(channel, header.log_time, &data, buf.len() - rest.len()).map_err(Err)?;
            }
            // The summary repeats channels; messages are all in the data section.
            Record::DataEnd(_) => break,
            _ => {}
        }
    }
    Ok(())
}

fn le_u64(bytes: &[u8], at: usize) -> Option<u64> {
    let b = bytes.get(at..at.checked_add(8)?)?;
    Some(u64::from_le_bytes(b.try_into().ok()?))
}

fn le_u32(bytes: &[u8], at: usize) -> Option<u32> {
    let b = bytes.get(at..at.checked_add(4)?)?;
    Some(u32::from_le_bytes(b.try_into().ok()?))
}

/// mcap 0.26's sans-io reader subtracts an inner record's length from an uncompressed chunk's
/// remaining bytes without checking that it fits (found by fuzzing, F11: an overflow panic in
/// debug builds, a misread past the chunk in release). Walks the top-level records and refuses an
/// uncompressed chunk whose inner records do not tile it exactly. Stops quietly where the
/// top-level structure itself is broken: mcap reports that with its own error. Also refuses an
/// attachment record too short for its own header (F12: mcap slices it unchecked). Runs before any
/// mcap reader sees the bytes (its summary reader can scan the file too).
pub(crate) fn check_uncompressed_chunks(buf: &[u8]) -> Result<(), McapError> {
    // mcap reads records linearly from the start (messages) and from the footer's summary start
    // (summary): walk both ways in. The footer is the last record before the closing magic:
    // opcode, length 20, summary start, summary offset start, CRC.
    let footer = buf.len().checked_sub(mcap::MAGIC.len() + 9 + 20);
    let summary_start = footer
        .and_then(|at| le_u64(buf, at + 9))
        .and_then(|s| usize::try_from(s).ok())
        .filter(|&s| s > 0 && s < buf.len());
    check_from(buf, mcap::MAGIC.len())?;
    match summary_start {
        Some(at) => check_from(buf, at),
        None => Ok(()),
    }
}

fn check_from(buf: &[u8], mut at: usize) -> Result<(), McapError> {
    const CHUNK: u8 = 0x06;
    const ATTACHMENT: u8 = 0x09;
    while let (Some(&opcode), Some(len)) = (buf.get(at), le_u64(buf, at + 1)) {
        let body_at = at + 9;
        let Some(body) = usize::try_from(len)
            .ok()
            .and_then(|len| buf.get(body_at..body_at.checked_add(len)?))
        else {
            return Ok(());
        };
        if opcode == ATTACHMENT {
            // log time u64, create time u64, name, media type, data length u64, data, CRC u32:
            // mcap slices `body[header ..len − 4]` without checking (F12).
            let name = le_u32(body, 16).and_then(|n| usize::try_from(n).ok());
            let media_at = name.and_then(|n| 20usize.checked_add(n));
            let media = media_at
                .and_then(|at| le_u32(body, at))
                .and_then(|n| usize::try_from(n).ok());
            let header = media_at
                .zip(media)
                .and_then(|(at, m)| at.checked_add(4)?.checked_add(m)?.checked_add(8));
            if header.is_some_and(|h| h.saturating_add(4) > body.len()) {
                return Err(McapError::UnexpectedEof);
            }
        }
        if opcode == CHUNK {
            // start u64, end u64, uncompressed size u64, crc u32, compression string, size u64.
            let Some(name_len) = le_u32(body, 28).and_then(|n| usize::try_from(n).ok()) else {
                return Ok(());
            };
            let records_at = 32usize.saturating_add(name_len).saturating_add(8);
            let size = le_u64(body, 32usize.saturating_add(name_len));
            let records = size
                .and_then(|n| usize::try_from(n).ok())
                .and_then(|n| body.get(records_at..records_at.checked_add(n)?));
            if let (Some(0), Some(records)) = (le_u32(body, 28), records) {
                let mut inner = 0usize;
                while inner < records.len() {
                    let end = le_u64(records, inner + 1)
                        .and_then(|n| usize::try_from(n).ok())
                        .and_then(|n| (inner + 9).checked_add(n))
                        .filter(|&end| end <= records.len());
                    inner = end.ok_or(McapError::UnexpectedEoc)?;
                }
            }
        }
        at = body_at + body.len();
    }
    Ok(())
}
