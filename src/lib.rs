//! The `gyrodrift` command line as a library, so integration tests drive the same code.

pub mod cli;
pub mod output;
pub mod report;
