//! What every target does with its input: writes it as a file of the
//! reader's kind and reads it back through the library's public loader, as
//! the `treelet` command does. A panic, an abort or a hang is libFuzzer's
//! finding; so is an error that does not name the file (the promise of the
//! README's "Bad input", and of the proptest fuzzers in `tests/fuzz.rs`).
use std::fmt::Display;
use std::path::{Path, PathBuf};

/// Writes `data` to a file named `name` in this process's scratch folder and
/// runs `load` on it; an error must name the file.
pub fn on_file<T, E: Display>(data: &[u8], name: &str, load: impl Fn(&Path) -> Result<T, E>) {
    let path = scratch().join(name);
    std::fs::write(&path, data).expect("the fuzzer's scratch folder takes the input");
    if let Err(e) = load(&path) {
        let message = format!("{e:#}");
        assert!(message.contains(&path.display().to_string()), "the error does not name {}: {message}", path.display());
    }
}

/// A folder of this process's own, in memory where the machine has one
/// (`/dev/shm`): libFuzzer runs thousands of inputs a second.
fn scratch() -> &'static Path {
    static DIR: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    DIR.get_or_init(|| {
        let base = Path::new("/dev/shm");
        let base = if base.is_dir() { base.to_path_buf() } else { std::env::temp_dir() };
        let dir = base.join(format!("treelet-fuzz-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("a scratch folder for the fuzzer's inputs");
        dir
    })
}
