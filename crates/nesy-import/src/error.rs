//! Why an import failed: always the file (or folder) and what was expected of it.

use std::path::PathBuf;

/// An import that could not be done.
#[derive(Debug, thiserror::Error)]
pub enum ImportError {
    /// A file or folder could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The source is not what an import can read, or holds something unexpected.
    #[error("{}: {message}", path.display())]
    Invalid {
        /// The file or folder at fault.
        path: PathBuf,
        /// What was expected, and what was found.
        message: String,
    },
    /// The keyframe choice cannot be made on this source.
    #[error("{}: keyframes: {message}", path.display())]
    Keyframes {
        /// The source.
        path: PathBuf,
        /// Why.
        message: String,
    },
    /// A frame could not be read as one of its view's, or the demo folder could not be
    /// written or read back (the error names the file).
    #[error("{0}")]
    Demo(#[from] nesy_sim::demo::DemoError),
}

impl ImportError {
    pub(crate) fn io(path: impl Into<PathBuf>, source: std::io::Error) -> ImportError {
        ImportError::Io {
            path: path.into(),
            source,
        }
    }

    pub(crate) fn invalid(path: impl Into<PathBuf>, message: impl Into<String>) -> ImportError {
        ImportError::Invalid {
            path: path.into(),
            message: message.into(),
        }
    }
}
