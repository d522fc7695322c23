//! The MCAP recording format: CDR encoding, schemas and topics, and the file writer.

pub mod bench;
pub mod cdr;
pub mod schema;
pub mod writer;
