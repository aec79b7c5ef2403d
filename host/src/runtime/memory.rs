//! Host memory: what the machine has left, and a check that refuses work
//! whose estimate is past it, before anything is allocated (an allocation
//! that fails aborts the process, with no word of what was too large).
use anyhow::Result;

/// Bytes of memory available to new allocations (free, plus caches the
/// kernel gives back), or `None` where it cannot be read.
/// The process's [`Tuning`](crate::tuning::Tuning) caps it
/// (`TREELET_MAX_MEMORY` for the command: room for other work on a shared
/// machine, and for tests): see [`memory_cap`].
pub fn available_bytes() -> Option<u64> {
    let cap = memory_cap();
    match (machine_available_bytes(), cap) {
        (Some(a), Some(c)) => Some(a.min(c)),
        (a, c) => a.or(c),
    }
}

/// The cap `TREELET_MAX_MEMORY` sets (`None` where unset or empty), as the
/// process's [`Tuning`](crate::tuning::Tuning) holds it: bytes, or a number
/// with a unit (`8GiB`, `512M`, `1.5GB`; see [`crate::tuning::parse_bytes`]).
pub fn memory_cap() -> Option<u64> {
    crate::tuning::Tuning::current().max_memory
}

fn machine_available_bytes() -> Option<u64> {
    let mut sys = sysinfo::System::new();
    sys.refresh_memory();
    let available = sys.available_memory();
    // A cgroup's limit (a container, a Slurm job) is what this process may
    // use; and `ulimit -v` (RLIMIT_AS) bounds its address space, which an
    // allocation past it fails to grow (an abort, after the work).
    let limits = [sys.cgroup_limits().map(|c| c.free_memory), address_space_room()];
    let limit = limits.into_iter().flatten().min();
    match (available, limit) {
        (0, None) => None,
        (a, Some(l)) if a > 0 => Some(a.min(l)),
        (0, Some(l)) => Some(l),
        (a, _) => Some(a),
    }
}

/// Room left under the address-space limit (`ulimit -v`): the soft limit
/// of `/proc/self/limits` less the process's size now (`VmSize` of
/// `/proc/self/status`); `None` where there is no limit or no `/proc`.
fn address_space_room() -> Option<u64> {
    let limits = std::fs::read_to_string("/proc/self/limits").ok()?;
    let soft = limits.lines().find(|l| l.starts_with("Max address space"))?.split_whitespace().nth(3)?.parse::<u64>().ok()?;
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let size_kb = status.lines().find(|l| l.starts_with("VmSize:"))?.split_whitespace().nth(1)?.parse::<u64>().ok()?;
    Some(soft.saturating_sub(size_kb * 1024))
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
            // Where the cap set the limit, say so: "this machine has 1 byte"
            // read as a fault of the machine's.
            let capped = memory_cap().is_some_and(|c| c <= available);
            let limit = if capped { " (the cap TREELET_MAX_MEMORY sets)" } else { "" };
            return Err(crate::error::too_large(format!("{what} needs about {} of memory ({detail}), and this machine has {} available{limit}",
                human(needed),
                human(available))));
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
