//! Errors shown to users: each names the file and, where known, the line or element.

use std::path::PathBuf;

/// A user-facing error. The CLI prints it on one line and exits with code 2.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The input could not be read or parsed.
    #[error("{path}: {message}")]
    Input {
        /// The file.
        path: PathBuf,
        /// What is wrong, with line or element when known.
        message: String,
    },
    /// The input was read but the data is not usable.
    #[error("{0}")]
    Invalid(String),
    /// An I/O failure.
    // The cause is part of the message and deliberately not a `source`, so that
    // `anyhow`'s `{:#}` does not print it twice.
    #[error("{path}: {cause}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        cause: std::io::Error,
    },
}

/// Result with the crate's [`Error`].
pub type Result<T> = std::result::Result<T, Error>;
