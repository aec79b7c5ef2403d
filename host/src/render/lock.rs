//! A lock file beside a render's output for the life of the render
//! (`image.png.lock`, holding `pid host`): a second render of the same
//! `--out` (and so of the same checkpoint beside it) refuses to start,
//! naming the first one, instead of the two writing over each other's part
//! and one deleting it at the end. A lock left by a render that was killed
//! (`kill -9`, a lost machine) is taken over when its process is gone.
use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

/// Held while a render writes `out`; the file is removed when dropped.
pub struct OutputLock {
    path: Option<PathBuf>,
}

impl OutputLock {
    /// Takes the lock of `out`. Outputs that are not regular files (a
    /// device such as `/dev/null`, a pipe) take none.
    pub fn take(out: &Path) -> Result<OutputLock> {
        if std::fs::metadata(out).is_ok_and(|m| !m.is_file()) {
            return Ok(OutputLock { path: None });
        }
        let name = out.file_name().with_context(|| format!("--out {}: names no file", out.display()))?;
        let path = out.with_file_name(format!("{}.lock", name.to_string_lossy()));
        let host = host_name();
        for _ in 0..3 {
            match std::fs::OpenOptions::new().write(true).create_new(true).open(&path) {
                Ok(mut f) => {
                    writeln!(f, "{} {host}", std::process::id()).with_context(|| format!("cannot write the lock {}", path.display()))?;
                    return Ok(OutputLock { path: Some(path) });
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                    let text = std::fs::read_to_string(&path).unwrap_or_default();
                    let mut words = text.split_whitespace();
                    let (pid, their_host) = (words.next().and_then(|p| p.parse::<u32>().ok()), words.next().unwrap_or(""));
                    match pid {
                        // A lock being written this instant: look again.
                        None if text.is_empty() => std::thread::sleep(std::time::Duration::from_millis(50)),
                        Some(pid) if their_host == host && !alive(pid) => {}
                        Some(pid) => bail!(
                            "{} is being rendered by another treelet (pid {pid} on {}; lock {}): wait for it to finish, or render to another --out (if no such render runs, delete the lock)",
                            out.display(),
                            if their_host.is_empty() { "an unknown host" } else { their_host },
                            path.display()
                        ),
                        None => bail!("{}: a lock that names no process: delete it if no render of {} runs", path.display(), out.display()),
                    }
                    // Its render is gone (killed): the lock is taken over.
                    if pid.is_some() {
                        let _ = std::fs::remove_file(&path);
                    }
                }
                Err(e) => bail!("cannot create the lock {} beside --out: {e}", path.display()),
            }
        }
        bail!("{}: could not take the lock (another render took and left it repeatedly)", path.display())
    }
}

impl Drop for OutputLock {
    fn drop(&mut self) {
        if let Some(p) = &self.path {
            let _ = std::fs::remove_file(p);
        }
    }
}

fn host_name() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .or_else(|_| std::fs::read_to_string("/etc/hostname"))
        .map(|h| h.trim().to_string())
        .ok()
        .filter(|h| !h.is_empty() && !h.contains(char::is_whitespace))
        .unwrap_or_else(|| "localhost".into())
}

/// Whether process `pid` of this host runs (where the system says; else
/// assumed, so a lock is never taken from a live render).
fn alive(pid: u32) -> bool {
    if Path::new("/proc/self").exists() {
        Path::new(&format!("/proc/{pid}")).exists()
    } else {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_lock_is_refused_and_a_dead_ones_taken_over() {
        let dir = std::env::temp_dir().join(format!("treelet-lock-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let out = dir.join("image.png");
        let first = OutputLock::take(&out).unwrap();
        let lock = dir.join("image.png.lock");
        assert!(lock.exists());
        // This process holds it: a second take is another render's.
        let e = OutputLock::take(&out).err().expect("a second lock").to_string();
        assert!(e.contains(&format!("pid {}", std::process::id())) && e.contains("image.png.lock"), "{e}");
        drop(first);
        assert!(!lock.exists(), "dropped with its render");
        // A lock of a process that is gone (pid past the kernel's largest).
        std::fs::write(&lock, format!("4294967295 {}\n", host_name())).unwrap();
        let taken = OutputLock::take(&out).unwrap();
        assert!(std::fs::read_to_string(&lock).unwrap().starts_with(&std::process::id().to_string()));
        drop(taken);
        // Another host's lock is never taken: its process cannot be asked.
        std::fs::write(&lock, "12345 some-other-host\n").unwrap();
        let e = OutputLock::take(&out).err().expect("another host's lock").to_string();
        assert!(e.contains("pid 12345 on some-other-host"), "{e}");
        // Devices take no lock.
        assert!(OutputLock::take(Path::new("/dev/null")).is_ok());
        std::fs::remove_dir_all(&dir).ok();
    }
}
