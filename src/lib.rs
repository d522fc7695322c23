//! The `gyrodrift` command line as a library, so integration tests drive the same code.

pub mod cli;
