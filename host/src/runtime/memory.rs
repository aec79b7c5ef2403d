//! Host memory: what the machine has left, and a check that refuses work
//! whose estimate is past it, before anything is allocated (an allocation
//! that fails aborts the process, with no word of what was too large).
use anyhow::{bail, Result};

/// Bytes of memory available to new allocations (free, plus caches the
/// kernel gives back), or `None` where it cannot be read.
/// `TREELET_MAX_MEMORY=BYTES` caps it (to leave room for other work on a
/// shared machine, and for tests).
pub fn available_bytes() -> Option<u64> {
    let cap = std::env::var("TREELET_MAX_MEMORY").ok().and_then(|v| v.trim().parse::<u64>().ok());
    match (machine_available_bytes(), cap) {
        (Some(a), Some(c)) => Some(a.min(c)),
        (a, c) => a.or(c),
    }
}

fn machine_available_bytes() -> Option<u64> {
    let mut sys = sysinfo::System::new();
    sys.refresh_memory();
    let available = sys.available_memory();
    // A cgroup's limit (a container, a Slurm job) is what this process may use.
    let limit = sys.cgroup_limits().map(|c| c.free_memory);
    match (available, limit) {
        (0, None) => None,
        (a, Some(l)) if a > 0 => Some(a.min(l)),
        (0, Some(l)) => Some(l),
        (a, _) => Some(a),
    }
}

/// Bytes as people read them: `1.5 GiB`.
pub fn human(bytes: u64) -> String {
    const UNITS: [&str; 5] = ["bytes", "KiB", "MiB", "GiB", "TiB"];
    let mut v = bytes as f64;
    let mut unit = 0;
    while v >= 1024.0 && unit + 1 < UNITS.len() {
        v /= 1024.0;
        unit += 1;
    }
    if unit == 0 {
        format!("{bytes} bytes")
    } else {
        format!("{v:.1} {}", UNITS[unit])
    }
}

/// Refuses `what` if it needs more than the memory available: the error
/// gives the estimate, what it is made of (`detail`) and the limit.
pub fn check_fits(what: &str, needed: u64, detail: &str) -> Result<()> {
    if let Some(available) = available_bytes() {
        if needed > available {
            bail!(
                "{what} needs about {} of memory ({detail}), and this machine has {} available",
                human(needed),
                human(available)
            );
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_machine_reports_memory_and_an_absurd_need_is_refused() {
        let available = available_bytes().expect("Linux reports its memory");
        assert!(available > 1 << 20, "{available}");
        let e = check_fits("a test", u64::MAX / 2, "all of it").unwrap_err().to_string();
        assert!(e.contains("a test") && e.contains("all of it") && e.contains("available"), "{e}");
        check_fits("a test", 1024, "a little").unwrap();
        assert_eq!(human(512), "512 bytes");
        assert_eq!(human(3 << 29), "1.5 GiB");
    }
}
