//! Writing to standard output and error without panicking. `println!`
//! panics when the stream is full or closed (`treelet build > /dev/full`);
//! the program's own `println!`, `print!` and `eprintln!` (macros defined in
//! `main.rs` and the crate root) come here instead. A failed write to
//! standard output is kept, later writes to it are dropped, and the program
//! exits 1 with a note ([`finish`]); notes on standard error are optional,
//! and a failed one is dropped.
use std::io::Write;
use std::sync::OnceLock;

/// The first failed write to standard output.
static STDOUT_ERROR: OnceLock<std::io::Error> = OnceLock::new();

/// Writes `args` (and a newline) to standard output, unless a write to it
/// failed before.
pub fn out(args: std::fmt::Arguments, newline: bool) {
    if STDOUT_ERROR.get().is_some() {
        return;
    }
    let mut o = std::io::stdout().lock();
    let written = o.write_fmt(args).and_then(|_| if newline { o.write_all(b"\n") } else { Ok(()) });
    if let Err(e) = written {
        let _ = STDOUT_ERROR.set(e);
    }
}

/// Writes `args` and a newline to standard error; a failure is dropped.
pub fn err(args: std::fmt::Arguments) {
    let mut e = std::io::stderr().lock();
    let _ = e.write_fmt(args).and_then(|_| e.write_all(b"\n"));
}

/// Flushes standard output: the first write to it that failed, if any
/// (a closed pipe, `| head`, is not a failure the user needs told of).
pub fn finish() -> Result<(), &'static std::io::Error> {
    if let Err(e) = std::io::stdout().lock().flush() {
        let _ = STDOUT_ERROR.set(e);
    }
    match STDOUT_ERROR.get() {
        Some(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(e),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn notes_never_panic() {
        super::err(format_args!("a note {}", 1));
        super::out(format_args!(""), false);
    }
}
