//! The library's error, typed by what a caller can do about it
//! ([`ErrorKind`]), with the whole story in its message.
//!
//! The engine API ([`crate::tracer`]) returns [`Error`]. Inside, the
//! library's code builds `anyhow` chains (what failed, within what); the
//! places that know a failure's kind mark it ([`input`], [`too_large`],
//! [`device`]), and the mark survives the context added above it.
//!
//! ```
//! use treelet::{CpuBackend, Quality, Tracer, Triangle};
//! use treelet::error::ErrorKind;
//! let bad = [Triangle::new([0.0, 0.0, 0.0], [f32::NAN, 0.0, 0.0], [0.0, 1.0, 0.0])];
//! let e = Tracer::build(&mut CpuBackend::new(), &[], &bad, Quality::Fast).err().unwrap();
//! assert_eq!(e.kind(), ErrorKind::Input);
//! assert!(e.to_string().contains("triangle 0"), "{e}");
//! ```
use std::fmt;

/// What kind of failure an [`Error`] is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum ErrorKind {
    /// The input cannot be traced or built: a mesh, an instance, a ray or
    /// a buffer (the message names which, and where). Fix the input.
    Input,
    /// The work is past what the device or the machine holds (the message
    /// gives the size and the limit). Split it, or use a larger device.
    TooLarge,
    /// The device cannot run Treelet (a missing feature, not Vulkan) or
    /// failed.
    Device,
    /// Anything else: files, or a check of the library's own.
    Other,
}

/// An error of the library: its [`kind`](Error::kind), and a message that
/// holds the whole chain (`what failed: within what: ...`).
#[derive(Debug, thiserror::Error)]
#[error("{message}")]
pub struct Error {
    kind: ErrorKind,
    message: String,
}

impl Error {
    /// What kind of failure this is.
    pub fn kind(&self) -> ErrorKind {
        self.kind
    }
}

/// A result of the library's API.
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl From<anyhow::Error> for Error {
    /// The kind the chain was marked with (the innermost mark, or typed
    /// error of a public function called within), else
    /// [`ErrorKind::Other`].
    fn from(e: anyhow::Error) -> Self {
        let kind = e
            .chain()
            .filter_map(|c| c.downcast_ref::<Marked>().map(|m| m.kind).or_else(|| c.downcast_ref::<Error>().map(|e| e.kind)))
            .last()
            .unwrap_or(ErrorKind::Other);
        Error { kind, message: format!("{e:#}") }
    }
}

/// A failure whose kind is known where it happens.
#[derive(Debug)]
struct Marked {
    kind: ErrorKind,
    message: String,
}

impl fmt::Display for Marked {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Marked {}

fn marked(kind: ErrorKind, message: impl fmt::Display) -> anyhow::Error {
    anyhow::Error::new(Marked { kind, message: message.to_string() })
}

/// An [`ErrorKind::Input`] failure, to return through `anyhow`.
pub fn input(message: impl fmt::Display) -> anyhow::Error {
    marked(ErrorKind::Input, message)
}

/// An [`ErrorKind::TooLarge`] failure, to return through `anyhow`.
pub fn too_large(message: impl fmt::Display) -> anyhow::Error {
    marked(ErrorKind::TooLarge, message)
}

/// An [`ErrorKind::Device`] failure, to return through `anyhow`.
pub fn device(message: impl fmt::Display) -> anyhow::Error {
    marked(ErrorKind::Device, message)
}

/// Runs `body` (the library's `anyhow` code) and types its error: how a
/// public function returns [`Result`].
pub(crate) fn typed<T>(body: impl FnOnce() -> anyhow::Result<T>) -> Result<T> {
    body().map_err(Error::from)
}

#[cfg(test)]
mod tests {
    use super::*;
    use anyhow::Context;

    #[test]
    fn the_mark_survives_context_and_the_message_keeps_the_chain() {
        let e: anyhow::Result<()> = Err(input("triangle 3 has a NaN coordinate"));
        let e = Error::from(e.context("mesh 2").unwrap_err());
        assert_eq!(e.kind(), ErrorKind::Input);
        assert_eq!(e.to_string(), "mesh 2: triangle 3 has a NaN coordinate");
        let plain = Error::from(anyhow::anyhow!("disk full"));
        assert_eq!(plain.kind(), ErrorKind::Other);
        // Back into anyhow (the command's `?`), the message is not repeated.
        let again = anyhow::Error::from(Error::from(too_large("a buffer of 9 GiB")));
        assert_eq!(format!("{again:#}"), "a buffer of 9 GiB");
    }
}
