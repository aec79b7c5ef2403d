//! GPU clocks around a benchmark, where the driver's tool reports them
//! (`nvidia-smi`), so that a run made at a low clock (a GPU still waking
//! up, power capping) shows beside its times. Elsewhere there is none to
//! read through Vulkan, and the benchmark says so.

/// One reading of the first GPU's clocks, in MHz.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub(crate) struct Clocks {
    pub(crate) sm_mhz: u32,
    pub(crate) sm_max_mhz: u32,
    pub(crate) memory_mhz: u32,
}

/// The clocks `nvidia-smi` reports for the first GPU, or `None` where it
/// is missing or says something else.
pub(crate) fn read() -> Option<Clocks> {
    let out = std::process::Command::new("nvidia-smi")
        .args(["--query-gpu=clocks.sm,clocks.max.sm,clocks.mem", "--format=csv,noheader,nounits"])
        .output()
        .ok()?;
    if !out.status.success() {
        return None;
    }
    parse(&String::from_utf8_lossy(&out.stdout))
}

/// The first line of `nvidia-smi`'s CSV: `sm, max sm, memory`.
fn parse(csv: &str) -> Option<Clocks> {
    let values: Vec<u32> = csv.lines().next()?.split(',').map(|v| v.trim().parse().ok()).collect::<Option<_>>()?;
    match values[..] {
        [sm_mhz, sm_max_mhz, memory_mhz] => Some(Clocks { sm_mhz, sm_max_mhz, memory_mhz }),
        _ => None,
    }
}

/// A line for the benchmark's output: the clocks before and after it.
pub(crate) fn describe(before: Option<Clocks>, after: Option<Clocks>) -> String {
    match (before, after) {
        (Some(b), Some(a)) => format!(
            "clocks (nvidia-smi, first GPU): SM {} MHz before the benchmark, {} after (max {}), memory {} MHz{}",
            b.sm_mhz,
            a.sm_mhz,
            a.sm_max_mhz,
            a.memory_mhz,
            // A benchmark that leaves the GPU idle between its timed parts
            // (host work) lets the driver lower the clock, and times slow
            // work: say so beside the numbers.
            if 5 * a.sm_mhz.min(b.sm_mhz) < 4 * a.sm_max_mhz {
                "; the SM clock was below 80% of its maximum: device times here are slower than at full clock"
            } else {
                ""
            }
        ),
        _ => "clocks: not known (no nvidia-smi; Vulkan does not report them)".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_nvidia_smi_csv() {
        assert_eq!(
            parse("1980, 1980, 2619\n1410, 1980, 2619\n"),
            Some(Clocks { sm_mhz: 1980, sm_max_mhz: 1980, memory_mhz: 2619 })
        );
        assert_eq!(parse("[N/A], 1980, 2619\n"), None);
        assert_eq!(parse(""), None);
        assert_eq!(parse("1, 2\n"), None);
    }

    #[test]
    fn a_fallen_clock_is_pointed_out() {
        let c = |sm_mhz| Some(Clocks { sm_mhz, sm_max_mhz: 1980, memory_mhz: 2619 });
        assert!(!describe(c(1980), c(1980)).contains("below 80%"));
        assert!(describe(c(1980), c(345)).contains("below 80%"));
        assert!(describe(c(1200), c(1980)).contains("below 80%"));
    }
}
