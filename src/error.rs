//! The library's error type. Every variant says what was wrong, where (file,
//! line, column when there is one) and what is allowed, so `main` can print it
//! as is and exit non-zero.

use std::path::PathBuf;

/// Errors returned by the cumulus library.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A text input (sounding, profile) could not be read at a given place.
    #[error("{}: {message}", place(path, *line, *column))]
    Parse {
        path: PathBuf,
        /// 1-based line; 0 when the error concerns the whole file.
        line: usize,
        /// 1-based column; 0 when unknown.
        column: usize,
        message: String,
    },
    /// A file could not be opened, read or written.
    #[error("{}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// A parameter (from a profile, the CLI or the panel) is outside what the
    /// model accepts.
    #[error("invalid {name} = {value}: {allowed}")]
    InvalidParameter {
        name: String,
        value: String,
        allowed: String,
    },
    /// No GPU adapter could be found or opened.
    #[error(
        "no GPU adapter: {0}. On Debian/Ubuntu without a GPU, `apt-get install mesa-vulkan-drivers libvulkan1` gives a CPU Vulkan adapter (llvmpipe)"
    )]
    NoAdapter(String),
    /// The GPU rejected a resource or ran out of limits.
    #[error("GPU: {0}")]
    Gpu(String),
    /// The adapter cannot run what was asked (the message names the
    /// adapter, what it lacks and the fix); the command exits with code 2.
    #[error("{0}")]
    Unsupported(String),
}

impl Error {
    /// A parse error at `path:line:column`.
    pub fn parse(
        path: impl Into<PathBuf>,
        line: usize,
        column: usize,
        message: impl Into<String>,
    ) -> Self {
        Error::Parse {
            path: path.into(),
            line,
            column,
            message: message.into(),
        }
    }

    /// A parameter outside its allowed range.
    pub fn invalid(
        name: impl Into<String>,
        value: impl std::fmt::Display,
        allowed: impl Into<String>,
    ) -> Self {
        Error::InvalidParameter {
            name: name.into(),
            value: value.to_string(),
            allowed: allowed.into(),
        }
    }

    /// An I/O error on `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }
}

/// `file:line:column`, or `file:line`, or `file` when they are unknown (0).
fn place(path: &std::path::Path, line: usize, column: usize) -> String {
    match (line, column) {
        (0, _) => path.display().to_string(),
        (l, 0) => format!("{}:{l}", path.display()),
        (l, c) => format!("{}:{l}:{c}", path.display()),
    }
}

/// Result with the library's error.
pub type Result<T> = std::result::Result<T, Error>;

/// Byte offset → 1-based (line, column).
pub fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before
        .rsplit('\n')
        .next()
        .map(|s| s.chars().count())
        .unwrap_or(0)
        + 1;
    (line, col)
}
