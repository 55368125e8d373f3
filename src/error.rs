//! The library's one error type.

use std::path::PathBuf;

/// Everything that can go wrong in tessera, each naming its input.
///
/// # Example
/// ```
/// let e = tessera::Error::Density("cap:1,2".into(), "expected 4 numbers".into());
/// assert!(e.to_string().contains("cap:1,2"));
/// ```
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A density specification or function that cannot be used.
    #[error("density '{0}': {1}")]
    Density(String, String),
    /// A request the sampler cannot honour.
    #[error("invalid request: {0}")]
    Request(String),
    /// A table file that does not decode or does not fit this build.
    #[error("table: {0}")]
    Table(String),
    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the system said.
        source: std::io::Error,
    },
    /// A file whose contents cannot be used.
    #[error("{path}: {reason}")]
    File {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        reason: String,
    },
}
