//! The MCAP message stream of a recording, with a bound on record sizes.
//!
//! `mcap::MessageStream` (0.26) reserves whatever length a record or a chunk's inner record
//! declares before reading it, so a few corrupt bytes ask for exabytes and abort the process (found
//! by fuzzing, `docs/reliability.md`). This drives mcap's sans-io reader with a record length
//! limit instead: an oversized declared length becomes an error naming the file. It also checks
//! the chunk and data-section CRCs, which `MessageStream` does not by default.

use std::collections::HashMap;

use mcap::records::Record;
use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};
use mcap::McapError;

/// Largest record accepted, bytes: a message, or a whole uncompressed chunk. A gyrodrift message
/// (100 ms at 1 kHz) is 1.2 KB and a chunk 512 KiB; benches writing bigger batches have room.
pub const RECORD_LENGTH_LIMIT: usize = 64 << 20;

/// Calls `each(topic, log_time_ns, data)` for every message of the data section, in file order.
/// Errors of `each` are passed through; container errors come back as `Err(Ok(mcap error))`.
pub(crate) fn for_each_message<E>(
    buf: &[u8],
    mut each: impl FnMut(&str, u64, &[u8]) -> Result<(), E>,
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
    let mut topics: HashMap<u16, String> = HashMap::new();
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
            Record::Channel(channel) => {
                if let Some(known) = topics.get(&channel.id) {
                    if *known != channel.topic {
                        return Err(Ok(McapError::ConflictingChannels(channel.topic)));
                    }
                }
                topics.insert(channel.id, channel.topic);
            }
            Record::Message { header, data } => {
                let topic = topics
                    .get(&header.channel_id)
                    .ok_or(Ok(McapError::UnknownChannel(
                        header.sequence,
                        header.channel_id,
                    )))?;
                each(topic, header.log_time, &data).map_err(Err)?;
            }
            // The summary repeats channels; messages are all in the data section.
            Record::DataEnd(_) => break,
            _ => {}
        }
    }
    Ok(())
}
